//! Gross errors in a camera's pixels: a misdetected corner (one point off
//! by pixels) or a shifted board (every point of a pose off), found by
//! Baarda's data snooping ([`crate::lsq::outliers::snoop`]) as the
//! tracker's poses are.
//!
//! Each pose's pixel rows are tested as one block. For the pose flagged,
//! its worst point is tested too (its two rows), and the rest of the pose
//! without it: the drop in the residual sum of squares when the rest is
//! left out after the point is `T_pose − T_point` exactly (both are drops
//! from the same fit), tested on `k_pose − k_point` rows against the σ
//! estimated without the pose. When the point is flagged (at `α` over the
//! points seen) and the rest passes (at `α` over the poses), only the
//! point is left out; otherwise the whole pose. The fit is then repeated.

use super::{CameraFit, CameraFitError, fit_camera};
use crate::data::CameraObservations;
use crate::identify::LmSettings;
use crate::identify::residual::{Calibration, Residuals};
use crate::lsq::outliers::{
    Flag, Flagged, MOST_OUTLIERS, OutlierChoice, PoseTest, Snoop, Tester, flagged, snoop, tail_of,
    too_many_note,
};
use crate::measure::camera::CameraSensor;
use crate::model::Robot;
use serde::Serialize;

/// What the camera's test leaves out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum CameraUnit {
    /// A whole pose (its index among the observations given).
    Pose {
        /// The pose's index (0-based).
        pose: usize,
    },
    /// One point of a pose (a misdetected corner).
    Point {
        /// The pose's index (0-based).
        pose: usize,
        /// The target point's index (0-based).
        point: usize,
    },
}

impl CameraUnit {
    fn pose(self) -> usize {
        match self {
            CameraUnit::Pose { pose } | CameraUnit::Point { pose, .. } => pose,
        }
    }
}

/// A pose or point left out as a gross error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CameraOutlier {
    /// What was left out.
    pub unit: CameraUnit,
    /// The pose's id in the observations file.
    pub pose_id: i64,
    /// Its test when flagged (`pose` is the pose's index).
    pub test: PoseTest,
    /// The bound its tail fell below (`α / n`, `n` the poses or the points
    /// tested).
    pub threshold: f64,
    /// Its pixels' RMS distance from their prediction at the final fit
    /// (over the pose's points seen, or the one point), px.
    pub residual_px: f64,
}

/// The fit of the pixels kept, what was left out and what the test did.
pub struct ScreenedCamera {
    /// The fit.
    pub fit: CameraFit,
    /// The observations fitted (those given less what was left out).
    pub fitted: CameraObservations,
    /// What was left out, in the order the test found it.
    pub outliers: Vec<CameraOutlier>,
    /// What the test did, in words.
    pub notes: Vec<String>,
}

/// `obs` without `out`: points marked not seen, poses removed.
#[must_use]
pub fn without(obs: &CameraObservations, out: &[CameraUnit]) -> CameraObservations {
    let mut o = obs.clone();
    for u in out {
        if let CameraUnit::Point { pose, point } = *u {
            o.seen[pose][point] = None;
        }
    }
    let keep: Vec<usize> = (0..o.qs.len())
        .filter(|i| !out.contains(&CameraUnit::Pose { pose: *i }))
        .collect();
    CameraObservations {
        origin: o.origin,
        pose_ids: keep.iter().map(|&i| o.pose_ids[i]).collect(),
        qs: keep.iter().map(|&i| o.qs[i].clone()).collect(),
        seen: keep.iter().map(|&i| o.seen[i].clone()).collect(),
    }
}

/// The camera's poses and points as units of [`snoop`].
struct Pixels<'a> {
    robot: &'a Robot,
    sensor: &'a CameraSensor,
    own0: &'a [f64],
    obs: &'a CameraObservations,
    lm: &'a LmSettings,
    sigma_px: Option<f64>,
}

impl Snoop for Pixels<'_> {
    type Unit = CameraUnit;
    type Fit = CameraFit;
    type Error = CameraFitError;

    fn fit(
        &mut self,
        out: &[CameraUnit],
        _from: Option<&CameraFit>,
    ) -> Result<CameraFit, CameraFitError> {
        fit_camera(
            self.robot,
            self.sensor,
            self.own0,
            &without(self.obs, out),
            self.lm,
        )
    }

    fn flag(&mut self, fit: &CameraFit, out: &[CameraUnit], alpha: f64) -> Flagged<CameraUnit> {
        self.flag_of(fit, out, alpha)
            .map_or(Flagged::Clean, Flagged::Unit)
    }
}

