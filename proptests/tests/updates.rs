//! The update kernels on raw matrices — add, remove and exchange of a
//! `t`-row block (`t = 1` is the single-row case of eq. (5)/(6), (10)/(11)),
//! block form and the paper's cascade — against `ln det` and inverses of the
//! changed matrix computed in double-double precision ([`proptests::dd`]),
//! with tolerances derived from the reference's condition numbers alone and
//! capped at `1e-6` ([`proptests::reference`]).

use activecal::criterion::lowrank::{cascade, woodbury};
use nalgebra::DMatrix;
use proptest::prelude::*;
use proptests::dd::DdMat;
use proptests::reference::{CAP, Change, Guard, run_property, update_tol};

/// Columns of a matrix.
fn c_p(x: &DMatrix<f64>) -> usize {
    x.ncols()
}
use proptests::*;

/// `max_condition` of `InfoState`'s default settings; the floor of its
/// singularity rule is `‖M‖₁‖M⁻¹‖₁ / MAX_CONDITION`, computed here from the
/// reference.
const MAX_CONDITION: f64 = 1e13;

/// Checks one change `M1 = M0 + plusᵀplus − minusᵀminus` of a design `x0`:
/// block form and cascade against the double-double reference, or, when the
/// kernel reports a singular result, that the reference agrees the change
/// keeps at most a floor-sized fraction of some direction. The kernels start
/// from the reference `M0⁻¹` rounded to `f64`.
fn check_change(
    x0: &DMatrix<f64>,
    plus: &DMatrix<f64>,
    minus: &DMatrix<f64>,
    guard: &Guard,
) -> Result<(), TestCaseError> {
    let m = x0.nrows() + plus.nrows();
    let ch = Change::of(&DdMat::gram(x0), plus, minus);
    let floor = ch.before.kappa_1 / MAX_CONDITION;
    let (fi, fp, fm) = (to_faer(&ch.before.inv), to_faer(plus), to_faer(minus));
    let block = woodbury(fi.as_ref(), fp.as_ref(), fm.as_ref(), floor);
    let casc = cascade(fi.as_ref(), fp.as_ref(), fm.as_ref(), floor);
    let slack = ch.refusal_slack(m);
    match block {
        Ok(w) => {
            let Some(after) = ch.after.as_ref() else {
                return Err(TestCaseError::fail(format!(
                    "update regular (min pivot {:e}) but the reference is singular",
                    w.min_pivot()
                )));
            };
            let bound = ch.tol(m);
            let tol = guard.tol(bound);
            let err = (ch.before.ln_det + w.ln_det_ratio() - after.ln_det).abs();
            guard.observe(err, bound);
            prop_assert!(
                err <= tol,
                "ln det error {err:e} > tol {tol:e} (κs0={:e}, κs1={:e}, μ={:e})",
                ch.before.kappa_scaled,
                after.kappa_scaled,
                ch.mu
            );
            let mut inv = fi.clone();
            w.apply_to_inverse(inv.as_mut());
            let e_inv = after.inverse_error(&to_nalgebra(inv.as_ref()), &ch.before.inv);
            guard.observe(e_inv, bound);
            prop_assert!(e_inv <= tol, "inverse error {e_inv:e} > {tol:e}");
            // The cascade removes row by row without pivoting; its factors
            // are the unpivoted LDLᵀ pivots of B, each ≥ λ_min(B) = μ, so it
            // may refuse only when μ is at the floor within rounding. It adds
            // row by row too: the inverse after an added row errs by
            // `u·κ_s·‖M⁻¹‖`, which is `g` times `M₁⁻¹` in the direction the
            // row filled, so its bound carries `g` (compared when that bound
            // is below the cap; the state uses the block form).
            let casc_bound = update_tol(
                m,
                c_p(x0),
                ch.before.kappa_scaled,
                ch.g + ch.amplification(),
                after.ln_det,
            ) + 8.0 * (ch.t * ch.t) as f64 * EPS * ch.kappa_a * ch.amplification();
            match casc {
                Ok(c) if casc_bound <= CAP => {
                    let tol = guard.tol(casc_bound);
                    let e = (ch.before.ln_det + c.ln_det_ratio - after.ln_det).abs();
                    guard.observe(e, casc_bound);
                    prop_assert!(e <= tol, "cascade ln det {e:e} > {tol:e}");
                    let e_inv = after.inverse_error(&to_nalgebra(c.m_inv.as_ref()), &ch.before.inv);
                    prop_assert!(e_inv <= tol, "cascade inverse {e_inv:e} > {tol:e}");
                }
                Ok(_) => {}
                Err(s) => prop_assert!(
                    s.pivot <= floor && ch.mu <= floor + guard.tol(slack),
                    "cascade rejected a clearly regular change: {s:?}, μ {:e}",
                    ch.mu
                ),
            }
        }
        Err(s) => {
            prop_assert!(minus.nrows() > 0, "an addition was reported singular");
            // Singular ⇒ the exact μ = λ_min(B) ≤ the computed pivot's exact
            // value ≤ floor + its rounding (Change::refusal_slack).
            prop_assert!(
                ch.mu <= s.pivot_floor + guard.tol(slack),
                "singular status but μ = {:e} > floor {:e} + {slack:e}",
                ch.mu,
                s.pivot_floor
            );
        }
    }
    Ok(())
}

