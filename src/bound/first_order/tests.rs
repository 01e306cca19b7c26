//! Unit tests of the first-order solver and its phases.

use super::*;

use crate::bound::newton::{NewtonSettings, solve_scaled as newton_solve};
use crate::bound::variance::certificate;
use crate::linalg::test_rng::lcg;

/// A pool of `n` random 2 × 3 poses (O(1) entries).
fn pool(n: usize, seed: u64) -> Blocks {
    let mut s = seed;
    Blocks::new(Mat::from_fn(2 * n, 3, |_, _| lcg(&mut s)), 2)
}

/// `ln det M(w)` of `M(w) = Σ w_i X_iᵀX_i` and the variances
/// `d_i = tr(X_i M⁻¹ X_iᵀ)`, formed here with nalgebra's Cholesky (no
/// column scaling, no shared code with the solver).
fn direct(x: &Blocks, w: &[f64]) -> (f64, Vec<f64>) {
    let (t, p) = (x.t(), x.p());
    let mut m = nalgebra::DMatrix::<f64>::zeros(p, p);
    for (i, &wi) in w.iter().enumerate() {
        let b = x.block(i);
        for a in 0..p {
            for c in 0..p {
                m[(a, c)] += wi * (0..t).map(|r| b[(r, a)] * b[(r, c)]).sum::<f64>();
            }
        }
    }
    let chol = m.cholesky().expect("positive definite");
    let ld = 2.0 * chol.l().diagonal().iter().map(|v| v.ln()).sum::<f64>();
    let inv = chol.inverse();
    let d = (0..x.n_poses())
        .map(|i| {
            let b = x.block(i);
            let mut s = 0.0;
            for r in 0..t {
                for a in 0..p {
                    for c in 0..p {
                        s += b[(r, a)] * inv[(a, c)] * b[(r, c)];
                    }
                }
            }
            s
        })
        .collect();
    (ld, d)
}

/// The sum of the `n` largest entries.
fn top(d: &[f64], n: usize) -> f64 {
    let mut v = d.to_vec();
    v.sort_by(|a, b| b.total_cmp(a));
    v[..n].iter().sum()
}

#[test]
fn settings_out_of_range_are_refused() {
    assert!(ExchangeSettings::default().validate().is_ok());
    let with = |f: fn(&mut ExchangeSettings)| {
        let mut s = ExchangeSettings::default();
        f(&mut s);
        s.validate()
    };
    assert!(with(|s| s.gap_tol = 0.0).is_err());
    assert!(with(|s| s.gap_tol = f64::NAN).is_err());
    assert!(with(|s| s.gap_tol = f64::INFINITY).is_err());
    assert!(with(|s| s.gap_tol = 1e-3).is_ok());
    assert!(with(|s| s.time_limit = 0.0).is_err());
    assert!(with(|s| s.time_limit = f64::NAN).is_err());
    assert!(with(|s| s.time_limit = 1e-3).is_ok());
    assert!(with(|s| s.max_rounds = 0).is_err());
    assert!(with(|s| s.keep = 0).is_err());
    assert!(with(|s| s.max_steps = 0).is_err());
    assert!(with(|s| s.max_rounds = 1).is_ok());
    assert!(with(|s| s.keep = 1).is_ok());
    assert!(with(|s| s.max_steps = 1).is_ok());
}

