//! The [`Criterion`] trait the selection algorithms are written against, and
//! its two implementations: [`DCriterion`] (`ln det M`, priced by the update
//! formulas over maintained pool variances) and [`OiCriterion`] (the paper's
//! eigenvalue OI of eq. (1), recomputed per candidate).
//!
//! An exchange algorithm needs, per iteration: the current score; the score
//! after adding each candidate (add step, DETMAX excursions); the score after
//! removing each design pose (remove step); and the score after exchanging
//! design pose `j` for candidate `i`, either for one `j` (the paper's
//! exchange step: remove the cheapest pose, then find the best replacement)
//! or for all `j` at once (Fedorov). All prices are batched and written into
//! caller-provided slices, so the D criterion can serve them from one dense
//! product per call while the OI criterion loops over eigenvalue problems.
//!
//! Prices are the *score of the changed design* (not a difference), so add,
//! remove and exchange prices compare directly with each other and with
//! [`Criterion::score`]. An infeasible change — a candidate already in the
//! design, or a result that is numerically singular — is priced
//! `f64::NEG_INFINITY`. Prices never are NaN for finite pools.

use faer::MatRef;
use rayon::prelude::*;

use super::state::InfoState;
use super::variances::{PoolVariances, SCAN_CHUNK};
use crate::linalg::eigen::EigenScratch;
use crate::linalg::gram::{add_gram, gather_block, view};
use crate::linalg::rank::{eigenvalues_regular, equilibrate_into};
use crate::linalg::small::{STACK_T, ln_det_i_minus};

/// Candidates per parallel work item of the OI criterion (`O(p³)` each).
const OI_CHUNK: usize = 8;
use crate::blocks::Blocks;

/// A design criterion: scores an information state (higher is better) and
/// prices the changes an exchange algorithm considers. Methods take `&mut
/// self` so an implementation can keep caches synchronized with the state
/// (keyed on [`InfoState::id`] and [`InfoState::version`]).
pub trait Criterion {
    /// Short name for reports.
    fn name(&self) -> &'static str;

    /// Score of the state's design.
    fn score(&mut self, pool: &Blocks, state: &InfoState) -> f64;

    /// `out[c]` = score after adding pool pose `candidates[c]`
    /// (`-∞` if it is already in the design). `out.len() == candidates.len()`.
    fn price_adds(
        &mut self,
        pool: &Blocks,
        state: &InfoState,
        candidates: &[usize],
        out: &mut [f64],
    );

    /// `out[k]` = score after removing design pose `state.design()[k]`
    /// (`-∞` if the result is numerically singular).
    /// `out.len() == state.design().len()`.
    fn price_removals(&mut self, pool: &Blocks, state: &InfoState, out: &mut [f64]);

    /// Candidate-major exchange prices: `out[c·outs.len() + o]` = score after
    /// removing design pose `outs[o]` (a pool index, which must be in the
    /// design) and adding pool pose `candidates[c]`; `-∞` if the candidate is
    /// in the design or the result is numerically singular.
    /// `out.len() == candidates.len() * outs.len()`.
    fn price_exchanges(
        &mut self,
        pool: &Blocks,
        state: &InfoState,
        outs: &[usize],
        candidates: &[usize],
        out: &mut [f64],
    );
}

/// Index of the largest value that is not `-∞` (NaN is skipped), the lowest
/// index on ties; `None` if there is none. Deterministic.
#[must_use]
pub fn argmax(values: &[f64]) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (i, &v) in values.iter().enumerate() {
        if v > f64::NEG_INFINITY && best.is_none_or(|(_, b)| v > b) {
            best = Some((i, v));
        }
    }
    best.map(|(i, _)| i)
}

fn check_outs(state: &InfoState, outs: &[usize]) {
    for &j in outs {
        assert!(
            state.contains(j),
            "exchange out-pose {j} is not in the design"
        );
    }
}

/// The determinant criterion `ln det M` (the log of the paper's `OI_D`),
/// priced by the matrix determinant lemma over [`PoolVariances`] that follow
/// the state by low-rank updates. Add prices cost `O(t³)` per candidate,
/// exchange prices `O(p·t²)` per (candidate, out-pose) pair.
#[derive(Clone, Debug, Default)]
pub struct DCriterion {
    vars: Option<PoolVariances>,
}

