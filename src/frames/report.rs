//! The calibrated frames as a report: what `calibrate` prints and what the
//! frames file (`cal.yaml`) holds. Units: metres and radians for values,
//! millimetres and degrees for changes and standard deviations, as their
//! names say; rpy as in URDF (`R = Rz(yaw) Ry(pitch) Rx(roll)`), quaternions
//! `[w, x, y, z]`.

use super::structure::{AxisRelation, relations};
use super::uncertainty::{FrameSigma, FramesSigma};
use super::{CalibratedFrames, chain::UrdfFrames};
use crate::measure::ToolRecord;
use crate::model::source::{UrdfSource, rpy};
use nalgebra::{Isometry3, Vector3};
use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};
use std::collections::BTreeMap;

/// The chain the frames belong to.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ChainBlock {
    /// Base link.
    pub base: String,
    /// Tip link.
    pub tip: String,
    /// Driven joints, in configuration order.
    pub joints: Vec<String>,
    /// Locked joints and their values (radians or metres).
    pub locked: BTreeMap<String, f64>,
}

/// A frame: the child's pose in the parent's frame.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct FrameBlock {
    /// The frame it is expressed in.
    pub parent: String,
    /// The frame it places (absent for a tool).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub child: Option<String>,
    /// Translation (m).
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw (rad).
    pub rpy: [f64; 3],
    /// Roll, pitch, yaw (degrees).
    pub rpy_deg: [f64; 3],
    /// Rotation as a unit quaternion `[w, x, y, z]`.
    pub quaternion: [f64; 4],
    /// σ of xyz (mm), when the fit has a covariance; `None` (null) for a
    /// coordinate no estimated unknown moves (see `fixed`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_xyz_mm: Option<[Option<f64>; 3]>,
    /// σ of a small rotation about the frame's own x, y, z axes (degrees);
    /// `None` (null) as for `sigma_xyz_mm`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_rotation_deg: Option<[Option<f64>; 3]>,
    /// The coordinates held at the file's value (no estimated unknown
    /// moves them: their σ is not 0, it is undefined), named `x y z rx ry
    /// rz`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub fixed: Vec<String>,
}

/// A marker (or the measured point) on the tip link.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct MarkerBlock {
    /// `point` for a point sensor, `marker1`… for markers.
    pub name: String,
    /// The tip link.
    pub parent: String,
    /// Position in the tip link's frame (m).
    pub xyz: [f64; 3],
    /// σ of xyz (mm); `None` (null) for a coordinate no estimated unknown
    /// moves (see `fixed`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_xyz_mm: Option<[Option<f64>; 3]>,
    /// The coordinates held at their nominal value (`x y z`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub fixed: Vec<String>,
}

/// A driven joint's calibrated origin.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct JointBlock {
    /// The joint's name (the key in the file).
    #[serde(skip)]
    pub name: String,
    /// The calibrated origin's translation (m).
    pub xyz: [f64; 3],
    /// The calibrated origin's rpy (rad).
    pub rpy: [f64; 3],
    /// Change of xyz from the file's (mm).
    pub delta_xyz_mm: [f64; 3],
    /// Change of rpy from the file's (degrees), with the calibrated rpy
    /// taken as the equivalent triple nearest the file's.
    pub delta_rpy_deg: [f64; 3],
    /// The change as a rotation about the joint frame's own x, y, z axes
    /// (degrees: the rotation vector of `R_fileᵀ R_calibrated`); unlike rpy
    /// it is small whenever the change is, gimbal lock or not.
    pub delta_rotation_deg: [f64; 3],
    /// Zero offset: the origin's turn about the joint's own axis (degrees).
    pub offset_deg: f64,
    /// σ of xyz (mm); `None` (null) for a coordinate no estimated unknown
    /// moves (see `fixed`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_xyz_mm: Option<[Option<f64>; 3]>,
    /// σ of the rotation change (degrees); `None` (null) as for
    /// `sigma_xyz_mm`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_rotation_deg: Option<[Option<f64>; 3]>,
    /// σ of the offset (degrees); `None` (null) when it is fixed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_offset_deg: Option<Option<f64>>,
    /// The coordinates held at the file's value (no estimated unknown
    /// moves them: their σ is not 0, it is undefined), named `x y z rx ry
    /// rz offset`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub fixed: Vec<String>,
    /// Largest |change / σ| over xyz and the rotation change.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_t: Option<f64>,
}