impl Pixels<'_> {
    /// [`Snoop::flag`], `None` for a clean fit.
    fn flag_of(&self, fit: &CameraFit, out: &[CameraUnit], alpha: f64) -> Option<Flag<CameraUnit>> {
        if !fit.converged {
            return None;
        }
        let sub = without(self.obs, out);
        let kept: Vec<usize> = (0..self.obs.qs.len())
            .filter(|i| !out.contains(&CameraUnit::Pose { pose: *i }))
            .collect();
        let mut prob = problem(fit, &sub);
        let t = prob.block_rows();
        let tester = Tester::new(&mut prob, &fit.estimate, self.sigma_px)?;
        let rows = |i: usize| (i * t..(i + 1) * t).collect::<Vec<usize>>();
        let tests: Vec<PoseTest> = (0..sub.qs.len())
            .filter_map(|i| tester.test(i, &rows(i)))
            .collect();
        let worst = flagged(&tests, alpha)?;
        let pose_threshold = alpha / tests.len() as f64;
        let i = worst.pose;
        let pose = kept[i];
        let whole = Flag {
            unit: CameraUnit::Pose { pose },
            test: worst.clone(),
            threshold: pose_threshold,
        };
        let Some((point, test)) = worst_point(&tester, i, t) else {
            return Some(whole);
        };
        let point_threshold = alpha / (sub.n_seen().max(1)) as f64;
        let rest_passes = rest_tail(&tester, i, t, point).is_none_or(|p| p >= pose_threshold);
        if test.p_value < point_threshold && rest_passes {
            return Some(Flag {
                unit: CameraUnit::Point { pose, point },
                test,
                threshold: point_threshold,
            });
        }
        Some(whole)
    }
}

/// The least-squares problem `fit` solved, on `obs`.
fn problem<'a>(fit: &'a CameraFit, obs: &'a CameraObservations) -> Calibration<'a> {
    Calibration::with_sensor(
        &fit.robot,
        &fit.robot.nominal,
        &obs.qs,
        Box::new(fit.sensor.clone()),
        obs.values(),
    )
}

/// The point of pose `i` (blocks of `t` rows, two per point) with the
/// largest test value, and its test.
fn worst_point(tester: &Tester, i: usize, t: usize) -> Option<(usize, PoseTest)> {
    (0..t / 2)
        .filter_map(|k| {
            let r = i * t + 2 * k;
            tester.test(i, &[r, r + 1]).map(|p| (k, p))
        })
        .max_by(|a, b| a.1.statistic.total_cmp(&b.1.statistic))
}

/// The tail of pose `i`'s rest without `point` (see the module
/// documentation); `None` when nothing is left to test.
fn rest_tail(tester: &Tester, i: usize, t: usize, point: usize) -> Option<f64> {
    let rows: Vec<usize> = (i * t..(i + 1) * t).collect();
    let r = i * t + 2 * point;
    let (tp, kp) = tester.drop_in_rss(&rows)?;
    let (tk, kk) = tester.drop_in_rss(&[r, r + 1])?;
    let (rss, f, sigma) = tester.rss();
    let k = kp.checked_sub(kk).filter(|k| *k > 0)?;
    // The rest's drop is tested against σ estimated without the whole pose:
    // `tail_of` takes the RSS and degrees of freedom before the drop, so
    // hand it those of the fit without the point.
    let (_, _, p) = tail_of((tp - tk).max(0.0), k, rss - tk, f.checked_sub(kk)?, sigma)?;
    Some(p)
}

/// Each point's residual at `fit`'s estimate, px: its prediction less
/// its pixel, pose by pose of `obs` (as fitted) in target order; `None`
/// where the point was not seen.
#[must_use]
pub fn pixel_residuals(fit: &CameraFit, obs: &CameraObservations) -> Vec<Vec<Option<[f64; 2]>>> {
    let mut prob = problem(fit, obs);
    let mut r = vec![0.0; prob.n_residuals()];
    prob.eval(&fit.estimate, &mut r, None);
    let t = r.len() / obs.seen.len().max(1);
    obs.seen
        .iter()
        .enumerate()
        .map(|(i, seen)| {
            seen.iter()
                .enumerate()
                .map(|(k, s)| s.map(|_| [r[i * t + 2 * k], r[i * t + 2 * k + 1]]))
                .collect()
        })
        .collect()
}

