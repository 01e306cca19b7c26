//! The arithmetic of one pairwise exchange step (eqs. X1, X2 of
//! [`super::first_order`]) on the small `2t × 2t` pair matrix, without
//! allocation.
//!
//! For the pair `U = [X_i; X_j]`, `G = U M⁻¹ Uᵀ` and `D = diag(I_t, −I_t)`,
//! the step `δ` changes `ln det M` by `Σ_k ln(1 + δ μ_k)` with `μ_k` the
//! eigenvalues of `D G` (X1), and `M⁻¹` by `−W R Wᵀ`, `W = M⁻¹Uᵀ`, `R = δ(I +
//! δ D G)⁻¹ D` (X2). Since `D² = I`, `R = δ (D + δ G)⁻¹`. With the Cholesky
//! factor `G = L Lᵀ` and the eigen-decomposition `B = Lᵀ D L = V diag(μ)
//! Vᵀ` (same eigenvalues as `D G`),
//!
//! `D + δG = L (B⁻¹ + δ I) Lᵀ`, so `R = E diag(s) Eᵀ`,  `E = L⁻ᵀ V`,
//! `s_k = δ μ_k / (1 + δ μ_k)`.
//!
//! One small Cholesky and one symmetric eigen-decomposition (faer's,
//! with reused scratch) give both the line search's `μ` and the update's factors; the
//! caller applies `M⁻¹ −= (W E) diag(s) (W E)ᵀ` and `d_k −= Σ_l s_l ‖X_k (W
//! E)_l‖²`. A pair whose `G` is not numerically positive definite (two
//! blocks with dependent rows) is left to the caller's general path.

use crate::linalg::simd::clear_upper_simd_state;
use crate::linalg::small::chol_pivots_in_place;
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{self, ComputeEigenvectors};
use faer::{Mat, MatRef, Par};

/// Reused memory of [`PairFactors`]: all `m × m` row-major, `m = 2t`.
pub(crate) struct PairFactors {
    m: usize,
    l: Vec<f64>,
    b: Vec<f64>,
    v: Vec<f64>,
    mu: Vec<f64>,
    e: Vec<f64>,
    s: Vec<f64>,
    ev: Diag<f64>,
    u: Mat<f64>,
    mem: MemBuffer,
}

impl PairFactors {
    /// Workspace for blocks of `t` rows.
    pub(crate) fn new(t: usize) -> Self {
        let m = 2 * t;
        Self {
            m,
            l: vec![0.0; m * m],
            b: vec![0.0; m * m],
            v: vec![0.0; m * m],
            mu: vec![0.0; m],
            e: vec![0.0; m * m],
            s: vec![0.0; m],
            ev: Diag::zeros(m),
            u: Mat::zeros(m, m),
            mem: MemBuffer::new(evd::self_adjoint_evd_scratch::<f64>(
                m,
                ComputeEigenvectors::Yes,
                Par::Seq,
                Default::default(),
            )),
        }
    }