/// The joints, in chain order, written as a map from name to origin.
#[derive(Clone, Debug, PartialEq)]
pub struct Joints(pub Vec<JointBlock>);

impl Serialize for Joints {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for j in &self.0 {
            m.serialize_entry(&j.name, j)?;
        }
        m.end()
    }
}

/// How well the calibrated model fits its data.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct FitBlock {
    /// Poses fitted.
    pub poses: usize,
    /// Position RMS (mm).
    pub position_rms_mm: f64,
    /// Orientation RMS (degrees), full poses only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<f64>,
}

/// The calibrated frames report (and frames file).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct FramesReport {
    /// The input description's file name.
    pub robot: String,
    /// The chain.
    pub chain: ChainBlock,
    /// The sensor's frame → the base link.
    pub measurement_frame: FrameBlock,
    /// Tip link → measured frame (full poses).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tool: Option<FrameBlock>,
    /// The measured point or markers on the tip link.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub markers: Vec<MarkerBlock>,
    /// Each driven joint's calibrated origin.
    pub joints: Joints,
    /// Relations of consecutive joint axes, nominal against calibrated.
    pub structure: Vec<AxisRelation>,
    /// The fit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitBlock>,
    /// Each compliant joint's compliance, by joint name (a fit with
    /// compliances): the joint deflects by `c·τ(q)` under its gravity
    /// torque from the URDF's inertials.
    #[serde(skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub compliance: std::collections::BTreeMap<String, ComplianceBlock>,
    /// The points and planes of a contact fit ([`super::contact`]), in the
    /// measurement frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts: Option<ContactsBlock>,
    /// The camera and target placements of a camera fit
    /// ([`super::camera`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera: Option<CameraBlock>,
}

/// One joint's compliance in the frames file.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ComplianceBlock {
    /// Compliance, rad per N·m.
    pub c: f64,
    /// Stiffness `−1/c`, N·m per rad (absent for c = 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub k: Option<f64>,
    /// σ of `c`, when the fit has a covariance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_c: Option<f64>,
}

/// A fitted contact point in the frames file.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ContactPointBlock {
    /// The point's name (as in the contact file).
    pub name: String,
    /// Its position in the measurement frame (m).
    pub xyz: [f64; 3],
    /// σ of xyz (mm), when the fit has a covariance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma_xyz_mm: Option<[f64; 3]>,
}

/// A contact plane in the frames file: `normal · x = offset` in the
/// measurement frame.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ContactPlaneBlock {
    /// The plane's name.
    pub name: String,
    /// Whether it was given (not estimated).
    pub known: bool,
    /// Its unit normal.
    pub normal: [f64; 3],
    /// Its offset (m).
    pub offset: f64,
}

/// What the frames file adds for a camera.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct CameraBlock {
    /// `eye-to-hand` or `eye-in-hand`.
    pub mounting: crate::measure::camera::Mounting,
    /// For a camera on the robot's own link (a head): that link, the
    /// chain's base (the chain runs from it to the tip through the tree,
    /// [`crate::io::urdf_branch`]; the mounting is eye-to-hand of that
    /// chain). Absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera_link: Option<String>,
    /// The camera's optical frame (x right, y down, z forward) in its
    /// link.
    pub camera: FrameBlock,
    /// The target's frame in its link.
    pub target: FrameBlock,
    /// The pixel noise the fit estimated (σ per image coordinate), px.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pixel_sigma_px: Option<f64>,
    /// The RMS pixel error at the estimate, px.
    pub rms_px: f64,
    /// Rows of seen points (2 per point).
    pub pixel_rows: usize,
}

