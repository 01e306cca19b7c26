//! Robot models: a serial chain of DH or Hayati frames with named parameters,
//! real and nominal parameter tables, unknowns and joint limits.
//!
//! Each frame's transform is `Rz(q + γ) Tz(d) Tx(a) Rx(α)` (DH) or
//! `Rz(q + γ) Tx(a) Rx(α) Ry(β)` (Hayati; `d` is kept in the table and applied
//! as `Tz(d)` after `Rz`, so a Hayati frame with `d = 0` is exactly the
//! paper's). A frame driven by a prismatic joint moves along z instead:
//! `Rz(γ) Tz(q + d) …`. A fixed frame has no `q`. The measured point is the
//! origin of the last frame, expressed in the measurement frame ("coordinate
//! zero"); a full-pose measurement ([`MeasurementKind::Pose`]) adds the last
//! frame's orientation.
//!
//! The model imports no loader, no pool and no sensor: built-in arms are in
//! [`catalogue`]; robots from files come from [`crate::io`] (TOML
//! descriptions, URDF), which produces these types; the unknowns a
//! measurement can identify are chosen in [`crate::observability`].

mod builtin;
pub mod catalogue;
mod chain;
pub mod frame;
pub mod gravity;
mod measurement;
mod params;
pub mod robot_ref;
pub mod source;
mod validate;

pub use builtin::BUILTIN;
pub use chain::{Convention, Frame, JointKind};
pub use frame::{FrameMotion, frame_transform};
pub use measurement::{MeasurementKind, SensorKey};
pub use params::{ParamId, ParamSet, ParamTable, Symbol};

use crate::error::{Error, Result};
use serde::Serialize;

/// An immutable serial-chain robot model.
#[derive(Clone, Debug, Serialize)]
pub struct Robot {
    /// Name (`puma560` for the built-in PUMA).
    pub name: String,
    /// Frames from the measurement frame to the end point.
    pub frames: Vec<Frame>,
    /// Parameters of the real robot (simulation truth).
    pub real: ParamTable,
    /// Nominal parameters (the model the Jacobians are computed with).
    pub nominal: ParamTable,
    /// The unknown parameters, frame-major, in column order.
    pub unknowns: Vec<ParamId>,
    /// Joint limits `[lo, hi]`, one per joint: radians for a revolute joint,
    /// metres for a prismatic one.
    pub limits: Vec<[f64; 2]>,
    /// What is measured.
    pub measurement: MeasurementKind,
    /// Metres per radian that make an orientation error comparable to a
    /// position error (full-pose robots): the orientation rows of the
    /// identification Jacobian and the orientation residuals of
    /// identification are multiplied by it. Set it to `σ_position /
    /// σ_orientation` of the sensor (e.g. 0.05 mm / 0.01° ≈ 0.29 m/rad for a
    /// laser tracker with a 6-DoF probe), so that every weighted row carries
    /// the same noise σ_position and `XᵀX` is the Fisher information up to
    /// `σ²`. Default [`DEFAULT_ORIENTATION_SCALE`]; unused for points.
    pub orientation_scale: f64,
    /// The URDF the chain was imported from, when it was (see
    /// [`source::UrdfSource`]): what writing a calibrated URDF back needs.
    #[serde(skip)]
    pub source: Option<std::sync::Arc<source::UrdfSource>>,
    /// Gravity torques of the joints, when the robot's joints deflect under
    /// them: the kinematics then evaluate `q + c∘τ(q)` with the table's
    /// [`ParamTable::compliance`] (see [`gravity`]).
    #[serde(skip)]
    pub gravity: Option<std::sync::Arc<gravity::GravityModel>>,
}

/// Default [`Robot::orientation_scale`]: 1 m/rad, i.e. an orientation noise
/// in radians equal to the position noise in metres (0.01 rad ≈ 0.57° beside
/// 1 cm).
pub const DEFAULT_ORIENTATION_SCALE: f64 = 1.0;

