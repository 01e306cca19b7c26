//! `InfoState`, `PoolVariances` and the criteria on random pools, against
//! direct computations on the explicitly stacked design matrix.

use activecal::criterion::{
    Criterion, CriterionError, DCriterion, Indices, InfoState, OiCriterion, PoolVariances,
    StateSettings,
};
use nalgebra::DMatrix;
use proptest::prelude::*;
use proptests::dd::DdMat;
use proptests::reference::{Change, Reference, growth, run_property};
use proptests::*;

/// A random pool of `n` poses and a starting design of `ceil(p/t) + extra`
/// poses (the first ones).
fn pool_and_design(c: &Case, n: usize, extra: usize) -> (DMatrix<f64>, Vec<usize>) {
    let mut rng = CaseRng::new(c.seed);
    let x = rng.matrix(n * c.t, c.p);
    let k = c.p.div_ceil(c.t) + extra;
    (x, (0..k.min(n)).collect())
}

/// A few random updates, then: `ln det M` (the paper's `OI_D`) and `M⁻¹`
/// equal the double-double reference of the explicitly stacked design, the
/// maintained variances equal `X_i M⁻¹ X_iᵀ` of the reference, refused
/// changes are justified by the reference's retained fraction, and the
/// indices satisfy `OI_D = ((OI·L)^L)²`.
///
/// Tolerance: the updates chain from one factorization of `M₀` (fewer than
/// `K = 64` of them), each adding its [`Change::tol_after`] with the
/// input error `κ_s(M₀)·G` (`G` the growth of `M` over `M₀`), all from the
/// reference.
#[test]
fn oi_d_from_updates_equals_stacked() {
    // Chains of removals toward the minimal size make 1/μ reach 1e2…1e4:
    // the equilibrated κ stays ≤ 1e3 so that the chained bound stays below
    // the 1e-6 cap; p ≤ 24 keeps the
    // double-double references of every step affordable.
    let strat = (
        1usize..=6,
        1usize..=24,
        0.0f64..=3.0,
        prop::bool::weighted(0.75),
        any::<u64>(),
        prop::collection::vec((0u8..3, any::<u32>(), any::<u32>()), 1..12),
    )
        .prop_map(|(t, p, log10_cond, graded, seed, ops)| {
            (
                GradedCase {
                    t: t.min(p),
                    p,
                    log10_cond,
                    graded,
                    seed,
                },
                ops,
            )
        });
    run_property(
        "oi_d_from_updates_equals_stacked",
        cases_or(96),
        strat,
        |(c, ops), guard| {
            // Twice the minimal design plus 6 poses: the removals rarely reach
            // the minimal size, where 1/μ (and the bound) explodes.
            let k = 2 * c.p.div_ceil(c.t) + 6;
            let n = k + 9;
            let mut rng = CaseRng::new(c.seed);
            let s = c.scales(&mut rng);
            // All poses from one conditioned matrix: a new pose adds
            // information of the design's own size (G = O(1); outliers are
            // state_reference's graded_updates_and_prices, one update each).
            let x = scale_columns(&conditioned(n * c.t, c.p, c.log10_cond, &mut rng), &s);
            let design: Vec<usize> = (0..k).collect();
            let pool = to_blocks(&x, c.t);
            let Ok(mut st) = InfoState::new(&pool, &design, StateSettings::default()) else {
                return Err(TestCaseError::reject(
                    "refused at construction (state_reference checks why)",
                ));
            };
            let mut pv = PoolVariances::new(&pool, &st);
            let r0 = Reference::of_rows(&stacked(&x, c.t, &design), &[]).unwrap();
            let p = c.p;
            let mut bound =
                8.0 * (k * c.t + p) as f64 * EPS * r0.kappa_scaled + 64.0 * EPS * r0.ln_det.abs();
            for (op, a, b) in ops {
                let d = st.design().to_vec();
                let free: Vec<usize> = (0..n).filter(|i| !st.contains(*i)).collect();
                let out = d[a as usize % d.len()];
                let inn = free[b as usize % free.len()];
                let (plus, minus) = match op {
                    0 => (Some(inn), None),
                    1 => (None, Some(out)),
                    _ => (Some(inn), Some(out)),
                };
                let rows_of = |i: Option<usize>| match i {
                    Some(i) => x.rows(i * c.t, c.t).into_owned(),
                    None => DMatrix::zeros(0, p),
                };
                let m_now = DdMat::gram(&stacked(&x, c.t, &d));
                let ch = Change::of(&m_now, &rows_of(plus), &rows_of(minus));
                let g = growth(&r0, &m_now);
                let rows = d.len() * c.t;
                let st_status = match op {
                    0 => st.add(&pool, inn).unwrap(),
                    1 => st.remove(&pool, out).unwrap(),
                    _ => st.exchange(&pool, out, inn).unwrap(),
                };
                if st_status.is_regular() {
                    prop_assert!(
                        ch.after.is_some(),
                        "accepted a change the reference finds singular"
                    );
                    bound += ch.tol_after(rows + c.t, r0.kappa_scaled * g);
                } else {
                    // A refused change leaves the design as it was, and the
                    // reference keeps at most a floor-sized fraction (the floor
                    // from the reference's equilibrated κ̂, 1% for the state's
                    // own rounding).
                    prop_assert_eq!(st.design(), &d[..]);
                    let floor = 1.01 * ch.before.kappa_1_scaled / 1e13;
                    let slack = guard.tol(ch.refusal_slack(rows) * g);
                    prop_assert!(
                        ch.mu <= floor + slack,
                        "refused with μ {:e} > {floor:e}",
                        ch.mu
                    );
                }
                pv.sync(&pool, &st);
            }
            let xd = stacked(&x, c.t, st.design());
            let r = Reference::of_rows(&xd, &[]).unwrap();
            let tol = guard.tol(bound);
            let e = (st.ln_det() - r.ln_det).abs();
            guard.observe(e, bound);
            prop_assert!(
                e <= tol,
                "ln det {} vs reference {} (tol {tol:e})",
                st.ln_det(),
                r.ln_det
            );
            let e = r.inverse_error(&to_nalgebra(st.m_inv()), &r0.inv);
            prop_assert!(e <= tol, "inverse error {e:e}");
            // Variances: V_i = X_i M⁻¹ X_iᵀ, whose error is that of M⁻¹ in the
            // scaled norm times ‖X_i D⁻¹‖², relative to the larger of M⁻¹, M₀⁻¹.
            let inv_scale = r.scaled_max(&r.inv).max(r.scaled_max(&r0.inv));
            for i in 0..n {
                let xi = x.rows(i * c.t, c.t).into_owned();
                let v = &xi * &r.inv * xi.transpose();
                let xs = DMatrix::from_fn(c.t, p, |a, j| xi[(a, j)] / r.col_scale[j]);
                let scale = xs.norm_squared() * inv_scale;
                for a in 0..c.t {
                    for b in 0..c.t {
                        let e = (pv.entry(i, a, b) - v[(a, b)]).abs();
                        prop_assert!(e <= tol * scale.max(1e-300), "V[{i}]({a},{b}) off by {e:e}");
                    }
                }
            }
            let ix = Indices::from_design(&pool, st.design());
            // The indices come from the singular values of the raw stacked X,
            // which err by ε·σ_max absolute (not scale-invariant): each ln σ_i²
            // by 2·(m+p)·ε·√κ(M) relative, p of them.
            let b_svd = 16.0 * (p * (xd.nrows() + p)) as f64 * EPS * r.kappa.sqrt()
                + 64.0 * EPS * r.ln_det.abs();
            prop_assert!(
                (ix.ln_oid - r.ln_det).abs() <= guard.tol(b_svd),
                "indices ln OI_D {} vs {}",
                ix.ln_oid,
                r.ln_det
            );
            let l = c.p as f64;
            prop_assert!(
                (ix.ln_oid - 2.0 * l * (ix.oi * l).ln()).abs() <= 1e-12 * ix.ln_oid.abs().max(1.0)
            );
            Ok(())
        },
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    /// `DCriterion` prices every candidate (add), design pose (remove) and
    /// pair (exchange) as the direct `ln det` of the changed stacked design;
    /// `OiCriterion` prices are `exp(ln det/(2p))/p` of the same.
    #[test]
    fn criteria_prices_equal_direct(c in well_conditioned_case()) {
        let n = c.p.div_ceil(c.t) + 8;
        let (x, design) = pool_and_design(&c, n, 2);
        let pool = to_blocks(&x, c.t);
        let st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
        let cands: Vec<usize> = (0..n).collect();
        let m0 = to_nalgebra(st.m());
        let k0 = cond2(&m0);
        let rows = design.len() * c.t;
        let direct = |plus: Option<usize>, minus: Option<usize>| {
            let mut m = m0.clone();
            if let Some(i) = plus { m += gram(&x.rows(i * c.t, c.t).into_owned()); }
            if let Some(j) = minus { m -= gram(&x.rows(j * c.t, c.t).into_owned()); }
            (direct_ln_det(&m), cond2(&m))
        };
        let m0_rows = rows;
        let rows_of = |i: Option<usize>| match i {
            Some(i) => x.rows(i * c.t, c.t).into_owned(),
            None => DMatrix::zeros(0, c.p),
        };
        let check = |price: f64, oi: f64, plus: Option<usize>, minus: Option<usize>| -> Result<(), TestCaseError> {
            let (ld, k1) = direct(plus, minus);
            if price == f64::NEG_INFINITY {
                // Only removals can be refused, and only when the exact
                // λ_min(M0^-½ M1 M0^-½) is at the floor up to the rounding
                // of the pivot, (m+p)·u·κ(M0) (see updates.rs).
                prop_assert!(minus.is_some());
                let mid = &m0 + gram(&rows_of(plus));
                let m1 = &mid - gram(&rows_of(minus));
                let mu = retained_fraction(&mid, &m1);
                let g = amplification(&m0, &rows_of(plus), &DMatrix::zeros(0, c.p));
                let slack = 8.0 * (m0_rows + c.p) as f64 * EPS * k0 * g;
                prop_assert!(mu <= st.pivot_floor() + slack, "refused with λ_min {mu:e}");
                return Ok(());
            }
            let ld = ld.expect("priced finite but direct Cholesky fails");
            let g = amplification(&m0, &rows_of(plus), &rows_of(minus));
            let tol = ln_det_tol(rows + c.t, c.p, k0, k1, g, ld);
            prop_assert!((price - ld).abs() <= tol, "price {price} vs direct {ld}");
            let p = c.p as f64;
            let want = (ld / (2.0 * p)).exp() / p;
            // OI = exp(ln det/2p)/p: relative error tol/(2p) plus the
            // eigenvalue route's own (m+p)·u·κ.
            if oi != f64::NEG_INFINITY {
                prop_assert!((oi - want).abs() <= want * (tol + 8.0 * (rows + c.p) as f64 * EPS * k1));
            }
            Ok(())
        };
        let (mut d, mut o) = (DCriterion::new(), OiCriterion::new());
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        d.price_adds(&pool, &st, &cands, &mut a);
        o.price_adds(&pool, &st, &cands, &mut b);
        for i in 0..n {
            if st.contains(i) {
                prop_assert!(a[i] == f64::NEG_INFINITY && b[i] == f64::NEG_INFINITY);
            } else {
                check(a[i], b[i], Some(i), None)?;
            }
        }
        let k = design.len();
        let (mut a, mut b) = (vec![0.0; k], vec![0.0; k]);
        d.price_removals(&pool, &st, &mut a);
        o.price_removals(&pool, &st, &mut b);
        for (r, &j) in design.iter().enumerate() {
            check(a[r], b[r], None, Some(j))?;
        }
        // Exchanges against up to three design poses (direct checks cost
        // O(p³) per pair).
        let outs: Vec<usize> = design.iter().copied().step_by(k.div_ceil(3)).collect();
        let k = outs.len();
        let (mut a, mut b) = (vec![0.0; n * k], vec![0.0; n * k]);
        d.price_exchanges(&pool, &st, &outs, &cands, &mut a);
        o.price_exchanges(&pool, &st, &outs, &cands, &mut b);
        for i in 0..n {
            for (r, &j) in outs.iter().enumerate() {
                let (pa, pb) = (a[i * k + r], b[i * k + r]);
                prop_assert!(!pa.is_nan() && !pb.is_nan());
                if st.contains(i) {
                    prop_assert!(pa == f64::NEG_INFINITY && pb == f64::NEG_INFINITY);
                } else {
                    check(pa, pb, Some(i), Some(j))?;
                }
            }
        }
    }

    /// A rank-deficient design is refused at construction with its rank.
    #[test]
    fn rank_deficient_design_is_singular(c in case(), deficit in 1usize..=5) {
        let mut rng = CaseRng::new(c.seed);
        prop_assume!(c.p >= 2);
        let rank = c.p.saturating_sub(deficit).max(1);
        let poses = (c.p.div_ceil(c.t) + 3).max(2);
        let x = rank_deficient(poses * c.t, c.p, rank, &mut rng);
        let pool = to_blocks(&x, c.t);
        let design: Vec<usize> = (0..poses).collect();
        let r = InfoState::new(&pool, &design, StateSettings::default());
        prop_assert_eq!(r.unwrap_err(), CriterionError::Singular { rank_estimate: rank, p: c.p });
    }

    /// With exactly `ceil(p/t)` poses every removal is refused, the state
    /// is left unchanged, and every criterion prices it `-∞` (never NaN);
    /// exchanging in a copy of another design pose is refused too.
    #[test]
    fn essential_removals_are_refused(c in well_conditioned_case()) {
        let k = c.p.div_ceil(c.t);
        let mut rng = CaseRng::new(c.seed);
        let base = rng.matrix(k * c.t, c.p);
        let dup = base.rows(0, c.t).into_owned();
        let x = vstack(&[&base, &dup]);
        let pool = to_blocks(&x, c.t);
        let design: Vec<usize> = (0..k).collect();
        let mut st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
        let before = (st.ln_det(), st.version());
        for &j in &design {
            let s = st.remove(&pool, j).unwrap();
            prop_assert!(!s.is_regular(), "removal of {j} accepted: {s:?}");
        }
        prop_assert_eq!((st.ln_det(), st.version()), before);
        let mut out = vec![0.0; k];
        DCriterion::new().price_removals(&pool, &st, &mut out);
        prop_assert!(out.iter().all(|&v| v == f64::NEG_INFINITY));
        OiCriterion::new().price_removals(&pool, &st, &mut out);
        prop_assert!(out.iter().all(|&v| v == f64::NEG_INFINITY));
        if k >= 2 {
            // Pose k duplicates pose 0: swapping pose 1 for it loses rank.
            let s = st.exchange(&pool, 1, k).unwrap();
            prop_assert!(!s.is_regular(), "{s:?}");
            let mut e = [0.0];
            DCriterion::new().price_exchanges(&pool, &st, &[1], &[k], &mut e);
            prop_assert_eq!(e[0], f64::NEG_INFINITY);
        }
    }
}
