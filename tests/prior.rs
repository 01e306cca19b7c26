//! Prior information `M0` (poses already measured): the criterion state,
//! the selection and the relaxation bound maximise `ln det(M0 + Σ new)`.
//! On small random pools with a random prior the certified bound is at least
//! the optimum found by enumerating every N-subset, and with `M0 = 0` it is
//! the bound without a prior.

use activecal::blocks::Blocks;
use activecal::bound::variance::{
    VarianceWork, certificate, certificate_with_prior, information, make_feasible, top_sum,
    variances_into,
};
use activecal::bound::{BoundSettings, RelaxationSolver, design_gap, relaxation_bound};
use activecal::criterion::{InfoState, Prior, StateSettings};
use activecal::select::{Algorithm, CriterionKind, Settings, select};
use faer::{Mat, MatRef, Side};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_blocks(poses: usize, t: usize, p: usize, seed: u64) -> Blocks {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut rows = Vec::with_capacity(poses * t * p);
    for i in 0..poses {
        let s = 0.5 + i as f64 / poses as f64;
        for _ in 0..t * p {
            rows.push(s * (rng.random::<f64>() - 0.5));
        }
    }
    Blocks::from_row_major(&rows, t, p)
}

/// A prior from `k` random measured rows (rank `min(k, p)`), of size
/// comparable to one pose of the pool times `weight`.
fn random_prior(k: usize, p: usize, weight: f64, seed: u64) -> Prior {
    let x = random_blocks(k, 1, p, seed);
    let m = x.information(&(0..k).collect::<Vec<_>>()) * weight;
    Prior::from_matrix(m.as_ref(), k).unwrap()
}

fn ln_det(m: MatRef<'_, f64>) -> Option<f64> {
    let l = m.llt(Side::Lower).ok()?;
    let l = l.L();
    Some((0..m.nrows()).map(|i| 2.0 * l[(i, i)].ln()).sum())
}

fn with_prior(x: &Blocks, prior: &Prior, design: &[usize]) -> Option<f64> {
    ln_det((x.information(design) + prior.matrix()).as_ref())
}

/// The exact optimum of `ln det(M0 + Σ_design X_iᵀX_i)` over all N-subsets.
fn enumerate(x: &Blocks, prior: &Prior, n: usize) -> f64 {
    fn rec(x: &Blocks, pr: &Prior, n: usize, start: usize, cur: &mut Vec<usize>, best: &mut f64) {
        if cur.len() == n {
            if let Some(v) = with_prior(x, pr, cur) {
                *best = best.max(v);
            }
            return;
        }
        for i in start..x.n_poses() {
            cur.push(i);
            rec(x, pr, n, i + 1, cur, best);
            cur.pop();
        }
    }
    let mut best = f64::NEG_INFINITY;
    rec(x, prior, n, 0, &mut Vec::new(), &mut best);
    best
}