impl DCriterion {
    /// A criterion with an empty cache.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// The pool variances, synchronized with `state`.
    pub fn variances(&mut self, pool: &Blocks, state: &InfoState) -> &mut PoolVariances {
        match &mut self.vars {
            Some(v) if v.t() == pool.t() => v.sync(pool, state),
            _ => self.vars = Some(PoolVariances::new(pool, state)),
        }
        self.vars.as_mut().expect("just set")
    }
}

impl Criterion for DCriterion {
    fn name(&self) -> &'static str {
        "D"
    }

    fn score(&mut self, _pool: &Blocks, state: &InfoState) -> f64 {
        state.ln_det()
    }

    fn price_adds(
        &mut self,
        pool: &Blocks,
        state: &InfoState,
        candidates: &[usize],
        out: &mut [f64],
    ) {
        assert_eq!(candidates.len(), out.len());
        let base = state.ln_det();
        let vars = &*self.variances(pool, state);
        vars.add_scores(candidates, out, base, |i| state.contains(i));
    }

    fn price_removals(&mut self, pool: &Blocks, state: &InfoState, out: &mut [f64]) {
        assert_eq!(state.design().len(), out.len());
        let base = state.ln_det();
        let floor = state.pivot_floor();
        let t = pool.t();
        let vars = &*self.variances(pool, state);
        for (o, &j) in out.iter_mut().zip(state.design()) {
            *o = ln_det_i_minus(vars.packed(j), t, floor).map_or(f64::NEG_INFINITY, |g| base + g);
        }
    }

    fn price_exchanges(
        &mut self,
        pool: &Blocks,
        state: &InfoState,
        outs: &[usize],
        candidates: &[usize],
        out: &mut [f64],
    ) {
        check_outs(state, outs);
        let base = state.ln_det();
        let floor = state.pivot_floor();
        self.variances(pool, state)
            .exchange_gains(pool, state, outs, candidates, floor, out);
        out.par_chunks_mut(SCAN_CHUNK).for_each(|oc| {
            for o in oc {
                *o += base;
            }
        });
    }
}

/// The paper's eigenvalue observability index, eq. (1):
/// `OI = (σ_1⋯σ_L)^{1/L} / L = (det M)^{1/(2L)} / L` with `L = p`,
/// recomputed for every candidate from the eigenvalues of the changed `M`
/// (`M + X_iᵀX_i`, `M − X_jᵀX_j`, or both): `O(p³)` per candidate, the slow
/// path the determinant updates replace.
///
/// A changed `M` whose equilibrated form `D^-½ M D^-½` (`D = diag M`, the
/// rule of `linalg::rank`) has `λ_max ≥ max_condition·λ_min`
/// ([`StateSettings::max_condition`](super::StateSettings::max_condition)
/// of the state) is numerically singular and priced `-∞`. Since `OI` is a
/// monotone function of `ln det M`, it ranks designs as [`DCriterion`] does.
#[derive(Clone, Copy, Debug, Default)]
pub struct OiCriterion;

/// Per-chunk scratch of the OI criterion.
struct OiScratch {
    p: usize,
    /// The changed `M`, `p×p` column-major.
    m: Vec<f64>,
    block: Vec<f64>,
    /// The equilibrated changed `M`.
    scaled: Vec<f64>,
    eig: EigenScratch,
}

impl OiScratch {
    fn new(p: usize) -> Self {
        Self {
            p,
            m: vec![0.0; p * p],
            block: Vec::with_capacity(STACK_T * p),
            scaled: Vec::with_capacity(p * p),
            eig: EigenScratch::new(p),
        }
    }

