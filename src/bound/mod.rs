//! The convex D-optimal relaxation as a certified upper bound on OI_D.
//!
//! For a pool of poses with Jacobian blocks `X_i` (`t × p`) and designs of
//! `N` poses, the relaxation
//!
//! `maximise ln det M(w),  M(w) = Σ_i w_i X_iᵀX_i,  0 ≤ w_i ≤ 1,  Σ_i w_i = N`   (R)
//!
//! contains every `N`-pose design (`w` = its indicator vector), so its optimum
//! `ln det M*` bounds `ln OI_D` of all of them from above. Every design then
//! carries a certified gap, its D-efficiency
//! `(det M_design / det M*)^{1/p}` ([`gap::DesignGap`]).
//!
//! The pipeline ([`relaxation_bound`]):
//! 1. scale the Jacobian columns to a common size ([`variance::scale_columns`];
//!    `ln det` shifts by the known `2·Σ ln s_j`);
//! 2. a first-order solver ([`exchange`]) gives a warm point and its variances
//!    `d_i = tr(X_i M(w)⁻¹ X_iᵀ)`;
//! 3. Clarabel ([`conic`]) solves (R) on the candidates that can carry weight
//!    (support ∪ the largest `d_i`); the optimality conditions
//!    (`w_i = 1 ⇒ d_i ≥ c`, `0 < w_i < 1 ⇒ d_i = c`, `w_i = 0 ⇒ d_i ≤ c`) are
//!    checked on the whole pool, violators added and (R) re-solved;
//! 4. the bound reported is the certificate (eq. C, [`variance::certificate`])
//!    `ln det M(w) + p·ln(S_N(w)/p)`, valid at any positive definite `M(w)`:
//!    it never depends on a solver having converged. Solver objective values
//!    are reported beside it but never used as the bound.
//!
//! **Prior information** ([`relaxation_bound`]): with poses
//! already measured, `M(w) = M0 + Σ_i w_i X_iᵀX_i` in (R); every stage
//! carries `M0` (the scaled `M̃0` of [`variance::Scaled`], the constant of
//! Clarabel's PSD block, Newton's `ln det`), and the certificate becomes
//! eq. (C0) `ln det M(w) + p·ln((tr(M(w)⁻¹M0) + S_N)/p)`, which equals (C)
//! when `M0 = 0`. `N·t < p` is then allowed.

pub mod conic;
mod error;
pub mod first_order;
pub mod gap;
pub mod newton;
mod pair;
mod support;
pub mod variance;

pub use error::BoundError;
pub use gap::{DesignGap, design_gap};

use crate::blocks::Blocks;
use crate::bound::conic::ConicOutcome;
use crate::bound::first_order::Evaluation;
use crate::criterion::Prior;
use crate::model::{ParamSet, Robot};
use crate::pool::Pool;
use conic::{ConicSettings, ConicStatus};
use first_order::{ExchangeOutcome, ExchangeSettings, candidates, evaluate};
use newton::NewtonSettings;
use serde::{Deserialize, Serialize};
use std::time::Instant;
use variance::{
    VarianceWork, check_problem_with_prior, make_feasible, nth_largest, scale_columns_with_prior,
};

/// Weight above which a pose counts as carrying relaxation weight in
/// [`Bound::support_size`].
pub const SUPPORT_TOL: f64 = 1e-6;

/// The solver of the candidate subproblems of (R).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum RelaxationSolver {
    /// Clarabel on the PSD + exponential-cone form ([`conic`]).
    Clarabel,
    /// The log-barrier Newton method on `ln det M(w)` itself ([`newton`]):
    /// the default, 5–15 times faster than Clarabel on every pool measured
    /// (PUMA, UR5 full pose, a four-marker TIAGo) with a tighter certificate.
    #[default]
    Newton,
}

crate::choice!(RelaxationSolver { Clarabel => "clarabel", Newton => "newton" });