/// The solve is certified and right: `gap = ln_bound − ln_det ≤
/// gap_tol`; `ln_det` is `ln det M(w)` of the returned weights (formed
/// here unscaled: 1e-9 relative, rounding of sums of a few dozen O(1)
/// products); `ln_bound` is at most the certificate (eq. C) at those
/// weights (the smallest seen, these included); and the Newton barrier
/// solve (accurate to 1e-10) finds an optimum between the two (1e-8 of
/// slack for both solvers' rounding).
#[test]
fn the_solve_is_certified_and_brackets_the_optimum() {
    for (n_pool, n, seed) in [(12, 3, 1), (30, 5, 2), (9, 6, 3)] {
        let x = pool(n_pool, seed);
        let s = ExchangeSettings::default();
        let out = solve(&x, n, None, &s).unwrap();
        assert!(out.converged, "pool {n_pool}");
        assert!((0.0..=s.gap_tol).contains(&out.gap), "gap {}", out.gap);
        // The gap is taken in scaled units, before `ln_scale` is added
        // to both values (O(10)): 1e-12 of rounding.
        assert!((out.gap - (out.ln_bound - out.ln_det)).abs() < 1e-12);
        let w = &out.weights;
        assert!(w.iter().all(|&v| (0.0..=1.0).contains(&v)));
        assert!((w.iter().sum::<f64>() - n as f64).abs() < 1e-9);
        let (ld, d) = direct(&x, w);
        assert!(
            (ld - out.ln_det).abs() < 1e-9 * (1.0 + ld.abs()),
            "{ld} vs {}",
            out.ln_det
        );
        let cert = certificate(ld, top(&d, n), x.p());
        assert!(out.ln_bound <= cert + 1e-9, "{} > {cert}", out.ln_bound);
        let sc = scale_columns(&x, n).unwrap();
        let nt = newton_solve(&sc, n, None, &NewtonSettings::default(), 1.0);
        assert!(
            out.ln_det - 1e-8 <= nt.ln_det_primal && nt.ln_det_primal <= out.ln_bound + 1e-8,
            "pool {n_pool}: {} not in [{}, {}]",
            nt.ln_det_primal,
            out.ln_det,
            out.ln_bound
        );
        assert!(out.rounds >= 1 && out.rounds <= s.max_rounds);
    }
}

/// `N` equal to the pool: every weight 1, no step, no gap, one
/// evaluation (`ln det` of the whole pool, to 1e-9 relative).
#[test]
fn a_design_of_the_whole_pool_is_its_own_optimum() {
    let x = pool(5, 4);
    let out = solve(&x, 5, None, &ExchangeSettings::default()).unwrap();
    assert!(out.weights.iter().all(|&v| v == 1.0));
    assert_eq!((out.gap, out.rounds, out.steps), (0.0, 1, 0));
    assert!(out.converged);
    assert_eq!(out.ln_bound, out.ln_det);
    let (ld, _) = direct(&x, &[1.0; 5]);
    assert!((ld - out.ln_det).abs() < 1e-9 * (1.0 + ld.abs()));
}

/// Started at its own optimum, the solve stays there (both results
/// within `gap_tol` of the optimum: 2·1e-7) in no more rounds; one
/// round allowed is a round limit: the uniform start, no step, its gap
/// above `gap_tol` (uniform is not optimal on a random pool) and not
/// converged.
#[test]
fn warm_starts_and_round_limits() {
    let x = pool(30, 5);
    let s = ExchangeSettings::default();
    let cold = solve(&x, 5, None, &s).unwrap();
    let warm = solve(&x, 5, Some(&cold.weights), &s).unwrap();
    assert!(warm.converged);
    assert!(cold.steps > 0, "uniform is not optimal: steps were taken");
    // Each round of steps is counted: the start's evaluation and at
    // least one more.
    assert!(cold.rounds >= 2, "{} rounds", cold.rounds);
    assert!((warm.ln_det - cold.ln_det).abs() <= 2.0 * s.gap_tol);
    assert!(
        warm.rounds <= cold.rounds,
        "{} > {}",
        warm.rounds,
        cold.rounds
    );
    let one = ExchangeSettings::builder().max_rounds(1).build().unwrap();
    let out = solve(&x, 5, None, &one).unwrap();
    assert_eq!((out.rounds, out.steps, out.converged), (1, 0, false));
    assert!(out.gap > one.gap_tol);
    assert!(out.weights.iter().all(|&v| v == 5.0 / 30.0));
}

