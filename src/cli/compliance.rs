//! `calibrate --compliance`, `--inertia`, `--payload` and
//! `--compare-compliance`: the options parsed into a gravity model, and the
//! rendering of compliances and of the side-by-side held-out comparison.
//! The work is the library's (`activecal::experiment::measured`).

use activecal::io::inertia::{InertiaOptions, Payload, gravity_model};
use activecal::model::Robot;
use activecal::model::gravity::GravityModel;
use anyhow::{Context, Result, bail};
use std::path::Path;
use std::sync::Arc;

/// Parses `--payload KG[@X,Y,Z]` (kg; metres in the tip link's frame).
pub fn parse_payload(s: &str) -> Result<Payload, String> {
    s.parse()
}

/// The gravity model of `robot` from its URDF's inertials, or from
/// `inertia`'s (another URDF with the same link names), with `payload`.
pub fn gravity_for(
    robot: &Robot,
    inertia: Option<&Path>,
    payload: Option<Payload>,
) -> Result<Arc<GravityModel>> {
    let inertials = match inertia {
        Some(p) => Some((
            std::fs::read_to_string(p).with_context(|| format!("--inertia {}", p.display()))?,
            p.display().to_string(),
        )),
        None => None,
    };
    if robot.source.is_none() {
        bail!(
            "--compliance needs a URDF robot (gravity torques come from its <inertial> elements); '{}' is not one",
            robot.name
        );
    }
    let opts = InertiaOptions { inertials, payload };
    Ok(Arc::new(gravity_model(robot, &opts)?))
}