/// Settings of [`relaxation_bound`]. Build with [`BoundSettings::builder`]
/// (validated) or take [`BoundSettings::default`].
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default)]
pub struct BoundSettings {
    /// Target certified gap `ln_bound − ln_primal`. Default 1e-6.
    pub gap_tol: f64,
    /// Solve (R) on candidate sets with `solver` (true) or with the
    /// first-order solver alone (false). Default true.
    pub use_conic: bool,
    /// The candidate-set solver: Newton (default) or Clarabel.
    pub solver: RelaxationSolver,
    /// First-order certificate gap at which screening stops and Clarabel
    /// takes over. Default 1e-2.
    pub screen_gap: f64,
    /// Poses outside the support added to Clarabel's candidate set, by
    /// largest `d_i`. Default 100.
    pub screen_extra: usize,
    /// Pools of at most this many poses go to Clarabel whole. Default 400.
    pub direct_limit: usize,
    /// Maximum candidate-set solves (screening rounds). Default 20: with
    /// the support reduction of large candidate sets a round is cheap, and
    /// the 10⁶-pose PUMA pool at N = 145 needs 11.
    pub max_rounds: usize,
    /// Most violators added to the candidates per round, by largest `d_i`.
    /// Default 300.
    pub max_add: usize,
    /// Clarabel's gap and feasibility tolerance in screening rounds: solves
    /// whose purpose is to find the poses that violate the optimality
    /// conditions outside the candidates. The last solve (no violator left,
    /// or the whole pool) uses `conic.tol_gap`. Default 1e-7.
    pub screen_tol: f64,
    /// When the last Clarabel solve leaves no violator outside its
    /// candidates but its certificate gap is still above `gap_tol` (solver
    /// accuracy), run the first-order solver from its point for at most
    /// `polish_rounds` rounds; when Clarabel fails, continue the first-order
    /// solver to `gap_tol` instead. Default true.
    pub polish: bool,
    /// Round limit of each polish. Default 20.
    pub polish_rounds: usize,
    /// The first-order solver's settings (its `gap_tol` is overridden by
    /// `screen_gap` or `gap_tol` as the stage needs).
    pub first_order: ExchangeSettings,
    /// Clarabel's settings.
    pub conic: ConicSettings,
    /// The Newton solver's settings.
    pub newton: NewtonSettings,
}

impl Default for BoundSettings {
    fn default() -> Self {
        Self {
            gap_tol: 1e-6,
            use_conic: true,
            solver: RelaxationSolver::Newton,
            screen_gap: 1e-2,
            screen_extra: 100,
            direct_limit: 400,
            max_rounds: 20,
            max_add: 300,
            screen_tol: 1e-7,
            polish: true,
            polish_rounds: 20,
            first_order: ExchangeSettings::default(),
            conic: ConicSettings::default(),
            newton: NewtonSettings::default(),
        }
    }
}

impl BoundSettings {
    /// A builder starting from the defaults.
    #[must_use]
    pub fn builder() -> BoundSettingsBuilder {
        BoundSettingsBuilder(Self::default())
    }

    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), BoundError> {
        let pos = error::positive;
        pos("gap_tol", self.gap_tol)?;
        pos("screen_gap", self.screen_gap)?;
        pos("screen_tol", self.screen_tol)?;
        if self.max_add == 0 {
            return Err(BoundError::InvalidSetting {
                name: "max_add",
                value: "0".into(),
                reason: "must be ≥ 1",
            });
        }
        if self.polish_rounds == 0 {
            return Err(BoundError::InvalidSetting {
                name: "polish_rounds",
                value: "0".into(),
                reason: "must be ≥ 1",
            });
        }
        if self.max_rounds == 0 {
            return Err(BoundError::InvalidSetting {
                name: "max_rounds",
                value: "0".into(),
                reason: "must be ≥ 1",
            });
        }
        self.first_order.validate()?;
        self.newton.validate()?;
        self.conic.validate()
    }
}

/// Validated construction of [`BoundSettings`].
#[derive(Clone, Debug)]
pub struct BoundSettingsBuilder(BoundSettings);

