//! The frames file (`cal.yaml`): a calibration's measurement frame, tool or
//! markers and joint origins ([`crate::frames::report::FramesReport`]),
//! written as YAML, and read back to mount a (calibrated) URDF in the
//! sensor's frame with its tool.
//!
//! Written and read with `serde_saphyr` (pure Rust, maintained, panic-free),
//! the crate design files use too.

use crate::error::{Error, Result};
use crate::frames::report::FramesReport;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;
use std::path::Path;

/// The header of a written frames file.
const HEADER: &str = "# Calibrated frames written by activecal. Units: metres and radians (xyz, rpy);\n# millimetres and degrees where a name says so (_mm, _deg). rpy as in URDF:\n# R = Rz(yaw) Ry(pitch) Rx(roll); quaternion [w, x, y, z]. measurement_frame is\n# the base link's pose in the sensor's frame; tool the measured frame's pose in\n# the tip link's; markers are positions in the tip link's frame.\n";

/// The frames file's text.
pub fn to_yaml(report: &FramesReport) -> Result<String> {
    let body = serde_saphyr::to_string(report)
        .map_err(|e| Error::Invalid(format!("cannot write the frames as YAML: {e}")))?;
    Ok(format!("{HEADER}{body}"))
}

#[derive(Deserialize)]
struct FrameEntry {
    xyz: [f64; 3],
    rpy: [f64; 3],
}

#[derive(Deserialize)]
struct MarkerEntry {
    xyz: [f64; 3],
}

#[derive(Deserialize)]
struct ChainEntry {
    base: Option<String>,
    tip: Option<String>,
}

#[derive(Deserialize)]
struct ComplianceEntry {
    c: f64,
}

#[derive(Deserialize)]
struct FileEntry {
    chain: Option<ChainEntry>,
    measurement_frame: Option<FrameEntry>,
    tool: Option<FrameEntry>,
    #[serde(default)]
    markers: Vec<MarkerEntry>,
    #[serde(default)]
    compliance: std::collections::BTreeMap<String, ComplianceEntry>,
}

/// What a frames file gives to mount a robot.
#[derive(Clone, Debug, PartialEq)]
pub struct Frames {
    /// Measurement frame → base link.
    pub mount: Isometry3<f64>,
    /// Tip link → measured frame (the measured point's offset for a single
    /// point).
    pub tool: Isometry3<f64>,
    /// Marker offsets in the tip link's frame (two or more markers).
    pub markers: Vec<[f64; 3]>,
    /// The chain's base and tip links, if the file names them.
    pub base: Option<String>,
    /// The tip link.
    pub tip: Option<String>,
    /// Joint compliances (rad per N·m) by joint name: the chain deflects
    /// under its gravity torques (from the URDF's inertials).
    pub compliance: Vec<(String, f64)>,
}

fn iso(e: &FrameEntry) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(e.xyz[0], e.xyz[1], e.xyz[2]),
        UnitQuaternion::from_euler_angles(e.rpy[0], e.rpy[1], e.rpy[2]),
    )
}

/// Reads a frames file.
pub fn read(path: &Path) -> Result<Frames> {
    let name = path.display().to_string();
    let text = crate::io::read::read_text(path)?;
    parse(&text, &name)
}

/// Parses a frames file's text (`origin` names it in errors).
pub fn parse(text: &str, origin: &str) -> Result<Frames> {
    let bad = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let f: FileEntry =
        serde_saphyr::from_str(text).map_err(|e| bad(format!("not a frames file: {e}")))?;
    let finite = |what: &str, v: &[f64]| {
        if v.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(bad(format!("{what}: {v:?} is not finite")))
        }
    };
    for (what, e) in [
        ("measurement_frame", &f.measurement_frame),
        ("tool", &f.tool),
    ] {
        if let Some(e) = e {
            finite(&format!("{what}.xyz"), &e.xyz)?;
            finite(&format!("{what}.rpy"), &e.rpy)?;
        }
    }
    for (k, m) in f.markers.iter().enumerate() {
        finite(&format!("markers[{k}].xyz"), &m.xyz)?;
    }
    for (joint, c) in &f.compliance {
        finite(&format!("compliance.{joint}.c"), &[c.c])?;
    }
    if f.tool.is_some() && !f.markers.is_empty() {
        return Err(bad(
            "both a tool and markers: a frames file has one or the other".into(),
        ));
    }
    let mut tool = f.tool.as_ref().map_or_else(Isometry3::identity, iso);
    let mut markers: Vec<[f64; 3]> = f.markers.iter().map(|m| m.xyz).collect();
    if markers.len() == 1 {
        // One measured point: the tool's origin.
        tool = Isometry3::from_parts(
            Translation3::from(Vector3::from(markers[0])),
            UnitQuaternion::identity(),
        );
        markers.clear();
    }
    Ok(Frames {
        mount: f
            .measurement_frame
            .as_ref()
            .map_or_else(Isometry3::identity, iso),
        tool,
        markers,
        base: f.chain.as_ref().and_then(|c| c.base.clone()),
        tip: f.chain.as_ref().and_then(|c| c.tip.clone()),
        compliance: f.compliance.iter().map(|(j, c)| (j.clone(), c.c)).collect(),
    })
}
