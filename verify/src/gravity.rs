//! Gravity torques (issue #31) against Pinocchio: activecal's
//! [`activecal::model::gravity::GravityModel`], built from a URDF's
//! `<inertial>` elements by [`activecal::io::inertia::gravity_model`],
//! against `computeGeneralizedGravity` of Pinocchio's `buildModelFromUrdf`
//! of the same file, for the chain's joints, with locked joints at their
//! values and every other joint of the tree at neutral (0).
//!
//! The cases are the URDF chains of [`crate::export::cases`]: FIGAROH's
//! UR10 and TIAGo (torso free and locked) and every arm of
//! [`crate::erd::ARMS`]. The live check (`verify/tests/live_gravity.rs`)
//! compares [`N_RANDOM`] random configurations in the chain's limits; the
//! fixtures `fixtures/gravity/<case>.json` keep Pinocchio's torques at the
//! same configurations for the cases whose URDFs are in the repository,
//! read by `tests/gravity_fixtures.rs` without Python.
//!
//! Tolerance: [`TOLERANCE`] relative to the largest torque of the
//! configuration (a vertical joint's torque is 0 to rounding, so a relative
//! bar per entry means nothing there). Both sides sum at most ~100 products
//! of masses (≤ 100 kg) and lever arms (≤ 2 m) in double precision after
//! ~30 composed rigid transforms: rounding is ~1e-14 relative; a centre of
//! mass off by a micrometre changes a torque by ~1e-6 relative.

#[cfg(feature = "live")]
use crate::export::random_configurations;
use crate::export::{Case, Description, cases};
use crate::fixture::Versions;
use activecal::io::inertia::{InertiaOptions, gravity_model};
use activecal::model::Robot;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Version of the fixture layout.
pub const FORMAT: u32 = 1;
/// Random configurations per case (the 100), live and fixture.
pub const N_RANDOM: usize = 100;
/// Largest relative deviation accepted (the 1e-10).
pub const TOLERANCE: f64 = 1e-10;
/// What a fixture's torques are.
pub const REFERENCE: &str = "Pinocchio buildModelFromUrdf + computeGeneralizedGravity (gravity \
     -9.81 m/s^2 along the root's z): the torques (N m, N for prismatic joints) of the chain's \
     driven joints, locked joints at their values, every other joint at neutral";

/// The cases: the URDF chains of [`cases`] (one per chain: the marker case
/// shares the TIAGo's chain).
#[must_use]
pub fn gravity_cases(erd_dir: Option<&Path>) -> Vec<Case> {
    cases(erd_dir)
        .into_iter()
        .filter(|c| matches!(c.description, Description::Urdf(_)))
        .filter(|c| c.sensor != crate::export::Sensor::Markers)
        .collect()
}

/// activecal's gravity torques of a case's chain at `qs`.
pub fn activecal_torques(robot: &Robot, qs: &[Vec<f64>]) -> Result<Vec<Vec<f64>>> {
    let g = gravity_model(robot, &InertiaOptions::default())
        .with_context(|| format!("gravity model of {}", robot.name))?;
    Ok(qs.iter().map(|q| g.torques_at(q)).collect())
}

/// Largest relative deviation: per configuration `max_j |a_j − b_j|`
/// over `max_j |b_j|` (1 where `b` is all zero), the largest over
/// configurations; NaN if anything is NaN.
#[must_use]
pub fn relative_deviation(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    let mut worst = 0.0f64;
    for (x, y) in a.iter().zip(b) {
        if x.len() != y.len() {
            return f64::NAN;
        }
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let d = x
            .iter()
            .zip(y)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        let r = d / if scale > 0.0 { scale } else { 1.0 };
        if r.is_nan() {
            return f64::NAN;
        }
        worst = worst.max(r);
    }
    worst
}

/// One configuration and Pinocchio's torques.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GravitySample {
    /// The driven joints' values (radians, metres).
    pub q: Vec<f64>,
    /// Pinocchio's torques of the driven joints.
    pub tau: Vec<f64>,
}