impl BoundSettingsBuilder {
    /// Target certified gap (default 1e-6).
    #[must_use]
    pub fn gap_tol(mut self, v: f64) -> Self {
        self.0.gap_tol = v;
        self
    }
    /// Clarabel (true, default) or the first-order solver alone.
    #[must_use]
    pub fn use_conic(mut self, v: bool) -> Self {
        self.0.use_conic = v;
        self
    }
    /// Screening gap of the first-order stage (default 1e-2).
    #[must_use]
    pub fn screen_gap(mut self, v: f64) -> Self {
        self.0.screen_gap = v;
        self
    }
    /// Extra candidates for Clarabel (default 100).
    #[must_use]
    pub fn screen_extra(mut self, v: usize) -> Self {
        self.0.screen_extra = v;
        self
    }
    /// Pool size up to which Clarabel gets the whole pool (default 400).
    #[must_use]
    pub fn direct_limit(mut self, v: usize) -> Self {
        self.0.direct_limit = v;
        self
    }
    /// Clarabel tolerance of screening rounds (default 1e-7).
    #[must_use]
    pub fn screen_tol(mut self, v: f64) -> Self {
        self.0.screen_tol = v;
        self
    }
    /// Most violators added per round (default 300).
    #[must_use]
    pub fn max_add(mut self, v: usize) -> Self {
        self.0.max_add = v;
        self
    }
    /// Maximum candidate-set solves (default 20).
    #[must_use]
    pub fn max_rounds(mut self, v: usize) -> Self {
        self.0.max_rounds = v;
        self
    }
    /// Round limit of each polish (default 20).
    #[must_use]
    pub fn polish_rounds(mut self, v: usize) -> Self {
        self.0.polish_rounds = v;
        self
    }
    /// First-order polishing after Clarabel (default true).
    #[must_use]
    pub fn polish(mut self, v: bool) -> Self {
        self.0.polish = v;
        self
    }
    /// First-order solver settings.
    #[must_use]
    pub fn first_order(mut self, v: ExchangeSettings) -> Self {
        self.0.first_order = v;
        self
    }
    /// Clarabel settings.
    #[must_use]
    pub fn conic(mut self, v: ConicSettings) -> Self {
        self.0.conic = v;
        self
    }
    /// The candidate-set solver (default Clarabel).
    #[must_use]
    pub fn solver(mut self, v: RelaxationSolver) -> Self {
        self.0.solver = v;
        self
    }
    /// Newton solver settings.
    #[must_use]
    pub fn newton(mut self, v: NewtonSettings) -> Self {
        self.0.newton = v;
        self
    }
    /// Validates and returns the settings.
    pub fn build(self) -> Result<BoundSettings, BoundError> {
        self.0.validate()?;
        Ok(self.0)
    }
}

/// How the bound ended. Every status carries a valid bound; only the gap to
/// the best feasible point differs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundStatus {
    /// `certificate_gap ≤ gap_tol`.
    Certified,
    /// `N` equals the pool size: the only feasible point is `w = 1`, and the
    /// bound is `ln det` of the whole pool, exactly.
    Exact,
    /// The bound is valid but its gap is above `gap_tol` (Clarabel did not
    /// converge, or the round or time limits were hit).
    GapAboveTolerance,
}

/// What the candidate-set stage (Clarabel or Newton) did.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ConicSummary {
    /// Which solver ran.
    pub solver: RelaxationSolver,
    /// Status of the last Clarabel solve (`None` if Clarabel did not run).
    pub status: Option<ConicStatus>,
    /// Interior-point iterations of the last solve.
    pub iterations: u32,
    /// Interior-point iterations of all solves.
    pub total_iterations: u32,
    /// Clarabel solves (screening rounds).
    pub rounds: usize,
    /// Candidates in the last solve.
    pub candidates: usize,
    /// Whether the last solve was repeated without equilibration.
    #[serde(rename = "retried_without_equilibration")]
    pub retried: bool,
    /// Seconds in Clarabel, all rounds.
    pub seconds: f64,
    /// Clarabel's primal objective of the last solve, unscaled (an estimate,
    /// not a bound).
    pub ln_det_primal: Option<f64>,
    /// Clarabel's dual objective of the last solve, unscaled (uncertified:
    /// it bounds only the candidate subproblem, and only up to the solver's
    /// residuals).
    pub ln_det_dual: Option<f64>,
    /// Pairwise steps of the first-order polish after Clarabel.
    pub polish_steps: usize,
}

