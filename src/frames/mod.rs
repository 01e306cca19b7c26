//! The calibrated robot in the user's terms: the measurement frame, the
//! tool (or the markers) and each URDF joint's origin, apart.
//!
//! Identification fits a DH/Hayati model whose first frames fold the
//! measurement frame into the first joints, and whose last frame folds the
//! tool into the last. [`decompose`] reads the fitted model back onto the
//! URDF it was imported from ([`crate::model::source::UrdfSource`]): the
//! URDF joint frames of the fitted model at `q = 0` ([`chain`]), split by
//! the gauge of [`gauge`] into
//!
//! * the measurement frame `M`: the pose of the chain's base link in the
//!   sensor's frame;
//! * each driven joint's `<origin>` (xyz, rpy as in URDF), and its zero
//!   offset (the origin's turn about the joint's own axis);
//! * the tool `T`: the pose of the measured frame in the tip link's frame
//!   (its origin is the measured point), and each marker's offset in the
//!   tip link's frame.
//!
//! The standard deviations of all of them ([`uncertainty`]) are the fit's
//! covariance carried through this map by central differences.

pub mod align;
pub mod camera;
pub mod chain;
pub mod contact;
pub mod gauge;
pub mod plausible;
pub mod report;
pub mod structure;
pub mod uncertainty;

use crate::model::{JointKind, ParamTable, Robot, Symbol};
use chain::{ModelFrames, UrdfFrames, model_to_urdf};
use nalgebra::{Isometry3, Vector3};

/// Errors of the split.
#[derive(Debug, thiserror::Error)]
pub enum FramesError {
    /// The robot was not imported from a URDF.
    #[error(
        "robot '{0}' was not imported from a URDF file: its calibrated joint origins, measurement frame and tool can be written only for a .urdf robot"
    )]
    NoSource(String),
    /// The model's frames do not match its source's.
    #[error("the model does not match its URDF: {0}")]
    NotTheSource(String),
}

/// One driven joint's origin, nominal and calibrated.
#[derive(Clone, Debug)]
pub struct JointOrigin {
    /// The URDF joint's name.
    pub name: String,
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// Unit axis in the joint's frame.
    pub axis: Vector3<f64>,
    /// The file's origin.
    pub nominal: Isometry3<f64>,
    /// The calibrated origin.
    pub calibrated: Isometry3<f64>,
}

impl JointOrigin {
    /// The zero offset: the calibrated origin's turn about the joint's own
    /// axis (radians), as `R_nomᵀ R_cal`'s rotation vector along the axis.
    #[must_use]
    pub fn offset(&self) -> f64 {
        (self.nominal.rotation.inverse() * self.calibrated.rotation)
            .scaled_axis()
            .dot(&self.axis)
    }
}

/// The calibrated robot split into its frames.
#[derive(Clone, Debug)]
pub struct CalibratedFrames {
    /// Measurement frame → base link (the base link's pose in the sensor's
    /// frame).
    pub measurement: Isometry3<f64>,
    /// Tip link → measured frame.
    pub tool: Isometry3<f64>,
    /// Marker offsets in the tip link's frame (markers sensors).
    pub markers: Vec<Vector3<f64>>,
    /// Each driven joint's origin, in chain order.
    pub joints: Vec<JointOrigin>,
}

/// The chain's length scale: the sum of its origins' translations (metres;
/// at least 1 mm), which makes a translation comparable with a rotation in
/// the gauge's cost whatever the length unit.
fn length_scale(urdf: &UrdfFrames) -> f64 {
    let l: f64 = urdf
        .origin
        .iter()
        .chain(std::iter::once(&urdf.to_tip))
        .map(|o| o.translation.vector.norm())
        .sum();
    l.max(1e-3)
}

