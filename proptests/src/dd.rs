//! Double-double arithmetic (a value is an unevaluated sum `hi + lo` of two
//! `f64`, `|lo| ≤ ulp(hi)/2`, about 106 bits) and the extended-precision
//! reference computations the property tests compare the update formulas
//! with: the Gram matrix `XᵀX` (exact products), an `LDLᵀ` factorization,
//! `ln det` and the inverse.
//!
//! The building blocks are Knuth's two-sum and the fused-multiply-add
//! two-product (`a·b = p + e` exactly with `e = fma(a, b, −p)`), as in
//! Dekker (1971) and the QD library (Hida, Li & Bailey 2001). The relative
//! error of one operation is `≲ 4·2⁻¹⁰⁶ ≈ 5e-32`, so a factorization of a
//! `p×p` matrix with condition number `κ` errs by `≲ p·κ·1e-31`: below
//! `1e-16` for every `κ ≤ 1e13`, `p ≤ 40` met in the tests, i.e. the
//! reference is exact as far as an `f64` computation can tell.

use nalgebra::DMatrix;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A double-double number `hi + lo`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dd {
    /// The leading part (the value rounded to `f64`).
    pub hi: f64,
    /// The trailing part, `|lo| ≤ ulp(hi)/2`.
    pub lo: f64,
}

/// `ln 2` in double-double (QD's constant): the high part is `f64`'s
/// `LN_2`, the low part the rounding error it leaves.
pub const LN2: Dd = Dd {
    hi: std::f64::consts::LN_2,
    lo: 2.319_046_813_846_299_6e-17,
};

/// `a + b = s + e` exactly (Knuth).
#[inline]
#[must_use]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `a + b = s + e` exactly, given `|a| ≥ |b|` (Dekker).
#[inline]
#[must_use]
pub fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// `a·b = p + e` exactly (barring underflow), with one fused multiply-add.
#[inline]
#[must_use]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl Dd {
    /// Zero.
    pub const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };
    /// One.
    pub const ONE: Dd = Dd { hi: 1.0, lo: 0.0 };

    /// An `f64` (exact).
    #[must_use]
    pub const fn from_f64(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }

    /// The exact product of two `f64`.
    #[must_use]
    pub fn prod(a: f64, b: f64) -> Dd {
        let (hi, lo) = two_prod(a, b);
        Dd { hi, lo }
    }

    /// Rounded to `f64`.
    #[must_use]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// Square root (one Newton correction of the `f64` root).
    #[must_use]
    pub fn sqrt(self) -> Dd {
        if self.hi <= 0.0 {
            return Dd::from_f64(self.hi.sqrt());
        }
        let q = self.hi.sqrt();
        let r = self - Dd::prod(q, q);
        let (hi, lo) = quick_two_sum(q, r.hi / (2.0 * q));
        Dd { hi, lo }
    }

    /// Absolute value.
    #[must_use]
    pub fn abs(self) -> Dd {
        if self.hi < 0.0 { -self } else { self }
    }
}

impl Neg for Dd {
    type Output = Dd;
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Add for Dd {
    type Output = Dd;
    /// The accurate ("IEEE") double-double sum.
    fn add(self, b: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, b.hi);
        let (t, f) = two_sum(self.lo, b.lo);
        let (s, e) = quick_two_sum(s, e + t);
        let (hi, lo) = quick_two_sum(s, e + f);
        Dd { hi, lo }
    }
}

impl Sub for Dd {
    type Output = Dd;
    fn sub(self, b: Dd) -> Dd {
        self + (-b)
    }
}

impl Mul for Dd {
    type Output = Dd;
    fn mul(self, b: Dd) -> Dd {
        let (p, e) = two_prod(self.hi, b.hi);
        let e = e + (self.hi * b.lo + self.lo * b.hi);
        let (hi, lo) = quick_two_sum(p, e);
        Dd { hi, lo }
    }
}

impl Div for Dd {
    type Output = Dd;
    /// Long division with three `f64` quotient digits.
    fn div(self, b: Dd) -> Dd {
        let q1 = self.hi / b.hi;
        let r = self - b * Dd::from_f64(q1);
        let q2 = r.hi / b.hi;
        let r = r - b * Dd::from_f64(q2);
        let q3 = r.hi / b.hi;
        let (hi, lo) = quick_two_sum(q1, q2);
        Dd { hi, lo } + Dd::from_f64(q3)
    }
}

