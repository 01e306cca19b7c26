//! Pricing with the pool's variances ([`PoolVariances`]): the gain of
//! adding each candidate, the loss of removing each design pose, the cross
//! terms `W = X_pool M⁻¹ X_Dᵀ`, and every exchange's gain, one-out (through
//! `(I − V_out)⁻¹`) or by the block determinant; in parallel over fixed
//! chunks, so results are bit-identical for any thread count.

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

use super::state::InfoState;
use super::variances::{PoolVariances, SCAN_CHUNK, SMALL_OUTS, col, full_product, run_start};
use crate::blocks::Blocks;
use crate::linalg::log::ln_in_place;
use crate::linalg::simd::clear_upper_simd_state;
use crate::linalg::small::{
    BlockScratch, FAST_EXCHANGE_PIVOT, det_i_plus3, exchange_in_factor, exchange_ln_det,
    exchange_out_ln_det, ln_det_i_minus, ln_det_i_plus, packed_len, removal_inverse_factor,
    variance_after_removal, variance_after_removal3,
};

impl PoolVariances {
    /// Add gains `ln det(I + V_i)` (eq. (17)/(20) in block form) of the given
    /// pool poses into `out` (same length). Parallel, allocation-free.
    pub fn add_gains(&self, candidates: &[usize], out: &mut [f64]) {
        self.add_scores(candidates, out, 0.0, |_| false);
    }

    /// `out[k] = base + ln det(I + V_i)` for `i = candidates[k]`, or `-∞`
    /// where `skip(i)` (a pose already in the design): the add scan of
    /// [`DCriterion`](super::DCriterion). Parallel over chunks of
    /// `SCAN_CHUNK` candidates, allocation-free. For points (`t = 3`) each
    /// chunk takes the block determinants first (`det_i_plus3`), then
    /// their logarithms in one vectorised pass (`ln_in_place`), then
    /// `ln_det_i_plus` for the rare determinant that is not finite and
    /// positive, so every value is `ln_det_i_plus`'s to within 1 ulp of
    /// the logarithm.
    pub fn add_scores(
        &self,
        candidates: &[usize],
        out: &mut [f64],
        base: f64,
        skip: impl Fn(usize) -> bool + Sync,
    ) {
        assert_eq!(candidates.len(), out.len());
        let t = self.t;
        out.par_chunks_mut(SCAN_CHUNK)
            .zip(candidates.par_chunks(SCAN_CHUNK))
            .for_each(|(oc, cc)| {
                if t == 3 {
                    if let Some(c0) = run_start(cc) {
                        let v = &self.v[c0 * 6..(c0 + cc.len()) * 6];
                        for (o, b) in oc.iter_mut().zip(v.chunks_exact(6)) {
                            *o = det_i_plus3(b);
                        }
                    } else {
                        for (o, &i) in oc.iter_mut().zip(cc) {
                            *o = det_i_plus3(self.packed(i));
                        }
                    }
                    ln_in_place(oc);
                    for (o, &i) in oc.iter_mut().zip(cc) {
                        *o = if skip(i) {
                            f64::NEG_INFINITY
                        } else if o.is_finite() {
                            base + *o
                        } else {
                            base + ln_det_i_plus(self.packed(i), t)
                        };
                    }
                } else {
                    for (o, &i) in oc.iter_mut().zip(cc) {
                        *o = if skip(i) {
                            f64::NEG_INFINITY
                        } else {
                            base + ln_det_i_plus(self.packed(i), t)
                        };
                    }
                }
            });
    }

    /// Removal losses `ln det(I − V_j)` (eq. (21)/(22) in block form) of the
    /// given poses into `out`; `-∞` where a pivot is `≤ pivot_floor`
    /// (numerically singular result).
    pub fn remove_losses(&self, poses: &[usize], pivot_floor: f64, out: &mut [f64]) {
        assert_eq!(poses.len(), out.len());
        let t = self.t;
        for (o, &j) in out.iter_mut().zip(poses) {
            *o = ln_det_i_minus(self.packed(j), t, pivot_floor).unwrap_or(f64::NEG_INFINITY);
        }
    }

