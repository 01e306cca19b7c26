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
                let ridged = StateSettings::builder().ridge(START_RIDGE).build();
                state(ridged.map_err(crit_err)?).map_err(crit_err)?
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
            crate::progress::checkpoint();
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
            crate::progress::checkpoint();
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
                crate::progress::checkpoint();
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
            crate::progress::checkpoint();
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
            crate::progress::checkpoint();
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
            crate::progress::checkpoint();
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
    s.validate_for(pool)?;
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
    s.validate_for(pool)?;
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
        // Starts still queued when the work is stopped end here, before
        // their criterion's set-up (tens of ms each on a large pool).
        crate::progress::checkpoint();
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
mod tests;