/// The certified upper bound on `ln OI_D` of every `N`-pose design of a pool.
#[derive(Clone, Debug, Serialize)]
pub struct Bound {
    /// Upper bound on `ln det M` of every `N`-pose design (and on the
    /// relaxation's optimum): the smallest certificate (eq. C) seen.
    pub ln_bound: f64,
    /// `ln det M(w)` at the feasible `weights`: a lower bound on the
    /// relaxation's optimum.
    pub ln_primal: f64,
    /// `ln_bound − ln_primal ≥ 0`.
    pub certificate_gap: f64,
    /// How it ended.
    pub status: BoundStatus,
    /// Poses per design.
    pub n: usize,
    /// Unknowns.
    pub p: usize,
    /// Pool size.
    pub pool_size: usize,
    /// Feasible relaxation weights, one per pool pose.
    pub weights: Vec<f64>,
    /// Poses with weight above [`SUPPORT_TOL`].
    pub support_size: usize,
    /// First-order stage (screening, or the whole solve without Clarabel).
    pub first_order: ExchangeSummary,
    /// Clarabel stage.
    pub conic: ConicSummary,
    /// Wall-clock seconds, all stages.
    pub seconds: f64,
    /// Whether the relaxation included prior information `M0`.
    pub with_prior: bool,
}

/// The summary of a [`Bound`] that every report prints: the bound, its
/// status and what each stage did (the weights left out). Serialised the
/// same way everywhere: the status in snake case (`certified`).
#[derive(Clone, Debug, Serialize)]
pub struct BoundReport {
    /// See [`Bound::ln_bound`].
    pub ln_bound: f64,
    /// `log10` of the bound on OI_D.
    pub log10_bound: f64,
    /// See [`Bound::ln_primal`].
    pub ln_primal: f64,
    /// See [`Bound::certificate_gap`].
    pub certificate_gap: f64,
    /// How it ended.
    pub status: BoundStatus,
    /// Poses per design.
    pub n: usize,
    /// Unknowns.
    pub p: usize,
    /// Pool size.
    pub pool_size: usize,
    /// Poses with weight above [`SUPPORT_TOL`].
    pub support_size: usize,
    /// Wall-clock seconds, all stages.
    pub seconds: f64,
    /// The candidate-set stage.
    pub solver: ConicSummary,
    /// The first-order stage.
    pub first_order: ExchangeSummary,
    /// Whether the relaxation included prior information `M0`.
    pub with_prior: bool,
}

impl From<&Bound> for BoundReport {
    fn from(b: &Bound) -> Self {
        Self {
            ln_bound: b.ln_bound,
            log10_bound: b.log10_bound(),
            ln_primal: b.ln_primal,
            certificate_gap: b.certificate_gap,
            status: b.status,
            n: b.n,
            p: b.p,
            pool_size: b.pool_size,
            support_size: b.support_size,
            seconds: b.seconds,
            solver: b.conic.clone(),
            first_order: b.first_order.clone(),
            with_prior: b.with_prior,
        }
    }
}

/// What the first-order stage did.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ExchangeSummary {
    /// Rounds (full-pool variance evaluations).
    pub rounds: usize,
    /// Pairwise exchange steps.
    pub steps: usize,
    /// Its certificate gap when it stopped.
    pub gap: f64,
    /// Seconds.
    pub seconds: f64,
}

impl Bound {
    /// `log10` of the bound on OI_D.
    #[must_use]
    pub fn log10_bound(&self) -> f64 {
        self.ln_bound / std::f64::consts::LN_10
    }

    /// Pool positions with weight above `tol`, ascending.
    #[must_use]
    pub fn support(&self, tol: f64) -> Vec<usize> {
        (0..self.weights.len())
            .filter(|&i| self.weights[i] > tol)
            .collect()
    }
}

/// The best valid bound and the best feasible point seen so far (scaled
/// units).
struct Best {
    bound: f64,
    ln_det: f64,
    w: Vec<f64>,
}

impl Best {
    fn gap(&self) -> f64 {
        self.bound - self.ln_det
    }