/// A graded starting design of `rows` rows and a block of `t` rows drawn
/// with the same column scales, times `scale`.
fn design_and_block(c: &GradedCase, rows: usize, scale: f64) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut rng = CaseRng::new(c.seed);
    let s = c.scales(&mut rng);
    let x0 = scale_columns(&conditioned(rows, c.p, c.log10_cond, &mut rng), &s);
    let q = scale_columns(&rng.matrix(c.t, c.p), &s) * scale;
    (x0, q)
}

/// Adding a `t`-row block: eq. (17)/(20) and Woodbury vs the reference.
#[test]
fn add_block() {
    let strat = (
        graded_case(),
        0usize..=8,
        prop::sample::select(vec![1e-3, 1.0, 1e3]),
    );
    run_property("add_block", cases(), strat, |(c, extra, scale), g| {
        let (x0, q) = design_and_block(&c, c.p + extra, scale);
        check_change(&x0, &q, &DMatrix::zeros(0, c.p), g)
    });
}

/// Removing a `t`-row block of the design: eq. (21)/(22) and Woodbury vs
/// the reference, or a justified singular status.
#[test]
fn remove_block() {
    let strat = (graded_case(), 0usize..=40);
    run_property("remove_block", cases(), strat, |(c, extra), g| {
        let (x0, _) = design_and_block(&c, c.p + c.t + extra, 1.0);
        let r = x0.rows(x0.nrows() - c.t, c.t).into_owned();
        check_change(&x0, &DMatrix::zeros(0, c.p), &r, g)
    });
}

/// Exchanging a design block for a new one in one step (the `2t×2t`
/// system) vs the reference, and the cascade (add rows, then remove rows).
#[test]
fn exchange_block() {
    let strat = (
        graded_case(),
        0usize..=40,
        prop::sample::select(vec![1e-2, 1.0, 1e2]),
    );
    run_property("exchange_block", cases(), strat, |(c, extra, scale), g| {
        let (x0, q) = design_and_block(&c, c.p + c.t + extra, scale);
        let r = x0.rows(x0.nrows() - c.t, c.t).into_owned();
        check_change(&x0, &q, &r, g)
    });
}

/// Removing a block that carries the only information in some direction
/// (a design of exactly `p` rows) is always reported singular by the block
/// form; the cascade either refuses or gets the determinant ratio right.
#[test]
fn remove_essential_block_is_singular() {
    run_property(
        "remove_essential_block_is_singular",
        cases(),
        graded_case(),
        |c, guard| {
            let rows = c.p.max(c.t);
            prop_assume!(c.log10_cond <= 6.0);
            let (x0, _) = design_and_block(&c, rows, 1.0);
            let t = c.t.min(x0.nrows());
            let r = x0.rows(x0.nrows() - t, t).into_owned();
            let Some(before) = reference::Reference::of(&DdMat::gram(&x0)) else {
                return Err(TestCaseError::reject("not positive definite"));
            };
            let floor = before.kappa_1 / MAX_CONDITION;
            let (fi, fr) = (to_faer(&before.inv), to_faer(&r));
            let empty = faer::Mat::<f64>::zeros(0, c.p);
            // The block form factors B = I − S with diagonal pivoting, so the zero
            // pivot carries only rounding and is always caught.
            prop_assert!(woodbury(fi.as_ref(), empty.as_ref(), fr.as_ref(), floor).is_err());
            // The cascade removes rows in the given order: a small early factor
            // amplifies the rounding of the last (zero) one, which may then pass
            // the floor. What it must get right is the determinant: the exact
            // ratio det(I − S) is 0, and a perturbation E of S changes it by at
            // most t·‖E‖ (all eigenvalues of I − S lie in [0, 1]), with
            // ‖E‖ ≲ (m+p)·u·κ_s(M0) (see the reference module).
            let m = x0.nrows();
            if let Ok(casc) = cascade(fi.as_ref(), empty.as_ref(), fr.as_ref(), floor) {
                let bound = guard.tol(8.0 * (t * (m + c.p)) as f64 * EPS * before.kappa_scaled);
                prop_assert!(
                    casc.ln_det_ratio.exp() <= bound,
                    "cascade det ratio {:e} > {bound:e}",
                    casc.ln_det_ratio.exp()
                );
            }
            Ok(())
        },
    );
}

use proptests::reference;
