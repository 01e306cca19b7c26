//! The exchange algorithms: EAE, Fedorov, DETMAX, and multi-start.

use super::random::{design_rng, oi_from_ln_oid, random_design};
use super::{Algorithm, Settings, StepKind, TraceRow};
use crate::blocks::Blocks;
use crate::criterion::{
    Criterion, CriterionError, InfoState, Prior, StateSettings, Status, argmax,
};
use crate::error::{Error, Result};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

/// A selected design with its trace.
#[derive(Clone, Debug, Serialize)]
pub struct Selection {
    /// Pool positions of the design, in the order they entered.
    pub poses: Vec<usize>,
    /// `ln OI_D = ln det(XᵀX)` of the design (no ridge); with a prior,
    /// `ln det(M0 + XᵀX)`.
    pub ln_oid: f64,
    /// The paper's OI, eq. (1).
    pub oi: f64,
    /// One row per step (the paper's Fig. 4–6).
    pub trace: Vec<TraceRow>,
    /// The algorithm that produced it.
    pub algorithm: Algorithm,
    /// Name of the criterion that drove the search (`D` or `OI`).
    pub criterion: String,
    /// The driving criterion's own score of the design
    /// ([`Criterion::score`]; `ln OI_D` for the D criterion).
    pub score: f64,
    /// Index of the start that won (multi-start; a random search: the
    /// number of the best design), 0 otherwise.
    pub start: usize,
    /// `ln OI_D` of every start, in start order (a random search: of its
    /// kept designs, every [`RandomSearch::stride`](super::RandomSearch)-th
    /// one, at most [`SAMPLE_CAP`](super::SAMPLE_CAP)).
    pub start_ln_oid: Vec<f64>,
    /// The criterion's score of every start, in start order: the starts are
    /// ranked by it (`-∞` for a start that failed). A random search ranks
    /// its designs by `ln OI_D` and holds the kept design's score only.
    pub start_score: Vec<f64>,
}

/// Relative improvement below which a step counts as no improvement: a
/// change of `ln det` below ~1e-10 is rounding, not progress (the criterion
/// engine's update error is ~p·u·κ ≈ 1e-12 for well-conditioned designs).
const TOL: f64 = 1e-10;

/// Most sweeps of one modified-Fedorov climb (each sweep tries every design
/// pose once; a climb from a kicked local optimum takes 2–4 on the PUMA).
const MAX_SWEEPS: usize = 100;

fn improves(new: f64, cur: f64) -> bool {
    new > cur + TOL * cur.abs().max(1.0)
}

fn crit_err(e: CriterionError) -> Error {
    Error::Invalid(e.to_string())
}

impl Selection {
    /// Pool positions of the initial design: the final design with every
    /// traced change undone, in order.
    #[must_use]
    pub fn trace_initial(&self) -> Vec<usize> {
        let mut d = self.poses.clone();
        for r in self.trace.iter().rev() {
            if let Some(a) = r.added {
                d.retain(|&x| x != a);
            }
            if let Some(rm) = r.removed {
                d.push(rm);
            }
        }
        d
    }
}

/// One search: the state, the criterion, and the trace.
struct Run<'a, C: Criterion> {
    pool: &'a Blocks,
    crit: &'a mut C,
    state: InfoState,
    fixed: Vec<bool>,
    all: Vec<usize>,
    trace: Vec<TraceRow>,
    buf: Vec<f64>,
}

impl<'a, C: Criterion> Run<'a, C> {
    /// Starts from `design` (on top of `prior`, if any), with a ridge if it
    /// is singular without one.
    fn new(
        pool: &'a Blocks,
        crit: &'a mut C,
        design: &[usize],
        fixed: &[usize],
        prior: Option<&Prior>,
    ) -> Result<Self> {
        let state = |settings| InfoState::with_prior(pool, design, prior.cloned(), settings);
        let state = match state(StateSettings::default()) {
            Ok(s) => s,
            Err(CriterionError::Singular { .. }) => {
                state(StateSettings::default().with_ridge(START_RIDGE)).map_err(crit_err)?
            }
            Err(e) => return Err(crit_err(e)),
        };
        let mut mask = vec![false; pool.n_poses()];
        for &f in fixed {
            mask[f] = true;
        }
        let mut run = Run {
            pool,
            crit,
            state,
            fixed: mask,
            all: (0..pool.n_poses()).collect(),
            trace: Vec::new(),
            buf: Vec::new(),
        };
        run.record(StepKind::Init, None, None);
        Ok(run)
    }