    /// Takes a polish's bound if smaller and its point if better.
    fn absorb(&mut self, pol: &ExchangeOutcome) {
        self.bound = self.bound.min(pol.ln_bound);
        if pol.ln_det > self.ln_det {
            self.ln_det = pol.ln_det;
            self.w.clone_from(&pol.weights);
        }
    }
}

/// Bounds `ln OI_D` of every `n`-pose design drawn from the pool whose
/// stacked Jacobian is `x`, by solving the relaxation (R) and certifying the
/// result with eq. (C).
///
/// Errors (bad input): `n` larger than the pool, `n·t < p` (every design
/// singular), a non-finite entry, a rank-deficient pool Jacobian, invalid
/// settings. A solver that stalls gives a valid bound with status
/// [`BoundStatus::GapAboveTolerance`].
///
/// With prior information `M0` (`prior`: poses already measured) it bounds
/// `ln det(M0 + Σ_{design} X_iᵀX_i)` of every `n`-pose design, certified by
/// eq. (C0); errors also on a prior of another size than the pool's `p`,
/// and when `M0` plus the whole pool is rank deficient.
pub fn relaxation_bound(
    x: &Blocks,
    prior: Option<&Prior>,
    n: usize,
    settings: &BoundSettings,
) -> Result<Bound, BoundError> {
    check_inputs(x, prior, n, settings)?;
    let clock = Instant::now();
    let sc = scale_columns_with_prior(x, prior.map(Prior::matrix), n)?;
    // --- first-order stage: screening (or the whole solve)
    let (fo, first_order) = first_order_stage(&sc, n, settings);
    let mut best = Best {
        bound: fo.ln_bound,
        ln_det: fo.ln_det,
        w: fo.weights.clone(),
    };
    let mut summary = ConicSummary::default();
    if sc.x.n_poses() == n {
        return finish(
            best,
            &sc,
            n,
            BoundStatus::Exact,
            first_order,
            summary,
            clock,
        );
    }
    if settings.use_conic && best.gap() > settings.gap_tol {
        // --- the candidate solves (Clarabel or Newton), screening rounds
        let mut solves = CandidateSolves {
            sc: &sc,
            n,
            settings,
            best: &mut best,
            summary: &mut summary,
            work: VarianceWork::default(),
            scratch: Vec::new(),
        };
        let solved = solves.run(&fo.weights)?;
        // --- they failed: continue the first-order solver instead
        if settings.polish && !solved && best.gap() > settings.gap_tol {
            let mut s = settings.first_order.clone();
            s.gap_tol = settings.gap_tol;
            let pol = first_order::solve_scaled(&sc, n, Some(best.w.clone()), &s);
            summary.polish_steps += pol.steps;
            best.absorb(&pol);
        }
    }
    let status = if best.gap() <= settings.gap_tol {
        BoundStatus::Certified
    } else {
        BoundStatus::GapAboveTolerance
    };
    finish(best, &sc, n, status, first_order, summary, clock)
}

/// Checks the settings, the prior's size and the problem (see
/// [`relaxation_bound`]'s errors), and the Newton system's
/// memory, before any work.
fn check_inputs(
    x: &Blocks,
    prior: Option<&Prior>,
    n: usize,
    settings: &BoundSettings,
) -> Result<(), BoundError> {
    settings.validate()?;
    if let Some(pr) = prior
        && pr.p() != x.p()
    {
        return Err(BoundError::InvalidDesign(format!(
            "the prior information is for {} unknowns, the pool has {}",
            pr.p(),
            x.p()
        )));
    }
    check_problem_with_prior(x, n, prior.is_some())?;
    if settings.use_conic && settings.solver == RelaxationSolver::Newton {
        // Every candidate set holds the support, at least N poses.
        check_newton_memory(n.min(x.n_poses()))?;
    }
    Ok(())
}

/// The first-order solver on the whole pool: to a screening gap when
/// candidate solves follow, else to the final gap.
fn first_order_stage(
    sc: &variance::Scaled,
    n: usize,
    settings: &BoundSettings,
) -> (ExchangeOutcome, ExchangeSummary) {
    let mut fo_settings = settings.first_order.clone();
    fo_settings.gap_tol = if settings.use_conic && sc.x.n_poses() > n {
        settings.screen_gap.max(settings.gap_tol)
    } else {
        settings.gap_tol
    };
    let fo = first_order::solve_scaled(sc, n, None, &fo_settings);
    let summary = ExchangeSummary {
        rounds: fo.rounds,
        steps: fo.steps,
        gap: fo.gap,
        seconds: fo.seconds,
    };
    (fo, summary)
}