/// The RMS pixel distance of `unit`'s points seen (of `obs`, the
/// observations given) from their prediction by `fit`.
fn residual_px(fit: &CameraFit, obs: &CameraObservations, unit: CameraUnit) -> f64 {
    let i = unit.pose();
    let mut seen = obs.seen[i].clone();
    if let CameraUnit::Point { point, .. } = unit {
        for (k, s) in seen.iter_mut().enumerate() {
            if k != point {
                *s = None;
            }
        }
    }
    let one = CameraObservations {
        origin: obs.origin.clone(),
        pose_ids: vec![obs.pose_ids[i]],
        qs: vec![obs.qs[i].clone()],
        seen: vec![seen],
    };
    let n = one.n_seen();
    let mut prob = problem(fit, &one);
    let mut r = vec![0.0; prob.n_residuals()];
    prob.eval(&fit.estimate, &mut r, None);
    (r.iter().map(|v| v * v).sum::<f64>() / n.max(1) as f64).sqrt()
}

/// The fit of `obs` seen by `sensor` (charts centred on `own0`), and with
/// [`OutlierChoice::Drop`], the poses and points the gross-error test
/// flags (see the module documentation) left out one at a time and the fit
/// repeated, until none is flagged or [`MOST_OUTLIERS`] of the poses are
/// out (then everything is kept). `sigma_px` is the detector's stated σ
/// (the tests are then χ² against it).
pub fn screen_camera(
    robot: &Robot,
    sensor: &CameraSensor,
    own0: &[f64],
    obs: &CameraObservations,
    lm: &LmSettings,
    choice: OutlierChoice,
    sigma_px: Option<f64>,
) -> Result<ScreenedCamera, CameraFitError> {
    let mut px = Pixels {
        robot,
        sensor,
        own0,
        obs,
        lm,
        sigma_px,
    };
    let OutlierChoice::Drop { alpha } = choice else {
        return Ok(ScreenedCamera {
            fit: px.fit(&[], None)?,
            fitted: obs.clone(),
            outliers: Vec::new(),
            notes: Vec::new(),
        });
    };
    let most = (MOST_OUTLIERS * obs.qs.len() as f64).floor() as usize;
    let snooped = snoop(&mut px, alpha, most)?;
    let mut notes = Vec::new();
    if snooped.capped.is_some() {
        notes.push(too_many_note(most, obs.qs.len(), "poses or points"));
    }
    let units: Vec<CameraUnit> = snooped.out.iter().map(|f| f.unit).collect();
    let fit = snooped.fit;
    let outliers: Vec<CameraOutlier> = snooped
        .out
        .into_iter()
        .map(|f| {
            let mut test = f.test;
            test.pose = f.unit.pose();
            CameraOutlier {
                unit: f.unit,
                pose_id: obs.pose_ids[f.unit.pose()],
                test,
                threshold: f.threshold,
                residual_px: residual_px(&fit, obs, f.unit),
            }
        })
        .collect();
    for o in &outliers {
        notes.push(note(o, alpha));
    }
    Ok(ScreenedCamera {
        fit,
        fitted: without(obs, &units),
        outliers,
        notes,
    })
}

/// The note on one unit left out.
fn note(o: &CameraOutlier, alpha: f64) -> String {
    let what = match o.unit {
        CameraUnit::Pose { .. } => format!("pose {}", o.pose_id),
        CameraUnit::Point { point, .. } => format!("point {point} of pose {}", o.pose_id),
    };
    let against = match o.test.dof.1 {
        0 => "the stated pixel noise".to_string(),
        d => format!("σ̂ on {d} degrees of freedom"),
    };
    format!(
        "{what} left out as a gross error: {:.2} px RMS off at the fit, test value {:.1} on {} rows against {against}, P = {:.1e} < {:.1e} (α {alpha} over {}; {keep})",
        o.residual_px,
        o.test.statistic,
        o.test.dof.0,
        o.test.p_value,
        o.threshold,
        (alpha / o.threshold).round(),
        keep = crate::names::phrase::KEEP_GROSS_ERRORS
    )
}