    /// Factors the symmetric pair matrix `g` (row-major `2t × 2t`, both
    /// triangles set): `G = L Lᵀ` and the eigenvalues `μ` of `D G`. `false`
    /// when `G` is not numerically positive definite (a pivot below
    /// `1e-13` of the largest diagonal entry).
    pub(crate) fn factor(&mut self, g: &[f64]) -> bool {
        let m = self.m;
        let t = m / 2;
        self.l.copy_from_slice(&g[..m * m]);
        let scale = (0..m).map(|k| g[k * m + k]).fold(0.0f64, f64::max);
        if !(scale > 0.0 && scale.is_finite()) {
            return false;
        }
        if chol_pivots_in_place(&mut self.l, m, 1e-13 * scale, |_| ()).is_err() {
            return false;
        }
        // B = Lᵀ D L (L lower: L_ka = 0 for k < a).
        for a in 0..m {
            for c in 0..=a {
                let mut acc = 0.0;
                for k in a..m {
                    let v = self.l[k * m + a] * self.l[k * m + c];
                    acc += if k < t { v } else { -v };
                }
                self.b[a * m + c] = acc;
                self.b[c * m + a] = acc;
            }
        }
        let bm = MatRef::from_row_major_slice(&self.b, m, m);
        let r = evd::self_adjoint_evd(
            bm,
            self.ev.as_mut(),
            Some(self.u.as_mut()),
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        clear_upper_simd_state();
        if r.is_err() {
            return false;
        }
        for a in 0..m {
            self.mu[a] = self.ev[a];
            for c in 0..m {
                self.v[a * m + c] = self.u[(a, c)];
            }
        }
        self.mu.iter().all(|x| x.is_finite())
    }

    /// The eigenvalues `μ` of `D G` after [`Self::factor`] (eq. X1).
    pub(crate) fn mu(&self) -> &[f64] {
        &self.mu
    }

    /// For the step `δ`: `E = L⁻ᵀ V` (row-major) and `s_k = δ μ_k / (1 + δ
    /// μ_k)`, so that `R = E diag(s) Eᵀ` (eq. X2).
    pub(crate) fn update(&mut self, delta: f64) -> (&[f64], &[f64]) {
        let m = self.m;
        for k in 0..m {
            self.s[k] = delta * self.mu[k] / (1.0 + delta * self.mu[k]);
        }
        // Lᵀ E = V, column by column (Lᵀ upper): back substitution.
        for c in 0..m {
            for a in (0..m).rev() {
                let mut acc = self.v[a * m + c];
                for k in a + 1..m {
                    acc -= self.l[k * m + a] * self.e[k * m + c];
                }
                self.e[a * m + c] = acc / self.l[a * m + a];
            }
        }
        (&self.e, &self.s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::test_rng::lcg;

    /// Row-major product helpers for the checks.
    fn mul(a: &[f64], b: &[f64], n: usize) -> Vec<f64> {
        let mut c = vec![0.0; n * n];
        for i in 0..n {
            for k in 0..n {
                for j in 0..n {
                    c[i * n + j] += a[i * n + k] * b[k * n + j];
                }
            }
        }
        c
    }

    fn random_spd(n: usize, seed: u64) -> Vec<f64> {
        let mut state = seed;
        let x: Vec<f64> = (0..n * (n + 3)).map(|_| lcg(&mut state) - 0.5).collect();
        let mut g = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                g[i * n + j] = (0..n + 3)
                    .map(|k| x[i * (n + 3) + k] * x[j * (n + 3) + k])
                    .sum();
            }
        }
        g
    }

    #[test]
    fn factors_give_the_eigenvalues_of_dg_and_r() {
        for (t, seed) in [(1, 5), (3, 6), (6, 7)] {
            let m = 2 * t;
            let g = random_spd(m, seed);
            let mut f = PairFactors::new(t);
            assert!(f.factor(&g));
            // The eigenvalues of D G, by their first two power sums against
            // traces computed directly: Σ μ = tr(D G), Σ μ² = tr((D G)²).
            let mut dg = g.clone();
            for a in t..m {
                for c in 0..m {
                    dg[a * m + c] = -dg[a * m + c];
                }
            }
            let tr: f64 = (0..m).map(|a| dg[a * m + a]).sum();
            let dg2 = mul(&dg, &dg, m);
            let tr2: f64 = (0..m).map(|a| dg2[a * m + a]).sum();
            let mu = f.mu().to_vec();
            let scale = (0..m).map(|a| g[a * m + a]).sum::<f64>();
            assert!((mu.iter().sum::<f64>() - tr).abs() < 1e-13 * scale);
            assert!((mu.iter().map(|x| x * x).sum::<f64>() - tr2).abs() < 1e-13 * scale * scale);
            // R = E diag(s) Eᵀ satisfies (D + δG) R = δ I.
            let delta = 0.3 / mu.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
            let (e, s) = f.update(delta);
            let mut r = vec![0.0; m * m];
            for i in 0..m {
                for j in 0..m {
                    r[i * m + j] = (0..m).map(|k| e[i * m + k] * s[k] * e[j * m + k]).sum();
                }
            }
            let mut h = g.iter().map(|x| delta * x).collect::<Vec<_>>();
            for a in 0..m {
                h[a * m + a] += if a < t { 1.0 } else { -1.0 };
            }
            let hr = mul(&h, &r, m);
            for i in 0..m {
                for j in 0..m {
                    let want = if i == j { delta } else { 0.0 };
                    assert!(
                        (hr[i * m + j] - want).abs() < 1e-12 * delta,
                        "t={t} ({i},{j})"
                    );
                }
            }
        }
    }

    #[test]
    fn a_singular_pair_is_left_to_the_general_path() {
        let t = 3;
        let m = 6;
        let mut g = random_spd(m, 9);
        // Make pose j's block a copy of pose i's: G singular.
        for a in 0..t {
            for c in 0..m {
                g[(a + t) * m + c] = g[a * m + c];
            }
        }
        for a in 0..m {
            for c in 0..t {
                g[a * m + c + t] = g[a * m + c];
            }
        }
        assert!(!PairFactors::new(t).factor(&g));
    }
}
