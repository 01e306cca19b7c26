//! The keyword arguments a fit takes (weights, held-out splits, loss,
//! restriction, outliers), checked and converted into the library's
//! settings, and the refusal of those that do not act on the sensor given:
//! shared by `calibrate`, `calibrate_camera` and `calibrate_contacts`.

use crate::convert::{arg_err, count};
use activecal::experiment::acts_on::{self as lib_acts, Sensor};
use activecal::options::Restriction;
use activecal::options::{LossChoice, LossKind};
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

/// The `loss` and `loss_scale` arguments, checked ([`LossChoice::of`]).
pub(crate) fn loss_of(loss: &str, loss_scale: Option<f64>) -> PyResult<LossChoice> {
    use activecal::names::Choice;
    let kind = LossKind::from_name(loss).ok_or_else(|| {
        arg_err(
            "loss",
            format!("unknown loss '{loss}': \"l2\", \"huber\" or \"cauchy\""),
        )
    })?;
    LossChoice::of(kind, loss_scale).map_err(|e| crate::convert::Fail::from(e).into_py())
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
            let why = match lib_acts::why_not(lib_acts::CALIBRATE_WHY, k) {
                // Keys in backticks are Python's keywords.
                Some(w) => w.replace('`', ""),
                None => format!("it acts on {}", on.join(" or ")),
            };
            // The table's `bag_design` is `calibrate`'s `design`.
            let k = if *k == "bag_design" { "design" } else { k };
            format!("{k}: not used with {}; {why}", sensor.words())
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
