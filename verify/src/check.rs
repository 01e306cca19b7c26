//! The live differential checks (feature `live`): activecal's end-point
//! position and joint Jacobian against Pinocchio and MuJoCo, and the
//! regeneration of `fixtures/`.

use crate::TOLERANCE;
use crate::bridge::Bridge;
use crate::compare::{Deviation, activecal_kinematics, deviation};
use crate::fixture::{self, Fixture, set_name};
use crate::model::{mjcf_of_spec, pinocchio_model_spec};
use crate::sample::configurations;
use activecal::model::{ParamSet, Robot};
use anyhow::{Result, bail};
use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};

/// Random configurations of a live check (the `2^dof` corners come on top).
pub const LIVE_RANDOM: usize = 1000;
/// Seed of the live check's random configurations.
pub const LIVE_SEED: u64 = 20_251_107;

/// Outcome of one live check: a robot, a parameter set, its configurations.
#[derive(Clone, Debug, Serialize)]
pub struct CheckReport {
    /// Robot name.
    pub robot: String,
    /// `nominal` or `real`.
    pub param_set: &'static str,
    /// Number of configurations (random + corners).
    pub configurations: usize,
    /// Pinocchio vs activecal.
    pub pinocchio: Deviation,
    /// MuJoCo vs activecal.
    pub mujoco: Deviation,
    /// Pinocchio vs MuJoCo.
    pub pinocchio_vs_mujoco: Deviation,
}

impl CheckReport {
    /// Whether every deviation is within `tol`.
    #[must_use]
    pub fn passed(&self, tol: f64) -> bool {
        self.pinocchio.within(tol)
            && self.mujoco.within(tol)
            && self.pinocchio_vs_mujoco.within(tol)
    }
}

impl fmt::Display for CheckReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let row = |f: &mut fmt::Formatter<'_>, what: &str, d: &Deviation| {
            writeln!(
                f,
                "  {what:<22} max|Δposition| {:9.2e} m   max|ΔJ| {:9.2e} m/rad",
                d.position, d.jacobian
            )
        };
        writeln!(
            f,
            "{} {} ({} configurations):",
            self.robot, self.param_set, self.configurations
        )?;
        row(f, "pinocchio vs activecal", &self.pinocchio)?;
        row(f, "mujoco vs activecal", &self.mujoco)?;
        row(f, "pinocchio vs mujoco", &self.pinocchio_vs_mujoco)
    }
}

/// Evaluates `qs` with activecal, Pinocchio and MuJoCo (models built by
/// [`pinocchio_model_spec`] and [`mjcf_of_spec`], independently of
/// activecal's kinematics) and reports the largest deviations.
pub fn check(
    bridge: &Bridge,
    robot: &Robot,
    set: ParamSet,
    qs: &[Vec<f64>],
) -> Result<CheckReport> {
    let table = robot.params(set);
    let spec = pinocchio_model_spec(robot, table)?;
    let ours = activecal_kinematics(robot, table, qs);
    let pin = bridge.pinocchio(&spec, qs)?;
    let mj = bridge.mujoco(&mjcf_of_spec(&spec), spec.dof(), qs)?;
    Ok(CheckReport {
        robot: robot.name.clone(),
        param_set: set_name(set),
        configurations: qs.len(),
        pinocchio: deviation(&pin, &ours)?,
        mujoco: deviation(&mj, &ours)?,
        pinocchio_vs_mujoco: deviation(&pin, &mj)?,
    })
}

/// The live check of a robot at one parameter set: [`LIVE_RANDOM`] random
/// configurations within the limits plus all `2^dof` corners.
pub fn check_live(bridge: &Bridge, robot: &Robot, set: ParamSet) -> Result<CheckReport> {
    check(
        bridge,
        robot,
        set,
        &configurations(robot, LIVE_RANDOM, LIVE_SEED),
    )
}

/// The fixture of a robot at one parameter set: Pinocchio's values at
/// [`fixture::N_RANDOM`] random configurations and the corners, after
/// checking that MuJoCo agrees within [`TOLERANCE`]. Independent of
/// activecal's kinematics, so a kinematics bug cannot leak into it.
pub fn make_fixture(bridge: &Bridge, robot: &Robot, set: ParamSet) -> Result<Fixture> {
    let qs = configurations(robot, fixture::N_RANDOM, fixture::SEED);
    let spec = pinocchio_model_spec(robot, robot.params(set))?;
    let pin = bridge.pinocchio(&spec, &qs)?;
    let mj = bridge.mujoco(&mjcf_of_spec(&spec), spec.dof(), &qs)?;
    let dev = deviation(&mj, &pin)?;
    if !dev.within(TOLERANCE) {
        bail!(
            "{} {}: Pinocchio and MuJoCo disagree ({dev:?}); not writing a fixture",
            robot.name,
            set_name(set)
        );
    }
    Fixture::new(
        robot,
        set,
        bridge.versions().clone(),
        &qs,
        fixture::N_RANDOM,
        &pin,
        dev,
    )
}

/// Writes the fixtures of every built-in robot at both parameter sets into
/// `dir` (created if missing) and returns the paths written.
pub fn regenerate(bridge: &Bridge, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    for robot in crate::builtin_robots()? {
        for set in [ParamSet::Nominal, ParamSet::Real] {
            let f = make_fixture(bridge, &robot, set)?;
            let path = dir.join(fixture::file_name(&robot.name, set));
            std::fs::write(&path, f.to_json())?;
            written.push(path);
        }
    }
    Ok(written)
}
