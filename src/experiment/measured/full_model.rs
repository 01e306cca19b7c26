//! What the full model would gain over a restricted calibration
//! ([`crate::identify::restriction`]: offsets only, or the axis relations
//! kept): the same data fitted with every unknown, and the two fitted
//! models compared at random configurations.
//!
//! The full model is the best estimate of the robot there is: the
//! restricted model's predicted error is its distance to it (a bias no
//! amount of data removes) on top of the full model's own predicted error,
//! `e_restricted = √(d² + e_full²)`, where `d` is the RMS distance between
//! the two models' predicted points and `e_full` the full model's predicted
//! RMS from its covariance ([`super::MeasuredReport::predicted`]).

use super::{ExperimentError, MeasuredSettings, PREDICTION_CONFIGURATIONS, fit_read};
use crate::data::Measurements;
use crate::identify::restriction::Restriction;
use crate::model::{ParamTable, Robot};
use nalgebra::Vector3;

pub use crate::report::measured::FullModelGain;

/// The measured points of `robot` at `table` and `q` (those its sensor
/// follows: [`crate::measure::Sensor::measured_points`]), metres.
fn points(robot: &Robot, table: &ParamTable, q: &[f64]) -> Vec<Vector3<f64>> {
    let end = crate::kinematics::Evaluator::new(robot, table).end_frame(q);
    crate::measure::sensor_for(robot).measured_points(&end, &table.marker_values())
}

/// RMS distance (mm) between the points of two fitted models at `qs`.
#[must_use]
pub fn models_apart_rms_mm(
    a: (&Robot, &ParamTable),
    b: (&Robot, &ParamTable),
    qs: &[Vec<f64>],
) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for q in qs {
        for (x, y) in points(a.0, a.1, q).iter().zip(points(b.0, b.1, q)) {
            sum += (x - y).norm_squared();
            n += 1;
        }
    }
    (sum / n.max(1) as f64).sqrt() * 1e3
}

/// After a fit with `settings` restricted by `restriction` (the user's own
/// fixed unknowns `user_fix` plus those it holds), which made `fitted`:
/// the full model's fit of the same data beside it, or `None` when the fit
/// was not restricted.
///
/// # Errors
/// The full fit's errors.
pub fn beside_full_model(
    robot: &Robot,
    meas: &Measurements,
    source: &str,
    settings: &MeasuredSettings,
    user_fix: &[String],
    restriction: Restriction,
    fitted: (&Robot, &ParamTable),
) -> Result<Option<FullModelGain>, ExperimentError> {
    if restriction == Restriction::All {
        return Ok(None);
    }
    let mut full = settings.clone();
    full.fix = user_fix.to_vec();
    full.restriction = Restriction::All;
    full_model_gain(
        robot,
        meas,
        source,
        &full,
        (restriction, fitted.0, fitted.1),
    )
    .map(Some)
}

/// Fits `meas` (named `source`) with `full` settings (every unknown, the
/// user's own fixed ones held) and compares the result with the fit
/// restricted by `restricted` (its robot as fitted and its estimate).
///
/// # Errors
/// The full fit's errors.
pub fn full_model_gain(
    robot: &Robot,
    meas: &Measurements,
    source: &str,
    full: &MeasuredSettings,
    restricted: (Restriction, &Robot, &ParamTable),
) -> Result<FullModelGain, ExperimentError> {
    let f = fit_read(robot, meas, source, Vec::new(), full, &mut |_| {})?;
    let qs = crate::how_many::random_configurations(&f.robot, PREDICTION_CONFIGURATIONS, 0);
    let apart = models_apart_rms_mm(
        (&f.robot, &f.fit.id.table),
        (restricted.1, restricted.2),
        &qs,
    );
    let full_rms = f
        .report
        .predicted
        .as_ref()
        .map_or(f64::NAN, |p| p.position_rms_mm);
    let own = apart.hypot(full_rms);
    Ok(FullModelGain {
        restricted: restricted.0,
        full_unknowns: f.fit.id.names.len(),
        full_predicted_rms_mm: full_rms,
        full_held_out_rms_mm: f.report.holdout.as_ref().map(|h| h.position_rms_mm.mean),
        models_apart_rms_mm: apart,
        restricted_predicted_rms_mm: own,
        gain_mm: own - full_rms,
        relations_held: if restricted.0 == Restriction::KeepAxisRelations {
            crate::identify::axis_relations::held_relations(robot)
        } else {
            Vec::new()
        },
    })
}