/// The contact setup a fit found: what the frames file adds for contacts.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ContactsBlock {
    /// The frame the points and planes are expressed in: `measurement`,
    /// the parent of `measurement_frame`.
    pub frame: String,
    /// The fitted tool offset in the model's end frame (m): what the fit
    /// estimated, before it is folded into the tool (`point` is the ball
    /// centre on the tip link).
    pub tool_offset_end_frame: [f64; 3],
    /// The fitted points.
    pub points: Vec<ContactPointBlock>,
    /// The planes.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub planes: Vec<ContactPlaneBlock>,
    /// The known distances the fit used (m).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub distances: Vec<crate::data::NamedDistance>,
}

fn quaternion(t: &Isometry3<f64>) -> [f64; 4] {
    let q = t.rotation.quaternion();
    [q.w, q.i, q.j, q.k]
}

fn mm(v: [f64; 3]) -> [f64; 3] {
    v.map(|x| x * 1e3)
}

fn deg(v: [f64; 3]) -> [f64; 3] {
    v.map(f64::to_degrees)
}

/// A frame's block: `t` places `child` in `parent`, with σ's.
pub(crate) fn frame_block(
    parent: &str,
    child: Option<&str>,
    t: &Isometry3<f64>,
    s: Option<&FrameSigma>,
) -> FrameBlock {
    let r = rpy(&t.rotation.to_rotation_matrix());
    FrameBlock {
        parent: parent.to_string(),
        child: child.map(str::to_string),
        xyz: t.translation.vector.into(),
        rpy: r,
        rpy_deg: deg(r),
        quaternion: quaternion(t),
        sigma_xyz_mm: s.map(|s| estimated(mm(s.xyz))),
        sigma_rotation_deg: s.map(|s| estimated(deg(s.rot))),
        fixed: s.map_or_else(Vec::new, |s| fixed_coordinates(&s.xyz, &s.rot, None)),
    }
}

/// Names of the coordinates a σ of exactly 0 marks as not estimated: the
/// split's derivatives below its noise are set to 0 (see
/// [`super::uncertainty::sigmas`]), so only a coordinate that no estimated
/// unknown moves has σ 0.
const COORDINATES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// σ's with the not-estimated ones (exactly 0) as `None`.
fn estimated(v: [f64; 3]) -> [Option<f64>; 3] {
    v.map(|x| (x != 0.0).then_some(x))
}

/// The names of the coordinates whose σ is exactly 0 (translation, then
/// rotation when given, then the joint offset when given).
fn fixed_coordinates(xyz: &[f64; 3], rot: &[f64], offset: Option<f64>) -> Vec<String> {
    let mut out: Vec<String> = xyz
        .iter()
        .chain(rot)
        .zip(COORDINATES)
        .filter(|(v, _)| **v == 0.0)
        .map(|(_, n)| n.to_string())
        .collect();
    if offset == Some(0.0) {
        out.push("offset".into());
    }
    out
}

/// `a − b` of rpy angles, each wrapped into (−π, π], with `a` replaced by
/// its other triple `(r + π, π − p, y + π)` when that is nearer `b`.
fn rpy_change(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    use std::f64::consts::{PI, TAU};
    let wrap = |x: f64| {
        let w = x - TAU * (x / TAU).round();
        if w <= -PI { w + TAU } else { w }
    };
    let diff = |a: [f64; 3]| -> [f64; 3] { std::array::from_fn(|i| wrap(a[i] - b[i])) };
    let (d1, d2) = (diff(a), diff([a[0] + PI, PI - a[1], a[2] + PI]));
    let size = |d: &[f64; 3]| d.iter().map(|x| x * x).sum::<f64>();
    if size(&d2) < size(&d1) { d2 } else { d1 }
}

