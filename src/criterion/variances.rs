//! Batched pricing over a whole pool: the variance blocks
//! `V_i = X_i M⁻¹ X_iᵀ` of every pool pose, kept up to date through the
//! low-rank updates of the state, and the cross terms `W = X_pool M⁻¹ X_Dᵀ`
//! that price every exchange (the pricing itself is in `pricing.rs`).
//!
//! After an update `M'⁻¹ = M⁻¹ − F₊F₊ᵀ + F₋F₋ᵀ` (see
//! [`lowrank`](super::lowrank)), `V_i' = V_i − P_i₊P_i₊ᵀ + P_i₋P_i₋ᵀ` with
//! `P = X_pool [F₊ F₋]`: one `(n·t) × p × k` product instead of the
//! `(n·t) × p × p` of a recomputation.
//!
//! Every per-candidate loop runs over fixed chunks ([`CHUNK`] poses for the
//! products, [`SCAN_CHUNK`] candidates for the cheap scans) in parallel
//! (rayon); each chunk's arithmetic is sequential and the chunk boundaries
//! do not depend on the number of threads, so results are bit-identical for
//! any thread count.

use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, MatMut, MatRef, Par};
use rayon::prelude::*;

use super::lowrank::LowRank;
use super::state::InfoState;
use crate::blocks::Blocks;
use crate::linalg::simd::clear_upper_simd_state;
use crate::linalg::small::{packed_len, pk};

/// Column `c` of a matrix with unit row stride, as a slice.
#[inline]
pub(super) fn col(m: MatRef<'_, f64>, c: usize) -> &[f64] {
    m.col(c)
        .try_as_col_major()
        .expect("unit row stride")
        .as_slice()
}

/// The first pose of `cc` if `cc` is a run of consecutive poses (every scan
/// without fixed poses: their blocks, and their rows of `X`, are one
/// contiguous slice), `None` otherwise.
pub(super) fn run_start(cc: &[usize]) -> Option<usize> {
    let c0 = *cc.first()?;
    cc.iter().zip(c0..).all(|(&i, k)| i == k).then_some(c0)
}

/// Poses per parallel work item of the products `X·A` (a 256-pose chunk of
/// a `p = 27`, `t = 3` pool times `M⁻¹` is ≈ 1 Mflop).
pub(crate) const CHUNK: usize = 256;

/// Candidates per parallel work item of the cheap per-candidate loops
/// (`O(t³)` each): large, so that a scan of a whole pool is a handful of
/// tasks and thread wake-ups do not dominate.
pub(crate) const SCAN_CHUNK: usize = 2048;

/// Up to this many out-poses, exchange pricing forms the whole cross-term
/// matrix `W = X·A` at once; beyond, it works in candidate chunks.
pub(super) const SMALL_OUTS: usize = 2;

/// `V_i = X_i M⁻¹ X_iᵀ` (packed lower triangle, `t(t+1)/2` numbers) for every
/// pose of a pool, synchronized with an [`InfoState`].
#[derive(Clone, Debug)]
pub struct PoolVariances {
    pub(super) t: usize,
    pub(super) p: usize,
    pub(super) n: usize,
    pub(super) v: Vec<f64>,
    pub(super) key: Option<(u64, u64, u64)>,
    pub(super) work: Vec<f64>,
    pub(super) full_recomputes: usize,
    pub(super) incremental_updates: usize,
}

