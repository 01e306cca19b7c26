//! `InfoState`, `PoolVariances` and the criteria on random pools, against
//! direct computations on the explicitly stacked design matrix.

use activecal::criterion::{
    Criterion, CriterionError, DCriterion, Indices, InfoState, OiCriterion, PoolVariances,
    StateSettings,
};
use nalgebra::DMatrix;
use proptest::prelude::*;
use proptests::*;

/// A random pool of `n` poses and a starting design of `ceil(p/t) + extra`
/// poses (the first ones).
fn pool_and_design(c: &Case, n: usize, extra: usize) -> (DMatrix<f64>, Vec<usize>) {
    let mut rng = CaseRng::new(c.seed);
    let x = rng.matrix(n * c.t, c.p);
    let k = c.p.div_ceil(c.t) + extra;
    (x, (0..k.min(n)).collect())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    /// A few random updates, then: `ln det M` (the paper's `OI_D`) equals
    /// `2 Σ ln σ_i` of the explicitly stacked `X` (nalgebra SVD), `M⁻¹`
    /// equals the direct inverse, the maintained variances equal
    /// `X_i M⁻¹ X_iᵀ`, and the indices satisfy `OI_D = ((OI·L)^L)²`.
    #[test]
    fn oi_d_from_updates_equals_stacked(c in well_conditioned_case(), ops in prop::collection::vec((0u8..3, any::<u32>(), any::<u32>()), 1..12)) {
        let n = c.p.div_ceil(c.t) + 12;
        let (x, design) = pool_and_design(&c, n, 3);
        let pool = to_blocks(&x, c.t);
        let mut st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
        let mut pv = PoolVariances::new(&pool, &st);
        let n_ops = ops.len();
        // Errors accumulate over the updates (fewer than K = 64, so no
        // refactorization), each bounded by its κ̂(M)·a (see walk.rs).
        let mut kappa = st.condition_estimate();
        for (op, a, b) in ops {
            let before = (st.condition_estimate(), st.m_inv());
            let k_before = before.0;
            let inv_norm = norm1_faer(before.1);
            let d = st.design().to_vec();
            let free: Vec<usize> = (0..n).filter(|i| !st.contains(*i)).collect();
            let out = d[a as usize % d.len()];
            let inn = free[b as usize % free.len()];
            let s = match op {
                0 => st.add(&pool, inn).unwrap(),
                1 => st.remove(&pool, out).unwrap(),
                _ => st.exchange(&pool, out, inn).unwrap(),
            };
            // A refused change leaves the design as it was.
            if !s.is_regular() {
                prop_assert_eq!(st.design(), &d[..]);
            }
            let added = if op == 1 { 0.0 } else { x.rows(inn * c.t, c.t).norm_squared() };
            kappa = kappa
                .max(k_before * step_amplification(&s, added, inv_norm))
                .max(st.condition_estimate());
            pv.sync(&pool, &st);
        }
        let xd = stacked(&x, c.t, st.design());
        let sv = xd.clone().svd(false, false).singular_values;
        // Refused removals keep at least p rows, so there are p singular values.
        prop_assert_eq!(sv.len(), c.p);
        let ln_oid: f64 = sv.iter().map(|s| 2.0 * s.ln()).sum();
        let m1 = gram(&xd);
        // The drift bound for n_ops updates (see walk.rs): each adds at most
        // ln_det_tol at the largest κ̂ met.
        let k1 = kappa * (n_ops + 1) as f64;
        let tol = ln_det_tol(xd.nrows(), c.p, k1, k1, 1.0, ln_oid);
        prop_assert!((st.ln_det() - ln_oid).abs() <= tol,
            "ln det {} vs stacked {} (tol {tol:e})", st.ln_det(), ln_oid);
        let direct = direct_inverse(&m1).unwrap();
        let e = max_abs(&(to_nalgebra(st.m_inv()) - &direct)) / max_abs(&direct);
        prop_assert!(e <= inverse_tol(xd.nrows(), c.p, k1, k1, 1.0), "inverse error {e:e}");
        // Variances: |V_i| ≤ ‖X_i‖²‖M⁻¹‖, so compare relative to that scale.
        for i in 0..n {
            let xi = x.rows(i * c.t, c.t).into_owned();
            let v = &xi * &direct * xi.transpose();
            let scale = max_abs(&(&xi * xi.transpose())) * max_abs(&direct) * c.p as f64;
            for a in 0..c.t {
                for b in 0..c.t {
                    let e = (pv.entry(i, a, b) - v[(a, b)]).abs();
                    prop_assert!(e <= inverse_tol(xd.nrows(), c.p, k1, k1, 1.0) * scale.max(1e-300),
                        "V[{i}]({a},{b}) off by {e:e}");
                }
            }
        }
        let ix = Indices::from_design(&pool, st.design());
        prop_assert!((ix.ln_oid - ln_oid).abs() <= tol);
        let l = c.p as f64;
        prop_assert!((ix.ln_oid - 2.0 * l * (ix.oi * l).ln()).abs() <= 1e-12 * ix.ln_oid.abs().max(1.0));
    }

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

    /// Ill-conditioned designs (κ(M) up to 1e10): every add, remove and
    /// exchange either matches the direct computation within the
    /// κ-scaled tolerance or is refused, and no price is NaN.
    #[test]
    fn ill_conditioned_updates(c in case()) {
        let mut rng = CaseRng::new(c.seed);
        let k = c.p.div_ceil(c.t) + 2;
        let x0 = conditioned(k * c.t, c.p, c.log10_cond, &mut rng);
        let extra = rng.matrix(4 * c.t, c.p);
        let x = vstack(&[&x0, &extra]);
        let pool = to_blocks(&x, c.t);
        let n = k + 4;
        let design: Vec<usize> = (0..k).collect();
        let st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
        let m0 = gram(&x0);
        let k0 = cond2(&m0);
        let rows = k * c.t;
        let mut d = DCriterion::new();
        let rows_of = |i: Option<usize>| match i {
            Some(i) => x.rows(i * c.t, c.t).into_owned(),
            None => DMatrix::zeros(0, c.p),
        };
        let cands: Vec<usize> = (0..n).collect();
        let mut ex = vec![0.0; n * k];
        d.price_exchanges(&pool, &st, &design, &cands, &mut ex);
        let mut rem = vec![0.0; k];
        d.price_removals(&pool, &st, &mut rem);
        prop_assert!(ex.iter().chain(&rem).all(|v| !v.is_nan()));
        // Up to four design poses out (direct checks cost O(p³) each).
        for (r, &j) in design.iter().enumerate().step_by(k.div_ceil(4)) {
            for i in std::iter::once(None).chain((k..n).map(Some)) {
                let mut s1 = st.clone();
                let status = match i {
                    None => s1.remove(&pool, j).unwrap(),
                    Some(i) => s1.exchange(&pool, j, i).unwrap(),
                };
                let price = match i { None => rem[r], Some(i) => ex[i * k + r] };
                let mut m1 = m0.clone();
                m1 -= gram(&x.rows(j * c.t, c.t).into_owned());
                if let Some(i) = i { m1 += gram(&x.rows(i * c.t, c.t).into_owned()); }
                match status.delta() {
                    Some(delta) => {
                        let ld1 = direct_ln_det(&m1).expect("accepted but not PD");
                        let k1 = cond2(&m1);
                        let g = amplification(&m0, &rows_of(i), &rows_of(Some(j)));
                        let tol = ln_det_tol(rows + c.t, c.p, k0, k1, g, ld1);
                        let ld0 = direct_ln_det(&m0).unwrap();
                        prop_assert!((ld0 + delta - ld1).abs() <= tol,
                            "Δ {delta} vs {} (tol {tol:e}, κ0 {k0:e}, κ1 {k1:e})", ld1 - ld0);
                        prop_assert!((s1.ln_det() - ld1).abs() <= tol);
                        // The batched price agrees with the state's pricing
                        // (same formula from V, W instead of S).
                        prop_assert!(price == f64::NEG_INFINITY || (price - s1.ln_det()).abs() <= tol);
                    }
                    None => {
                        let mid = &m0 + gram(&rows_of(i));
                        let mu = retained_fraction(&mid, &m1);
                        let g = amplification(&m0, &rows_of(i), &DMatrix::zeros(0, c.p));
                        let slack = 8.0 * (rows + c.p) as f64 * EPS * k0 * g;
                        prop_assert!(mu <= st.pivot_floor() + slack,
                            "refused with λ_min {mu:e} > floor {:e}", st.pivot_floor());
                        prop_assert_eq!(s1.version(), st.version());
                    }
                }
            }
        }
    }
}