fn joint_block(j: &super::JointOrigin, s: Option<(&FrameSigma, f64)>) -> JointBlock {
    let (r, rn) = (
        rpy(&j.calibrated.rotation.to_rotation_matrix()),
        rpy(&j.nominal.rotation.to_rotation_matrix()),
    );
    let dx: Vector3<f64> = j.calibrated.translation.vector - j.nominal.translation.vector;
    let dr = rpy_change(r, rn);
    let rot = (j.nominal.rotation.inverse() * j.calibrated.rotation).scaled_axis();
    let max_t = s.map(|(s, _)| {
        (0..3)
            .flat_map(|i| [dx[i] / s.xyz[i], rot[i] / s.rot[i]])
            .filter(|t| t.is_finite())
            .fold(0.0_f64, |m, t| m.max(t.abs()))
    });
    JointBlock {
        name: j.name.clone(),
        xyz: j.calibrated.translation.vector.into(),
        rpy: r,
        delta_xyz_mm: mm(dx.into()),
        delta_rpy_deg: deg(dr),
        delta_rotation_deg: deg(rot.into()),
        offset_deg: j.offset().to_degrees(),
        sigma_xyz_mm: s.map(|(s, _)| estimated(mm(s.xyz))),
        sigma_rotation_deg: s.map(|(s, _)| estimated(deg(s.rot))),
        sigma_offset_deg: s.map(|(_, o)| (o != 0.0).then(|| o.to_degrees())),
        fixed: s.map_or_else(Vec::new, |(s, o)| {
            fixed_coordinates(&s.xyz, &s.rot, Some(o))
        }),
        max_t,
    }
}

impl FramesReport {
    /// The report of calibrated frames `f` (with standard deviations
    /// `sigma` when the fit has them) of a robot from `src` whose sensor
    /// records `record` of the tool ([`crate::measure::Sensor::tool_record`]).
    #[must_use]
    pub fn new(
        src: &UrdfSource,
        record: ToolRecord,
        f: &CalibratedFrames,
        sigma: Option<&FramesSigma>,
        fit: Option<FitBlock>,
    ) -> FramesReport {
        let file = std::path::Path::new(&src.path)
            .file_name()
            .map_or_else(|| src.path.clone(), |n| n.to_string_lossy().into_owned());
        let chain = ChainBlock {
            base: src.base.clone(),
            tip: src.tip.clone(),
            joints: src.driven_names(),
            locked: src
                .joints
                .iter()
                .filter_map(|j| j.locked.map(|v| (j.name.clone(), v)))
                .collect(),
        };
        let (tool, markers) = match record {
            ToolRecord::Frame => (
                Some(frame_block(&src.tip, None, &f.tool, sigma.map(|s| &s.tool))),
                Vec::new(),
            ),
            ToolRecord::Point => (
                None,
                vec![MarkerBlock {
                    name: "point".into(),
                    parent: src.tip.clone(),
                    xyz: f.tool.translation.vector.into(),
                    sigma_xyz_mm: sigma.map(|s| estimated(mm(s.tool.xyz))),
                    fixed: sigma
                        .map_or_else(Vec::new, |s| fixed_coordinates(&s.tool.xyz, &[], None)),
                }],
            ),
            ToolRecord::Markers => (
                None,
                f.markers
                    .iter()
                    .enumerate()
                    .map(|(k, m)| MarkerBlock {
                        name: format!("marker{}", k + 1),
                        parent: src.tip.clone(),
                        xyz: (*m).into(),
                        sigma_xyz_mm: sigma.map(|s| estimated(mm(s.markers[k]))),
                        fixed: sigma
                            .map_or_else(Vec::new, |s| fixed_coordinates(&s.markers[k], &[], None)),
                    })
                    .collect(),
            ),
        };
        // A chain's first joint walked against the file's tree has no
        // origin of the file (the split keeps it; the camera's placement
        // holds what it would take): not a joint of the file's to report.
        let skip = usize::from(src.reversed.iter().any(|r| r.neighbour.is_none()));
        let joints = f
            .joints
            .iter()
            .enumerate()
            .skip(skip)
            .map(|(k, j)| joint_block(j, sigma.map(|s| (&s.joints[k], s.offsets[k]))))
            .collect();
        FramesReport {
            robot: file,
            chain,
            measurement_frame: frame_block(
                "measurement",
                Some(&src.base),
                &f.measurement,
                sigma.map(|s| &s.measurement),
            ),
            tool,
            markers,
            joints: Joints(joints),
            structure: relations(f, &UrdfFrames::of(src).before),
            fit,
            compliance: std::collections::BTreeMap::new(),
            contacts: None,
            camera: None,
        }
    }
}
