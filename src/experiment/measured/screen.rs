//! The least-squares fit of measured data with Baarda's data snooping
//! ([`crate::lsq::outliers`]): the poses the test flags left out one at
//! a time, the fit repeated.

use super::MeasuredSettings;
use crate::data::Measurements;
use crate::identify::{LossChoice, residuals};
use crate::lsq::outliers::{
    Flag, Flagged, MOST_OUTLIERS, Outlier, OutlierChoice, Snoop, flagged, kept_of, pose_tests,
    snoop, too_many_note,
};
use crate::model::{ParamTable, Robot};

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

/// The tracker's poses as units of [`snoop`].
struct Poses<'a> {
    robot: &'a Robot,
    start: &'a ParamTable,
    meas: &'a Measurements,
    s: &'a MeasuredSettings,
}

impl Snoop for Poses<'_> {
    type Unit = usize;
    type Fit = crate::identify::WeightedFit;
    type Error = crate::identify::IdentifyError;

    fn fit(
        &mut self,
        out: &[usize],
        from: Option<&Self::Fit>,
    ) -> crate::identify::Result<Self::Fit> {
        let kept = kept_of(self.meas.len(), out);
        let from = from.map_or(self.start, |f| &f.fit.id.table);
        let s = self.s;
        crate::identify::fit_weighted(
            self.robot,
            from,
            &self.meas.subset(&kept),
            &s.lm,
            s.loss,
            s.weights,
        )
    }

    fn flag(&mut self, wf: &Self::Fit, out: &[usize], alpha: f64) -> Flagged<usize> {
        let kept = kept_of(self.meas.len(), out);
        let sub = self.meas.subset(&kept);
        let Ok(mut prob) = crate::identify::Calibration::new(&wf.robot, &wf.start, &sub) else {
            return Flagged::Clean;
        };
        let Some(tests) = pose_tests(
            &mut prob,
            &wf.fit.id.estimate,
            sub.len(),
            self.s.stated_noise,
        ) else {
            return Flagged::Clean;
        };
        let Some(worst) = flagged(&tests, alpha) else {
            return Flagged::Clean;
        };
        Flagged::Unit(Flag {
            unit: kept[worst.pose],
            test: worst.clone(),
            threshold: alpha / tests.len() as f64,
        })
    }
}

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
    let mut poses = Poses {
        robot,
        start,
        meas,
        s,
    };
    let mut notes = Vec::new();
    let alpha = match (s.outliers, s.loss) {
        (OutlierChoice::Drop { alpha }, LossChoice::L2) => alpha,
        _ => {
            return Ok(Screened {
                fit: poses.fit(&[], None)?,
                kept: (0..meas.len()).collect(),
                outliers: Vec::new(),
                notes,
            });
        }
    };
    let most = (MOST_OUTLIERS * meas.len() as f64).floor() as usize;
    let snooped = snoop(&mut poses, alpha, most)?;
    if snooped.capped.is_some() {
        notes.push(too_many_note(most, meas.len(), "poses"));
    }
    let wf = snooped.fit;
    let kept = kept_of(
        meas.len(),
        &snooped.out.iter().map(|f| f.unit).collect::<Vec<_>>(),
    );
    let found: Vec<(usize, crate::lsq::outliers::PoseTest, f64)> = snooped
        .out
        .into_iter()
        .map(|f| (f.unit, f.test, f.threshold))
        .collect();
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
            "pose {} of the data left out as a gross error: residual {:.3} mm, test value {:.1} on {} rows against {against}, P = {:.1e} < {:.1e} (α {} over {} poses; {keep})",
            o.pose + 1,
            o.residual_mm,
            o.test.statistic,
            o.test.dof.0,
            o.test.p_value,
            o.threshold,
            alpha,
            (alpha / o.threshold).round(),
            keep = crate::names::phrase::KEEP_GROSS_ERRORS
        ));
    }
    Ok(Screened {
        fit: wf,
        kept,
        outliers,
        notes,
    })
}
