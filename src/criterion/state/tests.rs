//! Tests of the information state: updates against direct recomputation,
//! pivots, drift, settings and the update log.

use super::*;
use crate::criterion::test_util::random_pool;
use faer::Mat;

fn direct(pool: &Blocks, design: &[usize]) -> (f64, Mat<f64>) {
    let m = pool.information(design);
    let (inv, ld) = cholesky_inverse(m.as_ref()).unwrap();
    (ld, view(&inv, m.nrows()).to_owned())
}

/// The `min_pivot` a price reports (it sets the proptests' tolerance
/// and the singularity rule) is `+∞` for an addition, and for a removal
/// lies between `λ_min(B)` and `det(B)^{1/t}` of the Schur complement `B
/// = I − X_q M⁻¹ X_qᵀ` computed directly: every Cholesky pivot of an SPD
/// matrix is at least its smallest eigenvalue, and the smallest of `t`
/// pivots is at most their geometric mean, `det(B)^{1/t}` (< 1 here).
#[test]
fn the_reported_min_pivot_is_that_of_the_removal_schur_complement() {
    let pool = random_pool(40, 3, 9, 11);
    let design = [0, 1, 2, 3, 4, 5];
    let st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
    match st.price_add(&pool, 7).unwrap() {
        Status::Regular { min_pivot, .. } => assert_eq!(min_pivot, f64::INFINITY),
        s => panic!("adding is never singular: {s:?}"),
    }
    let (_, inv) = direct(&pool, &design);
    for q in [0, 2, 5] {
        let x = pool.block(q);
        let b = nalgebra::DMatrix::from_fn(3, 3, |a, c| {
            let mut v = if a == c { 1.0 } else { 0.0 };
            for k in 0..9 {
                for l in 0..9 {
                    v -= x[(a, k)] * inv[(k, l)] * x[(c, l)];
                }
            }
            v
        });
        let eig = b.clone().symmetric_eigenvalues();
        let lmin = eig.iter().copied().fold(f64::INFINITY, f64::min);
        let geo = b.determinant().powf(1.0 / 3.0);
        assert!(
            lmin > 0.0 && geo < 1.0 - 1e-6,
            "pose {q}: λ_min {lmin}, det^(1/3) {geo}"
        );
        match st.price_remove(&pool, q).unwrap() {
            Status::Regular { min_pivot, .. } => assert!(
                min_pivot >= lmin * (1.0 - 1e-9) && min_pivot <= geo * (1.0 + 1e-9),
                "pose {q}: pivot {min_pivot} outside [{lmin}, {geo}]"
            ),
            s => panic!("pose {q} is removable: {s:?}"),
        }
    }
}

#[test]
fn updates_match_direct() {
    let pool = random_pool(40, 3, 9, 11);
    let mut st = InfoState::new(&pool, &[0, 1, 2, 3, 4], StateSettings::default()).unwrap();
    let g = st.price_add(&pool, 7).unwrap().delta().unwrap();
    assert!(st.add(&pool, 7).unwrap().is_regular());
    let (ld, inv) = direct(&pool, &[0, 1, 2, 3, 4, 7]);
    assert!((st.ln_det() - ld).abs() < 1e-10);
    assert!((st.m_inv() - &inv).norm_max() < 1e-10 * inv.norm_max());
    let (ld0, _) = direct(&pool, &[0, 1, 2, 3, 4]);
    assert!((ld0 + g - ld).abs() < 1e-10);
    assert!(st.exchange(&pool, 2, 20).unwrap().is_regular());
    assert_eq!(st.design(), &[0, 1, 20, 3, 4, 7]);
    assert!(st.remove(&pool, 1).unwrap().is_regular());
    assert_eq!(st.design(), &[0, 20, 3, 4, 7]);
    assert_eq!(st.position_of(7), Some(4));
    let (ld, inv) = direct(&pool, &[0, 20, 3, 4, 7]);
    assert!((st.ln_det() - ld).abs() < 1e-10);
    assert!((st.m_inv() - &inv).norm_max() < 1e-10 * inv.norm_max());
}