/// A fixture file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GravityFixture {
    /// Layout version ([`FORMAT`]).
    pub format: u32,
    /// The case.
    pub case: String,
    /// The URDF, workspace-relative.
    pub description: String,
    /// Base link (`None`: the root).
    pub base: Option<String>,
    /// Tip link.
    pub tip: Option<String>,
    /// Locked joints.
    pub lock: Vec<(String, f64)>,
    /// The driven joints (the order of `q` and `tau`).
    pub joints: Vec<String>,
    /// The command that rewrites the file.
    pub regenerate: String,
    /// Software that produced the values.
    pub versions: Versions,
    /// What the torques are.
    pub reference: String,
    /// The samples.
    pub samples: Vec<GravitySample>,
}

impl GravityFixture {
    /// The file's text: keys in order, one sample per line.
    #[must_use]
    pub fn to_json(&self) -> String {
        use crate::fixture::{json_lines as lines, json_value as j};
        let fields: [(&str, String); 11] = [
            ("format", j(&self.format)),
            ("case", j(&self.case)),
            ("description", j(&self.description)),
            ("base", j(&self.base)),
            ("tip", j(&self.tip)),
            ("lock", j(&self.lock)),
            ("joints", j(&self.joints)),
            ("regenerate", j(&self.regenerate)),
            ("versions", j(&self.versions)),
            ("reference", j(&self.reference)),
            ("samples", lines(&self.samples)),
        ];
        crate::fixture::json_object(&fields)
    }

    /// Reads a fixture file.
    pub fn read(path: &Path) -> Result<GravityFixture> {
        crate::fixture::read_versioned(path, FORMAT, |f: &GravityFixture| f.format)
    }
}

/// `fixtures/gravity/`.
#[must_use]
pub fn default_dir() -> PathBuf {
    crate::erd_fk::workspace().join("fixtures").join("gravity")
}

/// The live part: Pinocchio's torques and the fixtures' regeneration.
#[cfg(feature = "live")]
pub mod live {
    use super::*;
    use crate::bridge::Bridge;

    /// A case's robot, its random configurations, and Pinocchio's torques
    /// there (locked joints at their values).
    pub fn pinocchio_case(
        bridge: &Bridge,
        case: &Case,
    ) -> Result<(Robot, Vec<String>, Vec<Vec<f64>>, Vec<Vec<f64>>)> {
        let robot = case.import()?;
        let src = robot.source.as_ref().context("a URDF case has a source")?;
        let driven = src.driven_names();
        let names: Vec<String> = driven
            .iter()
            .cloned()
            .chain(case.lock.iter().map(|(n, _)| n.clone()))
            .collect();
        let qs = random_configurations(&robot, N_RANDOM);
        let full: Vec<Vec<f64>> = qs
            .iter()
            .map(|q| {
                q.iter()
                    .copied()
                    .chain(case.lock.iter().map(|l| l.1))
                    .collect()
            })
            .collect();
        let path = case.path().context("a URDF case has a path")?;
        let tau = bridge
            .urdf_gravity(&path, &names, &full)?
            .into_iter()
            .map(|t| t[..driven.len()].to_vec())
            .collect();
        Ok((robot, driven, qs, tau))
    }

    /// A case's fixture.
    pub fn make_fixture(bridge: &Bridge, case: &Case) -> Result<GravityFixture> {
        let (_, joints, qs, tau) = pinocchio_case(bridge, case)?;
        Ok(GravityFixture {
            format: FORMAT,
            case: case.name.clone(),
            description: case.description_name(),
            base: case.base.clone(),
            tip: case.tip.clone(),
            lock: case.lock.clone(),
            joints,
            regenerate: crate::fixture::REGEN_COMMAND.to_string(),
            versions: bridge.versions().clone(),
            reference: REFERENCE.to_string(),
            samples: qs
                .into_iter()
                .zip(tau)
                .map(|(q, tau)| GravitySample { q, tau })
                .collect(),
        })
    }

    /// Writes the fixture of every case whose URDF is in the repository.
    pub fn regenerate(bridge: &Bridge, dir: &Path) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir)?;
        let mut written = Vec::new();
        for case in gravity_cases(None).iter().filter(|c| c.fixture) {
            let f = make_fixture(bridge, case)?;
            let path = dir.join(format!("{}.json", case.name));
            std::fs::write(&path, f.to_json())?;
            written.push(path);
        }
        Ok(written)
    }
}