/// The candidate-set solves of (R): each round solves the subproblem on a
/// candidate set, spreads its point onto the pool, certifies it there
/// (eq. C), and adds the poses that violate the optimality conditions.
struct CandidateSolves<'a> {
    sc: &'a variance::Scaled,
    n: usize,
    settings: &'a BoundSettings,
    best: &'a mut Best,
    summary: &'a mut ConicSummary,
    work: VarianceWork,
    scratch: Vec<f64>,
}

impl CandidateSolves<'_> {
    /// Runs the rounds from the first-order point `fo_w`; returns whether a
    /// subproblem was solved.
    fn run(&mut self, fo_w: &[f64]) -> Result<bool, BoundError> {
        let (sc, n, settings) = (self.sc, self.n, self.settings);
        let pool = sc.x.n_poses();
        let task = crate::progress::Task::start("bound: candidate solves", None);
        let fo_eval = evaluate(sc, n, fo_w, &mut self.work, &mut self.scratch)
            .expect("the first-order point is positive definite");
        let mut cand = if pool <= settings.direct_limit {
            (0..pool).collect()
        } else {
            candidates(fo_w, &fo_eval.d, settings.screen_extra)
        };
        let mut solved = false;
        // The whole pool needs no screening: solve it once, accurately.
        let mut last = cand.len() == pool;
        for round in 1..=settings.max_rounds {
            if last || round == settings.max_rounds {
                last = true;
            }
            task.inc(1);
            task.note(|| {
                format!(
                    "{:?} on {} candidates, gap {:.2e}",
                    settings.solver,
                    cand.len(),
                    self.best.gap()
                )
            });
            let Some(out) = self.solve(&cand, last)? else {
                break;
            };
            self.record(&out, round, cand.len());
            // Clamp and spread onto the pool; evaluate the certificate there.
            let mut w = vec![0.0; pool];
            for (k, &i) in cand.iter().enumerate() {
                w[i] = out.weights[k];
            }
            make_feasible(&mut w, n);
            let Some(e) = evaluate(sc, n, &w, &mut self.work, &mut self.scratch) else {
                break; // No usable point from the solver: keep the first-order one.
            };
            self.best.bound = self.best.bound.min(e.bound);
            if e.ln_det > self.best.ln_det {
                self.best.ln_det = e.ln_det;
                self.best.w.clone_from(&w);
            }
            solved |= out.status.is_solved();
            if self.best.gap() <= settings.gap_tol || !out.status.is_solved() {
                break;
            }
            if last && round == settings.max_rounds {
                break;
            }
            if !self.next(&mut cand, &e, &w, last) {
                break;
            }
            // Either the candidates hold the optimum (solve them again,
            // accurately), or violators were added from a point accurate
            // enough to find them: the next solve is meant to be the last.
            last = true;
        }
        Ok(solved)
    }

    /// Solves the subproblem on `cand` (to the screening tolerance unless
    /// `last`), warm-started from the best point for Newton; `None` when
    /// the candidate set is rank deficient (which cannot happen for a
    /// support of a positive definite `M(w)`: keep what we have).
    fn solve(&self, cand: &[usize], last: bool) -> Result<Option<ConicOutcome>, BoundError> {
        let (sc, n, settings) = (self.sc, self.n, self.settings);
        let sub = sc.x.select(cand);
        let sub_prior = sc.m0.as_ref().map(|m| m.as_ref());
        let Ok(sub_sc) = scale_columns_with_prior(&sub, sub_prior, n.min(cand.len())) else {
            return Ok(None);
        };
        Ok(Some(match settings.solver {
            RelaxationSolver::Clarabel => {
                let mut cs = settings.conic.clone();
                if !last {
                    cs.tol_gap = cs.tol_gap.max(settings.screen_tol);
                    cs.tol_feas = cs.tol_feas.max(settings.screen_tol);
                }
                conic::solve_scaled(&sub_sc, n, &cs)
            }
            RelaxationSolver::Newton => {
                check_newton_memory(cand.len())?;
                let warm: Vec<f64> = cand.iter().map(|&i| self.best.w[i]).collect();
                let mut ns = settings.newton.clone();
                if !last {
                    ns.tol = ns.tol.max(settings.screen_tol);
                }
                newton::solve_scaled(&sub_sc, n, Some(&warm), &ns, self.best.gap())
            }
        }))
    }

    /// Records a round's solve in the summary; its objective values are in
    /// the units of the pool-scaled blocks: unscaled to raw.
    fn record(&mut self, out: &ConicOutcome, round: usize, candidates: usize) {
        let ln_scale = self.sc.ln_scale;
        let s = &mut *self.summary;
        s.solver = self.settings.solver;
        s.status = Some(out.status);
        s.iterations = out.iterations;
        s.total_iterations += out.iterations;
        s.rounds = round;
        s.candidates = candidates;
        s.retried = out.retried;
        s.seconds += out.seconds;
        s.ln_det_primal = out
            .ln_det_primal
            .is_finite()
            .then_some(out.ln_det_primal + ln_scale);
        s.ln_det_dual = out
            .ln_det_dual
            .is_finite()
            .then_some(out.ln_det_dual + ln_scale);
    }

    /// The optimality conditions on the whole pool at the spread point `w`
    /// (evaluated as `e`): a pose outside the candidates whose `d_i`
    /// exceeds `c`, the N-th largest `d` among the candidates, would enter
    /// the top-N sum `S_N` (with `w` optimal on the candidates, their `d_i`
    /// satisfy the conditions with this `c`). Adds such violators to
    /// `cand` (at most `max_add`, after a Carathéodory reduction of a large
    /// Newton set) and returns true to solve again; with none, returns true
    /// once more for an accurate solve unless `last`, else polishes and
    /// returns false.
    fn next(&mut self, cand: &mut Vec<usize>, e: &Evaluation, w: &[f64], last: bool) -> bool {
        let (sc, n, settings) = (self.sc, self.n, self.settings);
        let pool = sc.x.n_poses();
        let dk: Vec<f64> = cand.iter().map(|&i| e.d[i]).collect();
        let c = nth_largest(&dk, n, &mut self.scratch);
        let mut in_cand = vec![false; pool];
        cand.iter().for_each(|&i| in_cand[i] = true);
        let mut viol: Vec<usize> = (0..pool).filter(|&i| !in_cand[i] && e.d[i] > c).collect();
        if viol.is_empty() {
            if !last {
                return true;
            }
            // What is left is the solver's accuracy. Pairwise steps from
            // the solver's point equalise the variances of the near-tied
            // poses.
            if settings.polish {
                let pol = polish(sc, n, w, settings);
                self.summary.polish_steps += pol.steps;
                self.best.absorb(&pol);
            }
            return false;
        }
        if viol.len() > settings.max_add {
            viol.select_nth_unstable_by(settings.max_add - 1, |&a, &b| e.d[b].total_cmp(&e.d[a]));
            viol.truncate(settings.max_add);
        }
        let m = sc.x.p() * (sc.x.p() + 1) / 2 + 1;
        if settings.solver == RelaxationSolver::Newton && cand.len() > 2 * m {
            // Carry only a Carathéodory-reduced support of this point into
            // the next solve (same M, at most p(p+1)/2 + 1 free poses): the
            // tied poses of a lattice would otherwise grow the Newton
            // system round after round. Only beyond twice that size: below,
            // the cubic cost is small, and a reduced set's degenerate
            // optimum (tied poses at weight 0) slows the barrier method (a
            // 4,096-pose PUMA lattice took 300 Newton steps instead of 60).
            let mut wr = w.to_vec();
            *cand = support::reduce(&sc.x, &mut wr, cand);
        }
        cand.extend(viol);
        cand.sort_unstable();
        cand.dedup();
        true
    }
}
/// First-order polish from a feasible point, limited to
/// `settings.polish_rounds` rounds.
/// Refuses a Newton solve on `k` candidates whose dense `k × k` system
/// exceeds the memory budget (it grows with the square of the design size).
fn check_newton_memory(k: usize) -> Result<(), BoundError> {
    crate::resources::MemoryBudget::from_env()?.check(
        &format!("the Newton solver's {k}×{k} system on {k} candidate poses"),
        crate::resources::bytes_of(k.saturating_mul(k), 8),
    )?;
    Ok(())
}

