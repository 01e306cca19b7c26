//! Differential checks of activecal's kinematics against Pinocchio and
//! MuJoCo, and the reference fixtures the root crate tests against.
//!
//! Without features this crate is pure Rust: the model builders
//! ([`model::pinocchio_model_spec`], [`model::mjcf`]), the configurations
//! ([`sample`]), the comparisons ([`compare`]) and the fixture format
//! ([`fixture`]). With `live` it embeds Python through pyo3 ([`bridge`]) and
//! runs the checks ([`check`]); `cargo run -p verify --features live --
//! regen` rewrites `fixtures/`, `… -- check` prints the deviations.
//!
//! [`erd`] is the table of the serial arms of `example-robot-data`, and
//! [`erd_fk`] compares their import with Pinocchio's forward kinematics of
//! the same URDF files (live) and writes the fixtures of
//! `fixtures/example-robot-data/fk/`; [`export`] checks the calibrated URDF
//! activecal writes back (issue #26) with Pinocchio and writes
//! `fixtures/export/`.
//!
//! What is compared, at each configuration `q`: the end-point position
//! `p(q)` in the measurement frame, and the positional joint Jacobian
//! `∂p/∂q` (3 × dof), whose column `j` is also the identification-Jacobian
//! column of the γ offset of the frame that joint `j` drives (`Rz(q+γ)`), or
//! of its `d` if the joint is prismatic (`Tz(q+d)`).
//! Pinocchio: `forwardKinematics`, `computeFrameJacobian(…,
//! LOCAL_WORLD_ALIGNED)` top rows; MuJoCo: `site_xpos`, `mj_jacSite` after
//! `mj_kinematics` + `mj_comPos`.
#![warn(missing_docs)]

pub mod compare;
pub mod erd;
pub mod erd_fk;
pub mod export;
pub mod fixture;
pub mod gravity;
pub mod idjac;
pub mod model;
pub mod placement;
pub mod sample;

#[cfg(feature = "live")]
pub mod bridge;
#[cfg(feature = "live")]
pub mod check;

use activecal::model::{
    Convention, Frame, JointKind, MeasurementKind, ParamId, ParamTable, Robot, Symbol,
};

/// Largest deviation accepted between any two of activecal, Pinocchio,
/// MuJoCo and the fixtures, for positions (m) and Jacobian entries (m/rad).
///
/// Why 1e-12: the values are at most about 21 m (the PUMA's tracker is 20 m
/// from the base). Each implementation composes at most ~10 rigid transforms,
/// some tens of floating-point operations per coordinate, each with a relative
/// rounding error of ε = 1.1e-16, so a pessimistic bound is
/// 100 · ε · 21 m ≈ 2e-13 m; the deviations observed are at most 7.2e-15
/// (two units in the last place of 20 m; `cargo run -p verify --features
/// live -- check` prints them). A real kinematic mistake is many orders larger:
/// a flipped α or a swapped Hayati rotation order moves the end point by
/// centimetres to metres, and even a parameter off by 1e-9 moves it by
/// ~1e-8 m at 20 m. So 1e-12 m is above rounding with margin and far below
/// any error worth catching.
pub const TOLERANCE: f64 = 1e-12;

/// The built-in robots (`activecal::model::BUILTIN`), which get fixtures.
pub fn builtin_robots() -> activecal::Result<Vec<Robot>> {
    activecal::model::BUILTIN
        .iter()
        .map(|name| Robot::builtin(name))
        .collect()
}

/// A 7-joint robot unlike the built-in ones, to show the model builders and
/// checks are not tied to them: fixed frames at the base, between joints 3
/// and 4 (a Hayati one) and at the tool; driven Hayati frames, one of them a
/// prismatic joint with `d ≠ 0`; a joint range wider than 2π; metre-scale
/// offsets. Its unknowns are the joint offsets γ of the revolute frames and
/// the `d` of the prismatic one (it is not meant for calibration).
#[must_use]
pub fn synthetic_robot() -> Robot {
    use Convention::{Dh, Hayati};
    use JointKind::{Prismatic as P, Revolute as R};
    // (label, convention, joint, kind, [γ, α, a, d, β]); β is ignored on DH frames.
    type Row = (&'static str, Convention, Option<usize>, JointKind, [f64; 5]);
    let frames: [Row; 10] = [
        ("base", Dh, None, R, [0.3, 0.2, 1.5, -0.4, 0.0]),
        ("1", Dh, Some(0), R, [0.1, -1.5608, 0.05, 0.5, 0.0]),
        ("2", Hayati, Some(1), R, [-0.2, 0.02, 0.6, 0.0, 0.03]),
        ("3", Dh, Some(2), R, [0.05, 1.58, -0.03, 0.12, 0.0]),
        ("mid", Hayati, None, R, [0.5, 0.4, 0.1, 0.2, -0.3]),
        ("4", Dh, Some(3), R, [-0.07, -1.55, 0.0, 0.45, 0.0]),
        ("5", Hayati, Some(4), P, [0.02, 0.9, 0.08, 0.07, -0.11]),
        ("6", Dh, Some(5), R, [0.0, 1.5702, 0.0, 0.0, 0.0]),
        ("7", Dh, Some(6), R, [0.13, -0.3, 0.02, 0.09, 0.0]),
        ("tool", Dh, None, R, [0.2, 0.0, 0.05, 0.1, 0.0]),
    ];
    let nominal = ParamTable::from_rows(frames.iter().map(|f| f.4).collect());
    // The "real" robot: every parameter perturbed by a few milli-units.
    let real = ParamTable {
        rows: nominal
            .rows
            .iter()
            .enumerate()
            .map(|(i, row)| {
                let mut r = *row;
                for (c, v) in r.iter_mut().enumerate() {
                    *v += 1e-3 * (((7 * i + 3 * c) % 11) as f64 - 5.0);
                }
                r
            })
            .collect(),
        ..ParamTable::default()
    };
    let unknowns = frames
        .iter()
        .enumerate()
        .filter_map(|(frame, f)| match (f.2, f.3) {
            (None, _) => None,
            (Some(_), R) => Some(ParamId {
                frame,
                symbol: Symbol::Gamma,
            }),
            (Some(_), P) => Some(ParamId {
                frame,
                symbol: Symbol::D,
            }),
        })
        .collect();
    let robot = Robot {
        name: "synthetic7".into(),
        frames: frames
            .iter()
            .map(|&(label, convention, joint, kind, _)| match joint {
                None => Frame::fixed(label, convention),
                Some(j) => Frame::driven(label, convention, j, kind),
            })
            .collect(),
        real,
        nominal,
        unknowns,
        limits: vec![
            [-3.0, 3.0],
            [-1.9, 2.2],
            [-2.5, 0.4],
            [-3.5, 4.0],
            [-0.3, 0.4],
            [-1.0, 3.0],
            [-3.1, 3.1],
        ],
        measurement: MeasurementKind::Point,
        orientation_scale: activecal::model::DEFAULT_ORIENTATION_SCALE,
        source: None,
        gravity: None,
    };
    robot.validate().expect("synthetic robot is valid");
    robot
}