    /// OI of `M + Σ plus blocks − Σ minus blocks`.
    fn oi(
        &mut self,
        m: MatRef<'_, f64>,
        pool: &Blocks,
        plus: Option<usize>,
        minus: Option<usize>,
        max_condition: f64,
    ) -> f64 {
        let p = self.p;
        for (j, col) in self.m.chunks_exact_mut(p).enumerate() {
            for (x, y) in col.iter_mut().zip(m.col(j).iter()) {
                *x = *y;
            }
        }
        for (q, sign) in [(plus, 1.0), (minus, -1.0)] {
            if let Some(q) = q {
                gather_block(pool.block(q), &mut self.block);
                add_gram(&mut self.m, p, &self.block, pool.t(), sign);
            }
        }
        oi_of(
            view(&self.m, p),
            max_condition,
            &mut self.eig,
            &mut self.scaled,
        )
    }
}

/// The OI of `M` from the eigenvalues of its equilibrated form `M̃`
/// (`ln det M = ln det M̃ + 2 Σ ln s_j`), `-∞` when `M̃` fails the rank
/// rule.
fn oi_of(
    m: MatRef<'_, f64>,
    max_condition: f64,
    eig: &mut EigenScratch,
    scaled: &mut Vec<f64>,
) -> f64 {
    let p = m.nrows();
    let s = equilibrate_into(m, scaled);
    let Some(ev) = eig.eigenvalues(view(scaled, p)) else {
        return f64::NEG_INFINITY;
    };
    if !eigenvalues_regular(ev, max_condition) {
        return f64::NEG_INFINITY;
    }
    let ln_det: f64 =
        ev.iter().map(|l| l.ln()).sum::<f64>() + 2.0 * s.iter().map(|v| v.ln()).sum::<f64>();
    let pf = p as f64;
    (ln_det / (2.0 * pf)).exp() / pf
}

impl OiCriterion {
    /// The criterion (stateless).
    #[must_use]
    pub fn new() -> Self {
        Self
    }
}