impl Robot {
    /// Number of joints.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.limits.len()
    }

    /// Number of unknown kinematic parameters (the robot's, without the
    /// sensor's own marker offsets; see [`Robot::n_params`]).
    #[must_use]
    pub fn n_unknowns(&self) -> usize {
        self.unknowns.len()
    }

    /// Number of parameters identified, `p`: the robot's unknowns, then three
    /// offset coordinates per marker of a [`MeasurementKind::Markers`]
    /// sensor. The width of every identification Jacobian.
    #[must_use]
    pub fn n_params(&self) -> usize {
        self.unknowns.len() + 3 * self.measurement.markers()
    }

    /// Rows of the identification Jacobian per pose.
    #[must_use]
    pub fn rows_per_pose(&self) -> usize {
        self.measurement.rows()
    }

    /// The parameter table of a set.
    #[must_use]
    pub fn params(&self, set: ParamSet) -> &ParamTable {
        match set {
            ParamSet::Nominal => &self.nominal,
            ParamSet::Real => &self.real,
        }
    }

    /// Name of a parameter, `<symbol>_<frame>` (e.g. `gamma_a`, `d_3`).
    #[must_use]
    pub fn param_name(&self, id: ParamId) -> String {
        format!("{}_{}", id.symbol.name(), self.frames[id.frame].label)
    }

    /// Names of the identified parameters, in parameter-vector order: the
    /// unknowns, then the marker offsets (`marker1_x`, `marker1_y`, …).
    #[must_use]
    pub fn parameter_names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.unknowns.iter().map(|&u| self.param_name(u)).collect();
        for k in 1..=self.measurement.markers() {
            v.extend(["x", "y", "z"].map(|c| format!("marker{k}_{c}")));
        }
        v
    }

    /// Looks a parameter up by name.
    pub fn param_id(&self, name: &str) -> Result<ParamId> {
        let bad = || Error::UnknownParameter(name.to_string());
        let (sym, frame) = name.split_once('_').ok_or_else(bad)?;
        let symbol = match sym {
            "c" => Symbol::C,
            _ => Symbol::parse(sym).ok_or_else(bad)?,
        };
        let frame = self
            .frames
            .iter()
            .position(|f| f.label == frame)
            .ok_or_else(bad)?;
        if symbol == Symbol::Beta && self.frames[frame].convention == Convention::Dh {
            return Err(bad());
        }
        if symbol == Symbol::C && !self.is_compliant_frame(frame) {
            return Err(bad());
        }
        Ok(ParamId { frame, symbol })
    }

    /// Whether frame `frame` can carry a compliance unknown: the robot has a
    /// gravity model and a revolute joint drives the frame.
    #[must_use]
    pub fn is_compliant_frame(&self, frame: usize) -> bool {
        self.gravity.is_some()
            && self.frames[frame].joint.is_some()
            && self.frames[frame].joint_kind == JointKind::Revolute
    }

    /// The identified parameters' values in a table, in parameter-vector
    /// order ([`Robot::n_params`] of them: unknowns, then marker offsets).
    #[must_use]
    pub fn unknown_values(&self, table: &ParamTable) -> Vec<f64> {
        let mut v: Vec<f64> = self.unknowns.iter().map(|&u| table.get(u)).collect();
        v.extend(table.marker_values());
        v
    }

    /// A copy of `table` with the identified parameters set from `values`
    /// ([`Robot::n_params`] entries, or just the robot's unknowns: the
    /// markers then keep their values).
    #[must_use]
    pub fn with_unknowns(&self, table: &ParamTable, values: &[f64]) -> ParamTable {
        let p = self.unknowns.len();
        assert!(values.len() == p || values.len() == self.n_params());
        let mut t = table.clone();
        for (&u, &v) in self.unknowns.iter().zip(values) {
            t.set(u, v);
        }
        for (o, c) in t.markers.iter_mut().zip(values[p..].chunks_exact(3)) {
            o.copy_from_slice(c);
        }
        t
    }

    /// A copy of this robot with a different set of unknowns (validated).
    pub fn with_unknown_names(&self, names: &[&str]) -> Result<Robot> {
        let mut ids = names
            .iter()
            .map(|n| self.param_id(n))
            .collect::<Result<Vec<_>>>()?;
        ids.sort();
        ids.dedup();
        let mut r = self.clone();
        r.unknowns = ids;
        r.validate()?;
        Ok(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn puma_has_27_unknowns_in_table_order() {
        let r = Robot::puma560();
        r.validate().unwrap();
        let names = r.parameter_names();
        assert_eq!(names.len(), 27);
        assert_eq!(
            &names[..5],
            ["gamma_a", "alpha_a", "a_a", "beta_a", "gamma_0"]
        );
        assert_eq!(&names[24..], ["gamma_5", "a_5", "d_5"]);
    }

    #[test]
    fn names_round_trip_and_bad_names_fail() {
        let r = Robot::puma560();
        for &u in &r.unknowns {
            assert_eq!(r.param_id(&r.param_name(u)).unwrap(), u);
        }
        assert!(r.param_id("beta_2").is_err()); // frame 2 is DH
        assert!(r.param_id("foo_1").is_err());
        assert!(r.param_id("gamma_9").is_err());
    }
}
