//! The relaxation bound's pipeline ([`relaxation_bound`]): inputs checked,
//! columns scaled, a first-order stage, candidate-set solves (Clarabel or
//! Newton) certified on the whole pool, a polish, and the certificate gap.

use super::first_order::{ExchangeOutcome, candidates, evaluate};
use super::variance::{
    VarianceWork, check_problem_with_prior, make_feasible, nth_largest, scale_columns_with_prior,
};
use crate::blocks::Blocks;
use crate::bound::conic::ConicOutcome;
use crate::bound::first_order::Evaluation;
use crate::criterion::Prior;
use crate::model::{ParamSet, Robot};
use crate::pool::Pool;
use std::time::Instant;

use super::error::BoundError;
use super::outcome::SUPPORT_TOL;
use super::outcome::{Bound, BoundStatus, ConicSummary, ExchangeSummary};
use super::settings::{BoundSettings, RelaxationSolver};
use super::{conic, first_order, newton, support, variance};
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
/// Refuses a Newton solve on `k` candidates whose dense `k × k` system
/// exceeds the memory budget (it grows with the square of the design size).
fn check_newton_memory(k: usize) -> Result<(), BoundError> {
    crate::resources::MemoryBudget::from_env()?.check(
        &format!("the Newton solver's {k}×{k} system on {k} candidate poses"),
        crate::resources::bytes_of(k.saturating_mul(k), 8),
    )?;
    Ok(())
}

/// First-order polish from a feasible point, limited to
/// `settings.polish_rounds` rounds.
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