fn polish(sc: &variance::Scaled, n: usize, w: &[f64], settings: &BoundSettings) -> ExchangeOutcome {
    let mut s = settings.first_order.clone();
    s.gap_tol = settings.gap_tol;
    s.max_rounds = settings.polish_rounds;
    first_order::solve_scaled(sc, n, Some(w.to_vec()), &s)
}

fn finish(
    best: Best,
    sc: &variance::Scaled,
    n: usize,
    status: BoundStatus,
    first_order: ExchangeSummary,
    conic: ConicSummary,
    clock: Instant,
) -> Result<Bound, BoundError> {
    let ln_bound = best.bound + sc.ln_scale;
    let ln_primal = best.ln_det + sc.ln_scale;
    Ok(Bound {
        certificate_gap: certificate_gap(ln_bound, ln_primal)?,
        ln_bound,
        ln_primal,
        status,
        n,
        p: sc.x.p(),
        pool_size: sc.x.n_poses(),
        support_size: best.w.iter().filter(|&&v| v > SUPPORT_TOL).count(),
        weights: best.w,
        first_order,
        conic,
        seconds: clock.elapsed().as_secs_f64(),
        with_prior: sc.m0.is_some(),
    })
}

/// `ln_bound − ln_primal`, or an error when the bound is below the primal by
/// more than rounding. Both are sums of `p` logarithms of Cholesky pivots of
/// matrices with entries of order 1 (column-scaled), each with a relative
/// error of a few `p·ε`; `1e-9·max(1, |ln_primal|)` is ~1,000 times that for
/// p ≤ 45, and any real defect (a wrong dual, a bad certificate) is many
/// orders larger. Within rounding the gap is reported as it is (possibly a
/// tiny negative number), never clamped.
fn certificate_gap(ln_bound: f64, ln_primal: f64) -> Result<f64, BoundError> {
    let gap = ln_bound - ln_primal;
    let tolerance = 1e-9 * ln_primal.abs().max(1.0);
    if gap.is_nan() || gap < -tolerance {
        return Err(BoundError::CertificateBelowPrimal {
            ln_bound,
            ln_primal,
            excess: -gap,
            tolerance,
        });
    }
    Ok(gap)
}

