//! The linear (I-/L-optimal) criterion `−tr(M⁻¹ W)` for a weight moment
//! `W ⪰ 0` (Atkinson, Donev & Tobias, *Optimum Experimental Designs*, §10.6):
//! with `W` the second moment of the rows whose predictions matter, the
//! average prediction variance of those rows (I-optimality); `W = I` gives
//! A-optimality.
//!
//! Prices follow from Woodbury. Adding and removing rows `U` (`±` by the
//! signature `Σ = diag(±I)`) changes `M` to `M + UᵀΣU`, and
//!
//! `tr((M + UᵀΣU)⁻¹W) = tr(M⁻¹W) − tr((Σ + U M⁻¹ Uᵀ)⁻¹ U G Uᵀ)`,
//! `G = M⁻¹ W M⁻¹`
//!
//! (`Σ⁻¹ = Σ`): an add is the `t × t` case, a removal the `t × t` case with
//! `Σ = −I`, an exchange the `2t × 2t` case. With `P = X_pool M⁻¹` and
//! `H = X_pool G` computed once per state, every entry of `U M⁻¹ Uᵀ` and
//! `U G Uᵀ` is a dot product of length `p`.
//!
//! Whether a change leaves `M` regular is decided as [`DCriterion`] decides
//! it (the shared singularity rule of the state): a change the determinant
//! criterion prices `−∞` is `−∞` here too.

use faer::Mat;
use nalgebra::DMatrix;

use super::criteria::{Criterion, DCriterion};
use super::state::InfoState;
use crate::blocks::Blocks;

/// The linear criterion `−tr(M⁻¹ W)` (higher is better) for a fixed
/// `p × p` weight moment `W` (see the module docs); prices by Woodbury
/// from `P = X_pool M⁻¹` and `H = X_pool M⁻¹ W M⁻¹`, recomputed when the
/// state changes (`O(n·t·p²)`), with every pose's own `t × t` products
/// `P_i X_iᵀ`, `H_i X_iᵀ`; an exchange scan adds the cross products with
/// the design poses it considers (one product each), then `O(t³)` per
/// candidate or pair.
#[derive(Clone, Debug)]
pub struct ICriterion {
    w: Mat<f64>,
    d: DCriterion,
    cache: Option<Cache>,
}

/// What one state version prices from.
#[derive(Clone, Debug)]
struct Cache {
    key: (u64, u64),
    /// `P = X_pool M⁻¹` (`n·t × p`).
    p_rows: Mat<f64>,
    /// `H = X_pool M⁻¹ W M⁻¹` (`n·t × p`).
    h_rows: Mat<f64>,
    /// `P X_poolᵀ` and `H X_poolᵀ` restricted to each pose's own `t × t`
    /// block, pose-major, row-major within.
    own_p: Vec<f64>,
    own_h: Vec<f64>,
    /// `tr(M⁻¹ W)`.
    trace: f64,
}

impl ICriterion {
    /// The criterion for the weight moment `w` (`p × p`, symmetric positive
    /// semidefinite; symmetrised as `(W + Wᵀ)/2`).
    #[must_use]
    pub fn new(w: &DMatrix<f64>) -> Self {
        let w = Mat::from_fn(w.nrows(), w.ncols(), |i, j| 0.5 * (w[(i, j)] + w[(j, i)]));
        Self {
            w,
            d: DCriterion::new(),
            cache: None,
        }
    }

    /// `tr(M⁻¹ W)` of the state's design (ridge and prior included, as the
    /// state's `M` holds them).
    pub fn trace(&mut self, pool: &Blocks, state: &InfoState) -> f64 {
        self.cached(pool, state).trace
    }

    fn cached(&mut self, pool: &Blocks, state: &InfoState) -> &Cache {
        let key = (state.id(), state.version());
        if self.cache.as_ref().is_none_or(|c| c.key != key) {
            self.cache = Some(self.compute(pool, state, key));
        }
        self.cache.as_ref().expect("just set")
    }