/// Driven joint `k`'s origin, nominal and `calibrated` (the split's), in
/// the file's terms: a joint the chain walks against the file's tree
/// ([`crate::model::source::Reversed`]) gives its neighbour's origin, the
/// inverse of its own in the chain.
fn in_file(
    src: &crate::model::source::UrdfSource,
    urdf: &UrdfFrames,
    k: usize,
    calibrated: Isometry3<f64>,
) -> JointOrigin {
    let neighbour = src
        .reversed
        .iter()
        .find(|r| r.joint == urdf.name[k])
        .and_then(|r| r.neighbour.as_ref());
    match neighbour {
        Some(n) => JointOrigin {
            name: n.name.clone(),
            kind: n.kind.unwrap_or(JointKind::Revolute),
            axis: n.axis.normalize(),
            nominal: n.origin,
            calibrated: calibrated.inverse(),
        },
        None => JointOrigin {
            name: urdf.name[k].clone(),
            kind: urdf.kind[k],
            axis: urdf.axis[k],
            nominal: urdf.origin[k],
            calibrated,
        },
    }
}

/// Splits `robot` at `table` into the measurement frame, the tool, the
/// markers and the joint origins of its URDF (see the module
/// documentation).
pub fn decompose(robot: &Robot, table: &ParamTable) -> Result<CalibratedFrames, FramesError> {
    let src = robot
        .source
        .as_ref()
        .ok_or_else(|| FramesError::NoSource(robot.name.clone()))?;
    let urdf = UrdfFrames::of(src);
    let to_urdf = model_to_urdf(robot, &urdf)?;
    let model = ModelFrames::of(robot, table);
    let cal: Vec<Isometry3<f64>> = model
        .joint
        .iter()
        .zip(&to_urdf)
        .map(|(z, c)| z * c)
        .collect();
    let split = gauge::split(&urdf, &cal, length_scale(&urdf));
    let base_to_first = src.mount.inverse() * urdf.joint[0];
    let measurement = split.joint[0] * base_to_first.inverse();
    let tip = split.joint[urdf.len() - 1] * urdf.to_tip;
    let tool = tip.inverse() * model.end;
    let markers = table
        .markers
        .iter()
        .map(|o| tool * nalgebra::Point3::from(Vector3::from(*o)))
        .map(|p| p.coords)
        .collect();
    let joints = (0..urdf.len())
        .map(|k| in_file(src, &urdf, k, split.origin[k]))
        .collect();
    Ok(CalibratedFrames {
        measurement,
        tool,
        markers,
        joints,
    })
}

/// The split of a robot imported from a URDF at `table` with its report:
/// standard deviations when the fit's covariance `cov` (of
/// [`Robot::unknown_values`]) is given, and the fit's figures. `None` for a
/// robot not imported from a URDF.
pub fn calibrated(
    robot: &Robot,
    table: &ParamTable,
    cov: Option<&[Vec<f64>]>,
    fit: Option<report::FitBlock>,
) -> Result<Option<(CalibratedFrames, report::FramesReport)>, FramesError> {
    let Some(src) = robot.source.as_ref() else {
        return Ok(None);
    };
    let f = decompose(robot, table)?;
    let sigma = cov
        .map(|c| uncertainty::sigmas(robot, table, c))
        .transpose()?;
    let mut r = report::FramesReport::new(
        src,
        crate::measure::sensor_for(robot).tool_record(),
        &f,
        sigma.as_ref(),
        fit,
    );
    let names = src.driven_names();
    for (k, u) in robot.unknowns.iter().enumerate() {
        let Some(j) = robot.frames[u.frame]
            .joint
            .filter(|_| u.symbol == Symbol::C)
        else {
            continue;
        };
        let c = table.get(*u);
        let sigma_c = cov
            .and_then(|m| m.get(k))
            .and_then(|row| row.get(k))
            .map(|v| v.sqrt());
        r.compliance.insert(
            names[j].clone(),
            report::ComplianceBlock {
                c,
                k: (c != 0.0).then(|| -1.0 / c),
                sigma_c,
            },
        );
    }
    Ok(Some((f, r)))
}
