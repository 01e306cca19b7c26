//! The update kernels on raw matrices — add, remove and exchange of a
//! `t`-row block (`t = 1` is the single-row case of eq. (5)/(6), (10)/(11)),
//! block form and the paper's cascade — against `ln det` and inverses
//! computed directly on the changed matrix with nalgebra.

use activecal::criterion::lowrank::{cascade, woodbury};
use nalgebra::DMatrix;
use proptest::prelude::*;
use proptests::*;

/// The singularity floor of `InfoState` with the default
/// `max_condition = 1e13`: `‖M‖₁‖M⁻¹‖₁ / 1e13`.
fn floor_of(m: &DMatrix<f64>, m_inv: &DMatrix<f64>) -> f64 {
    let n1 = |a: &DMatrix<f64>| {
        (0..a.ncols())
            .map(|c| a.column(c).iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    n1(m) * n1(m_inv) / 1e13
}

/// Checks one change `M1 = M0 + plusᵀplus − minusᵀminus` of a design with
/// `m` rows: block form and cascade against the direct computation, or, when
/// the kernel reports a singular result, that the direct computation agrees
/// the change keeps at most a `floor`-sized fraction of some direction.
fn check_change(
    x0: &DMatrix<f64>,
    plus: &DMatrix<f64>,
    minus: &DMatrix<f64>,
) -> Result<(), TestCaseError> {
    let p = x0.ncols();
    let m = x0.nrows() + plus.nrows();
    let m0 = gram(x0);
    let m0_inv = direct_inverse(&m0).expect("the starting design is positive definite");
    let ld0 = direct_ln_det(&m0).unwrap();
    let k0 = cond2(&m0);
    let m1 = &m0 + gram(plus) - gram(minus);
    let floor = floor_of(&m0, &m0_inv);
    let g = amplification(&m0, plus, minus);
    let (fi, fp, fm) = (to_faer(&m0_inv), to_faer(plus), to_faer(minus));
    let block = woodbury(fi.as_ref(), fp.as_ref(), fm.as_ref(), floor);
    let casc = cascade(fi.as_ref(), fp.as_ref(), fm.as_ref(), floor);
    match block {
        Ok(w) => {
            let ld1 = direct_ln_det(&m1);
            prop_assert!(ld1.is_some(), "update regular but direct Cholesky fails");
            let ld1 = ld1.unwrap();
            let k1 = cond2(&m1);
            let tol = ln_det_tol(m, p, k0, k1, g, ld1);
            let err = (ld0 + w.ln_det_ratio() - ld1).abs();
            prop_assert!(
                err <= tol,
                "ln det error {err:e} > tol {tol:e} (κ0={k0:e}, κ1={k1:e})"
            );
            let mut inv = fi.clone();
            w.apply_to_inverse(inv.as_mut());
            let direct = direct_inverse(&m1).unwrap();
            let scale = max_abs(&direct).max(max_abs(&m0_inv));
            let e_inv = max_abs(&(to_nalgebra(inv.as_ref()) - &direct)) / scale;
            let tol_inv = inverse_tol(m, p, k0, k1, g);
            prop_assert!(e_inv <= tol_inv, "inverse error {e_inv:e} > {tol_inv:e}");
            // Cascade == block form. The cascade removes row by row; its
            // factors are the LDLᵀ pivots of the block form, so it can only
            // reject what the block form accepted when a pivot sits at the
            // floor within rounding.
            match casc {
                Ok(c) => {
                    let e = (c.ln_det_ratio - w.ln_det_ratio()).abs();
                    prop_assert!(e <= tol, "cascade vs block {e:e} > {tol:e}");
                    let e_inv = max_abs(&(to_nalgebra(c.m_inv.as_ref()) - &direct)) / scale;
                    prop_assert!(e_inv <= tol_inv, "cascade inverse {e_inv:e} > {tol_inv:e}");
                }
                Err(s) => prop_assert!(
                    s.pivot <= floor
                        && w.min_pivot() <= floor + 8.0 * (m + p) as f64 * EPS * k0 * g,
                    "cascade rejected a clearly regular change: {s:?}, block pivot {}",
                    w.min_pivot()
                ),
            }
        }
        Err(s) => {
            prop_assert!(minus.nrows() > 0, "an addition was reported singular");
            // Singular ⇒ the exact λ_min(M0^-½ M1 M0^-½) ≤ floor, up to the
            // rounding of the computed pivot, |δd| ≲ (m+p)·u·κ(M0) (see the
            // crate docs: ‖X_out‖²‖M0⁻¹‖ ≤ κ(M0) since X_outᵀX_out ⪯ M0).
            // For an exchange, μ is relative to M0 + X₊ᵀX₊ and the pivot's
            // rounding carries the addition's g.
            let mid = &m0 + gram(plus);
            let mu = retained_fraction(&mid, &m1);
            let g = amplification(&m0, plus, &DMatrix::zeros(0, p));
            let slack = 8.0 * (m + p) as f64 * EPS * k0 * g;
            prop_assert!(
                mu <= s.pivot_floor + slack,
                "singular status but λ_min = {mu:e} > floor {:e} + {slack:e}",
                s.pivot_floor
            );
            prop_assert!(casc.is_err() || mu <= floor + slack);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    /// Adding a `t`-row block: eq. (17)/(20) and Woodbury vs direct.
    #[test]
    fn add_block(c in case(), extra in 0usize..=8, scale in prop::sample::select(vec![1e-3, 1.0, 1e3])) {
        let mut rng = CaseRng::new(c.seed);
        let x0 = conditioned(c.p + extra, c.p, c.log10_cond, &mut rng);
        let q = rng.matrix(c.t, c.p) * scale;
        check_change(&x0, &q, &DMatrix::zeros(0, c.p))?;
    }

    /// Removing a `t`-row block of the design: eq. (21)/(22) and Woodbury vs
    /// direct, or a justified singular status.
    #[test]
    fn remove_block(c in case(), extra in 0usize..=40) {
        let mut rng = CaseRng::new(c.seed);
        let x0 = conditioned(c.p + c.t + extra, c.p, c.log10_cond, &mut rng);
        let r = x0.rows(x0.nrows() - c.t, c.t).into_owned();
        check_change(&x0, &DMatrix::zeros(0, c.p), &r)?;
    }

    /// Exchanging a design block for a new one in one step (the `2t×2t`
    /// system) vs direct, and vs the cascade (add rows, then remove rows).
    #[test]
    fn exchange_block(c in case(), extra in 0usize..=40, scale in prop::sample::select(vec![1e-2, 1.0, 1e2])) {
        let mut rng = CaseRng::new(c.seed);
        let x0 = conditioned(c.p + c.t + extra, c.p, c.log10_cond, &mut rng);
        let r = x0.rows(x0.nrows() - c.t, c.t).into_owned();
        let q = rng.matrix(c.t, c.p) * scale;
        check_change(&x0, &q, &r)?;
    }

    /// Removing a block that carries the only information in some direction
    /// (a design of exactly `p` rows) is always reported singular.
    #[test]
    fn remove_essential_block_is_singular(c in case()) {
        let mut rng = CaseRng::new(c.seed);
        let x0 = conditioned(c.p.max(c.t), c.p, c.log10_cond.min(6.0), &mut rng);
        let t = c.t.min(x0.nrows());
        let r = x0.rows(x0.nrows() - t, t).into_owned();
        let m0 = gram(&x0);
        let m0_inv = direct_inverse(&m0).unwrap();
        let floor = floor_of(&m0, &m0_inv);
        let (fi, fr) = (to_faer(&m0_inv), to_faer(&r));
        let empty = faer::Mat::<f64>::zeros(0, c.p);
        // The block form factors B = I − S with diagonal pivoting, so the zero
        // pivot carries only rounding and is always caught.
        prop_assert!(woodbury(fi.as_ref(), empty.as_ref(), fr.as_ref(), floor).is_err());
        // The cascade removes rows in the given order: a small early factor
        // amplifies the rounding of the last (zero) one, which may then pass
        // the floor. What it must get right is the determinant: the exact
        // ratio det(I − S) is 0, and a perturbation E of S changes it by at
        // most t·‖E‖ (all eigenvalues of I − S lie in [0, 1]), with
        // ‖E‖ ≲ (m+p)·u·κ(M0) (see the crate docs).
        let m = x0.nrows();
        if let Ok(casc) = cascade(fi.as_ref(), empty.as_ref(), fr.as_ref(), floor) {
            let bound = 8.0 * (t * (m + c.p)) as f64 * EPS * cond2(&m0);
            prop_assert!(casc.ln_det_ratio.exp() <= bound,
                "cascade det ratio {:e} > {bound:e}", casc.ln_det_ratio.exp());
        }
    }
}
