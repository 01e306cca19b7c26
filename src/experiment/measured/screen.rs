//! The least-squares fit of measured data with Baarda's data snooping
//! ([`crate::lsq::outliers`]): the poses the test flags left out one at
//! a time, the fit repeated.

use super::MeasuredSettings;
use crate::identify::{LossChoice, Measurements, residuals};
use crate::lsq::outliers::{Outlier, OutlierChoice};
use crate::model::{ParamTable, Robot};
use serde::Serialize;

/// The gross-error test's part of a report.
#[derive(Clone, Debug, Serialize)]
pub struct OutlierReport {
    /// Drop (at a rate) or keep.
    pub choice: OutlierChoice,
    /// The poses left out, in the order the test found them.
    pub left_out: Vec<Outlier>,
}

/// A fit with the poses the gross-error test left out.
pub(super) struct Screened {
    /// The fit of the poses kept.
    pub(super) fit: crate::identify::WeightedFit,
    /// The poses kept (indices into the measurements given).
    pub(super) kept: Vec<usize>,
    /// The poses left out.
    pub(super) outliers: Vec<Outlier>,
    /// What the test did, for the report.
    pub(super) notes: Vec<String>,
}

/// At most this fraction of the poses is left out as gross errors: beyond
/// it the data are not a few glitches but a noise or a model other than
/// assumed, which leaving poses out would hide.
const MOST_OUTLIERS: f64 = 0.2;

/// The fit of `meas` ([`crate::identify::fit_weighted`]), and with least
/// squares and [`OutlierChoice::Drop`], Baarda's data snooping
/// ([`crate::lsq::outliers`]): the pose the test flags left out and
/// the fit repeated from the last estimate, until none is flagged or
/// [`MOST_OUTLIERS`] of the poses are out.
pub(super) fn screen(
    robot: &Robot,
    start: &ParamTable,
    meas: &Measurements,
    s: &MeasuredSettings,
) -> crate::identify::Result<Screened> {
    crate::lsq::outliers::check_choice(s.outliers)?;
    let fit = |m: &Measurements, from: &ParamTable| {
        crate::identify::fit_weighted(robot, from, m, &s.lm, s.loss, s.weights)
    };
    let mut kept: Vec<usize> = (0..meas.len()).collect();
    let mut wf = fit(meas, start)?;
    let mut found: Vec<(usize, crate::lsq::outliers::PoseTest, f64)> = Vec::new();
    let mut notes = Vec::new();
    let alpha = match (s.outliers, s.loss) {
        (OutlierChoice::Drop { alpha }, LossChoice::L2) => alpha,
        _ => {
            return Ok(Screened {
                fit: wf,
                kept,
                outliers: Vec::new(),
                notes,
            });
        }
    };
    let most = (MOST_OUTLIERS * meas.len() as f64).floor() as usize;
    let all = wf.clone();
    loop {
        let sub = meas.subset(&kept);
        let mut prob = crate::identify::Calibration::new(&wf.robot, &wf.start, &sub)?;
        let Some(tests) = crate::lsq::outliers::pose_tests(
            &mut prob,
            &wf.fit.id.estimate,
            sub.len(),
            s.stated_noise,
        ) else {
            break;
        };
        let Some(worst) = crate::lsq::outliers::flagged(&tests, alpha) else {
            break;
        };
        if found.len() >= most {
            notes.push(format!(
                "the gross-error test flags more than {} poses ({:.0} % of {}): not isolated glitches but a noise larger than the sensor's or a model that misses something (joint sag under gravity: --compliance); every pose is kept",
                most,
                MOST_OUTLIERS * 100.0,
                meas.len()
            ));
            let kept = (0..meas.len()).collect();
            return Ok(Screened {
                fit: all,
                kept,
                outliers: Vec::new(),
                notes,
            });
        }
        let threshold = alpha / tests.len() as f64;
        found.push((kept[worst.pose], worst.clone(), threshold));
        kept.remove(worst.pose);
        let next = fit(&meas.subset(&kept), &wf.fit.id.table.clone())?;
        wf = next;
    }
    let outliers = found
        .into_iter()
        .map(|(pose, mut test, threshold)| {
            test.pose = pose;
            let residual_mm = residuals(&wf.robot, &wf.fit.id.table, &meas.subset(&[pose]))
                .map_or(f64::NAN, |e| e.position_rms_mm);
            Outlier {
                pose,
                test,
                threshold,
                residual_mm,
            }
        })
        .collect::<Vec<_>>();
    for o in &outliers {
        let against = match o.test.dof.1 {
            0 => "the stated σ".to_string(),
            d => format!("σ̂ on {d} degrees of freedom"),
        };
        notes.push(format!(
            "pose {} of the data left out as a gross error: residual {:.3} mm, test value {:.1} on {} rows against {against}, P = {:.1e} < {:.1e} (α {} over {} poses; --outliers keep keeps it)",
            o.pose + 1,
            o.residual_mm,
            o.test.statistic,
            o.test.dof.0,
            o.test.p_value,
            o.threshold,
            alpha,
            (alpha / o.threshold).round()
        ));
    }
    Ok(Screened {
        fit: wf,
        kept,
        outliers,
        notes,
    })
}