/// A square double-double matrix, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct DdMat {
    /// Order.
    pub n: usize,
    /// Entries, row-major.
    pub a: Vec<Dd>,
}

impl DdMat {
    /// The `n×n` zero matrix.
    #[must_use]
    pub fn zeros(n: usize) -> Self {
        Self {
            n,
            a: vec![Dd::ZERO; n * n],
        }
    }

    /// Entry `(i, j)`.
    #[must_use]
    pub fn get(&self, i: usize, j: usize) -> Dd {
        self.a[i * self.n + j]
    }

    /// Sets entry `(i, j)`.
    pub fn set(&mut self, i: usize, j: usize, v: Dd) {
        self.a[i * self.n + j] = v;
    }

    /// An `f64` matrix (exact).
    #[must_use]
    pub fn from_f64(m: &DMatrix<f64>) -> Self {
        assert_eq!(m.nrows(), m.ncols());
        let n = m.nrows();
        Self {
            n,
            a: (0..n * n)
                .map(|k| Dd::from_f64(m[(k / n, k % n)]))
                .collect(),
        }
    }

    /// Rounded to `f64`.
    #[must_use]
    pub fn to_f64(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.n, self.n, |i, j| self.get(i, j).to_f64())
    }

    /// `self += sign·XᵀX` for the rows of `x` (exact products, double-double
    /// sums): the information of a block, added or removed.
    pub fn add_gram(&mut self, x: &DMatrix<f64>, sign: f64) {
        assert_eq!(x.ncols(), self.n);
        let n = self.n;
        for r in 0..x.nrows() {
            for i in 0..n {
                for j in 0..=i {
                    let v = self.get(i, j) + Dd::prod(sign * x[(r, i)], x[(r, j)]);
                    self.set(i, j, v);
                    self.set(j, i, v);
                }
            }
        }
    }

    /// `self += δ·I`.
    pub fn add_diagonal(&mut self, delta: f64) {
        for i in 0..self.n {
            let v = self.get(i, i) + Dd::from_f64(delta);
            self.set(i, i, v);
        }
    }

    /// `self += diag(d)` (`d` empty: unchanged).
    pub fn add_diagonal_entries(&mut self, d: &[f64]) {
        for (i, &v) in d.iter().enumerate() {
            let s = self.get(i, i) + Dd::from_f64(v);
            self.set(i, i, s);
        }
    }

    /// `XᵀX` of an `f64` matrix.
    #[must_use]
    pub fn gram(x: &DMatrix<f64>) -> Self {
        let mut m = Self::zeros(x.ncols());
        m.add_gram(x, 1.0);
        m
    }

    /// `‖·‖₁` (largest absolute column sum), rounded to `f64`.
    #[must_use]
    pub fn norm1(&self) -> f64 {
        (0..self.n)
            .map(|j| {
                (0..self.n)
                    .map(|i| self.get(i, j).to_f64().abs())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// `LDLᵀ` factorization of a symmetric matrix (no pivoting); `None`
    /// unless every pivot is positive, i.e. the matrix is positive definite
    /// in double-double precision.
    #[must_use]
    pub fn ldlt(&self) -> Option<Ldlt> {
        let n = self.n;
        let mut l = DdMat::zeros(n);
        let mut d = vec![Dd::ZERO; n];
        for j in 0..n {
            let mut dj = self.get(j, j);
            for k in 0..j {
                let ljk = l.get(j, k);
                dj = dj - ljk * ljk * d[k];
            }
            if !(dj.hi > 0.0) {
                return None;
            }
            d[j] = dj;
            l.set(j, j, Dd::ONE);
            for i in j + 1..n {
                let mut v = self.get(i, j);
                for k in 0..j {
                    v = v - l.get(i, k) * l.get(j, k) * d[k];
                }
                l.set(i, j, v / dj);
            }
        }
        Some(Ldlt { l, d })
    }
}

/// `M = L D Lᵀ` with unit lower triangular `L`, in double-double.
#[derive(Clone, Debug)]
pub struct Ldlt {
    /// Unit lower triangular factor.
    pub l: DdMat,
    /// The pivots (all positive).
    pub d: Vec<Dd>,
}

impl Ldlt {
    /// `ln det M = Σ ln d_i`, to about `1e-16` absolute: the pivots are
    /// multiplied in double-double with the binary exponent kept apart, so
    /// only one `f64` logarithm of a mantissa in `[1, 2)` is rounded.
    #[must_use]
    pub fn ln_det(&self) -> f64 {
        let mut mant = Dd::ONE;
        let mut exp: i64 = 0;
        for &di in &self.d {
            mant = mant * di;
            let e = mant.hi.abs().log2().floor() as i32;
            let s = 2f64.powi(-e);
            mant = Dd {
                hi: mant.hi * s,
                lo: mant.lo * s,
            };
            exp += i64::from(e);
        }
        let ln_mant = mant.hi.ln() + (mant.lo / mant.hi);
        (LN2 * Dd::from_f64(exp as f64) + Dd::from_f64(ln_mant)).to_f64()
    }

    /// `L⁻¹ B` for the columns of `B` (forward substitution).
    #[must_use]
    pub fn solve_l(&self, b: &DdMat) -> DdMat {
        let n = self.l.n;
        let mut y = b.clone();
        for c in 0..n {
            for r in 0..n {
                let mut v = y.get(r, c);
                for k in 0..r {
                    v = v - self.l.get(r, k) * y.get(k, c);
                }
                y.set(r, c, v);
            }
        }
        y
    }

    /// `M⁻¹ = L⁻ᵀ D⁻¹ L⁻¹`, exactly symmetric.
    #[must_use]
    pub fn inverse(&self) -> DdMat {
        let n = self.l.n;
        let mut id = DdMat::zeros(n);
        for i in 0..n {
            id.set(i, i, Dd::ONE);
        }
        // Y = L⁻¹ (unit lower triangular), then M⁻¹ = Yᵀ D⁻¹ Y.
        let y = self.solve_l(&id);
        let mut inv = DdMat::zeros(n);
        for i in 0..n {
            for j in 0..=i {
                let mut v = Dd::ZERO;
                for k in i..n {
                    v = v + y.get(k, i) * y.get(k, j) / self.d[k];
                }
                inv.set(i, j, v);
                inv.set(j, i, v);
            }
        }
        inv
    }

    /// `D^-½ L⁻¹ A L⁻ᵀ D^-½` rounded to `f64` (symmetric): the matrix
    /// whose eigenvalues are the generalized eigenvalues of `(A, M)`.
    #[must_use]
    pub fn congruence(&self, a: &DdMat) -> DMatrix<f64> {
        let n = self.l.n;
        let y = self.solve_l(a); // L⁻¹ A
        let mut yt = DdMat::zeros(n);
        for i in 0..n {
            for j in 0..n {
                yt.set(i, j, y.get(j, i));
            }
        }
        let e = self.solve_l(&yt); // L⁻¹ (L⁻¹ A)ᵀ = L⁻¹ A L⁻ᵀ
        let s: Vec<f64> = self.d.iter().map(|d| d.sqrt().to_f64()).collect();
        let c = DMatrix::from_fn(n, n, |i, j| e.get(i, j).to_f64() / (s[i] * s[j]));
        (&c + c.transpose()) * 0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hilbert(n: usize) -> DdMat {
        let mut h = DdMat::zeros(n);
        for i in 0..n {
            for j in 0..n {
                h.set(i, j, Dd::ONE / Dd::from_f64((i + j + 1) as f64));
            }
        }
        h
    }

    /// `ln det H_n = 4 ln c_n − ln c_{2n}`, `c_n = Π_{i<n} i!`, summed in
    /// `f64` from exact integers' logarithms (each `ln k` to 0.5 ulp).
    fn ln_det_hilbert(n: usize) -> f64 {
        let ln_c = |n: usize| -> f64 {
            (1..n)
                .map(|i| (1..=i).map(|k| (k as f64).ln()).sum::<f64>())
                .sum()
        };
        4.0 * ln_c(n) - ln_c(2 * n)
    }

    /// Binomial coefficient as `f64` (exact below 2⁵³).
    fn binom(n: u64, k: u64) -> f64 {
        (0..k).fold(1.0, |a, i| a * (n - i) as f64 / (i + 1) as f64)
    }

    #[test]
    fn error_free_transformations_are_exact() {
        let (a, b) = (1.0 + 2f64.powi(-40), 1.0 - 2f64.powi(-45));
        let (p, e) = two_prod(a, b);
        // a·b = 1 + 2⁻⁴⁰ − 2⁻⁴⁵ − 2⁻⁸⁵: the last term is below ulp(1)/2.
        assert_eq!(p, 1.0 + 2f64.powi(-40) - 2f64.powi(-45));
        assert_eq!(e, -(2f64.powi(-85)));
        let (s, e) = two_sum(1.0, 2f64.powi(-60));
        assert_eq!((s, e), (1.0, 2f64.powi(-60)));
        let x = Dd::from_f64(1.0) + Dd::from_f64(2f64.powi(-80));
        assert_eq!((x - Dd::ONE).to_f64(), 2f64.powi(-80));
    }

    #[test]
    fn division_and_sqrt_reach_double_double_precision() {
        let third = Dd::ONE / Dd::from_f64(3.0);
        let r = Dd::ONE - third * Dd::from_f64(3.0);
        assert!(r.to_f64().abs() < 1e-31, "{r:?}");
        let s = Dd::from_f64(2.0).sqrt();
        let r = s * s - Dd::from_f64(2.0);
        assert!(r.to_f64().abs() < 1e-31, "{r:?}");
    }

    #[test]
    fn ln_det_of_hilbert_matrices_matches_closed_form() {
        // κ(H_10) ≈ 1.6e13, κ(H_12) ≈ 1.7e16: f64 Cholesky loses 3 and 0
        // digits of ln det respectively; double-double keeps ~1e-15.
        for n in [4, 8, 10, 12] {
            let f = hilbert(n).ldlt().expect("H_n is positive definite");
            let want = ln_det_hilbert(n);
            // The closed form sums O(n²) logs in f64: 0.5 ulp each.
            let tol = 4.0 * (n * n) as f64 * f64::EPSILON * want.abs();
            assert!(
                (f.ln_det() - want).abs() <= tol,
                "n={n}: {} vs {want}",
                f.ln_det()
            );
        }
    }

    #[test]
    fn inverse_of_hilbert_matrix_is_the_integer_formula() {
        // (H_n⁻¹)_ij = (−1)^{i+j} (i+j−1) C(n+i−1, n−j) C(n+j−1, n−i) C(i+j−2, i−1)²
        // (1-based), integers below 2⁵³ for n ≤ 10.
        let n = 10;
        let inv = hilbert(n).ldlt().unwrap().inverse();
        for i in 1..=n as u64 {
            for j in 1..=n as u64 {
                let sign = if (i + j) % 2 == 0 { 1.0 } else { -1.0 };
                let c = binom(i + j - 2, i - 1);
                let want = sign
                    * (i + j - 1) as f64
                    * binom(n as u64 + i - 1, n as u64 - j)
                    * binom(n as u64 + j - 1, n as u64 - i)
                    * c
                    * c;
                let got = inv.get(i as usize - 1, j as usize - 1).to_f64();
                // κ(H_10)·2⁻¹⁰⁴ ≈ 1e-18 relative.
                assert!(
                    (got - want).abs() <= 1e-15 * want.abs(),
                    "({i},{j}): {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn exact_gram_and_ln_det_of_a_diagonal() {
        // Rows e_j·2^j: XᵀX = diag(4^j), ln det = Σ 2j ln 2.
        let x = DMatrix::from_fn(5, 5, |i, j| if i == j { 2f64.powi(j as i32) } else { 0.0 });
        let m = DdMat::gram(&x);
        let want: f64 = (0..5).map(|j| 2.0 * j as f64).sum::<f64>() * std::f64::consts::LN_2;
        assert!((m.ldlt().unwrap().ln_det() - want).abs() < 1e-15);
        // A singular Gram matrix is refused.
        let y = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        assert!(DdMat::gram(&y).ldlt().is_none());
    }

    #[test]
    fn congruence_gives_generalized_eigenvalues() {
        // A = diag(1, 2, 3), M = diag(2, 2, 2): eigenvalues 1/2, 1, 3/2.
        let a = DdMat::from_f64(&DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![
            1.0, 2.0, 3.0,
        ])));
        let m = DdMat::from_f64(&(DMatrix::identity(3, 3) * 2.0));
        let c = m.ldlt().unwrap().congruence(&a);
        let mut ev: Vec<f64> = c.symmetric_eigen().eigenvalues.iter().copied().collect();
        ev.sort_by(f64::total_cmp);
        for (g, w) in ev.iter().zip([0.5, 1.0, 1.5]) {
            assert!((g - w).abs() < 1e-15);
        }
    }
}