/// Computes `P = X · A` in parallel over fixed row chunks of `CHUNK` poses
/// (sequential faer GEMM inside each) and calls `f(first_pose, X_c, P_c,
/// out_c)` on each chunk with the matching chunk of `out` (`per_pose`
/// entries a pose). Each worker thread holds one chunk's `P_c` (`CHUNK·t ×
/// k`), never the whole product: for `k = p` that would be a second copy of
/// the pool's Jacobian (648 MB at 10⁶ PUMA poses).
pub(super) fn chunked_product<F>(
    x: MatRef<'_, f64>,
    t: usize,
    a: MatRef<'_, f64>,
    out: &mut [f64],
    per_pose: usize,
    f: F,
) where
    F: Fn(usize, MatRef<'_, f64>, MatRef<'_, f64>, &mut [f64]) + Sync + Send,
{
    let rows = x.nrows();
    let k = a.ncols();
    assert!(per_pose > 0 && out.len() == rows / t * per_pose);
    let chunk_rows = CHUNK * t;
    x.par_row_chunks(chunk_rows)
        .zip(out.par_chunks_mut(CHUNK * per_pose))
        .enumerate()
        .for_each_init(Vec::new, |buf: &mut Vec<f64>, (c, (xc, oc))| {
            let r = xc.nrows();
            buf.resize(chunk_rows * k, 0.0);
            let mut pc = MatMut::from_column_major_slice_mut(&mut buf[..r * k], r, k);
            matmul(pc.rb_mut(), Accum::Replace, xc, a, 1.0, Par::Seq);
            clear_upper_simd_state();
            f(c * CHUNK, xc, pc.rb(), oc);
        });
}

/// The whole product `W = X · A` (`n·t × k`, column-major) into the first
/// `n·t·k` entries of `work`, in parallel over the same row chunks as
/// [`chunked_product`]; for the cross terms, whose `k = |outs|·t` columns
/// are few.
pub(super) fn full_product(x: MatRef<'_, f64>, a: MatRef<'_, f64>, t: usize, work: &mut Vec<f64>) {
    let rows = x.nrows();
    let k = a.ncols();
    if work.len() < rows * k {
        work.resize(rows * k, 0.0);
    }
    let w = MatMut::from_column_major_slice_mut(&mut work[..rows * k], rows, k);
    // Whole poses per chunk for symmetry with `chunked_product`; the product
    // is row by row, so any chunk height gives the same `W` (to rounding):
    // `CHUNK / t` for `CHUNK * t` is equivalent in value (issue #30's sample).
    let chunk_rows = CHUNK * t;
    x.par_row_chunks(chunk_rows)
        .zip(w.par_row_chunks_mut(chunk_rows))
        .for_each(|(xc, mut pc)| {
            matmul(pc.rb_mut(), Accum::Replace, xc, a, 1.0, Par::Seq);
            clear_upper_simd_state();
        });
}

impl PoolVariances {
    /// Computes `V_i` for every pose of `pool` from the state's `M⁻¹`.
    #[must_use]
    pub fn new(pool: &Blocks, state: &InfoState) -> Self {
        let mut pv = Self {
            t: pool.t(),
            p: pool.p(),
            n: pool.n_poses(),
            v: vec![0.0; pool.n_poses() * packed_len(pool.t())],
            key: None,
            work: Vec::new(),
            full_recomputes: 0,
            incremental_updates: 0,
        };
        pv.recompute(pool, state);
        pv
    }

    pub(super) fn check(&self, pool: &Blocks, state: &InfoState) {
        assert!(
            pool.t() == self.t
                && pool.p() == self.p
                && pool.n_poses() == self.n
                && state.t() == self.t
                && state.p() == self.p
                && state.n_pool() == self.n,
            "PoolVariances used with a pool or state of another shape"
        );
    }

    /// Recomputes every `V_i` from scratch: `Y = X M⁻¹` by chunks, then the
    /// row-block dot products `V_i[a,b] = Σ_k Y[ta+a,k] X[ti+b,k]`.
    /// `O(n·t·p²)`.
    pub fn recompute(&mut self, pool: &Blocks, state: &InfoState) {
        self.check(pool, state);
        let t = self.t;
        let tp = packed_len(t);
        let p = self.p;
        chunked_product(
            pool.mat(),
            t,
            state.m_inv(),
            &mut self.v,
            tp,
            |_, xc, yc, vc| {
                vc.fill(0.0);
                // Column by column (contiguous), the same summation order
                // over k for every pose.
                for k in 0..p {
                    let (yk, xk) = (col(yc, k), col(xc, k));
                    if t == 3 {
                        // Points, unrolled (same sums, same order).
                        for ((vi, y), x) in vc
                            .chunks_exact_mut(6)
                            .zip(yk.chunks_exact(3))
                            .zip(xk.chunks_exact(3))
                        {
                            vi[0] += y[0] * x[0];
                            vi[1] += y[1] * x[0];
                            vi[2] += y[1] * x[1];
                            vi[3] += y[2] * x[0];
                            vi[4] += y[2] * x[1];
                            vi[5] += y[2] * x[2];
                        }
                        continue;
                    }
                    for (i, vi) in vc.chunks_mut(tp).enumerate() {
                        let (y, x) = (&yk[i * t..i * t + t], &xk[i * t..i * t + t]);
                        for a in 0..t {
                            for b in 0..a + 1 {
                                vi[pk(a, b)] += y[a] * x[b];
                            }
                        }
                    }
                }
            },
        );
        self.key = Some((state.id(), state.epoch(), state.version()));
        self.full_recomputes += 1;
    }