    fn record(&mut self, kind: StepKind, added: Option<usize>, removed: Option<usize>) {
        let ln_oid = self.state.ln_det();
        self.trace.push(TraceRow {
            step: self.trace.len(),
            kind,
            added,
            removed,
            size: self.state.design().len(),
            ln_oid,
            oi: oi_from_ln_oid(ln_oid, self.pool.p()),
            ridge: self.state.ridge() > 0.0,
        });
    }

    fn score(&mut self) -> f64 {
        self.crit.score(self.pool, &self.state)
    }

    /// Drops the ridge if the design is non-singular without it.
    fn try_drop_ridge(&mut self) {
        if self.state.ridge() > 0.0 && self.state.set_ridge(self.pool, 0.0).is_ok() {
            self.record(StepKind::DropRidge, None, None);
        }
    }

    /// The removable design pose whose removal leaves the best score, with
    /// that score.
    fn best_removal(&mut self) -> Option<(usize, f64)> {
        let n = self.state.design().len();
        self.buf.resize(n, 0.0);
        self.crit
            .price_removals(self.pool, &self.state, &mut self.buf);
        for (k, &j) in self.state.design().iter().enumerate() {
            if self.fixed[j] {
                self.buf[k] = f64::NEG_INFINITY;
            }
        }
        argmax(&self.buf).map(|k| (self.state.design()[k], self.buf[k]))
    }

    /// The pool pose whose addition gives the best score, with that score.
    fn best_add(&mut self) -> Option<(usize, f64)> {
        self.buf.resize(self.all.len(), 0.0);
        self.crit
            .price_adds(self.pool, &self.state, &self.all, &mut self.buf);
        argmax(&self.buf).map(|i| (self.all[i], self.buf[i]))
    }

    /// The best `(out, in)` pair over `outs × pool`, with its score.
    fn best_exchange(&mut self, outs: &[usize]) -> Option<(usize, usize, f64)> {
        if outs.is_empty() {
            return None;
        }
        self.buf.resize(self.all.len() * outs.len(), 0.0);
        self.crit
            .price_exchanges(self.pool, &self.state, outs, &self.all, &mut self.buf);
        argmax(&self.buf).map(|k| (outs[k % outs.len()], self.all[k / outs.len()], self.buf[k]))
    }

    fn apply_exchange(&mut self, out: usize, inn: usize) -> bool {
        match self.state.exchange(self.pool, out, inn) {
            Ok(Status::Regular { .. }) => {
                self.record(StepKind::Exchange, Some(inn), Some(out));
                true
            }
            _ => false,
        }
    }

    /// The paper's exchange step (§IV, step 2): remove the pose whose removal
    /// costs least, add the best pose for the reduced design, keep the swap
    /// if the criterion increases; repeat until it does not.
    fn exchange_phase(&mut self, max_iter: usize) {
        for _ in 0..max_iter {
            let cur = self.score();
            let Some((out, _)) = self.best_removal() else {
                return;
            };
            let Some((_, inn, new)) = self.best_exchange(&[out]) else {
                return;
            };
            if !improves(new, cur) || !self.apply_exchange(out, inn) {
                return;
            }
        }
    }

    /// Fedorov exchange: the best `(out, in)` pair over design × pool,
    /// priced by the one-step `2t × 2t` exchange formula, until no pair
    /// improves.
    fn fedorov_phase(&mut self, max_iter: usize) {
        for _ in 0..max_iter {
            let cur = self.score();
            let outs = self.removable();
            let Some((out, inn, new)) = self.best_exchange(&outs) else {
                return;
            };
            if !improves(new, cur) || !self.apply_exchange(out, inn) {
                return;
            }
        }
    }

    /// The design poses a step may remove (all but the fixed ones).
    fn removable(&self) -> Vec<usize> {
        self.state
            .design()
            .iter()
            .copied()
            .filter(|&j| !self.fixed[j])
            .collect()
    }

    /// Modified Fedorov exchange (Cook & Nachtsheim 1980): each removable
    /// design pose in turn is exchanged for the pool pose that gives the best
    /// score, at once if that improves it; sweeps until a whole sweep
    /// improves nothing (or `max_sweeps`).
    fn modified_fedorov_phase(&mut self, max_sweeps: usize) {
        for _ in 0..max_sweeps {
            let mut improved = false;
            let outs = self.removable();
            for out in outs {
                let cur = self.score();
                let Some((_, inn, new)) = self.best_exchange(&[out]) else {
                    continue;
                };
                if improves(new, cur) && self.apply_exchange(out, inn) {
                    improved = true;
                }
            }
            if !improved {
                return;
            }
        }
    }