/// The bound for a built-in robot's full lattice pool at a parameter set:
/// builds the pool and its Jacobian and calls [`relaxation_bound`]. The
/// benchmark entry point (`pool_bound(&Robot::puma560(), ParamSet::Nominal,
/// 5, 30, &BoundSettings::default())` is the 15,625-pose PUMA problem).
pub fn pool_bound(
    robot: &Robot,
    params: ParamSet,
    levels: usize,
    n: usize,
    settings: &BoundSettings,
) -> Result<(Pool, Blocks, Bound), BoundError> {
    let pool = Pool::full(robot, levels)?;
    let x = pool.jacobian(robot, robot.params(params));
    let b = relaxation_bound(&x, None, n, settings)?;
    Ok((pool, x, b))
}

#[cfg(test)]
mod certificate_tests {
    use super::*;

    #[test]
    fn a_certificate_below_its_primal_is_an_error_not_a_zero_gap() {
        assert_eq!(certificate_gap(44.0, 43.5).unwrap(), 0.5);
        // Rounding below the primal is reported as it is, not clamped.
        let g = certificate_gap(43.5 - 1e-12, 43.5).unwrap();
        assert!(g < 0.0 && g > -2e-12);
        let e = certificate_gap(43.0, 43.5).unwrap_err().to_string();
        assert!(
            e.contains("below the primal") && e.contains("5.000e-1"),
            "{e}"
        );
        assert!(certificate_gap(f64::NAN, 43.5).is_err());
    }
}