    /// Applies one low-rank update `M'⁻¹ = M⁻¹ − F₊F₊ᵀ + F₋F₋ᵀ`:
    /// `V_i −= P₊P₊ᵀ − P₋P₋ᵀ` with `P = X_i F`. `O(n·t·p·k)`.
    fn apply(&mut self, pool: &Blocks, lr: &LowRank) {
        let t = self.t;
        let tp = packed_len(t);
        let f = lr.factors();
        let a = lr.n_plus();
        let k = f.ncols();
        chunked_product(pool.mat(), t, f, &mut self.v, tp, |_, _, pc, vc| {
            for c in 0..k {
                let sign = if c < a { -1.0 } else { 1.0 };
                let pcol = col(pc, c);
                if t == 3 {
                    // Points, unrolled: the same products and sums as the
                    // general loop below, in the same order.
                    for (vi, q) in vc.chunks_exact_mut(6).zip(pcol.chunks_exact(3)) {
                        let (s0, s1, s2) = (sign * q[0], sign * q[1], sign * q[2]);
                        vi[0] += s0 * q[0];
                        vi[1] += s1 * q[0];
                        vi[2] += s1 * q[1];
                        vi[3] += s2 * q[0];
                        vi[4] += s2 * q[1];
                        vi[5] += s2 * q[2];
                    }
                    continue;
                }
                for (i, vi) in vc.chunks_mut(tp).enumerate() {
                    let q = &pcol[i * t..i * t + t];
                    for r in 0..t {
                        let sr = sign * q[r];
                        for s in 0..r + 1 {
                            vi[pk(r, s)] += sr * q[s];
                        }
                    }
                }
            }
        });
        self.incremental_updates += 1;
    }

    /// Brings the variances up to date with `state`: nothing if already
    /// synchronized; the pending low-rank updates (one `X·F` product each) if
    /// the state has only been updated since, unless their total rank reaches
    /// `p`; otherwise (another state, a refactorization, a ridge change) a
    /// full [`recompute`](Self::recompute).
    pub fn sync(&mut self, pool: &Blocks, state: &InfoState) {
        self.check(pool, state);
        let now = (state.id(), state.epoch(), state.version());
        if self.key == Some(now) {
            return;
        }
        if let Some((id, epoch, version)) = self.key
            && id == now.0
            && epoch == now.1
        {
            let (base, log) = state.updates_since();
            // `version < now.2` holds whenever it is reached (same state and
            // epoch but another key: an older version), so `<` as `<=` is
            // equivalent (issue #30's sample).
            if version >= base && version < now.2 {
                let pending = &log[(version - base) as usize..];
                let total: usize = pending.iter().map(LowRank::rank).sum();
                if total < self.p {
                    for lr in pending {
                        self.apply(pool, lr);
                    }
                    self.key = Some(now);
                    return;
                }
            }
        }
        self.recompute(pool, state);
    }

    /// Rows per pose.
    #[must_use]
    pub fn t(&self) -> usize {
        self.t
    }

    /// The packed lower triangle of `V_i` (`t(t+1)/2` numbers, by rows:
    /// `(0,0), (1,0), (1,1), (2,0), …`).
    #[must_use]
    pub fn packed(&self, i: usize) -> &[f64] {
        let tp = packed_len(self.t);
        &self.v[i * tp..(i + 1) * tp]
    }