    fn compute(&self, pool: &Blocks, state: &InfoState, key: (u64, u64)) -> Cache {
        let p = pool.p();
        assert_eq!(self.w.nrows(), p, "the weight moment is p × p");
        let m_inv = state.m_inv();
        let p_rows = pool.mat() * m_inv;
        let g = m_inv * &self.w * m_inv;
        let h_rows = pool.mat() * &g;
        let mut trace = 0.0;
        for j in 0..p {
            for i in 0..p {
                trace += m_inv[(i, j)] * self.w[(j, i)];
            }
        }
        let t = pool.t();
        let x = pool.mat();
        let own = |a: &Mat<f64>| -> Vec<f64> {
            let mut out = vec![0.0; pool.n_poses() * t * t];
            for (q, o) in out.chunks_exact_mut(t * t).enumerate() {
                for c in 0..p {
                    for r in 0..t {
                        let ar = a[(q * t + r, c)];
                        for s in 0..t {
                            o[r * t + s] += ar * x[(q * t + s, c)];
                        }
                    }
                }
            }
            out
        };
        Cache {
            key,
            own_p: own(&p_rows),
            own_h: own(&h_rows),
            p_rows,
            h_rows,
            trace,
        }
    }
}

/// `tr(S⁻¹ V)` for `k × k` row-major `s` and `v` (both overwritten; `x`
/// of length `k` is scratch), by Gaussian elimination with partial
/// pivoting; `None` when a pivot is zero or not finite (the change leaves
/// `M` singular).
fn trace_solve(s: &mut [f64], v: &mut [f64], x: &mut [f64], k: usize) -> Option<f64> {
    for col in 0..k {
        let piv =
            (col..k).max_by(|&a, &b| s[a * k + col].abs().total_cmp(&s[b * k + col].abs()))?;
        if !(s[piv * k + col].abs() > 0.0) || !s[piv * k + col].is_finite() {
            return None;
        }
        if piv != col {
            for j in 0..k {
                s.swap(piv * k + j, col * k + j);
                v.swap(piv * k + j, col * k + j);
            }
        }
        let d = s[col * k + col];
        for r in col + 1..k {
            let f = s[r * k + col] / d;
            if f == 0.0 {
                continue;
            }
            for j in col..k {
                s[r * k + j] -= f * s[col * k + j];
            }
            for j in 0..k {
                v[r * k + j] -= f * v[col * k + j];
            }
        }
    }
    // Back substitution, column by column of V; only the diagonal of the
    // solution is needed, but every row of a column is.
    let mut tr = 0.0;
    for c in 0..k {
        for r in (0..k).rev() {
            let mut acc = v[r * k + c];
            for j in r + 1..k {
                acc -= s[r * k + j] * x[j];
            }
            x[r] = acc / s[r * k + r];
        }
        tr += x[c];
    }
    Some(tr)
}

/// `S = Σ + U M⁻¹ Uᵀ` and `V = U G Uᵀ` of a change (`U` the added rows,
/// then the removed ones) assembled from a state's [`Cache`], and
/// `tr(S⁻¹V)`; `s`, `v` (`k²`) and `x` (`k`) are scratch.
struct Pair<'a> {
    c: &'a Cache,
    t: usize,
}

