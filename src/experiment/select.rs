//! The `select` pipeline, owned by the library: the selection, its
//! certified gap and refinement when asked for, the visiting order with its
//! moves checked (a stuck pose exchanged), the predicted error after
//! calibrating and the design file. The command line and the Python
//! package both call [`run`]; neither assembles these steps.

use super::ExperimentError;
use super::visiting::{Visiting, ordered_design, visit_selection};
use crate::blocks::Blocks;
use crate::bound::BoundSettings;
use crate::criterion::Prior;
use crate::error::{Error, Result};
use crate::io::design::{DesignFile, ExistingPoses};
use crate::model::{ParamSet, Robot};
use crate::pool::Pool;
use crate::report::{ExistingReport, PredictedAfter, RefinementReport, SelectReport};
use crate::select::{
    Algorithm, CriterionKind, RefineSettings, Refinement, Selection, Settings, select,
};
use crate::units::Units;
use std::path::Path;
use std::time::Instant;

/// Poses measured before a selection: their prior information `M0` and
/// its report.
#[derive(Clone, Debug)]
pub struct Existing {
    /// `M0 = Σ XᵢᵀXᵢ` of the poses, at the pool's parameters.
    pub prior: Prior,
    /// What the file (or array) held.
    pub report: ExistingReport,
    /// Their joint values (a design file stores them).
    pub qs: Vec<Vec<f64>>,
}

impl Existing {
    /// The prior information of poses `qs` (from `file`, named in messages
    /// and the report) at `params`; the Jacobian's memory checked first.
    pub fn from_poses(
        file: String,
        qs: Vec<Vec<f64>>,
        notes: Vec<String>,
        robot: &Robot,
        params: ParamSet,
    ) -> Result<Existing> {
        crate::resources::MemoryBudget::from_env()?.check(
            &format!("the Jacobian of {} existing poses", qs.len()),
            crate::pool::memory_estimate(robot, qs.len()),
        )?;
        if let Some(k) = qs.iter().position(|q| q.len() != robot.dof()) {
            return Err(Error::Invalid(format!(
                "{file}: existing pose {} has {} joint values, the robot {}",
                k + 1,
                qs[k].len(),
                robot.dof()
            )));
        }
        let x = crate::blocks::jacobian_of(robot, robot.params(params), qs.len(), |k, q| {
            q.copy_from_slice(&qs[k]);
        });
        let prior = Prior::from_blocks(&x)
            .map_err(|e| Error::Invalid(format!("{file}: the existing poses' Jacobian: {e}")))?;
        let report = ExistingReport::new(file, &x, &prior, notes);
        Ok(Existing { prior, report, qs })
    }

    /// Reads poses measured before (a CSV or JSON of joint configurations,
    /// a JSON measurement file or a design file, as `--pool file:` reads
    /// them; or a design written as YAML) and makes their prior information
    /// at `params`.
    pub fn read(path: &Path, robot: &Robot, params: ParamSet, units: Units) -> Result<Existing> {
        use crate::io::design_formats::DesignFormat;
        let file = path.display().to_string();
        if DesignFormat::of(path).ok() == Some(DesignFormat::Yaml) {
            let qs = DesignFile::read(path)
                .and_then(|d| d.joint_values(robot))
                .map_err(|e| Error::Invalid(format!("{file}: {e}")))?;
            return Existing::from_poses(file, qs, Vec::new(), robot, params);
        }
        let c = crate::pool::read_configurations_in(path, robot, units)?;
        Existing::from_poses(file, c.qs, c.notes, robot, params)
    }
}

/// What a selection run asks for beyond the search's own settings.
#[derive(Clone, Debug)]
pub struct SelectRun {
    /// The criterion maximised.
    pub criterion: CriterionKind,
    /// The search.
    pub algorithm: Algorithm,
    /// The search's settings (N, starts, seed, fixed poses, prior …).
    pub settings: Settings,
    /// The visiting order and the moves' checks.
    pub visiting: Visiting,
    /// The design against the pool's certified bound (`None`: not asked).
    pub gap: Option<BoundSettings>,
    /// The design refined off the pool (`None`: not asked).
    pub refine: Option<RefineSettings>,
    /// The sensor's σ per coordinate, metres: the predicted error after
    /// calibrating (not made when poses were measured before).
    pub noise: Option<f64>,
    /// The parameters the pool's Jacobian is of (refinement and prediction
    /// use the same).
    pub params: ParamSet,
}

/// What a selection run returns.
#[derive(Clone, Debug)]
pub struct SelectOutcome {
    /// The selection (pool positions, criterion value).
    pub selection: Selection,
    /// Its report, configurations in visiting order.
    pub report: SelectReport,
    /// The visiting order (positions in selection order).
    pub order: Vec<usize>,
    /// The refinement, when asked for.
    pub refined: Option<Refinement>,
    /// The design file, in visiting order.
    pub design: DesignFile,
    /// Seconds the search took.
    pub seconds: f64,
}