    /// Entry `(a, b)` of `V_i`.
    #[must_use]
    pub fn entry(&self, i: usize, a: usize, b: usize) -> f64 {
        let (a, b) = if a >= b { (a, b) } else { (b, a) };
        self.packed(i)[pk(a, b)]
    }

    /// Number of full recomputations so far.
    #[must_use]
    pub fn full_recomputes(&self) -> usize {
        self.full_recomputes
    }

    /// Number of incremental (low-rank) updates so far.
    #[must_use]
    pub fn incremental_updates(&self) -> usize {
        self.incremental_updates
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::state::StateSettings;
    use crate::criterion::test_util::random_pool;

    /// Pending updates are applied while their total rank stays below `p`
    /// and replaced by one recomputation once it reaches `p` (the
    /// recomputation is then no dearer). `t = 5`, `p = 10`: an add is a
    /// rank-5 update (applied), an exchange a rank-10 one (recomputed), and
    /// two adds pending at once total 10 (recomputed); a synchronized pool
    /// is left as it is. The counters are exact.
    #[test]
    fn updates_reaching_rank_p_are_recomputed() {
        let (t, p) = (5, 10);
        let pool = random_pool(40, t, p, 3);
        let design: Vec<usize> = (0..4).collect();
        let mut st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
        let mut pv = PoolVariances::new(&pool, &st);
        assert_eq!(pv.t(), t);
        let counts = |pv: &PoolVariances| (pv.full_recomputes(), pv.incremental_updates());
        assert_eq!(counts(&pv), (1, 0));
        let _ = st.add(&pool, 20).unwrap();
        pv.sync(&pool, &st);
        assert_eq!(counts(&pv), (1, 1), "a rank-5 add is applied");
        let _ = st.exchange(&pool, 1, 21).unwrap();
        pv.sync(&pool, &st);
        assert_eq!(counts(&pv), (2, 1), "a rank-10 exchange is recomputed");
        let _ = st.add(&pool, 22).unwrap();
        let _ = st.add(&pool, 23).unwrap();
        pv.sync(&pool, &st);
        assert_eq!(counts(&pv), (3, 1), "two rank-5 adds are recomputed");
        pv.sync(&pool, &st);
        assert_eq!(counts(&pv), (3, 1), "nothing to do");
    }

    /// A pool of another shape than the one the variances were made for
    /// is a programming error, refused by a panic (before any work).
    #[test]
    #[should_panic(expected = "another shape")]
    fn a_pool_of_another_shape_is_refused() {
        let pool = random_pool(20, 3, 9, 1);
        let design: Vec<usize> = (0..4).collect();
        let st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
        let mut pv = PoolVariances::new(&pool, &st);
        pv.sync(&random_pool(21, 3, 9, 2), &st);
    }
    /// A pool left behind by more updates than the state's log keeps (128
    /// without a refactorization: the log's base moves past the pool's
    /// version) is recomputed, not updated from a log that has lost its
    /// first updates; its variances then match `X_i M⁻¹ X_iᵀ` formed here
    /// (entries O(1): 1e-10 covers the 128 updates' rounding in `M⁻¹`).
    #[test]
    fn a_pool_behind_the_trimmed_log_is_recomputed() {
        let pool = random_pool(12, 3, 4, 21);
        let s = StateSettings::builder()
            .refactor_every(10_000)
            .build()
            .unwrap();
        let mut st = InfoState::new(&pool, &[0, 1, 2, 3], s).unwrap();
        let mut pv = PoolVariances::new(&pool, &st);
        for k in 0..128 {
            if k % 2 == 0 {
                st.add(&pool, 5).unwrap().delta().unwrap();
            } else {
                st.remove(&pool, 5).unwrap().delta().unwrap();
            }
        }
        assert!(st.updates_since().0 > 0, "the log was trimmed");
        pv.sync(&pool, &st);
        assert_eq!((pv.full_recomputes(), pv.incremental_updates()), (2, 0));
        for i in 0..12 {
            let x = pool.block(i);
            let v = x * st.m_inv() * x.transpose();
            for a in 0..3 {
                for b in 0..3 {
                    assert!((pv.entry(i, a, b) - v[(a, b)]).abs() < 1e-10, "pose {i}");
                }
            }
        }
    }
}
