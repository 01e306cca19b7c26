//! The D-optimal relaxation bound: on 14-pose pools it bounds the exact
//! optimum found by enumerating every N-subset, the first-order solver and
//! Clarabel agree, and degenerate input gives an error or a status, never a
//! bound that is not one.

use activecal::blocks::Blocks;
use activecal::bound::conic::{self, ConicSettings, ConicStatus};
use activecal::bound::first_order::{self, ExchangeSettings};
use activecal::bound::gap::{WEIGHT_TOL, design_ln_det, weights_ln_det};
use activecal::bound::newton::NewtonSettings;
use activecal::bound::variance::{
    VarianceWork, certificate, information, make_feasible, scale_columns, top_sum, variances_into,
};
use activecal::bound::{
    BoundError, BoundSettings, BoundStatus, RelaxationSolver, design_gap, relaxation_bound,
};
use activecal::model::Robot;
use activecal::pool::Pool;
use faer::Mat;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// 14 PUMA poses (3-level lattice, every 52nd pose) and the first 12
/// unknowns, so that N = 5 poses (15 rows) can determine them.
fn puma_data() -> Blocks {
    let r = Robot::puma560();
    let pool = Pool::full(&r, 3).unwrap();
    let x = pool.jacobian(&r, &r.nominal);
    let poses: Vec<usize> = (0..14).map(|k| k * 52).collect();
    let sub = x.select(&poses);
    let cols = 12;
    Blocks::new(
        Mat::from_fn(sub.mat().nrows(), cols, |i, j| sub.mat()[(i, j)]),
        3,
    )
}

/// 14 random 3 × 10 blocks of different sizes.
fn random_data(poses: usize, seed: u64) -> Blocks {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (t, p) = (3, 10);
    let mut rows = Vec::with_capacity(poses * t * p);
    for i in 0..poses {
        let s = 0.5 + i as f64 / poses as f64;
        for _ in 0..t * p {
            rows.push(s * (rng.random::<f64>() - 0.5));
        }
    }
    Blocks::from_row_major(&rows, t, p)
}

/// The exact optimum of ln det over all N-subsets, and its subset.
fn enumerate(x: &Blocks, n: usize) -> (f64, Vec<usize>) {
    fn rec(x: &Blocks, n: usize, start: usize, cur: &mut Vec<usize>, best: &mut (f64, Vec<usize>)) {
        if cur.len() == n {
            if let Some(v) = design_ln_det(x, None, cur)
                && v > best.0
            {
                *best = (v, cur.clone());
            }
            return;
        }
        for i in start..x.n_poses() {
            if x.n_poses() - i < n - cur.len() {
                break;
            }
            cur.push(i);
            rec(x, n, i + 1, cur, best);
            cur.pop();
        }
    }
    let mut best = (f64::NEG_INFINITY, vec![]);
    rec(x, n, 0, &mut Vec::new(), &mut best);
    best
}

fn fixtures() -> Vec<(&'static str, Blocks)> {
    vec![("puma", puma_data()), ("random", random_data(14, 7))]
}