    /// Iterated local search (Lourenço, Martin & Stützle 2003) from the
    /// current design: [`modified_fedorov_phase`](Self::modified_fedorov_phase)
    /// to a local optimum, then `rounds` times: exchange `kick` random
    /// removable design poses for random pool poses outside the design
    /// (drawn from `rng`), climb back with exchange steps and modified
    /// Fedorov, and keep the result if it beats the best so far; otherwise
    /// return to the best (state and trace). The kicks let the search leave
    /// the local optima of single exchanges, where EAE and Fedorov stop.
    fn iterated_phase(
        &mut self,
        rounds: usize,
        kick: usize,
        max_iter: usize,
        rng: &mut ChaCha8Rng,
    ) {
        use rand::RngExt;
        self.modified_fedorov_phase(MAX_SWEEPS);
        let mut best = (self.state.clone(), self.trace.clone(), self.score());
        let n_pool = self.pool.n_poses();
        if self.removable().is_empty() || self.state.design().len() >= n_pool {
            return; // nothing to kick out, or nothing to kick in
        }
        for _ in 0..rounds {
            for _ in 0..kick {
                let outs = self.removable();
                let out = outs[rng.random_range(0..outs.len())];
                let inn = loop {
                    let c = rng.random_range(0..n_pool);
                    if !self.state.contains(c) {
                        break c;
                    }
                };
                // A kick that would make the design singular is skipped.
                self.apply_exchange(out, inn);
            }
            self.exchange_phase(max_iter);
            self.modified_fedorov_phase(MAX_SWEEPS);
            let score = self.score();
            if improves(score, best.2) {
                best = (self.state.clone(), self.trace.clone(), score);
            } else {
                self.state = best.0.clone();
                self.trace = best.1.clone();
            }
        }
    }

    /// Add steps (§IV, steps 4–5): add the best pose until the design has
    /// `n` poses or no addition increases the criterion.
    fn add_phase(&mut self, n: usize) {
        while self.state.design().len() < n {
            let cur = self.score();
            let Some((inn, new)) = self.best_add() else {
                return;
            };
            // A D-criterion addition never decreases ln det; the OI of eq. (1)
            // is monotone in it too, but keep the paper's stopping rule.
            let improves = new >= cur; // false for NaN
            if !improves && self.state.ridge() == 0.0 {
                return;
            }
            if self.state.add(self.pool, inn).is_err() {
                return;
            }
            self.record(StepKind::Add, Some(inn), None);
            self.try_drop_ridge();
        }
    }

    /// DETMAX excursions (§II): add the best pose, remove the least useful
    /// one; stop when the pose just added is the one removed.
    fn detmax_phase(&mut self, max_iter: usize) {
        for _ in 0..max_iter {
            let Some((inn, _)) = self.best_add() else {
                return;
            };
            if self.state.add(self.pool, inn).is_err() {
                return;
            }
            self.record(StepKind::Add, Some(inn), None);
            let Some((out, _)) = self.best_removal() else {
                return;
            };
            if !matches!(
                self.state.remove(self.pool, out),
                Ok(Status::Regular { .. })
            ) {
                return;
            }
            self.record(StepKind::Remove, None, Some(out));
            if out == inn {
                return;
            }
        }
    }

    fn finish(mut self, algorithm: Algorithm) -> Result<Selection> {
        self.try_drop_ridge();
        if self.state.ridge() > 0.0 {
            return Err(Error::Invalid(format!(
                "the best design found is singular: the pool cannot determine all {} unknowns",
                self.pool.p()
            )));
        }
        let ln_oid = self.state.ln_det();
        let score = self.score();
        Ok(Selection {
            poses: self.state.design().to_vec(),
            ln_oid,
            oi: oi_from_ln_oid(ln_oid, self.pool.p()),
            trace: self.trace,
            algorithm,
            criterion: self.crit.name().to_string(),
            score,
            start: 0,
            start_ln_oid: vec![ln_oid],
            start_score: vec![score],
        })
    }
}

/// Relative ridge `δ` of a rank-deficient start: `1e-8` times each
/// column's mean information per pool pose
/// ([`StateSettings::ridge`](crate::criterion::StateSettings::ridge); see
/// the module docs).
const START_RIDGE: f64 = 1e-8;

fn non_fixed(pool: &Blocks, fixed: &[usize]) -> Vec<usize> {
    let mut mask = vec![false; pool.n_poses()];
    fixed.iter().for_each(|&f| mask[f] = true);
    (0..pool.n_poses()).filter(|&i| !mask[i]).collect()
}

fn start_design(pool: &Blocks, s: &Settings, size: usize, rng: &mut ChaCha8Rng) -> Vec<usize> {
    random_design(
        rng,
        &non_fixed(pool, &s.fixed),
        &s.fixed,
        size.max(s.fixed.len()),
    )
}