/// Runs a selection over `pool` (Jacobian `x`) of `robot`, with poses
/// measured before (`existing`, whose prior must be `run.settings`'s).
pub fn run(
    robot: &Robot,
    pool: &Pool,
    x: &Blocks,
    existing: Option<&Existing>,
    run: &SelectRun,
) -> std::result::Result<SelectOutcome, ExperimentError> {
    let prior = existing.map(|e| &e.prior);
    let t0 = Instant::now();
    let mut sel = select(x, run.criterion, run.algorithm, &run.settings)?;
    let seconds = t0.elapsed().as_secs_f64();
    let mut refined = None;
    let (mut report, order, swapped) =
        visit_selection(robot, pool, x, prior, &mut sel, &run.visiting, |sel| {
            let mut report =
                SelectReport::new(robot, pool, sel, run.criterion, &run.settings, seconds);
            if let Some(e) = existing {
                let alone = crate::criterion::design_ln_det(x, None, &sel.poses);
                report.set_existing(e.report.clone(), alone);
            }
            let pool_bound = with_gap(x, prior, sel, run, &mut report)?;
            refined = refine(robot, pool, x, prior, sel, run, pool_bound, &mut report)?;
            Ok::<_, ExperimentError>(report)
        })?;
    report.swapped = swapped;
    if let (Some(noise), None) = (run.noise, existing) {
        report.predicted =
            PredictedAfter::of_design(robot, robot.params(run.params), x, &sel.poses, noise);
    }
    let mut design = ordered_design(robot, pool, &sel, refined.as_ref(), &order, &report);
    design.existing = existing.map(|e| ExistingPoses {
        path: e.report.file.clone(),
        q: e.qs.clone(),
    });
    Ok(SelectOutcome {
        selection: sel,
        report,
        order,
        refined,
        design,
        seconds,
    })
}

/// The design against the pool's bound (`run.gap`); returns the bound's
/// ln det.
fn with_gap(
    x: &Blocks,
    prior: Option<&Prior>,
    sel: &Selection,
    run: &SelectRun,
    report: &mut SelectReport,
) -> std::result::Result<Option<f64>, ExperimentError> {
    let Some(settings) = &run.gap else {
        return Ok(None);
    };
    let bound = crate::bound::relaxation_bound(x, prior, run.settings.n, settings)?;
    let g = crate::bound::design_gap(x, prior, &sel.poses, &bound)?;
    report.set_gap(&g);
    Ok(Some(bound.ln_bound))
}

/// The design refined off the pool (`run.refine`): its joint values
/// replace the pool's in the report.
#[allow(clippy::too_many_arguments)]
fn refine(
    robot: &Robot,
    pool: &Pool,
    x: &Blocks,
    prior: Option<&Prior>,
    sel: &Selection,
    run: &SelectRun,
    pool_bound: Option<f64>,
    report: &mut SelectReport,
) -> std::result::Result<Option<Refinement>, ExperimentError> {
    let Some(settings) = &run.refine else {
        return Ok(None);
    };
    let qs: Vec<Vec<f64>> = sel.poses.iter().map(|&k| pool.q(k)).collect();
    let r = crate::select::refine(
        robot,
        robot.params(run.params),
        &robot.nominal,
        &pool.spec.filters,
        prior,
        &qs,
        settings,
    )?;
    let mut rr = RefinementReport::new(pool, &sel.poses, &r);
    if let Some(lb) = pool_bound {
        rr.set_bound(lb, x.p());
    }
    report.refinement = Some(rr);
    for (c, p) in report.configurations.iter_mut().zip(&r.poses) {
        c.q.clone_from(&p.q);
    }
    Ok(Some(r))
}

/// What a selection's "how many poses" curve is computed from: its pool
/// (robot at `params`, Jacobian, ids by position) and search.
#[derive(Clone, Copy, Debug)]
pub struct CurveOf<'a> {
    /// The robot.
    pub robot: &'a Robot,
    /// The parameters the pool's Jacobian is at.
    pub params: ParamSet,
    /// The pool's Jacobian.
    pub x: &'a Blocks,
    /// The pool's ids, by position.
    pub ids: &'a [usize],
    /// The selection's settings.
    pub settings: &'a Settings,
    /// Its criterion.
    pub criterion: CriterionKind,
    /// Its algorithm.
    pub algorithm: Algorithm,
    /// The design's own size (always among the curve's sizes).
    pub n: usize,
}

/// The "how many poses" curve of a selection ([`crate::how_many`]) at
/// sensor noise σ `noise` (metres per coordinate), recommending the
/// fewest poses predicted to reach `target_mm` when given, else the knee:
/// what `select --report` draws and Python's `Design.how_many` returns.
///
/// # Errors
/// A noise or target that is not a finite number > 0, or a failing
/// selection or bound.
pub fn how_many_curve(
    c: CurveOf<'_>,
    noise: f64,
    target_mm: Option<f64>,
) -> std::result::Result<crate::how_many::PoseCountCurve, crate::how_many::HowManyError> {
    let mut cs = crate::how_many::CurveSettings::new(c.settings.clone(), noise);
    cs.criterion = c.criterion;
    cs.algorithm = c.algorithm;
    cs.also = vec![c.n];
    cs.target_mm = target_mm;
    crate::how_many::pose_count_curve(c.robot, c.robot.params(c.params), c.x, c.ids, &cs)
}