#[test]
fn bad_input_and_singular() {
    let pool = random_pool(10, 3, 9, 5);
    let s = StateSettings::default();
    assert!(matches!(
        InfoState::new(&pool, &[0, 10], s),
        Err(CriterionError::PoseOutOfRange { pose: 10, .. })
    ));
    assert!(matches!(
        InfoState::new(&pool, &[1, 1, 2], s),
        Err(CriterionError::DuplicatePose { pose: 1 })
    ));
    // Two poses: 6 rows for 9 parameters.
    assert_eq!(
        InfoState::new(&pool, &[0, 1], s).unwrap_err(),
        CriterionError::Singular {
            rank_estimate: 6,
            p: 9
        }
    );
    // With a ridge it works, and dropping the ridge is refused.
    let mut st = InfoState::new(
        &pool,
        &[0, 1],
        s.into_builder().ridge(1e-3).build().unwrap(),
    )
    .unwrap();
    assert!(matches!(
        st.set_ridge(&pool, 0.0),
        Err(CriterionError::Singular { .. })
    ));
    assert_eq!(st.ridge(), 1e-3);
    st.add(&pool, 2).unwrap().delta().unwrap();
    st.set_ridge(&pool, 0.0).unwrap();
    // Exactly 9 rows: removing any pose is singular, state unchanged.
    let before = st.ln_det();
    let r = st.remove(&pool, 1).unwrap();
    assert!(!r.is_regular(), "{r:?}");
    assert_eq!(st.ln_det(), before);
    assert_eq!(st.design(), &[0, 1, 2]);
    assert!(matches!(
        st.remove(&pool, 5),
        Err(CriterionError::NotInDesign { pose: 5 })
    ));
    assert!(matches!(
        st.add(&pool, 0),
        Err(CriterionError::AlreadyInDesign { pose: 0 })
    ));
    assert!(StateSettings::builder().ridge(f64::NAN).build().is_err());
}

#[test]
fn refactorizes_periodically_and_drift_is_small() {
    let pool = random_pool(60, 3, 12, 2);
    let design: Vec<usize> = (0..10).collect();
    let mut st = InfoState::new(
        &pool,
        &design,
        StateSettings::builder().refactor_every(8).build().unwrap(),
    )
    .unwrap();
    let mut next = 10;
    for k in 0..100 {
        let out = st.design()[k % st.design().len()];
        if st.exchange(&pool, out, next).unwrap().is_regular() {
            next = out;
        }
        assert!(st.updates_since_refactor() < 8);
    }
    assert!(st.epoch() >= 12);
    let d = st.drift(&pool);
    assert!(
        d.ln_det < 1e-10 && d.inverse < 1e-10 && d.information < 1e-14,
        "{d:?}"
    );
}

/// Issue #30's mutation sample: a ridge must be finite and `≥ 0` (a
/// negative or infinite one is refused, as NaN is).
#[test]
fn a_negative_or_infinite_ridge_is_refused() {
    let s = StateSettings::default();
    for r in [-1e-3, f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        assert!(s.into_builder().ridge(r).build().is_err(), "ridge {r}");
    }
    assert!(s.into_builder().ridge(0.0).build().is_ok());
}

/// Every construction and every clone has its own id: caches keyed on
/// `(id, version)` must never confuse two states.
#[test]
fn every_state_and_clone_has_its_own_id() {
    let pool = random_pool(12, 3, 4, 3);
    let s = StateSettings::default();
    let a = InfoState::new(&pool, &[0, 1, 2], s).unwrap();
    let b = InfoState::new(&pool, &[0, 1, 2], s).unwrap();
    let c = a.clone();
    assert!(
        a.id() != b.id() && a.id() != c.id() && b.id() != c.id(),
        "{} {} {}",
        a.id(),
        b.id(),
        c.id()
    );
}

/// `r_j = ‖X_pool[:, j]‖² / n_pool`, and `1` for a column that is zero
/// on the whole pool. The scales are sums of 30 squares of numbers of
/// order 1: a relative tolerance of 1e-14 covers their rounding.
#[test]
fn ridge_scales_are_the_mean_column_information() {
    let base = random_pool(10, 3, 4, 9);
    let mat = Mat::from_fn(30, 5, |r, c| if c == 4 { 0.0 } else { base.mat()[(r, c)] });
    let pool = Blocks::new(mat, 3);
    let s = StateSettings::builder().ridge(1e-2).build().unwrap();
    let st = InfoState::new(&pool, &[0, 1, 2, 3], s).unwrap();
    for c in 0..4 {
        let want: f64 = (0..30).map(|r| pool.mat()[(r, c)].powi(2)).sum::<f64>() / 10.0;
        let got = st.ridge_scales()[c];
        assert!(
            (got - want).abs() <= 1e-14 * want,
            "column {c}: {got} vs {want}"
        );
    }
    assert_eq!(st.ridge_scales()[4], 1.0);
}

/// A prior adds its information: `ln det M = ln det(M0 + X_DᵀX_D)`
/// (both sides Cholesky of the same well-conditioned 6×6 sum, so 1e-10
/// is generous); a prior of another `p` than the pool's is refused.
#[test]
fn a_prior_adds_its_information_and_must_match_the_pool() {
    let pool = random_pool(20, 3, 6, 4);
    let s = StateSettings::default();
    let prior = Prior::from_blocks(&random_pool(3, 3, 6, 8)).unwrap();
    let st = InfoState::with_prior(&pool, &[0, 1], Some(prior.clone()), s).unwrap();
    let m = prior.matrix().to_owned() + pool.information(&[0, 1]);
    let (_, want) = cholesky_inverse(m.as_ref()).unwrap();
    assert!(
        (st.ln_det() - want).abs() < 1e-10,
        "{} vs {want}",
        st.ln_det()
    );
    let wrong = Prior::from_blocks(&random_pool(3, 3, 5, 8)).unwrap();
    assert!(matches!(
        InfoState::with_prior(&pool, &[0, 1, 2], Some(wrong), s),
        Err(CriterionError::UnsupportedShape { .. })
    ));
}