#[test]
fn small_pools_bound_the_enumerated_optimum_and_solvers_agree() {
    for (name, x) in fixtures() {
        for n in [5, 8] {
            let (best, _) = enumerate(&x, n);
            assert!(best.is_finite(), "{name} N={n}: some subset is nonsingular");

            let b = relaxation_bound(&x, None, n, &BoundSettings::default()).unwrap();
            assert_eq!(b.status, BoundStatus::Certified, "{name} N={n}");
            assert!(
                b.ln_bound >= best,
                "{name} N={n}: bound {} < optimum {best}",
                b.ln_bound
            );
            assert!(
                b.ln_primal >= best - 1e-9,
                "relaxation contains every design"
            );
            assert!(b.certificate_gap <= 1e-6 && b.certificate_gap >= 0.0);
            assert!(b.ln_bound >= b.ln_primal);
            let sum: f64 = b.weights.iter().sum();
            assert!((sum - n as f64).abs() < 1e-9);
            assert!(b.weights.iter().all(|&w| (0.0..=1.0).contains(&w)));
            let lp = weights_ln_det(&x, &b.weights).unwrap();
            assert!(
                (lp - b.ln_primal).abs() < 1e-9,
                "ln_primal is ln det M(weights)"
            );

            let fo_settings = ExchangeSettings::builder().gap_tol(1e-9).build().unwrap();
            let fo = first_order::solve(&x, n, None, &fo_settings).unwrap();
            assert!(fo.converged, "{name} N={n}: first-order gap {}", fo.gap);
            assert!(fo.ln_bound >= best);
            let co = conic::solve(&x, n, &ConicSettings::default()).unwrap();
            assert_eq!(co.status, ConicStatus::Solved, "{name} N={n}");
            let mut w = co.weights.clone();
            make_feasible(&mut w, n);
            let co_ln_det = weights_ln_det(&x, &w).unwrap();
            assert!(
                (fo.ln_det - co_ln_det).abs() <= 1e-6,
                "{name} N={n}: first-order {} vs Clarabel {co_ln_det}",
                fo.ln_det
            );
            assert!((fo.ln_det - co.ln_det_primal).abs() <= 1e-6);
        }
    }
}

#[test]
fn certificate_bounds_the_optimum_from_any_point() {
    let x = random_data(14, 3);
    let n = 5;
    let (best, _) = enumerate(&x, n);
    let sc = scale_columns(&x, n).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut work = VarianceWork::default();
    let mut scratch = Vec::new();
    for _ in 0..20 {
        // Arbitrary positive weights, not even summing to N: eq. (C) needs
        // only a positive definite M.
        let w: Vec<f64> = (0..14).map(|_| rng.random::<f64>() * 2.0).collect();
        let m = information(&sc.x, &w);
        let mut d = vec![0.0; 14];
        let (ld, _) = variances_into(&sc.x, m.as_ref(), &mut work, &mut d).unwrap();
        let c = certificate(ld, top_sum(&d, n, &mut scratch), x.p()) + sc.ln_scale;
        assert!(c >= best, "certificate {c} below the optimum {best}");
    }
}

#[test]
fn n_equal_to_pool_size_is_exact() {
    let x = random_data(14, 5);
    let b = relaxation_bound(&x, None, 14, &BoundSettings::default()).unwrap();
    assert_eq!(b.status, BoundStatus::Exact);
    let all: Vec<usize> = (0..14).collect();
    let exact = design_ln_det(&x, None, &all).unwrap();
    assert!((b.ln_bound - exact).abs() < 1e-9);
    assert_eq!(b.certificate_gap, 0.0);
    assert!(b.weights.iter().all(|&w| w == 1.0));
}

#[test]
fn bad_input_is_an_error() {
    let x = random_data(14, 5);
    let s = BoundSettings::default();
    assert!(matches!(
        relaxation_bound(&x, None, 15, &s),
        Err(BoundError::TooManyPoses { n: 15, pool: 14 })
    ));
    // 3 poses · 3 rows < 10 unknowns: every design singular.
    let e = relaxation_bound(&x, None, 3, &s).unwrap_err();
    assert!(matches!(e, BoundError::TooFewRows { need: 4, .. }), "{e}");
    assert!(e.to_string().contains("singular"));
    // A repeated column: rank deficient.
    let m = x.mat();
    let dup = Blocks::new(
        Mat::from_fn(m.nrows(), 10, |i, j| m[(i, if j == 9 { 0 } else { j })]),
        3,
    );
    assert!(matches!(
        relaxation_bound(&dup, None, 8, &s),
        Err(BoundError::RankDeficient { rank: 9, p: 10, .. })
    ));
    let zero = Blocks::new(
        Mat::from_fn(m.nrows(), 10, |i, j| if j == 4 { 0.0 } else { m[(i, j)] }),
        3,
    );
    assert!(matches!(
        relaxation_bound(&zero, None, 8, &s),
        Err(BoundError::RankDeficient { .. })
    ));
    let nan = Blocks::new(
        Mat::from_fn(m.nrows(), 10, |i, j| {
            if (i, j) == (7, 2) {
                f64::NAN
            } else {
                m[(i, j)]
            }
        }),
        3,
    );
    assert!(matches!(
        relaxation_bound(&nan, None, 8, &s),
        Err(BoundError::NonFinite { row: 7, col: 2, .. })
    ));
    assert!(matches!(
        BoundSettings::builder().gap_tol(0.0).build(),
        Err(BoundError::InvalidSetting {
            name: "gap_tol",
            ..
        })
    ));
    assert!(matches!(
        first_order::solve(&x, 8, Some(&[1.0; 3]), &ExchangeSettings::default()),
        Err(BoundError::InvalidWeights(_))
    ));
}