/// From a uniform start on a pool larger than `keep`, the capped
/// multiplicative warm-up and the pruning to the `keep` largest weights
/// (`keep` raised to `N`) still lead to the optimum: the same `ln det`
/// as without pruning, within both gaps (2·1e-7); with no warm-up
/// rounds too.
#[test]
fn pruning_after_the_warm_up_keeps_the_optimum() {
    let x = pool(40, 6);
    let s = ExchangeSettings::default();
    let reference = solve(&x, 4, None, &s).unwrap();
    for warmup_rounds in [30, 0] {
        let pruned = ExchangeSettings::builder()
            .keep(1)
            .warmup_rounds(warmup_rounds)
            .build()
            .unwrap();
        let out = solve(&x, 4, None, &pruned).unwrap();
        assert!(out.converged, "warm-up {warmup_rounds}");
        assert!(
            (out.ln_det - reference.ln_det).abs() <= 2.0 * s.gap_tol,
            "warm-up {warmup_rounds}: {} vs {}",
            out.ln_det,
            reference.ln_det
        );
    }
}

/// A start of the wrong length, or with a negative or non-finite
/// weight, is refused naming the figure.
#[test]
fn bad_starts_are_refused() {
    let x = pool(6, 7);
    let s = ExchangeSettings::default();
    for (w, says) in [
        (vec![0.5; 5], "5 weights for a pool of 6"),
        (vec![0.5, 0.5, -0.1, 0.5, 0.5, 0.5], "weight 2 is -0.1"),
        (vec![0.5, f64::NAN, 0.5, 0.5, 0.5, 0.5], "weight 1 is NaN"),
        (
            vec![0.5, 0.5, 0.5, f64::INFINITY, 0.5, 0.5],
            "weight 3 is inf",
        ),
    ] {
        match solve(&x, 3, Some(&w), &s) {
            Err(BoundError::InvalidWeights(m)) => assert!(m.contains(says), "{m}"),
            other => panic!("{w:?}: {other:?}"),
        }
    }
    assert!(check_start(&[0.0, 1.0, 2.0], 3).is_ok());
}

/// `prune` keeps the `k` largest weights and zeroes the rest (all of
/// them for `k` at least the length); `candidates` is the support plus
/// the `extra` poses outside it with the largest variances, ascending.
#[test]
fn pruning_and_candidates_pick_the_largest() {
    let w = [0.1, 0.5, 0.3, 0.9, 0.2];
    assert_eq!(prune(&w, 2), vec![0.0, 0.5, 0.0, 0.9, 0.0]);
    assert_eq!(prune(&w, 1), vec![0.0, 0.0, 0.0, 0.9, 0.0]);
    assert_eq!(prune(&w, 5), w.to_vec());
    assert_eq!(prune(&w, 7), w.to_vec());
    let w = [0.5, 0.0, 0.0, 1.0, 0.0, 0.0];
    let d = [1.0, 5.0, 2.0, 3.0, 4.0, 0.5];
    assert_eq!(candidates(&w, &d, 2), vec![0, 1, 3, 4]);
    assert_eq!(candidates(&w, &d, 1), vec![0, 1, 3]);
    assert_eq!(candidates(&w, &d, 0), vec![0, 3]);
    assert_eq!(candidates(&w, &d, 10), vec![0, 1, 2, 3, 4, 5]);
}

/// The multiplicative step caps the largest `w_i d_i` at 1 and shares
/// the rest of `N` in proportion to `w_i d_i` (here `w_0 d_0 = 5`
/// capped, the five others `0.5` each sharing 2: 0.4 each, to
/// rounding); with fewer than `N` poses carrying weight it refuses and
/// leaves `w`.
#[test]
fn the_multiplicative_step_shares_n_in_proportion() {
    let mut w = vec![0.5; 6];
    let d = [10.0, 1.0, 1.0, 1.0, 1.0, 1.0];
    assert!(multiplicative_step(&mut w, &d, 3));
    assert_eq!(w[0], 1.0);
    assert!(w[1..].iter().all(|&v| (v - 0.4).abs() < 1e-15), "{w:?}");
    let mut w = vec![0.5, 0.5, 0.0, 0.0];
    assert!(!multiplicative_step(&mut w, &[1.0; 4], 3));
    assert_eq!(w, vec![0.5, 0.5, 0.0, 0.0]);
    // A zero variance carries no weight either.
    let mut w = vec![0.5; 4];
    assert!(!multiplicative_step(&mut w, &[1.0, 1.0, 0.0, 0.0], 3));
}