    /// The cross terms `W = X_pool · (M⁻¹ X_outsᵀ)` (`n·t × |outs|·t`):
    /// `W[t·i + a, t·o + b] = x_{i,a}' M⁻¹ x_{outs[o],b}`, the off-diagonal
    /// blocks `S_io` of the exchange system. One product of cost
    /// `O(n·t·p·|outs|·t)`; the returned view borrows an internal workspace.
    pub fn cross_terms(
        &mut self,
        pool: &Blocks,
        state: &InfoState,
        outs: &[usize],
    ) -> MatRef<'_, f64> {
        self.check(pool, state);
        let t = self.t;
        let a = out_projection(pool, state, outs);
        full_product(pool.mat(), a.as_ref(), t, &mut self.work);
        let (rows, k) = (self.n * t, outs.len() * t);
        MatRef::from_column_major_slice(&self.work[..rows * k], rows, k)
    }

    /// [`exchange_gains`](Self::exchange_gains) for one out-pose of a point
    /// pool whose removal is comfortably regular: each candidate's gain is
    /// `loss + ln det(I + V_i + Z Zᵀ)`, `Z = W_i U`
    /// ([`removal_inverse_factor3`]), the determinants of a chunk first and
    /// their logarithms in one vectorised pass, as the add scan does. A
    /// candidate whose determinant is not finite and positive falls back to
    /// the general formula.
    #[allow(clippy::too_many_arguments)]
    fn exchange_gains_one_out(
        &self,
        pool: &Blocks,
        state: &InfoState,
        out_pose: usize,
        a: &Mat<f64>,
        loss: f64,
        u: &[f64],
        candidates: &[usize],
        pivot_floor: f64,
        out: &mut [f64],
    ) {
        let (x, t, tp) = (pool.mat(), self.t, packed_len(self.t));
        let this = self;
        let u3: [f64; 9] = std::array::from_fn(|k| u.get(k).copied().unwrap_or(0.0));
        // The cross terms W = X·A are formed a chunk of candidates at a time
        // into a per-task buffer (`t·len × t`, column-major): no pool-sized
        // workspace (72 MB at 10⁶ poses).
        out.par_chunks_mut(SCAN_CHUNK)
            .zip(candidates.par_chunks(SCAN_CHUNK))
            .for_each_init(
                || {
                    (
                        vec![0.0; SCAN_CHUNK * t * t],
                        vec![0.0; t * t],
                        vec![0.0; tp],
                    )
                },
                |(buf, wi, vt), (oc, cc)| {
                    let len = cc.len();
                    let mut wc =
                        MatMut::from_column_major_slice_mut(&mut buf[..len * t * t], len * t, t);
                    if let Some(c0) = run_start(cc) {
                        let xc = x.subrows(c0 * t, len * t);
                        matmul(wc.rb_mut(), Accum::Replace, xc, a.as_ref(), 1.0, Par::Seq);
                        clear_upper_simd_state();
                    } else {
                        for (k, &i) in cc.iter().enumerate() {
                            for r in 0..t {
                                for c in 0..t {
                                    let mut acc = 0.0;
                                    for q in 0..x.ncols() {
                                        acc += x[(i * t + r, q)] * a[(q, c)];
                                    }
                                    wc[(k * t + r, c)] = acc;
                                }
                            }
                        }
                    }
                    let wc = wc.rb();
                    let w_at = |k: usize, r: usize, c: usize| wc[(k * t + r, c)];
                    if t == 3 {
                        // Points: the three columns read as slices, the
                        // block's determinant unrolled, one vectorised ln.
                        let (w0, w1, w2) = (col(wc, 0), col(wc, 1), col(wc, 2));
                        for (k, (o, &i)) in oc.iter_mut().zip(cc).enumerate() {
                            let b = 3 * k;
                            let w3 = [
                                w0[b],
                                w1[b],
                                w2[b],
                                w0[b + 1],
                                w1[b + 1],
                                w2[b + 1],
                                w0[b + 2],
                                w1[b + 2],
                                w2[b + 2],
                            ];
                            *o = det_i_plus3(&variance_after_removal3(this.packed(i), &w3, &u3));
                        }
                        ln_in_place(oc);
                    } else {
                        for (k, (o, &i)) in oc.iter_mut().zip(cc).enumerate() {
                            for r in 0..t {
                                for c in 0..t {
                                    wi[r * t + c] = w_at(k, r, c);
                                }
                            }
                            variance_after_removal(this.packed(i), wi, u, t, vt);
                            *o = ln_det_i_plus(vt, t);
                        }
                    }
                    for (k, (o, &i)) in oc.iter_mut().zip(cc).enumerate() {
                        *o = if state.contains(i) {
                            f64::NEG_INFINITY
                        } else if o.is_finite() {
                            loss + *o
                        } else {
                            let mut g = [0.0];
                            exchange_row(
                                t,
                                this.packed(i),
                                &[out_pose],
                                |j| this.packed(j),
                                |_, r, c| w_at(k, r, c),
                                pivot_floor,
                                &mut g,
                            );
                            g[0]
                        };
                    }
                },
            );
    }

    /// Exchange gains `ln det M' − ln det M` for removing design pose
    /// `outs[o]` and adding pool pose `candidates[c]`, written candidate-major:
    /// `out[c·|outs| + o]`. Computed from `V_in`, `V_out` and the cross terms
    /// by [`exchange_gain`]; `-∞` where the result is numerically singular
    /// (pivot `≤ pivot_floor`) and where the candidate is in the state's
    /// design. Call [`sync`](Self::sync) first.
    pub fn exchange_gains(
        &mut self,
        pool: &Blocks,
        state: &InfoState,
        outs: &[usize],
        candidates: &[usize],
        pivot_floor: f64,
        out: &mut [f64],
    ) {
        let no = outs.len();
        assert_eq!(out.len(), candidates.len() * no);
        if no == 0 {
            return;
        }
        self.check(pool, state);
        let (t, p) = (self.t, self.p);
        let k = no * t;
        let a = out_projection(pool, state, outs);
        if no == 1
            && let Some((loss, u)) =
                removal_inverse_factor(self.packed(outs[0]), t, FAST_EXCHANGE_PIVOT)
        {
            self.exchange_gains_one_out(
                pool,
                state,
                outs[0],
                &a,
                loss,
                &u,
                candidates,
                pivot_floor,
                out,
            );
            return;
        }
        if no <= SMALL_OUTS {
            // Few out-poses (the paper's exchange step has one): one dense
            // product W = X·A (n·t × k, column-major), whose few columns a
            // candidate reads in contiguous runs of t rows, beats gathering
            // the candidates' rows per task.
            full_product(pool.mat(), a.as_ref(), t, &mut self.work);
            let rows = self.n * t;
            let w = MatRef::from_column_major_slice(&self.work[..rows * k], rows, k);
            let wcols: Vec<&[f64]> = (0..k).map(|c| col(w, c)).collect();
            let this = &*self;
            out.par_chunks_mut(SCAN_CHUNK * no)
                .zip(candidates.par_chunks(SCAN_CHUNK))
                .for_each(|(oc, cc)| {
                    for (oi, &i) in oc.chunks_mut(no).zip(cc) {
                        if state.contains(i) {
                            oi.fill(f64::NEG_INFINITY);
                            continue;
                        }
                        exchange_row(
                            t,
                            this.packed(i),
                            outs,
                            |j| this.packed(j),
                            |o, r, c| wcols[o * t + c][i * t + r],
                            pivot_floor,
                            oi,
                        );
                    }
                });
            return;
        }
        let at = a.transpose();
        let x = pool.mat();
        let this = &*self;
        // Fused and chunked: per task of PER candidates, gather their rows
        // Xᵀ (p × PER·t), form Wᵀ = Aᵀ Xᵀ (k × PER·t) so that each candidate's
        // cross terms with every out-pose are contiguous, then price the
        // pairs. W never exists for the whole pool (it would be n·t × k,
        // 34 MB for the PUMA, read with a stride per entry).
        const PER: usize = 64;
        out.par_chunks_mut(PER * no)
            .zip(candidates.par_chunks(PER))
            .for_each_init(
                || (Mat::<f64>::zeros(p, PER * t), Mat::<f64>::zeros(k, PER * t)),
                |(xg, wt), (oc, cc)| {
                    let cols = cc.len() * t;
                    for (ci, &i) in cc.iter().enumerate() {
                        for r in 0..t {
                            for c in 0..p {
                                xg[(c, ci * t + r)] = x[(i * t + r, c)];
                            }
                        }
                    }
                    matmul(
                        wt.as_mut().subcols_mut(0, cols),
                        Accum::Replace,
                        at,
                        xg.as_ref().subcols(0, cols),
                        1.0,
                        Par::Seq,
                    );
                    clear_upper_simd_state();
                    let wt = wt.as_ref();
                    for (ci, (oi, &i)) in oc.chunks_mut(no).zip(cc).enumerate() {
                        if state.contains(i) {
                            oi.fill(f64::NEG_INFINITY);
                            continue;
                        }
                        // Column ci·t + r of Wᵀ holds row r of every W_ij.
                        let base = ci * t;
                        exchange_row(
                            t,
                            this.packed(i),
                            outs,
                            |j| this.packed(j),
                            |o, r, c| col(wt, base + r)[o * t + c],
                            pivot_floor,
                            oi,
                        );
                    }
                },
            );
    }
}

