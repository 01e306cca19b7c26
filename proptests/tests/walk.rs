//! Long random walks of updates stay within the documented drift bound of
//! direct recomputation.

use activecal::criterion::{InfoState, PoolVariances, StateSettings};
use proptest::prelude::*;
use proptests::*;

/// Updates per walk.
const STEPS: usize = 10_000;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    /// 10,000 random adds, removes and exchanges (refused ones included).
    /// Every 2,500 steps and at the end, `ln det M`, `M⁻¹` and the pool
    /// variances are compared with a direct recomputation from the design.
    ///
    /// Tolerance: the module's drift bound. Errors accumulate only over the
    /// updates since the last refactorization (at most `K`), each adding
    /// `≲ (m+p)·u·κ(M)·a` to `ln det` and to the relative error of `M⁻¹`
    /// (`a` the update's amplification, see the crate docs); so
    /// `|Δ ln det| ≤ 4·K·(m+p)·ε·B` with `B = max κ̂(M)·a` over those updates
    /// (`κ̂ = ‖M‖₁‖M⁻¹‖₁ ≥ κ₂`; `ε = 2u`, so 4 is `c = 8` in units of `u`),
    /// plus `64·ε·|ln det|` for the sum itself; `M⁻¹` and `V_i` likewise,
    /// relative to the largest `‖M⁻¹‖_max` over the same window.
    #[test]
    fn random_walk_stays_within_drift_bound(
        c in well_conditioned_case(),
        k in prop::sample::select(vec![16usize, 64, 256]),
    ) {
        let (t, p) = (c.t, c.p);
        let mut rng = CaseRng::new(c.seed);
        let kmin = p.div_ceil(t) + 1;
        let n = kmin + 12;
        let x = rng.matrix(n * t, p);
        let pool = to_blocks(&x, t);
        let design: Vec<usize> = (0..kmin + 2).collect();
        let settings = StateSettings::builder().refactor_every(k).build().unwrap();
        let mut st = InfoState::new(&pool, &design, settings).unwrap();
        let mut pv = PoolVariances::new(&pool, &st);
        let mut epoch = st.epoch();
        let (mut kappa, mut inv_norm) = (0.0f64, 0.0f64);
        let mut refused = 0usize;
        for step in 0..STEPS {
            let d = st.design();
            let free: Vec<usize> = (0..n).filter(|&i| !st.contains(i)).collect();
            let out = d[rng.below(d.len())];
            let inn = free[rng.below(free.len())];
            let op = match rng.below(3) {
                0 if d.len() < kmin + 8 => 0,
                1 if d.len() > kmin => 1,
                _ => 2,
            };
            let k_before = st.condition_estimate();
            let inv_norm1 = norm1_faer(st.m_inv());
            let s = match op {
                0 => st.add(&pool, inn).unwrap(),
                1 => st.remove(&pool, out).unwrap(),
                _ => st.exchange(&pool, out, inn).unwrap(),
            };
            refused += usize::from(!s.is_regular());
            if st.epoch() != epoch {
                epoch = st.epoch();
                kappa = 0.0;
                inv_norm = 0.0;
            }
            let added = if op == 1 { 0.0 } else { x.rows(inn * t, t).norm_squared() };
            kappa = kappa
                .max(k_before * step_amplification(&s, added, inv_norm1))
                .max(st.condition_estimate());
            inv_norm = inv_norm.max(max_abs_faer(st.m_inv()));
            if step % 8 == 0 {
                pv.sync(&pool, &st);
            }
            if (step + 1) % 2500 == 0 {
                pv.sync(&pool, &st);
                let xd = stacked(&x, t, st.design());
                let m = xd.nrows();
                let md = gram(&xd);
                let ld = direct_ln_det(&md).expect("the walk keeps M positive definite");
                let bound = 4.0 * k as f64 * (m + p) as f64 * EPS * kappa;
                let tol = bound + 64.0 * EPS * ld.abs();
                let e = (st.ln_det() - ld).abs();
                prop_assert!(e <= tol, "step {step}: ln det drift {e:e} > {tol:e}");
                let inv = direct_inverse(&md).unwrap();
                let e_inv = max_abs(&(to_nalgebra(st.m_inv()) - &inv));
                let scale = inv_norm.max(max_abs(&inv));
                prop_assert!(e_inv <= bound * scale, "step {step}: M⁻¹ drift {e_inv:e}");
                for i in 0..n {
                    let xi = x.rows(i * t, t).into_owned();
                    let v = &xi * &inv * xi.transpose();
                    let vs = max_abs(&(&xi * xi.transpose())) * scale * p as f64;
                    for a in 0..t {
                        for b in 0..t {
                            let e = (pv.entry(i, a, b) - v[(a, b)]).abs();
                            prop_assert!(e <= bound * vs.max(1e-300), "step {step}: V drift {e:e}");
                        }
                    }
                }
                let dr = st.drift(&pool);
                prop_assert!(dr.ln_det <= tol && dr.inverse.is_finite());
            }
        }
        // The walk must mostly move: refusals are rare for random pools.
        prop_assert!(refused < STEPS / 2, "{refused} of {STEPS} updates refused");
    }
}
