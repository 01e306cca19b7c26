//! The keyword arguments a fit takes (weights, held-out splits, loss,
//! restriction, outliers), checked and converted into the library's
//! settings, and the refusal of those that do not act on the sensor given:
//! shared by `calibrate`, `calibrate_camera` and `calibrate_contacts`.

use crate::convert::{arg_err, count};
use activecal::experiment::acts_on::{self as lib_acts, Sensor};
use activecal::options::LossChoice;
use activecal::options::Restriction;
use pyo3::prelude::*;

/// The `weights` and `orientation_scale` arguments, checked.
pub(crate) fn weights_of(
    weights: Option<&str>,
    orientation_scale: Option<f64>,
) -> PyResult<activecal::options::Weights> {
    use activecal::options::Weights;
    if let Some(w) = orientation_scale.filter(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(arg_err(
            "orientation_scale",
            format!("{w}: must be a finite number > 0 (metres per radian)"),
        ));
    }
    match (weights, orientation_scale) {
        (Some("estimated"), Some(_)) => Err(arg_err(
            "orientation_scale",
            "fixes the orientation weight: it implies weights=\"fixed\", not \"estimated\"",
        )),
        (None | Some("estimated"), None) => Ok(Weights::Estimated),
        (None | Some("fixed"), _) => Ok(Weights::Fixed),
        (Some(other), _) => Err(arg_err(
            "weights",
            format!("unknown weights '{other}': \"estimated\" or \"fixed\""),
        )),
    }
}

/// The held-out splits of `holdout` (a fraction in (0, 1)), checked.
pub(crate) fn holdout_of(
    holdout: Option<f64>,
    splits: i64,
    seed: i128,
    weights: activecal::options::Weights,
) -> PyResult<Option<activecal::options::HoldoutSettings>> {
    let splits = count("splits", splits, 1)?;
    let seed = crate::convert::non_negative("seed", seed)?;
    holdout
        .map(|fraction| {
            if !(fraction > 0.0 && fraction < 1.0) {
                return Err(arg_err(
                    "holdout",
                    format!("{fraction}: the fraction of poses held out is in (0, 1)"),
                ));
            }
            activecal::options::HoldoutSettings::builder()
                .fraction(fraction)
                .splits(splits)
                .seed(seed)
                .weights(weights)
                .build()
                .map_err(|e| crate::convert::Fail::from(e).into_py())
        })
        .transpose()
}

/// The `loss` and `loss_scale` arguments, checked.
pub(crate) fn loss_of(loss: &str, loss_scale: Option<f64>) -> PyResult<LossChoice> {
    let scale = |s: Option<f64>| match s {
        Some(s) if s.is_finite() && s > 0.0 => Ok(s),
        Some(s) => Err(arg_err(
            "loss_scale",
            format!("{s}: must be a finite number > 0 (metres)"),
        )),
        None => Err(arg_err(
            "loss_scale",
            format!(
                "loss=\"{loss}\" needs loss_scale (metres: the residual norm of one pose where the loss turns robust, e.g. 3 times the sensor noise)"
            ),
        )),
    };
    Ok(match loss {
        "l2" if loss_scale.is_some() => {
            return Err(arg_err("loss_scale", "is for loss=\"huber\" or \"cauchy\""));
        }
        "l2" => LossChoice::L2,
        "huber" => LossChoice::Huber {
            scale: scale(loss_scale)?,
        },
        "cauchy" => LossChoice::Cauchy {
            scale: scale(loss_scale)?,
        },
        other => {
            return Err(arg_err(
                "loss",
                format!("unknown loss '{other}': \"l2\", \"huber\" or \"cauchy\""),
            ));
        }
    })
}

/// The unknowns `unknowns` and `keep_axis_relations` restrict a fit to.
pub(crate) fn restriction_of(unknowns: &str, keep_axis_relations: bool) -> PyResult<Restriction> {
    match (unknowns, keep_axis_relations) {
        ("all", false) => Ok(Restriction::All),
        ("all", true) => Ok(Restriction::KeepAxisRelations),
        ("offsets", false) => Ok(Restriction::Offsets),
        ("offsets", true) => Err(arg_err(
            "keep_axis_relations",
            "with unknowns=\"offsets\": an offsets-only fit keeps every axis relation already",
        )),
        (other, _) => Err(arg_err(
            "unknowns",
            format!("'{other}': \"all\" or \"offsets\""),
        )),
    }
}

/// Refuses each keyword argument of `given` that does not act on `sensor`
/// by `table` (the command line's, [`activecal::experiment::acts_on`]),
/// naming the argument and the sensor.
pub(crate) fn refuse_unused(
    table: &[lib_acts::ActsOn],
    given: &[&str],
    sensor: Sensor,
) -> PyResult<()> {
    let unused = lib_acts::not_acting(table, given, &[sensor]);
    if unused.is_empty() {
        return Ok(());
    }
    let lines: Vec<String> = unused
        .iter()
        .map(|k| {
            let on: Vec<&str> = lib_acts::sensors_of(table, k)
                .unwrap_or_default()
                .iter()
                .map(|s| s.words())
                .collect();
            // The table's `bag_design` is `calibrate`'s `design`.
            let k = if *k == "bag_design" { "design" } else { k };
            format!(
                "{k}: not used with {}; it acts on {}",
                sensor.words(),
                on.join(" or ")
            )
        })
        .collect();
    Err(pyo3::exceptions::PyValueError::new_err(lines.join("\n")))
}

/// The outlier choice of `outliers=` ("drop" or "keep") and
/// `outlier_rate=`.
pub(crate) fn outliers_of(kind: &str, rate: f64) -> PyResult<activecal::options::OutlierChoice> {
    use activecal::options::OutlierChoice;
    let c = match kind {
        "drop" => OutlierChoice::Drop { alpha: rate },
        "keep" => OutlierChoice::Keep,
        other => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "outliers={other:?}: give \"drop\" or \"keep\""
            )));
        }
    };
    c.validate().map_err(|e| {
        pyo3::exceptions::PyValueError::new_err(format!("outlier_rate={rate}: {e}"))
    })?;
    Ok(c)
}

/// The `noise` (metres per coordinate) and `orientation_noise` (radians per
/// axis) arguments, the sensor's stated σ, checked.
pub(crate) fn stated_noises(
    noise: Option<f64>,
    orientation_noise: Option<f64>,
) -> PyResult<(Option<f64>, Option<f64>)> {
    if let Some(s) = noise.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(crate::errors::new_err(
            crate::errors::Kind::Input,
            format!(
                "noise={s}: the sensor's stated σ per coordinate must be a number > 0 (metres)"
            ),
        ));
    }
    if let Some(s) = orientation_noise.filter(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(pyo3::exceptions::PyValueError::new_err(format!(
            "orientation_noise={s}: the tracker's stated σ per orientation axis must be a number > 0 (radians)"
        )));
    }
    Ok((noise, orientation_noise))
}

/// The gravity model `compliance=True` fits the joints' compliances with
/// (the torques of the robot's URDF <inertial> elements), or None.
pub(crate) fn gravity_of(
    compliance: bool,
    robot: &activecal::model::Robot,
) -> PyResult<Option<std::sync::Arc<activecal::model::gravity::GravityModel>>> {
    compliance
        .then(|| {
            let opts = activecal::io::inertia::InertiaOptions {
                inertials: None,
                payload: None,
            };
            activecal::io::inertia::gravity_model(robot, &opts)
                .map(std::sync::Arc::new)
                .map_err(|e| crate::convert::arg_err("compliance", e))
        })
        .transpose()
}