#[test]
fn a_stalled_solver_still_gives_a_valid_bound() {
    let x = random_data(14, 9);
    let n = 8;
    let (best, _) = enumerate(&x, n);
    let s = BoundSettings::builder()
        .polish(false)
        .solver(RelaxationSolver::Clarabel)
        .first_order(
            ExchangeSettings::builder()
                .max_rounds(1)
                .warmup_rounds(0)
                .build()
                .unwrap(),
        )
        .conic(
            ConicSettings::builder()
                .max_iter(2)
                .retry_without_equilibration(false)
                .build()
                .unwrap(),
        )
        .build()
        .unwrap();
    let b = relaxation_bound(&x, None, n, &s).unwrap();
    assert_eq!(b.status, BoundStatus::GapAboveTolerance);
    assert_eq!(b.conic.status, Some(ConicStatus::MaxIterations));
    assert!(b.certificate_gap > s.gap_tol);
    assert!(
        b.ln_bound >= best,
        "still a bound: {} vs {best}",
        b.ln_bound
    );
    assert!(b.ln_primal <= b.ln_bound);
}

#[test]
fn active_box_constraints_are_respected() {
    // N close to the pool size: several weights sit at their upper bound 1.
    let x = random_data(40, 21);
    let n = 30;
    let b = relaxation_bound(&x, None, n, &BoundSettings::default()).unwrap();
    assert_eq!(b.status, BoundStatus::Certified);
    let full = b.weights.iter().filter(|&&w| w > 1.0 - 1e-6).count();
    assert!(full >= 10, "{full} weights at 1");
    let fo = first_order::solve(
        &x,
        n,
        None,
        &ExchangeSettings::builder().gap_tol(1e-9).build().unwrap(),
    )
    .unwrap();
    assert!((fo.ln_det - b.ln_primal).abs() <= 1e-6);
    assert!(fo.ln_det <= b.ln_bound && b.ln_primal <= fo.ln_bound);
}

#[test]
fn screening_reaches_the_same_optimum_as_the_whole_pool() {
    // 400 random poses, N = 12: Clarabel on screened candidates (forced by
    // direct_limit = 0) against Clarabel and the first-order solver on the
    // whole pool.
    let x = random_data(400, 17);
    let n = 12;
    let s = BoundSettings::builder()
        .direct_limit(0)
        .screen_extra(20)
        .build()
        .unwrap();
    let b = relaxation_bound(&x, None, n, &s).unwrap();
    assert_eq!(b.status, BoundStatus::Certified, "{:?}", b.conic);
    assert!(
        b.conic.candidates < 400,
        "{} candidates",
        b.conic.candidates
    );
    let whole = conic::solve(&x, n, &ConicSettings::default()).unwrap();
    let mut w = whole.weights.clone();
    make_feasible(&mut w, n);
    let whole_ln_det = weights_ln_det(&x, &w).unwrap();
    assert!((whole_ln_det - b.ln_primal).abs() <= 1e-6);
    assert!(b.ln_bound >= whole_ln_det);
    let fo = first_order::solve(
        &x,
        n,
        None,
        &ExchangeSettings::builder().gap_tol(1e-8).build().unwrap(),
    )
    .unwrap();
    assert!(fo.converged, "first-order gap {}", fo.gap);
    assert!((fo.ln_det - b.ln_primal).abs() <= 1e-6);
    assert!(b.ln_bound >= fo.ln_det && fo.ln_bound >= b.ln_primal);
}