impl Pair<'_> {
    /// `tr(S⁻¹V)` of adding pose `q` (`sign` 1) or removing it (−1).
    fn single(
        &self,
        q: usize,
        sign: f64,
        s: &mut [f64],
        v: &mut [f64],
        x: &mut [f64],
    ) -> Option<f64> {
        let t = self.t;
        let own = q * t * t;
        s[..t * t].copy_from_slice(&self.c.own_p[own..own + t * t]);
        v[..t * t].copy_from_slice(&self.c.own_h[own..own + t * t]);
        for r in 0..t {
            s[r * t + r] += sign;
        }
        trace_solve(&mut s[..t * t], &mut v[..t * t], x, t)
    }

    /// `tr(S⁻¹V)` of exchanging design pose `o` (column block `oi` of the
    /// cross products `P X_outsᵀ`, `H X_outsᵀ`) for pool pose `q`.
    fn exchange(
        &self,
        (q, o, oi): (usize, usize, usize),
        cross: (&Mat<f64>, &Mat<f64>),
        s: &mut [f64],
        v: &mut [f64],
        x: &mut [f64],
    ) -> Option<f64> {
        let (t, k) = (self.t, 2 * self.t);
        let (qo, oo) = (q * t * t, o * t * t);
        for a in 0..t {
            for b in 0..t {
                // in–in and out–out: the poses' own blocks.
                s[a * k + b] = self.c.own_p[qo + a * t + b];
                v[a * k + b] = self.c.own_h[qo + a * t + b];
                s[(t + a) * k + t + b] = self.c.own_p[oo + a * t + b];
                v[(t + a) * k + t + b] = self.c.own_h[oo + a * t + b];
                // in–out: row q·t + a of P (H) against the out pose's row b;
                // out–in by symmetry of M⁻¹ and G.
                let x = cross.0[(q * t + a, oi * t + b)];
                let y = cross.1[(q * t + a, oi * t + b)];
                s[a * k + t + b] = x;
                s[(t + b) * k + a] = x;
                v[a * k + t + b] = y;
                v[(t + b) * k + a] = y;
            }
            s[a * k + a] += 1.0;
            s[(t + a) * k + t + a] -= 1.0;
        }
        trace_solve(&mut s[..k * k], &mut v[..k * k], x, k)
    }
}

