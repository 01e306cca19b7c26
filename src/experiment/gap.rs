//! The `gap` pipeline, owned by the library: a design's certified
//! D-efficiency against the relaxation bound of its pool (eq. (C)), with
//! the information of poses measured before it, for a design whose poses
//! are in the pool or one refined off it (scored from its own joint
//! values against the bound of the pool it started from). The command
//! line and the Python package both call [`score_design`].

use super::ExperimentError;
use super::select::Existing;
use crate::bound::gap::{d_efficiency, design_gap};
use crate::bound::{Bound, BoundSettings, DesignGap, relaxation_bound};
use crate::io::design::DesignFile;
use crate::model::{ParamSet, Robot};
use crate::pool::PoolFilter;
use crate::report::{GapReport, PoolInfo};
use std::path::Path;

/// A design's poses.
#[derive(Clone, Copy, Debug)]
pub enum DesignPoses<'a> {
    /// Positions in the pool.
    InPool(&'a [usize]),
    /// Joint values off the pool (a refined design; radians, metres).
    Refined(&'a [Vec<f64>]),
}

/// A design scored: the report, the bound and the gap.
#[derive(Clone, Debug)]
pub struct ScoredDesign {
    /// The report (`gap --json`'s).
    pub report: GapReport,
    /// The pool's certified bound.
    pub bound: Bound,
    /// The design against it.
    pub gap: DesignGap,
}

pub use super::pool::ScoringPool;

/// Scores a design of `ids` (its poses' pool ids, for the report) against
/// the bound of pool `on` for as many poses, with the prior information of
/// `existing` poses when given.
///
/// # Errors
/// A failing bound, or a design not of the pool.
pub fn score_design(
    on: ScoringPool<'_>,
    ids: Vec<usize>,
    poses: DesignPoses<'_>,
    existing: Option<Existing>,
    settings: &BoundSettings,
) -> Result<ScoredDesign, ExperimentError> {
    let prior = existing.as_ref().map(|e| &e.prior);
    let n = match poses {
        DesignPoses::InPool(p) => p.len(),
        DesignPoses::Refined(q) => q.len(),
    };
    let bound = relaxation_bound(on.x, prior, n, settings)?;
    let gap = match poses {
        DesignPoses::InPool(positions) => design_gap(on.x, prior, positions, &bound)?,
        DesignPoses::Refined(qs) => refined_gap(on, qs, prior, &bound),
    };
    let mut report = GapReport::new(
        PoolInfo::new(on.robot, on.pool),
        on.params,
        ids,
        &gap,
        &bound,
    );
    report.existing = existing.map(|e| e.report);
    if matches!(poses, DesignPoses::Refined(_)) {
        report.refined = true;
        report.exceeds_bound = gap.ln_oid.map(|l| l > bound.ln_bound);
    }
    Ok(ScoredDesign { report, bound, gap })
}

/// A refined design's gap: its own Jacobian's `ln det` against the value
/// of the pool's bound (which is for the pool's Jacobian, and so may not
/// bound it).
fn refined_gap(
    on: ScoringPool<'_>,
    qs: &[Vec<f64>],
    prior: Option<&crate::criterion::Prior>,
    b: &Bound,
) -> DesignGap {
    let xd = crate::blocks::jacobian_of(on.robot, on.robot.params(on.params), qs.len(), |k, q| {
        q.copy_from_slice(&qs[k]);
    });
    let all: Vec<usize> = (0..qs.len()).collect();
    let ln = crate::criterion::design_ln_det(&xd, prior, &all);
    DesignGap {
        n: qs.len(),
        p: b.p,
        ln_oid: ln,
        log10_oid: ln.map(|l| l / std::f64::consts::LN_10),
        ln_bound: b.ln_bound,
        log10_bound: b.log10_bound(),
        d_efficiency: d_efficiency(ln, b.ln_bound, b.p),
        bound_status: b.status,
        certificate_gap: b.certificate_gap,
        weighted: Vec::new(),
        weights: Vec::new(),
    }
}

/// The indices of a design given by its joint values `qs` (radians,
/// metres; `ids` its poses' ids, for the report) at `params`, from its own
/// Jacobian: a design read from a file, scored off any pool.
#[must_use]
pub fn score_joint_values(
    robot: &Robot,
    params: ParamSet,
    qs: &[Vec<f64>],
    ids: Vec<usize>,
    info: PoolInfo,
) -> crate::report::ScoreReport {
    let x = crate::blocks::jacobian_of(robot, robot.params(params), qs.len(), |k, q| {
        q.copy_from_slice(&qs[k]);
    });
    crate::report::ScoreReport::new(info, ids, &x)
}

/// The robot a design was chosen for: with the compliance unknowns of
/// `select --compliance` (the gravity torques from its URDF's inertials),
/// or as it is.
///
/// # Errors
/// A design with compliances for a robot without a URDF's inertials.
pub fn design_robot(robot: Robot, d: &DesignFile) -> Result<Robot, ExperimentError> {
    if d.compliance.is_empty() {
        return Ok(robot);
    }
    let g = super::pool::urdf_gravity(&robot)?;
    Ok(crate::identify::compliance::with_compliant_joints(
        &robot,
        &g,
        &d.compliance,
    )?)
}

/// The `score` of the design file `d` (read from `path`) for the robot of
/// `desc` (the description it names, its orientation rows weighed as the
/// caller asks): its stored joint values on the robot it was chosen for
/// (its compliances included), with table `params`.
pub fn score_design_file(
    path: &Path,
    d: &DesignFile,
    desc: crate::io::Description,
    params: ParamSet,
) -> Result<crate::report::ScoreReport, ExperimentError> {
    let robot = design_robot(desc.robot, d)?;
    let qs = d
        .joint_values(&robot)
        .map_err(|e| crate::Error::Invalid(format!("{}: {e}", path.display())))?;
    let info = PoolInfo {
        robot: robot.name.clone(),
        chain: crate::report::chain(&robot),
        levels: d.spec()?.levels(),
        pool: d.spec()?,
        pool_stats: None,
    };
    Ok(score_joint_values(
        &robot,
        params,
        &qs,
        d.poses.clone(),
        info,
    ))
}

/// The `gap` of the design file `d` (read from `path`): its poses against
/// the certified bound of its own pool, rebuilt from the file's source and
/// filters (`filters` replacing the latter when given) for the robot of
/// `desc` with the compliance unknowns the design was chosen for
/// ([`design_robot`]), at `params`; a design chosen on top of poses
/// measured before is scored and bounded with their information (stored
/// in the file); a refined design, whose poses are off the pool, from its
/// joint values against the bound of the pool it started from.
///
/// # Errors
/// A pool that cannot be rebuilt, poses not of it, a failing bound.
pub fn gap_of_design_file(
    path: &Path,
    d: &DesignFile,
    desc: crate::io::Description,
    filters: Option<Vec<PoolFilter>>,
    params: ParamSet,
    settings: &BoundSettings,
) -> Result<GapReport, ExperimentError> {
    let in_file = |e: crate::Error| crate::Error::Invalid(format!("{}: {e}", path.display()));
    let mut spec = d.spec()?;
    if let Some(f) = filters {
        spec.filters = f;
    }
    let pool = d
        .build_pool(&spec, &desc.robot, &desc.robot.nominal)
        .map_err(in_file)?;
    let robot = design_robot(desc.robot, d)?;
    let x = pool.try_jacobian(&robot, robot.params(params))?;
    let (positions, qs) = if d.refined {
        (Vec::new(), d.joint_values(&robot).map_err(in_file)?)
    } else {
        (d.positions_in(&robot, &pool).map_err(in_file)?, Vec::new())
    };
    let existing = d
        .existing
        .as_ref()
        .map(|e| Existing::from_poses(e.path.clone(), e.q.clone(), Vec::new(), &robot, params))
        .transpose()?;
    let poses = if d.refined {
        DesignPoses::Refined(&qs)
    } else {
        DesignPoses::InPool(&positions)
    };
    let on = ScoringPool {
        robot: &robot,
        pool: &pool,
        x: &x,
        params,
    };
    Ok(score_design(on, d.poses.clone(), poses, existing, settings)?.report)
}