#[test]
fn design_gap_reports_d_efficiency() {
    let x = random_data(14, 13);
    let n = 6;
    let (best, design) = enumerate(&x, n);
    let b = relaxation_bound(&x, None, n, &BoundSettings::default()).unwrap();
    let g = design_gap(&x, None, &design, &b).unwrap();
    assert!((g.ln_oid.unwrap() - best).abs() < 1e-9);
    let eff = ((best - b.ln_bound) / x.p() as f64).exp();
    assert!((g.d_efficiency - eff).abs() < 1e-12);
    assert!(g.d_efficiency > 0.0 && g.d_efficiency <= 1.0);
    assert!((g.log10_bound - b.ln_bound / std::f64::consts::LN_10).abs() < 1e-12);
    assert!((g.log10_oid.unwrap() - best / std::f64::consts::LN_10).abs() < 1e-9);
    for (k, &i) in design.iter().enumerate() {
        assert_eq!(g.weights[k], b.weights[i]);
        assert_eq!(g.weighted.contains(&k), b.weights[i] > WEIGHT_TOL);
    }
    assert!(matches!(
        design_gap(&x, None, &design[..n - 1], &b),
        Err(BoundError::InvalidDesign(_))
    ));
    let mut dup = design.clone();
    dup[1] = dup[0];
    assert!(design_gap(&x, None, &dup, &b).is_err());
    // A Jacobian of another pool: the same size with fewer unknowns, or the
    // same unknowns with more poses (each mismatch alone is refused).
    let fewer_columns = Blocks::new(
        Mat::from_fn(x.mat().nrows(), x.p() - 1, |i, j| x.mat()[(i, j)]),
        x.t(),
    );
    assert!(matches!(
        design_gap(&fewer_columns, None, &design, &b),
        Err(BoundError::InvalidDesign(m)) if m.contains("unknowns")
    ));
    let more_poses = random_data(15, 13);
    assert_eq!(more_poses.p(), x.p());
    assert!(matches!(
        design_gap(&more_poses, None, &design, &b),
        Err(BoundError::InvalidDesign(m)) if m.contains("pool of 14 poses")
    ));
}