/// `A = M⁻¹ X_outsᵀ` (`p × |outs|·t`): the projection every cross term
/// `W = X · A` of an exchange pricing starts from.
fn out_projection(pool: &Blocks, state: &InfoState, outs: &[usize]) -> Mat<f64> {
    let (t, p) = (pool.t(), pool.p());
    let k = outs.len() * t;
    let mut xo = Mat::<f64>::zeros(k, p);
    for (o, &j) in outs.iter().enumerate() {
        xo.as_mut().subrows_mut(o * t, t).copy_from(pool.block(j));
    }
    let mut a = Mat::<f64>::zeros(p, k);
    matmul(
        a.as_mut(),
        Accum::Replace,
        state.m_inv(),
        xo.transpose(),
        1.0,
        Par::Seq,
    );
    clear_upper_simd_state();
    a
}

/// Exchange gains of one candidate against every out-pose, `oi[o]`, with the
/// factor of `I + V_in` computed once ([`exchange_in_factor`]) and one `ln`
/// per pair ([`exchange_out_ln_det`]). `w(o, r, b)` is `W_io[r, b]`.
/// A numerically singular pair is priced `-∞`.
fn exchange_row<'v>(
    t: usize,
    v_in: &[f64],
    outs: &[usize],
    v_of: impl Fn(usize) -> &'v [f64],
    w: impl Fn(usize, usize, usize) -> f64,
    floor: f64,
    oi: &mut [f64],
) {
    let mut la = BlockScratch::new(t * t);
    let Ok(ln_a) = exchange_in_factor(t, v_in, &mut la) else {
        oi.fill(f64::NEG_INFINITY);
        return;
    };
    for (o, (g, &j)) in oi.iter_mut().zip(outs).enumerate() {
        *g = exchange_out_ln_det(t, &la, v_of(j), |r, c| w(o, r, c), floor)
            .map_or(f64::NEG_INFINITY, |b| ln_a + b);
    }
}