/// Every solver's certified bound is at least the enumerated optimum, on
/// pools where `N·t ≥ p` and where only the prior makes a design regular
/// (`N·t < p`), with full-rank and rank-deficient priors.
#[test]
fn the_prior_aware_bound_is_at_least_the_enumerated_optimum() {
    let (t, p) = (2, 6);
    let mut checked = 0;
    for seed in 0..6u64 {
        let x = random_blocks(11, t, p, 100 + seed);
        for (k, n) in [(8, 2), (8, 4), (3, 3), (3, 4)] {
            // k = 3 rows leave M0 rank 3: the new poses must supply the rest.
            let prior = random_prior(k, p, 0.7, 200 + seed);
            let opt = enumerate(&x, &prior, n);
            assert!(opt.is_finite());
            for (solver, conic) in [
                (RelaxationSolver::Clarabel, true),
                (RelaxationSolver::Newton, true),
                (RelaxationSolver::Clarabel, false),
            ] {
                let s = BoundSettings::builder()
                    .solver(solver)
                    .use_conic(conic)
                    .build()
                    .unwrap();
                let b = relaxation_bound(&x, Some(&prior), n, &s).unwrap();
                assert!(b.with_prior);
                // The bound and the optimum are sums of p logs of pivots of
                // O(1) matrices: 1e-9 relative is far above their rounding.
                assert!(
                    b.ln_bound >= opt - 1e-9 * opt.abs().max(1.0),
                    "seed {seed} k {k} n {n} {solver:?}/{conic}: bound {} < optimum {opt}",
                    b.ln_bound
                );
                assert!(b.ln_primal <= b.ln_bound + 1e-9 * b.ln_bound.abs().max(1.0));
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 6 * 4 * 3);
}

/// Eq. (C0) directly: at any feasible weights, the certificate bounds the
/// enumerated optimum; dropping the prior's term `tr(M⁻¹M0)` does not (so
/// the test would catch the term missing).
#[test]
fn certificate_c0_holds_at_any_feasible_point_and_needs_the_prior_term() {
    let (t, p, n) = (2, 6, 3);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut without_term_fails = 0;
    for seed in 0..5u64 {
        let x = random_blocks(10, t, p, seed);
        let prior = random_prior(12, p, 2.0, 50 + seed);
        let opt = enumerate(&x, &prior, n);
        for _ in 0..20 {
            let mut w: Vec<f64> = (0..10).map(|_| rng.random::<f64>()).collect();
            make_feasible(&mut w, n);
            let m = information(&x, &w) + prior.matrix();
            let mut d = vec![0.0; 10];
            let (ld, minv) =
                variances_into(&x, m.as_ref(), &mut VarianceWork::default(), &mut d).unwrap();
            let c0: f64 = (0..p)
                .map(|i| {
                    (0..p)
                        .map(|j| minv[(i, j)] * prior.matrix()[(j, i)])
                        .sum::<f64>()
                })
                .sum();
            let s_n = top_sum(&d, n, &mut Vec::new());
            let c = certificate_with_prior(ld, c0, s_n, p);
            assert!(c >= opt - 1e-9 * opt.abs(), "C0 {c} < optimum {opt}");
            // The Lagrangian (linearised) bound is valid and never tighter.
            let lagrangian = ld + c0 + s_n - p as f64;
            assert!(lagrangian >= c - 1e-12 * c.abs());
            if certificate(ld, s_n, p) < opt {
                without_term_fails += 1;
            }
        }
    }
    assert!(without_term_fails > 0);
}

#[test]
fn a_zero_prior_gives_the_bound_without_one() {
    let (t, p, n) = (3, 8, 4);
    let zero = Prior::from_matrix(Mat::<f64>::zeros(p, p).as_ref(), 0).unwrap();
    for seed in 0..3 {
        let x = random_blocks(40, t, p, seed);
        for solver in [RelaxationSolver::Clarabel, RelaxationSolver::Newton] {
            let s = BoundSettings::builder().solver(solver).build().unwrap();
            let a = relaxation_bound(&x, None, n, &s).unwrap();
            let b = relaxation_bound(&x, Some(&zero), n, &s).unwrap();
            // Both are certified to gap_tol above the same relaxation optimum.
            let tol = 2.0 * s.gap_tol;
            assert!(
                (a.ln_bound - b.ln_bound).abs() <= tol,
                "{solver:?}: {} vs {}",
                a.ln_bound,
                b.ln_bound
            );
            assert!(!a.with_prior && b.with_prior);
            // A design scored against the other kind of bound is refused.
            assert!(design_gap(&x, None, &[0, 1, 2, 3], &b).is_err());
            assert!(design_gap(&x, Some(&zero), &[0, 1, 2, 3], &a).is_err());
        }
    }
}

#[test]
fn the_state_and_selection_work_on_top_of_the_prior() {
    let (t, p) = (2, 6);
    let x = random_blocks(30, t, p, 3);
    let prior = random_prior(9, p, 1.0, 4);
    // Updates with a prior match a direct factorisation of M0 + XᵀX.
    let mut st =
        InfoState::with_prior(&x, &[0, 1], Some(prior.clone()), StateSettings::default()).unwrap();
    st.add(&x, 5).unwrap().delta().unwrap();
    assert!(st.exchange(&x, 0, 9).unwrap().is_regular());
    let direct = with_prior(&x, &prior, &[9, 1, 5]).unwrap();
    assert!((st.ln_det() - direct).abs() < 1e-10 * direct.abs().max(1.0));
    // Two poses (4 rows) cannot determine 6 unknowns alone; with the prior
    // they can, and the selection maximises ln det(M0 + new).
    let s = Settings::builder()
        .n(2)
        .initial(1)
        .starts(4)
        .prior(Some(prior.clone()))
        .build()
        .unwrap();
    let sel = select(&x, CriterionKind::Det, Algorithm::Eae, &s).unwrap();
    let recomputed = with_prior(&x, &prior, &sel.poses).unwrap();
    assert!((sel.ln_oid - recomputed).abs() < 1e-9 * recomputed.abs().max(1.0));
    let opt = enumerate(&x, &prior, 2);
    assert!(sel.ln_oid <= opt + 1e-9 * opt.abs().max(1.0));
    let bound = relaxation_bound(&x, Some(&prior), 2, &BoundSettings::default()).unwrap();
    let g = design_gap(&x, Some(&prior), &sel.poses, &bound).unwrap();
    assert!(
        g.d_efficiency > 0.0 && g.d_efficiency <= 1.0 + 1e-12,
        "{}",
        g.d_efficiency
    );
    // Without the prior, N = 2 is refused as singular.
    let plain = s.clone().into_builder().prior(None).build().unwrap();
    assert!(select(&x, CriterionKind::Det, Algorithm::Eae, &plain).is_err());
    // A zero prior changes nothing.
    let zero = Prior::from_matrix(Mat::<f64>::zeros(p, p).as_ref(), 0).unwrap();
    let s6 = Settings::builder().n(6).initial(3).build().unwrap();
    let a = select(&x, CriterionKind::Det, Algorithm::Fedorov, &s6).unwrap();
    let b = select(
        &x,
        CriterionKind::Det,
        Algorithm::Fedorov,
        &s6.clone().into_builder().prior(Some(zero)).build().unwrap(),
    )
    .unwrap();
    assert_eq!(a.poses, b.poses);
    // A prior of the wrong size is an error, not a panic.
    let wrong = random_prior(9, p + 1, 1.0, 4);
    assert!(
        InfoState::with_prior(
            &x,
            &[0, 1, 2],
            Some(wrong.clone()),
            StateSettings::default()
        )
        .is_err()
    );
    assert!(relaxation_bound(&x, Some(&wrong), 3, &BoundSettings::default()).is_err());
}