/// The warm-up runs only from the uniform start on a pool larger than
/// `keep` (raised to `N` and `⌈p/t⌉`), one evaluation per
/// multiplicative step and one for the pruned weights: with the rounds
/// stopped at their first check (`max_rounds = 1`) the solve reports
/// `1 + warmup_rounds + 1` evaluations (no step fails from the uniform
/// start: every weight stays positive) and the `N` poses kept; a pool
/// of exactly `keep` poses gets neither (one evaluation, uniform).
#[test]
fn the_warm_up_runs_only_above_keep() {
    let x = pool(40, 8);
    for warmup_rounds in [0, 1, 3] {
        let s = ExchangeSettings::builder()
            .keep(1)
            .warmup_rounds(warmup_rounds)
            .max_rounds(1)
            .build()
            .unwrap();
        let out = solve(&x, 4, None, &s).unwrap();
        assert_eq!(out.rounds, warmup_rounds + 2, "warm-up {warmup_rounds}");
        // `make_feasible` may spread a rounding-size rest of `N` over
        // the pruned poses: 1e-9 tells them apart.
        let kept = out.weights.iter().filter(|&&v| v > 1e-9).count();
        assert_eq!(kept, 4, "warm-up {warmup_rounds}");
    }
    let s = ExchangeSettings::builder()
        .keep(40)
        .max_rounds(1)
        .build()
        .unwrap();
    let out = solve(&x, 4, None, &s).unwrap();
    assert_eq!(out.rounds, 1);
    assert!(out.weights.iter().all(|&v| v == 4.0 / 40.0));
}

/// Pruned weights whose `M` is singular are widened (`k` doubled, up to
/// the whole pool) until `M` is regular: only the last of 10 poses
/// informs the third parameter and, with no warm-up, the uniform
/// weights tie and the prune keeps the first `k` poses, so the prunes
/// to 2, 4 and 8 poses are singular and the whole pool is kept: one
/// evaluation for the start and one for the regular prune (the
/// singular ones are not counted), the weights uniform (`make_feasible`
/// rescales their sum: 1e-15).
#[test]
fn a_singular_prune_is_widened_to_a_regular_one() {
    let mut m = pool(10, 9).mat().to_owned();
    for r in 0..18 {
        m[(r, 2)] = 0.0;
    }
    let x = Blocks::new(m, 2);
    let s = ExchangeSettings::builder()
        .keep(1)
        .warmup_rounds(0)
        .max_rounds(1)
        .build()
        .unwrap();
    let out = solve(&x, 2, None, &s).unwrap();
    assert_eq!(out.rounds, 2);
    assert!(
        out.weights.iter().all(|&v| (v - 0.2).abs() < 1e-15),
        "{:?}",
        out.weights
    );
}

#[test]
fn line_search_finds_stationary_point() {
    // φ'(δ) = 1/(1+δ) − 1/(1−δ)·0.5 ... root where the derivative vanishes.
    let mu = [1.0, -0.5];
    let d = line_search(&mu, 1.0);
    let f: f64 = mu.iter().map(|m| m / (1.0 + d * m)).sum();
    assert!(f.abs() < 1e-12, "{d} {f}");
    assert_eq!(line_search(&[1.0, 0.5], 0.3), 0.3);
    assert_eq!(line_search(&[-1.0], 0.3), 0.0);
}

#[test]
fn multiplicative_step_respects_caps() {
    let mut w = vec![0.5; 6];
    let d = vec![10.0, 1.0, 1.0, 1.0, 1.0, 1.0];
    assert!(multiplicative_step(&mut w, &d, 3));
    assert_eq!(w[0], 1.0);
    assert!((w.iter().sum::<f64>() - 3.0).abs() < 1e-12);
    assert!(w.iter().all(|&v| (0.0..=1.0).contains(&v)));
}