/// Exchange gain `ln det M' − ln det M` for removing pose `j` and adding pose
/// `i`, from `V_i`, `V_j` (packed, see [`PoolVariances::packed`]) and the
/// cross block `W_ij = X_i M⁻¹ X_jᵀ` (`t×t`): the determinant of
/// `[[I + V_i, W_ij], [−W_ijᵀ, I − V_j]]` by block elimination,
/// `det(I + V_i) · det(I − V_j + W_ijᵀ (I + V_i)⁻¹ W_ij)`.
///
/// `Err(pivot)` when a pivot of the second factor is `≤ pivot_floor`
/// (numerically singular result).
pub fn exchange_gain(
    t: usize,
    v_i: &[f64],
    v_j: &[f64],
    w_ij: MatRef<'_, f64>,
    pivot_floor: f64,
) -> Result<f64, f64> {
    assert!(w_ij.nrows() == t && w_ij.ncols() == t);
    let mut w_buf = BlockScratch::new(t * t);
    let w: &mut [f64] = &mut w_buf;
    for a in 0..t {
        for b in 0..t {
            w[a * t + b] = w_ij[(a, b)];
        }
    }
    exchange_ln_det(t, v_i, v_j, |a, b| w[a * t + b], pivot_floor)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::state::StateSettings;
    use crate::criterion::test_util::random_pool;

    fn direct_v(pool: &Blocks, state: &InfoState, i: usize) -> Mat<f64> {
        let x = pool.block(i);
        x * state.m_inv() * x.transpose()
    }

    #[test]
    fn variances_follow_updates() {
        for t in 1..=6 {
            let p = 10;
            let pool = random_pool(200, t, p, t as u64);
            let design: Vec<usize> = (0..(p / t + 3)).collect();
            let mut st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
            let mut pv = PoolVariances::new(&pool, &st);
            let _ = st.add(&pool, 150).unwrap();
            pv.sync(&pool, &st);
            let _ = st.exchange(&pool, 1, 151).unwrap();
            pv.sync(&pool, &st);
            let _ = st.remove(&pool, 0).unwrap();
            pv.sync(&pool, &st);
            // Updates of rank >= p are cheaper as a recomputation.
            if 2 * t < p {
                assert_eq!(pv.full_recomputes(), 1);
                assert_eq!(pv.incremental_updates(), 3);
            }
            for i in [0, 1, 2, 77, 150, 151, 199] {
                let v = direct_v(&pool, &st, i);
                for a in 0..t {
                    for b in 0..t {
                        assert!((pv.entry(i, a, b) - v[(a, b)]).abs() < 1e-10, "t={t}");
                    }
                }
            }
            // Gains agree with the state's single-pose pricing.
            let cands = [60usize, 61, 199];
            let mut g = [0.0; 3];
            pv.add_gains(&cands, &mut g);
            for (c, &gi) in cands.iter().zip(&g) {
                let s = st.price_add(&pool, *c).unwrap().delta().unwrap();
                assert!((s - gi).abs() < 1e-11);
            }
            let outs = [st.design()[0], st.design()[2]];
            let mut e = [0.0; 6];
            pv.exchange_gains(&pool, &st, &outs, &cands, st.pivot_floor(), &mut e);
            for (ci, c) in cands.iter().enumerate() {
                for (oi, o) in outs.iter().enumerate() {
                    let s = st.price_exchange(&pool, *o, *c).unwrap();
                    match s.delta() {
                        Some(d) => assert!((d - e[ci * 2 + oi]).abs() < 1e-10),
                        None => assert_eq!(e[ci * 2 + oi], f64::NEG_INFINITY),
                    }
                }
            }
        }
    }

    /// The one-out scan of a point pool. Where the removal is regular it
    /// goes through `(I − V_out)⁻¹` with no factorization per candidate;
    /// checked against the state's own pricing of each exchange (a
    /// factorization of the `2t×2t` exchange system per pair, no shared
    /// formula) to 1e-10, the multi-out check's tolerance on gains of order
    /// 1 (the fast route's own error is about `ε/FAST_EXCHANGE_PIVOT` ≈
    /// 2e-12; a wrong term changes a gain by O(0.1)). On a square design
    /// (exactly `p` rows) every removal alone is singular, so the scan must
    /// take the general formula: checked against [`exchange_gain`] on the
    /// same cross terms, which it must reproduce to rounding (1e-12).
    #[test]
    fn one_out_point_scan_matches_the_state_pricing() {
        // Points: p = 27 with 12 poses (regular removals), p = 9 with 3
        // (square); full poses (t = 6, the general-t route): p = 30 with 8.
        for (t, p, n, fast) in [(3, 27, 12, true), (3, 9, 3, false), (6, 30, 8, true)] {
            let pool = random_pool(400, t, p, 5);
            let design: Vec<usize> = (0..n).map(|k| 7 * k + 3).collect();
            let st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
            let mut pv = PoolVariances::new(&pool, &st);
            let cands: Vec<usize> = (0..400).collect();
            for &o in st.design() {
                assert_eq!(
                    removal_inverse_factor(pv.packed(o), t, FAST_EXCHANGE_PIVOT).is_some(),
                    fast,
                    "t = {t}, p = {p}: the removal of {o} is regular exactly off the square design"
                );
                let mut e = vec![0.0; cands.len()];
                pv.exchange_gains(&pool, &st, &[o], &cands, st.pivot_floor(), &mut e);
                // Scattered candidates (their cross terms gathered, not one
                // product) give the same gains to rounding.
                let scattered: Vec<usize> = (0..400).rev().step_by(3).collect();
                let mut es = vec![0.0; scattered.len()];
                pv.exchange_gains(&pool, &st, &[o], &scattered, st.pivot_floor(), &mut es);
                for (&c, &g) in scattered.iter().zip(&es) {
                    let want = e[c];
                    assert!(
                        g == want || (g - want).abs() < 1e-12 * (1.0 + want.abs()),
                        "p = {p}, out {o}, scattered in {c}: {g} vs {want}"
                    );
                }
                let w = pv.cross_terms(&pool, &st, &[o]).to_owned();
                for (&c, &g) in cands.iter().zip(&e) {
                    if st.contains(c) {
                        assert_eq!(g, f64::NEG_INFINITY);
                        continue;
                    }
                    let want = if fast {
                        st.price_exchange(&pool, o, c).unwrap().delta()
                    } else {
                        let wc = w.as_ref().subrows(c * t, t);
                        exchange_gain(t, pv.packed(c), pv.packed(o), wc, st.pivot_floor()).ok()
                    };
                    let tol = if fast { 1e-10 } else { 1e-12 };
                    match want {
                        Some(d) => assert!(
                            (d - g).abs() < tol * (1.0 + d.abs()),
                            "p = {p}, out {o}, in {c}: {d} vs {g}"
                        ),
                        None => assert_eq!(g, f64::NEG_INFINITY, "p = {p}, out {o}, in {c}"),
                    }
                }
            }
        }
    }

    #[test]
    fn bit_identical_for_any_thread_count() {
        // Several chunks of every kind: 5000 poses = 20 product chunks and 3
        // scan chunks.
        let pool = random_pool(5000, 3, 27, 99);
        let design: Vec<usize> = (0..12).collect();
        let st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
        let cands: Vec<usize> = (12..5000).collect();
        let run = |threads: usize| {
            let tp = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            tp.install(|| {
                let mut st2 = st.clone();
                let mut pv = PoolVariances::new(&pool, &st2);
                let _ = st2.exchange(&pool, 3, 500).unwrap();
                pv.sync(&pool, &st2);
                let mut g = vec![0.0; cands.len()];
                pv.add_gains(&cands, &mut g);
                let outs = st2.design().to_vec();
                let mut e = vec![0.0; cands.len() * outs.len()];
                pv.exchange_gains(&pool, &st2, &outs, &cands, st2.pivot_floor(), &mut e);
                (g, e)
            })
        };
        let (g1, e1) = run(1);
        for threads in [2, 3] {
            let (g, e) = run(threads);
            assert!(g.iter().zip(&g1).all(|(a, b)| a.to_bits() == b.to_bits()));
            assert!(e.iter().zip(&e1).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }
}