/// Runs `phases` on a state started from a random design of `size` poses
/// (fixed ones included), then, with [`Settings::ils`] rounds, the iterated
/// local search from its result, and finishes it.
fn run_from_random<C: Criterion>(
    pool: &Blocks,
    crit: &mut C,
    s: &Settings,
    rng: &mut ChaCha8Rng,
    size: usize,
    algorithm: Algorithm,
    phases: impl FnOnce(&mut Run<'_, C>),
) -> Result<Selection> {
    s.validate(pool)?;
    let init = start_design(pool, s, size, rng);
    let mut run = Run::new(pool, crit, &init, &s.fixed, s.prior.as_ref())?;
    phases(&mut run);
    if s.ils > 0 {
        run.iterated_phase(s.ils, s.kick, s.max_iter, rng);
    }
    run.finish(algorithm)
}

/// The paper's exchange-add-exchange (§IV): `n0` random initial poses (fixed
/// ones included) → exchange steps → add steps up to `N` → exchange steps.
pub fn eae<C: Criterion>(
    pool: &Blocks,
    crit: &mut C,
    s: &Settings,
    rng: &mut ChaCha8Rng,
) -> Result<Selection> {
    run_from_random(pool, crit, s, rng, s.initial, Algorithm::Eae, |run| {
        run.exchange_phase(s.max_iter);
        run.add_phase(s.n);
        run.exchange_phase(s.max_iter);
    })
}

/// Fedorov exchange from a random `N`-pose design.
pub fn fedorov<C: Criterion>(
    pool: &Blocks,
    crit: &mut C,
    s: &Settings,
    rng: &mut ChaCha8Rng,
) -> Result<Selection> {
    run_from_random(pool, crit, s, rng, s.n, Algorithm::Fedorov, |run| {
        run.fedorov_phase(s.max_iter)
    })
}

/// DETMAX from a random `N`-pose design.
pub fn detmax<C: Criterion>(
    pool: &Blocks,
    crit: &mut C,
    s: &Settings,
    rng: &mut ChaCha8Rng,
) -> Result<Selection> {
    run_from_random(pool, crit, s, rng, s.n, Algorithm::Detmax, |run| {
        run.detmax_phase(s.max_iter)
    })
}

/// Fedorov polish of a finished design: its trace continues.
pub fn polish<C: Criterion>(
    pool: &Blocks,
    crit: &mut C,
    sel: Selection,
    s: &Settings,
) -> Result<Selection> {
    let mut run = Run::new(pool, crit, &sel.poses, &s.fixed, s.prior.as_ref())?;
    run.trace = sel.trace.clone();
    run.fedorov_phase(s.max_iter);
    let mut out = run.finish(sel.algorithm)?;
    out.start = sel.start;
    out.start_ln_oid = sel.start_ln_oid;
    out.start_score = sel.start_score;
    Ok(out)
}

/// Runs `algorithm` from `s.starts` independent random starts in parallel
/// (start `k` draws from ChaCha stream `k` of `s.seed`), keeps the best by
/// the criterion's own score ([`Criterion::score`]; the lowest start on
/// ties), and optionally polishes it with Fedorov exchange.
/// `make` builds one criterion per start. Deterministic for a seed whatever
/// the number of threads.
pub fn multistart<C, F>(
    pool: &Blocks,
    make: F,
    algorithm: Algorithm,
    s: &Settings,
) -> Result<Selection>
where
    C: Criterion,
    F: Fn() -> C + Sync,
{
    s.validate(pool)?;
    if algorithm == Algorithm::Random {
        let r = super::random_search(
            pool,
            s.prior.as_ref(),
            &non_fixed(pool, &s.fixed),
            &s.fixed,
            s.n,
            s.designs,
            s.seed,
        );
        if !r.best_ln_oid.is_finite() {
            return Err(Error::Invalid("every random design is singular".into()));
        }
        let mut crit = make();
        let run = Run::new(pool, &mut crit, &r.best, &s.fixed, s.prior.as_ref())?;
        let mut sel = run.finish(Algorithm::Random)?;
        // The kept sample of the designs (every `r.stride`-th); `start` is
        // the number of the best design.
        sel.start_ln_oid = r.ln_oid;
        sel.start = r.best_design;
        return finish_polish(pool, make, sel, s);
    }
    let one = |k: usize| -> Result<Selection> {
        let mut rng = design_rng(s.seed, k as u64);
        let mut crit = make();
        match algorithm {
            Algorithm::Eae => eae(pool, &mut crit, s, &mut rng),
            Algorithm::Fedorov => fedorov(pool, &mut crit, s, &mut rng),
            Algorithm::Detmax => detmax(pool, &mut crit, s, &mut rng),
            Algorithm::Random => unreachable!("handled above"),
        }
    };
    let task = crate::progress::Task::start(
        &format!("select ({algorithm:?} starts)").to_lowercase(),
        Some(s.starts as u64),
    );
    let one = |k: usize| {
        let r = one(k);
        task.inc(1);
        r
    };
    let results: Vec<Result<Selection>> = if s.starts == 1 {
        vec![one(0)]
    } else {
        (0..s.starts).into_par_iter().map(one).collect()
    };
    drop(task);
    let mut best: Option<Selection> = None;
    let mut lns = Vec::with_capacity(results.len());
    let mut scores = Vec::with_capacity(results.len());
    let mut first_err = None;
    for (k, r) in results.into_iter().enumerate() {
        match r {
            Ok(mut sel) => {
                lns.push(sel.ln_oid);
                scores.push(sel.score);
                sel.start = k;
                if best.as_ref().is_none_or(|b| sel.score > b.score) {
                    best = Some(sel);
                }
            }
            Err(e) => {
                lns.push(f64::NEG_INFINITY);
                scores.push(f64::NEG_INFINITY);
                first_err.get_or_insert(e);
            }
        }
    }
    let Some(mut sel) = best else {
        return Err(first_err.expect("at least one start"));
    };
    sel.start_ln_oid = lns;
    sel.start_score = scores;
    finish_polish(pool, make, sel, s)
}

fn finish_polish<C, F>(pool: &Blocks, make: F, sel: Selection, s: &Settings) -> Result<Selection>
where
    C: Criterion,
    F: Fn() -> C + Sync,
{
    if s.polish {
        polish(pool, &mut make(), sel, s)
    } else {
        Ok(sel)
    }
}

#[cfg(test)]
mod tests {
    //! The exchange algorithms on small random pools (30 poses, `t = 2`,
    //! `p = 4`), checked against a direct evaluation of every design
    //! ([`design_ln_det`], a Cholesky of `XᵀX` from scratch) and by brute
    //! force over all single swaps.
    use super::*;
    use crate::criterion::{DCriterion, design_ln_det};
    use crate::select::{StepKind, design_rng};
    use faer::Mat;

    /// The searches accept a step that raises `ln det` by more than
    /// `TOL·max(|ln det|, 1)` (1e-10 here, `ln det` ≈ 5); the updated values
    /// differ from a direct evaluation by ~1e-13 on these well-conditioned
    /// 4 × 4 problems. 1e-8 covers both and is far below any real
    /// improvement of a swap (≥ 1e-3 on a random pool).
    const EPS: f64 = 1e-8;

    fn pool(seed: u64) -> Blocks {
        let mut s = seed;
        Blocks::new(
            Mat::from_fn(60, 4, |_, _| crate::linalg::test_rng::lcg(&mut s)),
            2,
        )
    }

    fn settings() -> Settings {
        Settings {
            n: 6,
            initial: 3,
            ..Settings::default()
        }
    }

    fn ln_det(x: &Blocks, poses: &[usize]) -> f64 {
        design_ln_det(x, None, poses).expect("a regular design")
    }

    /// No swap of a design pose (other than `fixed`) for a pool pose
    /// outside the design raises `ln det` by more than `EPS`.
    fn assert_swap_optimal(x: &Blocks, poses: &[usize], fixed: &[usize]) {
        let base = ln_det(x, poses);
        for k in 0..poses.len() {
            for i in (0..x.n_poses()).filter(|i| !poses.contains(i)) {
                let mut d = poses.to_vec();
                d[k] = i;
                if let (false, Some(v)) = (fixed.contains(&poses[k]), design_ln_det(x, None, &d)) {
                    assert!(v <= base + EPS, "swap {k}->{i}: {base} to {v}");
                }
            }
        }
    }

    /// A finished selection reports its own design: `N` distinct poses,
    /// `ln OI_D` and the D criterion's score equal to a direct evaluation,
    /// `oi` from it; its trace replays from `trace_initial` step by step,
    /// each row's size and (ridge-free) `ln OI_D` that of the design after
    /// it, and ends at the design.
    fn assert_consistent(x: &Blocks, sel: &Selection, n: usize) {
        let mut sorted = sel.poses.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), n, "{:?}", sel.poses);
        let direct = ln_det(x, &sel.poses);
        assert!(
            (sel.ln_oid - direct).abs() < EPS,
            "{} vs {direct}",
            sel.ln_oid
        );
        assert!((sel.score - direct).abs() < EPS);
        assert_eq!(sel.oi, oi_from_ln_oid(sel.ln_oid, x.p()));
        assert_eq!(sel.criterion, DCriterion::new().name());
        let mut d = sel.trace_initial();
        for (k, row) in sel.trace.iter().enumerate() {
            assert_eq!(row.step, k);
            if let Some(r) = row.removed {
                d.retain(|&j| j != r);
            }
            if let Some(a) = row.added {
                d.push(a);
            }
            assert_eq!(row.size, d.len(), "row {k}");
            if !row.ridge {
                let v = ln_det(x, &d);
                assert!(
                    (row.ln_oid - v).abs() < EPS,
                    "row {k}: {} vs {v}",
                    row.ln_oid
                );
            }
        }
        d.sort_unstable();
        assert_eq!(d, sorted);
        assert_eq!(sel.trace.last().map(|r| r.ln_oid), Some(sel.ln_oid));
    }

    /// An exchange is kept only if it raises the criterion: along every
    /// trace, each exchange row's `ln OI_D` is above the row before it.
    fn assert_exchanges_improve(sel: &Selection) {
        for w in sel.trace.windows(2) {
            if w[1].kind == StepKind::Exchange && !w[0].ridge {
                assert!(w[1].ln_oid > w[0].ln_oid, "{:?}", w);
            }
        }
    }

    #[test]
    fn fedorov_ends_where_no_swap_improves() {
        for seed in 1..4 {
            let x = pool(seed);
            let s = settings();
            let sel = fedorov(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
            assert_consistent(&x, &sel, 6);
            assert_exchanges_improve(&sel);
            assert_eq!(sel.algorithm, Algorithm::Fedorov);
            assert_eq!(sel.trace_initial().len(), 6);
            assert!(sel.trace.len() > 1, "no exchange from a random start");
            assert_swap_optimal(&x, &sel.poses, &[]);
        }
    }

    /// EAE: `n0` random poses, exchange steps, add steps up to `N`, exchange
    /// steps; the paper's rule keeps adding while the criterion does not
    /// fall, which for `ln det` is always.
    #[test]
    fn eae_grows_from_its_initial_design_to_n() {
        for seed in 1..4 {
            let x = pool(seed);
            let s = settings();
            let sel = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
            assert_consistent(&x, &sel, 6);
            assert_exchanges_improve(&sel);
            assert_eq!(sel.algorithm, Algorithm::Eae);
            assert_eq!(sel.trace_initial().len(), 3);
            let adds = sel.trace.iter().filter(|r| r.kind == StepKind::Add).count();
            assert_eq!(adds, 3);
            // A regular start (6 rows for 4 unknowns) never had a ridge to drop.
            assert!(!sel.trace[0].ridge);
            assert!(sel.trace.iter().all(|r| r.kind != StepKind::DropRidge));
            assert_exchange_step_stopped(&x, &sel.poses);
            // The last exchange phase leaves no better (out, in) pair for
            // the pose whose removal costs least: at least not below the
            // start.
            assert!(sel.ln_oid > sel.trace[0].ln_oid);
        }
    }

    /// DETMAX ends when the pose just added is the one removed, with the
    /// design back at `N` and never below its start.
    #[test]
    fn detmax_stops_when_the_added_pose_is_removed() {
        for seed in 1..4 {
            let x = pool(seed);
            let sel = detmax(
                &x,
                &mut DCriterion::new(),
                &settings(),
                &mut design_rng(seed, 0),
            )
            .unwrap();
            assert_consistent(&x, &sel, 6);
            let n = sel.trace.len();
            assert!(n >= 3);
            let (add, rem) = (&sel.trace[n - 2], &sel.trace[n - 1]);
            assert_eq!((add.kind, rem.kind), (StepKind::Add, StepKind::Remove));
            assert_eq!(add.added, rem.removed);
            assert!(sel.ln_oid >= sel.trace[0].ln_oid - EPS);
            // Each excursion adds the best pose and removes the least
            // useful: the removal row never ends below the row before the add.
            for k in (1..n - 1).filter(|&k| sel.trace[k].kind == StepKind::Add) {
                assert!(sel.trace[k + 1].ln_oid >= sel.trace[k - 1].ln_oid - EPS);
            }
        }
    }

    /// Fixed poses are in every design and no step removes them; a start
    /// too small to be regular (one pose, 2 rows for 4 unknowns) runs on a
    /// ridge that is dropped once the design is regular, and the result is
    /// ridge-free.
    #[test]
    fn fixed_poses_stay_and_a_singular_start_runs_on_a_ridge() {
        let x = pool(5);
        let s = Settings {
            initial: 1,
            fixed: vec![7, 11],
            ..settings()
        };
        for algorithm in [Algorithm::Eae, Algorithm::Fedorov, Algorithm::Detmax] {
            let sel = multistart(&x, DCriterion::new, algorithm, &s).unwrap();
            assert_consistent(&x, &sel, 6);
            assert!(
                sel.poses.contains(&7) && sel.poses.contains(&11),
                "{algorithm:?}"
            );
            assert!(
                sel.trace
                    .iter()
                    .all(|r| r.removed != Some(7) && r.removed != Some(11))
            );
            if algorithm == Algorithm::Fedorov {
                assert_swap_optimal(&x, &sel.poses, &[7, 11]);
            }
        }
        let sel = eae(
            &x,
            &mut DCriterion::new(),
            &Settings {
                fixed: vec![],
                ..s.clone()
            },
            &mut design_rng(1, 0),
        )
        .unwrap();
        assert!(sel.trace[0].ridge, "a one-pose start is singular");
        let drops = sel
            .trace
            .iter()
            .filter(|r| r.kind == StepKind::DropRidge)
            .count();
        assert_eq!(drops, 1);
        assert!(!sel.trace.last().unwrap().ridge);
    }

    /// Multi-start keeps the start of highest score (the lowest on ties)
    /// and reports every start's `ln OI_D` and score in start order; each
    /// start is the single-start run of its own stream, so the kept one is
    /// reproduced by `eae` on stream `start`.
    #[test]
    fn multistart_keeps_the_best_start() {
        let x = pool(2);
        // One exchange per phase, so that the starts end apart.
        let s = Settings {
            starts: 5,
            seed: 9,
            max_iter: 1,
            ..settings()
        };
        let sel = multistart(&x, DCriterion::new, Algorithm::Eae, &s).unwrap();
        assert_consistent(&x, &sel, 6);
        assert_eq!(sel.start_score.len(), 5);
        assert_eq!(sel.start_ln_oid, sel.start_score);
        let best = sel
            .start_score
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let first = sel.start_score.iter().position(|&v| v == best).unwrap();
        assert_eq!((sel.start, sel.score), (first, best));
        for k in 0..5 {
            let one = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(9, k as u64)).unwrap();
            assert_eq!(one.ln_oid, sel.start_ln_oid[k], "start {k}");
            if k == sel.start {
                assert_eq!(one.poses, sel.poses);
            }
        }
        assert!(
            sel.start_score.iter().any(|&v| v < best - 1e-3),
            "starts that all tie test no ranking: {:?}",
            sel.start_score
        );
    }

    /// The Fedorov polish continues the trace of the design it polishes,
    /// never lowers it, ends where no swap improves, and keeps the
    /// multi-start record.
    #[test]
    fn polish_continues_the_trace_to_a_swap_optimum() {
        let x = pool(3);
        let s = Settings {
            starts: 2,
            ..settings()
        };
        let plain = multistart(&x, DCriterion::new, Algorithm::Detmax, &s).unwrap();
        let polished = multistart(
            &x,
            DCriterion::new,
            Algorithm::Detmax,
            &Settings {
                polish: true,
                ..s.clone()
            },
        )
        .unwrap();
        assert_consistent(&x, &polished, 6);
        assert_eq!(polished.trace[..plain.trace.len()], plain.trace[..]);
        assert!(polished.ln_oid >= plain.ln_oid - EPS);
        assert_swap_optimal(&x, &polished.poses, &[]);
        assert_eq!(
            (polished.start, &polished.start_ln_oid, polished.algorithm),
            (plain.start, &plain.start_ln_oid, Algorithm::Detmax)
        );
    }

    /// Iterated local search starts from the algorithm's result and keeps
    /// only improvements: never below the same start without it, and at a
    /// swap optimum (its climbs are modified-Fedorov sweeps).
    #[test]
    fn iterated_local_search_ends_at_a_swap_optimum_above_its_start() {
        for seed in 1..4 {
            let x = pool(seed);
            let plain = settings();
            let s = Settings {
                ils: 4,
                kick: 2,
                ..plain.clone()
            };
            let a = eae(&x, &mut DCriterion::new(), &plain, &mut design_rng(seed, 0)).unwrap();
            let b = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
            assert_consistent(&x, &b, 6);
            assert!(b.ln_oid >= a.ln_oid - EPS, "{} < {}", b.ln_oid, a.ln_oid);
            assert_swap_optimal(&x, &b.poses, &[]);
        }
    }

    /// A pool that cannot determine every unknown (its last column zero):
    /// every algorithm, random search included, refuses rather than return
    /// a singular design.
    #[test]
    fn a_rank_deficient_pool_is_an_error() {
        let x = pool(4);
        let mut m = x.mat().to_owned();
        m.col_mut(3).fill(0.0);
        let x = Blocks::new(m, 2);
        let s = Settings {
            designs: 20,
            ..settings()
        };
        for algorithm in [
            Algorithm::Eae,
            Algorithm::Fedorov,
            Algorithm::Detmax,
            Algorithm::Random,
        ] {
            let e = multistart(&x, DCriterion::new, algorithm, &s).unwrap_err();
            assert!(e.to_string().contains("singular"), "{algorithm:?}: {e}");
        }
    }

    /// The random search reports its best design, evaluated afresh, with
    /// the number of that design and its sample of `ln OI_D`, none above
    /// the kept one.
    #[test]
    fn random_search_keeps_its_best_design() {
        let x = pool(6);
        let s = Settings {
            designs: 40,
            ..settings()
        };
        let sel = multistart(&x, DCriterion::new, Algorithm::Random, &s).unwrap();
        assert_consistent(&x, &sel, 6);
        assert_eq!(sel.algorithm, Algorithm::Random);
        assert!(sel.start < 40);
        assert!(!sel.start_ln_oid.is_empty());
        assert!(sel.start_ln_oid.iter().all(|&v| v <= sel.ln_oid + EPS));
    }

    /// `pool` with `n` poses.
    fn pool_of(n: usize, seed: u64) -> Blocks {
        let mut s = seed;
        Blocks::new(
            Mat::from_fn(2 * n, 4, |_, _| crate::linalg::test_rng::lcg(&mut s)),
            2,
        )
    }

    /// Iterated local search keeps a round only if it improves: from the
    /// global optimum (8 poses, `N = 6`, checked over all 28 designs) each
    /// round's kick is climbed back from and undone, so the state and the
    /// trace are those of the climb alone, whatever the rounds did.
    #[test]
    fn rounds_that_do_not_improve_are_undone() {
        let x = pool_of(8, 21);
        let start: Vec<usize> = (0..6).collect();
        let mut best = f64::NEG_INFINITY;
        for a in 0..8 {
            for b in a + 1..8 {
                let d: Vec<usize> = (0..8).filter(|&i| i != a && i != b).collect();
                best = best.max(ln_det(&x, &d));
            }
        }
        let mut crit = DCriterion::new();
        let mut climb = Run::new(&x, &mut crit, &start, &[], None).unwrap();
        climb.modified_fedorov_phase(MAX_SWEEPS);
        assert!(
            (climb.state.ln_det() - best).abs() < EPS,
            "the climb is not at the optimum"
        );
        let mut crit = DCriterion::new();
        let mut ils = Run::new(&x, &mut crit, &start, &[], None).unwrap();
        ils.iterated_phase(6, 2, 1000, &mut design_rng(1, 0));
        assert_eq!(ils.state.design(), climb.state.design());
        assert_eq!(ils.trace, climb.trace);
    }

    /// EAE's last phase stops where the paper's exchange step does: the
    /// best exchange of the design pose whose removal costs least (brute
    /// force) does not raise `ln det`.
    fn assert_exchange_step_stopped(x: &Blocks, poses: &[usize]) {
        let without = |k: usize| {
            let d: Vec<usize> = poses.iter().copied().filter(|&j| j != poses[k]).collect();
            ln_det(x, &d)
        };
        let out = (0..poses.len())
            .max_by(|&a, &b| without(a).total_cmp(&without(b)))
            .unwrap();
        let base = ln_det(x, poses);
        for i in (0..x.n_poses()).filter(|i| !poses.contains(i)) {
            let mut d = poses.to_vec();
            d[out] = i;
            if let Some(v) = design_ln_det(x, None, &d) {
                assert!(
                    v <= base + EPS,
                    "exchange {}->{i}: {base} to {v}",
                    poses[out]
                );
            }
        }
    }

    /// The kicks get past local optima of single exchanges, the point of
    /// the search: over ten pools of 40 poses, from the first 6, it never
    /// ends below the modified-Fedorov optimum it starts from, and some
    /// search ends above it (by more than 1e-6, far above rounding). Both
    /// the climb and the search end where no single swap improves.
    #[test]
    fn kicks_get_past_single_exchange_optima() {
        let mut above = 0;
        for seed in 0..10 {
            let x = pool_of(40, 50 + seed);
            let start: Vec<usize> = (0..6).collect();
            let mut crit = DCriterion::new();
            let mut climb = Run::new(&x, &mut crit, &start, &[], None).unwrap();
            climb.modified_fedorov_phase(MAX_SWEEPS);
            let mut crit = DCriterion::new();
            let mut ils = Run::new(&x, &mut crit, &start, &[], None).unwrap();
            ils.iterated_phase(8, 2, 1000, &mut design_rng(seed, 0));
            let (a, b) = (climb.state.ln_det(), ils.state.ln_det());
            assert!(b >= a - EPS, "pool {seed}: {b} < {a}");
            assert_swap_optimal(&x, climb.state.design(), &[]);
            assert_swap_optimal(&x, ils.state.design(), &[]);
            if b > a + 1e-6 {
                above += 1;
            }
        }
        assert!(above > 0, "no search left its local optimum");
    }
}