#[test]
fn settings_round_trip_through_json() {
    let s = BoundSettings::builder()
        .gap_tol(1e-8)
        .screen_extra(123)
        .build()
        .unwrap();
    let text = serde_json::to_string(&s).unwrap();
    let back: BoundSettings = serde_json::from_str(&text).unwrap();
    assert_eq!(s, back);
    // Missing keys take their defaults.
    let partial: BoundSettings = serde_json::from_str(r#"{"gap_tol": 1e-5}"#).unwrap();
    assert_eq!(partial.screen_extra, BoundSettings::default().screen_extra);
}

// ---- the Newton barrier solver ------------------------------------------------

fn newton_settings() -> BoundSettings {
    BoundSettings::builder()
        .solver(RelaxationSolver::Newton)
        .build()
        .unwrap()
}

/// The Newton solver reaches Clarabel's optimum — on the 14-pose pools
/// (where enumeration gives the true discrete optimum below both), with box
/// constraints active, and through screening — and its bound is certified
/// like Clarabel's. 1e-7 in ln det: both are certified to 1e-6, and their
/// primal values sit within the smaller of their gaps of the true optimum.
#[test]
fn newton_solver_agrees_with_clarabel() {
    let mut cases: Vec<(String, Blocks, usize, BoundSettings)> = Vec::new();
    for (name, x) in fixtures() {
        for n in [5, 8] {
            cases.push((format!("{name} N={n}"), x.clone(), n, newton_settings()));
        }
    }
    cases.push((
        "box N=30".into(),
        random_data(40, 21),
        30,
        newton_settings(),
    ));
    let screened = BoundSettings::builder()
        .solver(RelaxationSolver::Newton)
        .direct_limit(0)
        .screen_extra(20)
        .build()
        .unwrap();
    cases.push(("screened N=12".into(), random_data(400, 17), 12, screened));
    for (name, x, n, s) in cases {
        let nb = relaxation_bound(&x, None, n, &s).unwrap();
        let mut cs = s.clone();
        cs.solver = RelaxationSolver::Clarabel;
        let cb = relaxation_bound(&x, None, n, &cs).unwrap();
        println!(
            "{name}: newton {:.10} (gap {:.1e}, {} steps) clarabel {:.10} (gap {:.1e})",
            nb.ln_primal,
            nb.certificate_gap,
            nb.conic.total_iterations,
            cb.ln_primal,
            cb.certificate_gap
        );
        assert_eq!(nb.status, BoundStatus::Certified, "{name}: {:?}", nb.conic);
        assert_eq!(nb.conic.solver, RelaxationSolver::Newton);
        if x.n_poses() <= 14 {
            let (best, _) = enumerate(&x, n);
            assert!(nb.ln_bound >= best, "{name}");
        }
        assert!((nb.ln_primal - cb.ln_primal).abs() < 1e-7, "{name}");
        assert!(
            nb.ln_bound >= cb.ln_primal && cb.ln_bound >= nb.ln_primal,
            "{name}"
        );
        let sum: f64 = nb.weights.iter().sum();
        assert!((sum - n as f64).abs() < 1e-9, "{name}");
        assert!(nb.weights.iter().all(|&w| (0.0..=1.0).contains(&w)));
        let lp = weights_ln_det(&x, &nb.weights).unwrap();
        assert!((lp - nb.ln_primal).abs() < 1e-9, "{name}");
    }
}

/// A Newton solve cut short still leaves a valid bound, flagged.
#[test]
fn a_stalled_newton_solve_still_gives_a_valid_bound() {
    let x = random_data(14, 9);
    let n = 8;
    let (best, _) = enumerate(&x, n);
    let s = BoundSettings::builder()
        .solver(RelaxationSolver::Newton)
        .polish(false)
        .first_order(
            ExchangeSettings::builder()
                .max_rounds(1)
                .warmup_rounds(0)
                .build()
                .unwrap(),
        )
        .newton(NewtonSettings::builder().max_steps(1).build().unwrap())
        .build()
        .unwrap();
    let b = relaxation_bound(&x, None, n, &s).unwrap();
    assert_eq!(b.status, BoundStatus::GapAboveTolerance);
    assert_eq!(b.conic.status, Some(ConicStatus::MaxIterations));
    assert!(
        b.ln_bound >= best,
        "still a bound: {} vs {best}",
        b.ln_bound
    );
    assert!(b.ln_primal <= b.ln_bound);
    // Invalid Newton settings are refused by their builder, and by the
    // bound's when set field by field.
    let with = |f: fn(&mut NewtonSettings)| {
        let mut s = NewtonSettings::default();
        f(&mut s);
        s
    };
    for bad in [
        with(|s| s.tol = 0.0),
        with(|s| s.mu_factor = 1.0),
        with(|s| s.max_steps = 0),
    ] {
        let e = bad.clone().into_builder().build().unwrap_err();
        assert!(e.to_string().contains("newton."), "{e}");
        let e = BoundSettings::builder().newton(bad).build().unwrap_err();
        assert!(e.to_string().contains("newton."), "{e}");
    }
    assert!(serde_json::from_str::<RelaxationSolver>("\"gurobi\"").is_err());
    use activecal::names::Choice;
    assert!(RelaxationSolver::from_name("gurobi").is_none());
    assert_eq!(
        RelaxationSolver::from_name("newton"),
        Some(RelaxationSolver::Newton)
    );
    // The names offered on the command line are the serialised ones.
    for s in RelaxationSolver::ALL {
        let json = serde_json::to_string(s).unwrap();
        assert_eq!(json, format!("\"{}\"", s.name()));
    }
}