/// `condition_estimate` bounds the 2-norm condition number `κ₂(M̃)` of
/// the equilibrated `M̃ = D^-½ M D^-½` from above, by at most a factor
/// `p` (`‖A‖₁ ≤ √p ‖A‖₂` for each factor), computed here from
/// nalgebra's eigenvalues of `M̃` (relative error ~1e-15·κ, so 1e-9 of
/// slack), after construction and after an update.
#[test]
fn condition_estimate_bounds_the_equilibrated_condition_number() {
    let pool = random_pool(30, 3, 6, 17);
    let mut st = InfoState::new(&pool, &[0, 1, 2, 3], StateSettings::default()).unwrap();
    for step in 0..2 {
        let m = st.m();
        let p = m.nrows();
        let a = nalgebra::DMatrix::from_fn(p, p, |i, j| m[(i, j)] / (m[(i, i)] * m[(j, j)]).sqrt());
        let ev = a.symmetric_eigenvalues();
        let (lo, hi) = ev
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
        let k2 = hi / lo;
        let est = st.condition_estimate();
        assert!(
            k2 > 2.0,
            "a random design is not that well conditioned: {k2}"
        );
        assert!(
            est >= k2 * (1.0 - 1e-9) && est <= p as f64 * k2 * (1.0 + 1e-9),
            "step {step}: estimate {est}, κ₂ {k2}"
        );
        st.add(&pool, 10 + step).unwrap().delta().unwrap();
    }
}

/// Without refactorizations the update log keeps between `LOG_KEEP`
/// and `2·LOG_KEEP` entries: 127 updates are all there, the 128th
/// drops the oldest 64 and moves the base to 64.
#[test]
fn the_update_log_is_trimmed_at_twice_log_keep() {
    let pool = random_pool(12, 3, 4, 21);
    let s = StateSettings::builder()
        .refactor_every(10_000)
        .build()
        .unwrap();
    let mut st = InfoState::new(&pool, &[0, 1, 2, 3], s).unwrap();
    for k in 0..2 * LOG_KEEP {
        if k % 2 == 0 {
            st.add(&pool, 5).unwrap().delta().unwrap();
        } else {
            st.remove(&pool, 5).unwrap().delta().unwrap();
        }
        let (base, log) = st.updates_since();
        if k + 1 < 2 * LOG_KEEP {
            assert_eq!((base, log.len()), (0, k + 1), "after {} updates", k + 1);
        } else {
            assert_eq!((base, log.len()), (LOG_KEEP as u64, LOG_KEEP));
        }
    }
}

/// `drift`'s information error is relative to `max |M|`: scaling the
/// pool by 2^10 (exact in binary) scales `M` by 2^20 and every rounding
/// with it, so the figure is the same to the bit — and nonzero after
/// 32 updates without a refactorization.
#[test]
fn the_information_drift_is_relative_to_the_information() {
    let base = random_pool(12, 3, 4, 5);
    let drift_of = |scale: f64| {
        let pool = Blocks::new(Mat::from_fn(36, 4, |r, c| scale * base.mat()[(r, c)]), 3);
        let s = StateSettings::builder()
            .refactor_every(1000)
            .build()
            .unwrap();
        let mut st = InfoState::new(&pool, &[0, 1, 2, 3], s).unwrap();
        for q in 4..12 {
            st.add(&pool, q).unwrap().delta().unwrap();
        }
        for q in 4..12 {
            st.remove(&pool, q).unwrap().delta().unwrap();
        }
        for q in (4..12).rev() {
            st.add(&pool, q).unwrap().delta().unwrap();
        }
        for q in 4..12 {
            st.remove(&pool, q).unwrap().delta().unwrap();
        }
        st.drift(&pool).information
    };
    let (a, b) = (drift_of(1.0), drift_of(1024.0));
    assert!(a > 0.0 && a < 1e-13, "{a}");
    assert_eq!(a, b);
}

/// A pool with no unknowns is refused by name, and `settings` reports
/// the settings the state was built with.
#[test]
fn no_unknowns_is_refused_and_settings_are_kept() {
    let empty = Blocks::new(Mat::zeros(6, 0), 3);
    assert!(matches!(
        InfoState::new(&empty, &[0, 1], StateSettings::default()),
        Err(CriterionError::UnsupportedShape { .. })
    ));
    let pool = random_pool(12, 3, 4, 3);
    let s = StateSettings::builder()
        .ridge(1e-3)
        .refactor_every(7)
        .max_condition(1e10)
        .build()
        .unwrap();
    let st = InfoState::new(&pool, &[0, 1, 2], s).unwrap();
    assert_eq!(*st.settings(), s);
}
