//! A pool ready for the criteria: the robot, its pool of poses built from a
//! spec (generated, or a file's configurations read in the user's units),
//! the compliance unknowns the pool's gravity torques call for, and the
//! pool's identification Jacobian at the parameters chosen. What `select`,
//! `bound` and `score` work on, from the command line and from Python.

use super::ExperimentError;
use crate::blocks::Blocks;
use crate::model::gravity::GravityModel;
use crate::model::{ParamSet, Robot};
use crate::pool::{Configurations, Pool, PoolSource, PoolSpec};
use crate::units::Units;
use std::path::Path;
use std::sync::Arc;

/// A robot, its pose pool and the pool's identification Jacobian.
pub struct PoolRun {
    /// The robot (with compliance unknowns when asked).
    pub robot: Robot,
    /// The pool.
    pub pool: Pool,
    /// Identification Jacobian of every pool pose.
    pub x: Blocks,
    /// The parameters the Jacobian was evaluated at.
    pub params: ParamSet,
}

/// The pool a design is scored on: the robot, the pool and its Jacobian at
/// `params`.
#[derive(Clone, Copy, Debug)]
pub struct ScoringPool<'a> {
    /// The robot.
    pub robot: &'a Robot,
    /// The pool.
    pub pool: &'a Pool,
    /// Its Jacobian.
    pub x: &'a Blocks,
    /// The parameters it was evaluated at.
    pub params: ParamSet,
}

impl PoolRun {
    /// The pool to score and bound designs on.
    #[must_use]
    pub fn scoring(&self) -> ScoringPool<'_> {
        ScoringPool {
            robot: &self.robot,
            pool: &self.pool,
            x: &self.x,
            params: self.params,
        }
    }
}

/// Builds the pool of `spec` for `robot` and its Jacobian at `params`
/// (reserved fallibly: memory the system refuses is an error, not an
/// abort). A pool file is read in `units`; `listed` configurations, when
/// given, are the pool's candidates instead of its source's. With
/// `compliance`, the robot gains a compliance unknown per joint whose
/// gravity torque varies over the pool.
///
/// # Errors
/// A pool file that cannot be read, a pool that cannot be built, a robot
/// without a URDF's inertials for compliance, memory refused.
pub fn build_pool(
    robot: Robot,
    spec: &PoolSpec,
    listed: Option<Configurations>,
    units: Units,
    params: ParamSet,
    compliance: bool,
) -> Result<PoolRun, ExperimentError> {
    let listed = match (&spec.source, listed) {
        (_, Some(rows)) => Some(rows),
        (PoolSource::File { path }, None) => Some(crate::pool::read_configurations_in(
            Path::new(path),
            &robot,
            units,
        )?),
        _ => None,
    };
    let pool = match listed {
        Some(rows) => spec.build_listed(&robot, &robot.nominal, rows)?,
        None => spec.build(&robot, &robot.nominal)?,
    };
    let robot = if compliance {
        let g = urdf_gravity(&robot)?;
        let qs: Vec<Vec<f64>> = (0..pool.len()).map(|k| pool.q(k)).collect();
        crate::identify::compliance::with_compliance_at(&robot, &g, &qs).0
    } else {
        robot
    };
    let x = pool.try_jacobian(&robot, robot.params(params))?;
    Ok(PoolRun {
        robot,
        pool,
        x,
        params,
    })
}

/// The gravity model of a URDF robot from its own `<inertial>` elements.
///
/// # Errors
/// A robot not imported from a URDF, or whose inertials are unusable.
pub fn urdf_gravity(robot: &Robot) -> Result<Arc<GravityModel>, ExperimentError> {
    if robot.source.is_none() {
        return Err(crate::Error::Invalid(format!(
            "{} needs a URDF robot (gravity torques come from its <inertial> elements); '{}' is not one",
            crate::names::phrase::COMPLIANCE,
            robot.name
        ))
        .into());
    }
    Ok(Arc::new(crate::io::inertia::gravity_model(
        robot,
        &crate::io::inertia::InertiaOptions::default(),
    )?))
}

/// The position noise σ a design is chosen or scored for when none is
/// given, metres (a calibration's default stated noise).
pub const DEFAULT_DESIGN_NOISE: f64 = 0.01;

/// The weight of a full-pose sensor's orientation rows (metres per radian)
/// for position noise `noise` (metres; [`DEFAULT_DESIGN_NOISE`] without it)
/// and orientation noise `orientation` (radians): each row then carries
/// the position's σ. Refused for a sensor of `robot` that measures no
/// orientation, or a σ that is not a finite number > 0.
pub fn orientation_scale(
    robot: &Robot,
    noise: Option<f64>,
    orientation: f64,
) -> Result<f64, crate::error::SettingError> {
    use crate::error::SettingError;
    if let Some(n) = noise {
        crate::error::positive("noise", n, "metres: the position noise σ")?;
    }
    if !(orientation.is_finite() && orientation > 0.0) {
        return Err(SettingError::new(
            "orientation_noise",
            orientation,
            "the orientation noise σ must be a finite number > 0 (radians)",
        ));
    }
    let sensor = crate::measure::sensor_for(robot);
    if !sensor.observes_orientation() {
        return Err(SettingError::because(
            "orientation_noise",
            format!(
                "robot '{}' measures {}, no orientation (append ':pose' to `robot` for full poses)",
                robot.name,
                sensor.describe()
            ),
        ));
    }
    Ok(noise.unwrap_or(DEFAULT_DESIGN_NOISE) / orientation)
}