impl Criterion for ICriterion {
    fn name(&self) -> &'static str {
        "I"
    }

    fn score(&mut self, pool: &Blocks, state: &InfoState) -> f64 {
        -self.trace(pool, state)
    }

    fn price_adds(
        &mut self,
        pool: &Blocks,
        state: &InfoState,
        candidates: &[usize],
        out: &mut [f64],
    ) {
        self.d.price_adds(pool, state, candidates, out);
        let t = pool.t();
        let c = self.cached(pool, state);
        let pair = Pair { c, t };
        let (mut s, mut v, mut x) = (vec![0.0; t * t], vec![0.0; t * t], vec![0.0; t]);
        for (o, &q) in out.iter_mut().zip(candidates) {
            if *o > f64::NEG_INFINITY {
                *o = pair
                    .single(q, 1.0, &mut s, &mut v, &mut x)
                    .map_or(f64::NEG_INFINITY, |d| d - c.trace);
            }
        }
    }

    fn price_removals(&mut self, pool: &Blocks, state: &InfoState, out: &mut [f64]) {
        self.d.price_removals(pool, state, out);
        let t = pool.t();
        let c = self.cached(pool, state);
        let pair = Pair { c, t };
        let (mut s, mut v, mut x) = (vec![0.0; t * t], vec![0.0; t * t], vec![0.0; t]);
        for (o, &q) in out.iter_mut().zip(state.design()) {
            if *o > f64::NEG_INFINITY {
                *o = pair
                    .single(q, -1.0, &mut s, &mut v, &mut x)
                    .map_or(f64::NEG_INFINITY, |d| d - c.trace);
            }
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
        self.d.price_exchanges(pool, state, outs, candidates, out);
        let t = pool.t();
        let c = self.cached(pool, state);
        // Cross products of every pool row with the out poses' rows.
        let x_out = pool.select(outs);
        let cross_p = &c.p_rows * x_out.mat().transpose();
        let cross_h = &c.h_rows * x_out.mat().transpose();
        let pair = Pair { c, t };
        let k = 2 * t;
        let (mut s, mut v, mut x) = (vec![0.0; k * k], vec![0.0; k * k], vec![0.0; k]);
        for (ci, &q) in candidates.iter().enumerate() {
            for (oi, &j) in outs.iter().enumerate() {
                let o = &mut out[ci * outs.len() + oi];
                if *o > f64::NEG_INFINITY {
                    *o = pair
                        .exchange((q, j, oi), (&cross_p, &cross_h), &mut s, &mut v, &mut x)
                        .map_or(f64::NEG_INFINITY, |d| d - c.trace);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::StateSettings;

    /// A pool of `n` random `t × p` blocks (fixed seed).
    fn pool(n: usize, t: usize, p: usize) -> Blocks {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        Blocks::new(Mat::from_fn(n * t, p, |_, _| rng.random::<f64>() - 0.5), t)
    }

    /// `tr(M⁻¹W)` from scratch (nalgebra inverse of the summed information).
    fn direct(x: &Blocks, design: &[usize], w: &DMatrix<f64>) -> f64 {
        let m = x.information(design);
        let m = DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)]);
        (m.try_inverse().expect("regular") * w).trace()
    }

    fn moment(p: usize) -> DMatrix<f64> {
        let a = DMatrix::from_fn(p, p, |i, j| ((i * 7 + j * 3) % 5) as f64 - 2.0);
        &a * a.transpose()
    }

    /// Every price equals `tr(M'⁻¹W)` of the changed design recomputed from
    /// scratch. The Woodbury forms and the direct inverse agree to rounding
    /// amplified by the condition number (below 1e3 for these random
    /// pools, 20 × 3 rows of 6 unknowns), so a relative 1e-9 is loose.
    #[test]
    fn prices_equal_the_changed_designs_traces() {
        let (t, p) = (3, 6);
        let x = pool(20, t, p);
        let w = moment(p);
        let design = vec![0, 3, 5, 8, 11];
        let state = InfoState::new(&x, &design, StateSettings::default()).unwrap();
        let mut c = ICriterion::new(&w);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
        assert!(close(-c.score(&x, &state), direct(&x, &design, &w)));
        let cands: Vec<usize> = (0..20).collect();
        let mut adds = vec![0.0; 20];
        c.price_adds(&x, &state, &cands, &mut adds);
        for q in 0..20 {
            if design.contains(&q) {
                assert_eq!(adds[q], f64::NEG_INFINITY);
                continue;
            }
            let mut d = design.clone();
            d.push(q);
            assert!(close(-adds[q], direct(&x, &d, &w)), "add {q}");
        }
        let mut rem = vec![0.0; design.len()];
        c.price_removals(&x, &state, &mut rem);
        for (k, &j) in design.iter().enumerate() {
            let d: Vec<usize> = design.iter().copied().filter(|&i| i != j).collect();
            assert!(close(-rem[k], direct(&x, &d, &w)), "remove {j}");
        }
        let mut ex = vec![0.0; 20 * design.len()];
        c.price_exchanges(&x, &state, &design, &cands, &mut ex);
        for q in (0..20).filter(|q| !design.contains(q)) {
            for (o, &j) in design.iter().enumerate() {
                let mut d: Vec<usize> = design.iter().copied().filter(|&i| i != j).collect();
                d.push(q);
                assert!(close(-ex[q * design.len() + o], direct(&x, &d, &w)));
            }
        }
    }

    /// The common exchange run with the linear criterion ends at a design
    /// no single exchange improves (checked by brute force over every pair),
    /// at least as good as the design it started from.
    #[test]
    fn fedorov_with_the_linear_criterion_ends_at_a_local_optimum() {
        let (t, p, n) = (3, 6, 4);
        let x = pool(25, t, p);
        let w = moment(p);
        let s = crate::select::Settings::builder()
            .n(n)
            .initial(n)
            .build()
            .unwrap();
        let start = crate::select::select(
            &x,
            crate::select::CriterionKind::Det,
            crate::select::Algorithm::Fedorov,
            &s,
        )
        .unwrap();
        let sel = crate::select::polish(&x, &mut ICriterion::new(&w), start.clone(), &s).unwrap();
        let got = direct(&x, &sel.poses, &w);
        assert!(got <= direct(&x, &start.poses, &w));
        assert!((-sel.score - got).abs() <= 1e-9 * got);
        for &j in &sel.poses {
            for q in (0..25).filter(|q| !sel.poses.contains(q)) {
                let mut d: Vec<usize> = sel.poses.iter().copied().filter(|&i| i != j).collect();
                d.push(q);
                assert!(
                    direct(&x, &d, &w) >= got * (1.0 - 1e-9),
                    "({j} → {q}) improves"
                );
            }
        }
    }
}
