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
    let (m, at) = match s.split_once('@') {
        Some((m, at)) => (m, Some(at)),
        None => (s, None),
    };
    let mass: f64 = m
        .trim()
        .parse()
        .map_err(|_| format!("'{m}' is not a mass in kg (KG or KG@X,Y,Z)"))?;
    if !(mass.is_finite() && mass >= 0.0) {
        return Err(format!("{mass} kg: the mass must be finite and >= 0"));
    }
    let at = match at {
        None => [0.0; 3],
        Some(a) => {
            let v: Vec<f64> = a
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| format!("'{a}' is not X,Y,Z in metres"))?;
            if v.len() != 3 || !v.iter().all(|x| x.is_finite()) {
                return Err(format!("'{a}' is not three finite numbers X,Y,Z (metres)"));
            }
            [v[0], v[1], v[2]]
        }
    };
    Ok(Payload { mass, at })
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