impl Criterion for OiCriterion {
    fn name(&self) -> &'static str {
        "OI"
    }

    fn score(&mut self, _pool: &Blocks, state: &InfoState) -> f64 {
        let mut eig = EigenScratch::new(state.p());
        oi_of(
            state.m(),
            state.settings().max_condition,
            &mut eig,
            &mut Vec::new(),
        )
    }

    fn price_adds(
        &mut self,
        pool: &Blocks,
        state: &InfoState,
        candidates: &[usize],
        out: &mut [f64],
    ) {
        assert_eq!(candidates.len(), out.len());
        let maxc = state.settings().max_condition;
        out.par_chunks_mut(OI_CHUNK)
            .zip(candidates.par_chunks(OI_CHUNK))
            .for_each(|(oc, cc)| {
                let mut s = OiScratch::new(state.p());
                for (o, &i) in oc.iter_mut().zip(cc) {
                    *o = if state.contains(i) {
                        f64::NEG_INFINITY
                    } else {
                        s.oi(state.m(), pool, Some(i), None, maxc)
                    };
                }
            });
    }

    fn price_removals(&mut self, pool: &Blocks, state: &InfoState, out: &mut [f64]) {
        assert_eq!(state.design().len(), out.len());
        let maxc = state.settings().max_condition;
        let design = state.design();
        out.par_chunks_mut(OI_CHUNK)
            .zip(design.par_chunks(OI_CHUNK))
            .for_each(|(oc, dc)| {
                let mut s = OiScratch::new(state.p());
                for (o, &j) in oc.iter_mut().zip(dc) {
                    *o = s.oi(state.m(), pool, None, Some(j), maxc);
                }
            });
    }

    fn price_exchanges(
        &mut self,
        pool: &Blocks,
        state: &InfoState,
        outs: &[usize],
        candidates: &[usize],
        out: &mut [f64],
    ) {
        check_outs(state, outs);
        let no = outs.len();
        assert_eq!(out.len(), candidates.len() * no);
        if no == 0 {
            return;
        }
        let maxc = state.settings().max_condition;
        out.par_chunks_mut(OI_CHUNK * no)
            .zip(candidates.par_chunks(OI_CHUNK))
            .for_each(|(oc, cc)| {
                let mut s = OiScratch::new(state.p());
                for (oi, &i) in oc.chunks_mut(no).zip(cc) {
                    for (o, &j) in oi.iter_mut().zip(outs) {
                        *o = if state.contains(i) {
                            f64::NEG_INFINITY
                        } else {
                            s.oi(state.m(), pool, Some(i), Some(j), maxc)
                        };
                    }
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::state::StateSettings;
    use crate::criterion::test_util::random_pool;

    /// The paper's exchange step (§IV step 2), written once against the
    /// trait: remove the pose whose removal costs least, find its best
    /// replacement, exchange if the score improves.
    fn exchange_step(crit: &mut dyn Criterion, pool: &Blocks, state: &mut InfoState) -> bool {
        let current = crit.score(pool, state);
        let mut rem = vec![0.0; state.design().len()];
        crit.price_removals(pool, state, &mut rem);
        let Some(k) = argmax(&rem) else { return false };
        let out = state.design()[k];
        let cands: Vec<usize> = (0..pool.n_poses()).collect();
        let mut ex = vec![0.0; cands.len()];
        crit.price_exchanges(pool, state, &[out], &cands, &mut ex);
        let Some(c) = argmax(&ex) else { return false };
        if ex[c] > current + 1e-9 * current.abs().max(1.0) {
            state.exchange(pool, out, cands[c]).unwrap().is_regular()
        } else {
            false
        }
    }

    #[test]
    fn one_exchange_routine_runs_on_both_criteria() {
        let pool = random_pool(300, 3, 8, 17);
        let start: Vec<usize> = (0..6).collect();
        let mut designs = Vec::new();
        for crit in [
            &mut DCriterion::new() as &mut dyn Criterion,
            &mut OiCriterion::new(),
        ] {
            let mut st = InfoState::new(&pool, &start, StateSettings::default()).unwrap();
            let s0 = crit.score(&pool, &st);
            let mut steps = 0;
            while exchange_step(crit, &pool, &mut st) && steps < 200 {
                steps += 1;
            }
            assert!(steps > 0);
            assert!(crit.score(&pool, &st) > s0);
            designs.push(st.design().to_vec());
        }
        // OI is a monotone function of ln det, so the same moves are chosen.
        assert_eq!(designs[0], designs[1]);
    }

    #[test]
    fn oi_prices_are_monotone_images_of_d_prices() {
        let pool = random_pool(120, 3, 9, 5);
        let st = InfoState::new(&pool, &[0, 1, 2, 3, 4], StateSettings::default()).unwrap();
        let p = 9.0;
        let to_oi = |d: f64| (d / (2.0 * p)).exp() / p;
        let (mut dc, mut oc) = (DCriterion::new(), OiCriterion::new());
        assert!((to_oi(dc.score(&pool, &st)) - oc.score(&pool, &st)).abs() < 1e-12);
        let cands: Vec<usize> = (0..120).collect();
        let (mut a, mut b) = (vec![0.0; 120], vec![0.0; 120]);
        dc.price_adds(&pool, &st, &cands, &mut a);
        oc.price_adds(&pool, &st, &cands, &mut b);
        for (x, y) in a.iter().zip(&b) {
            if *x == f64::NEG_INFINITY {
                assert_eq!(*y, f64::NEG_INFINITY);
            } else {
                assert!((to_oi(*x) - y).abs() < 1e-10 * y);
            }
        }
        let (mut a, mut b) = (vec![0.0; 5], vec![0.0; 5]);
        dc.price_removals(&pool, &st, &mut a);
        oc.price_removals(&pool, &st, &mut b);
        for (x, y) in a.iter().zip(&b) {
            assert!((to_oi(*x) - y).abs() < 1e-9 * y);
        }
        let outs = [1, 3];
        let (mut a, mut b) = (vec![0.0; 240], vec![0.0; 240]);
        dc.price_exchanges(&pool, &st, &outs, &cands, &mut a);
        oc.price_exchanges(&pool, &st, &outs, &cands, &mut b);
        for (x, y) in a.iter().zip(&b) {
            if *x == f64::NEG_INFINITY {
                assert_eq!(*y, f64::NEG_INFINITY);
            } else {
                assert!((to_oi(*x) - y).abs() < 1e-9 * y);
            }
        }
        assert_eq!(
            argmax(&[f64::NEG_INFINITY, 1.0, 3.0, 3.0, f64::NAN]),
            Some(2)
        );
        assert_eq!(argmax(&[f64::NEG_INFINITY]), None);
    }
}
