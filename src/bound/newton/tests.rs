//! The Newton solve's parts against direct evaluations, and its result
//! against the optimality certificate (eq. C) on small random pools.
use super::*;
use crate::blocks::Blocks;
use crate::bound::variance::{VarianceWork, certificate, scale_columns, top_sum, variances_into};
use crate::linalg::test_rng::lcg;

/// `n` random 2 × 3 blocks, column-scaled for designs of `n_design`.
fn scaled(n: usize, n_design: usize, seed: u64) -> Scaled {
    let mut s = seed;
    let x = Blocks::new(Mat::from_fn(2 * n, 3, |_, _| lcg(&mut s)), 2);
    scale_columns(&x, n_design).expect("a random pool has full rank")
}

/// An interior point of `Σ w = N`: uniform, perturbed by ±20 %.
/// At `w`: the second derivatives `Q` (lower triangle), the gradient `d`,
/// and the Newton direction and decrement for barrier weight `mu`.
fn newton_step(sc: &Scaled, w: &[f64], mu: f64) -> (Mat<f64>, Vec<f64>, Vec<f64>, f64) {
    let n = w.len();
    let mut q = Mat::zeros(n, n);
    let mut d = vec![0.0; n];
    derivatives(sc, w, &mut q, &mut d).unwrap();
    let ones = Mat::from_fn(n, 1, |_, _| 1.0);
    let (delta, lambda2) = newton_direction(&q, &d, w, mu, &ones).unwrap();
    (q, d, delta, lambda2)
}

fn interior(n: usize, nf: f64, seed: u64) -> Vec<f64> {
    let mut s = seed;
    let mut w: Vec<f64> = (0..n).map(|_| 1.0 + 0.2 * lcg(&mut s)).collect();
    let sum: f64 = w.iter().sum();
    w.iter_mut().for_each(|v| *v *= nf / sum);
    w
}

#[test]
fn settings_out_of_range_are_refused() {
    assert!(NewtonSettings::default().validate().is_ok());
    let with = |f: fn(&mut NewtonSettings)| {
        let mut s = NewtonSettings::default();
        f(&mut s);
        s.validate()
    };
    assert!(with(|s| s.tol = 0.0).is_err());
    assert!(with(|s| s.tol = f64::NAN).is_err());
    assert!(with(|s| s.mu_factor = 1.0).is_err());
    assert!(with(|s| s.mu_factor = f64::NAN).is_err());
    assert!(with(|s| s.mu_factor = 1.5).is_ok());
    assert!(with(|s| s.max_steps = 0).is_err());
    assert!(with(|s| s.max_steps = 1).is_ok());
}

/// `d_i = tr A_i` and `Q_ij = tr(A_i A_j)` for `A_i = Y_iᵀY_i`, each
/// formed here from its definition; `ln det M(w)` and `d_i = tr(X_i
/// M⁻¹ X_iᵀ)` from an independent inverse. O(1) entries, sums of a few
/// dozen products: 1e-12 relative is rounding.
#[test]
fn derivatives_are_the_traces_of_their_definition() {
    let (n, t, p) = (7, 2, 3);
    let sc = scaled(n, 3, 4);
    let w = interior(n, 3.0, 5);
    let mut q = Mat::zeros(n, n);
    let mut d = vec![0.0; n];
    let ld = derivatives(&sc, &w, &mut q, &mut d).expect("positive definite");
    let mut dv = vec![0.0; n];
    let m = sc.information(&w);
    let (ld2, m_inv) =
        variances_into(&sc.x, m.as_ref(), &mut VarianceWork::default(), &mut dv).unwrap();
    assert!((ld - ld2).abs() < 1e-12 * ld2.abs().max(1.0));
    let x = sc.x.mat();
    // A_i in the metric of M: tr(A_i A_j) = tr(X_iᵀX_i M⁻¹ X_jᵀX_j M⁻¹).
    let a: Vec<Mat<f64>> = (0..n)
        .map(|i| {
            let xi = x.subrows(i * t, t);
            xi.transpose() * xi * &m_inv
        })
        .collect();
    for i in 0..n {
        let tr: f64 = (0..p).map(|k| a[i][(k, k)]).sum();
        assert!((d[i] - tr).abs() < 1e-12 * tr, "d[{i}]");
        assert!((d[i] - dv[i]).abs() < 1e-12 * tr, "d[{i}] vs variances");
        for j in 0..=i {
            let prod = &a[i] * &a[j];
            let qij: f64 = (0..p).map(|k| prod[(k, k)]).sum();
            assert!(
                (q[(i, j)] - qij).abs() < 1e-12 * qij.abs().max(1.0),
                "Q[{i},{j}]"
            );
        }
    }
    // No weight at all: M = 0 is not positive definite.
    assert!(derivatives(&sc, &vec![0.0; n], &mut q, &mut d).is_none());
}

/// Every start is strictly inside `(0, 1)` with `Σ w = N` (to rounding:
/// 1e-12 relative), uniform without a usable warm point, and follows a
/// feasible warm point (its largest weight stays the largest). A warm
/// point that needs capping at 1 (case 2: clamped weights 1, 1, 0.5, 1
/// summing to 3.5 < N = 4) keeps its shape: the 0.5 is scaled up to the
/// cap too, so its four poses get `0.9 + 0.1·N/n` and the others
/// `0.1·N/n` (a few roundings of O(1) numbers: 1e-12).
#[test]
fn interior_starts_are_interior_and_follow_the_warm_point() {
    let (n, nf) = (10, 4.0);
    let mut warm = vec![0.0; n];
    warm[2] = 1.0;
    warm[5] = 1.0;
    warm[7] = 0.5;
    warm[8] = 1.5;
    let feasible = [0.9, 0.1, 0.3, 0.4, 0.2, 0.5, 0.6, 0.3, 0.4, 0.3];
    let cases: [Option<&[f64]>; 5] = [
        None,
        Some(&warm[..4]),
        Some(&warm),
        Some(&[0.0; 10]),
        Some(&feasible),
    ];
    for (k, c) in cases.iter().enumerate() {
        let w = interior_start(*c, n, nf);
        assert_eq!(w.len(), n);
        assert!(w.iter().all(|&v| v > 0.0 && v < 1.0), "case {k}: {w:?}");
        let s: f64 = w.iter().sum();
        assert!((s - nf).abs() < 1e-12 * nf, "case {k}: Σ w = {s}");
        if k == 2 {
            for (i, &v) in w.iter().enumerate() {
                let p = if [2, 5, 7, 8].contains(&i) { 1.0 } else { 0.0 };
                let want = 0.9 * p + 0.1 * nf / n as f64;
                assert!((v - want).abs() < 1e-12, "case 2, w[{i}] = {v}");
            }
        } else if k < 4 {
            assert!(w.iter().all(|&v| v == nf / n as f64), "case {k}: {w:?}");
        }
    }
    let w = interior_start(Some(&feasible), n, nf);
    let top = (0..n).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap();
    assert_eq!(top, 0, "{w:?}");
}

/// A warm point whose rescaling to `Σ w = N` passes 1 (issue #30: it was
/// dropped for the uniform start) keeps its shape: the weight above 1 is
/// capped, the others scaled by the `c` that makes the sum `N` (here
/// clamped `1, 0.7, 0.4, 0.2, 0.2` for `N = 3`: `c = 2/1.5`), keeping
/// their ratios, then blended 9:1 with uniform. A warm point with fewer
/// than `N` poses of weight cannot carry `N` under the caps: uniform. A
/// few roundings of O(1) numbers: 1e-12.
#[test]
fn a_warm_point_with_capped_weights_keeps_its_shape() {
    let (n, nf) = (8, 3.0);
    let uniform = nf / n as f64;
    let warm = [2.0, 0.7, 0.4, 0.2, 0.2, 0.0, 0.0, 0.0];
    let c = 2.0 / 1.5;
    let w = interior_start(Some(&warm), n, nf);
    for i in 0..n {
        let p = if i == 0 { 1.0 } else { c * warm[i] };
        let want = 0.9 * p + 0.1 * uniform;
        assert!((w[i] - want).abs() < 1e-12, "w[{i}] = {} vs {want}", w[i]);
    }
    let s: f64 = w.iter().sum();
    assert!((s - nf).abs() < 1e-12 * nf, "Σ w = {s}");
    let thin = [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    assert_eq!(capped_to_sum(&thin, nf), None);
    let w = interior_start(Some(&thin), n, nf);
    assert!(w.iter().all(|&v| v == uniform), "{w:?}");
    // Entries that already sum to N are kept as they are (`c = 1`).
    let exact = [1.0, 0.5, 0.5, 0.5, 0.25, 0.25, 0.0, 0.0];
    let p = capped_to_sum(&exact, nf).expect("Σ = N");
    assert!(
        p.iter().zip(&exact).all(|(a, b)| (a - b).abs() < 1e-15),
        "{p:?}"
    );
}

/// The direction keeps `Σ w` (`1ᵀΔ = 0`), solves `KΔ = g − ν1` (the
/// residual `KΔ − g` is one constant), and its decrement `λ² = gᵀΔ`
/// equals `ΔᵀKΔ > 0`, with `K` and `g` formed here from `Q`, `d`, `μ`.
/// Entries O(1)–O(10²): 1e-9 relative covers the two solves' rounding.
#[test]
fn the_newton_direction_solves_its_system() {
    let n = 8;
    let sc = scaled(n, 3, 6);
    let w = interior(n, 3.0, 7);
    let mu = 0.05;
    let (q, d, delta, lambda2) = newton_step(&sc, &w, mu);
    let k = Mat::from_fn(n, n, |i, j| {
        let qij = if i >= j { q[(i, j)] } else { q[(j, i)] };
        let b = 1.0 - w[i];
        qij + if i == j {
            mu * (1.0 / (w[i] * w[i]) + 1.0 / (b * b))
        } else {
            0.0
        }
    });
    let g: Vec<f64> = (0..n)
        .map(|i| d[i] + mu * (1.0 / w[i] - 1.0 / (1.0 - w[i])))
        .collect();
    let sum: f64 = delta.iter().sum();
    let scale = delta.iter().map(|v| v.abs()).sum::<f64>();
    assert!(sum.abs() < 1e-9 * scale, "1ᵀΔ = {sum}");
    let r: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| k[(i, j)] * delta[j]).sum::<f64>() - g[i])
        .collect();
    let gmax = g.iter().map(|v| v.abs()).fold(0.0, f64::max);
    assert!(r.iter().all(|&v| (v - r[0]).abs() < 1e-9 * gmax), "{r:?}");
    let dkd: f64 = (0..n)
        .map(|i| delta[i] * (0..n).map(|j| k[(i, j)] * delta[j]).sum::<f64>())
        .sum();
    assert!(
        lambda2 > 0.0 && (lambda2 - dkd).abs() < 1e-9 * dkd,
        "{lambda2} vs {dkd}"
    );
    let gd: f64 = (0..n).map(|i| g[i] * delta[i]).sum();
    assert!((lambda2 - gd).abs() < 1e-12 * gd.abs());
}

/// `F_μ` is `ln det M(w) + μ Σ ln w_i(1 − w_i)` inside `(0, 1)` and
/// undefined on or outside its boundary; the line search returns an
/// interior point where `F_μ` rose by at least a quarter of the
/// decrement's prediction for the step taken.
#[test]
fn the_line_search_ascends_inside_the_box() {
    let n = 8;
    let sc = scaled(n, 3, 8);
    let w = interior(n, 3.0, 9);
    let mu = 0.05;
    let ld = ln_det_spd(sc.information(&w).as_ref()).unwrap();
    let f0 = barrier_value(&sc, &w, mu).unwrap();
    let direct = ld + mu * w.iter().map(|&v| (v * (1.0 - v)).ln()).sum::<f64>();
    assert!((f0 - direct).abs() < 1e-12 * direct.abs().max(1.0));
    let mut edge = w.clone();
    edge[0] = 0.0;
    assert!(barrier_value(&sc, &edge, mu).is_none());
    edge[0] = 1.0;
    assert!(barrier_value(&sc, &edge, mu).is_none());
    let (_, _, delta, lambda2) = newton_step(&sc, &w, mu);
    let t = line_search(&sc, &w, &delta, lambda2, mu, ld).expect("an ascent direction");
    assert!(t.iter().all(|&v| v > 0.0 && v < 1.0));
    let s: f64 = t.iter().sum();
    assert!((s - 3.0).abs() < 1e-12 * 3.0);
    let f1 = barrier_value(&sc, &t, mu).unwrap();
    // The accepted step s·Δ with s ≤ 1 satisfies Armijo with s: the
    // rise is at least 0.25·s·λ², s = |t − w|/|Δ|.
    let step = (t[0] - w[0]) / delta[0];
    assert!(step > 0.0 && step <= 1.0 + 1e-12, "step {step}");
    assert!(
        f1 >= f0 + 0.25 * step * lambda2 - 1e-12,
        "{f1} < {f0} + ¼·{step}·{lambda2}"
    );
}

/// The solve reaches the optimum of (R): at its weights the certificate
/// `ln det M + p ln(S_N/p)` (eq. C, an upper bound on the optimum from
/// any point) is within 1e-7 of `ln det M` itself, so `ln det M` is
/// within 1e-7 of optimal (the barrier stops at `2nμ ≤ 1e-10`; the
/// certificate's gap at such a point is of order √(2nμ)·p ≈ 1e-5 at
/// worst, measured ~1e-9 here). Weights in `(0, 1)`, `Σ w = N`, the
/// primal value `ln det M(w)` unscaled, the dual value `2nμ ≤ tol`
/// above it.
#[test]
fn the_solve_reaches_the_certified_optimum() {
    for (n, n_design, seed) in [(12, 4, 10), (20, 3, 11), (9, 6, 12)] {
        let sc = scaled(n, n_design, seed);
        let settings = NewtonSettings::default();
        // Barrier bounds 0.5, 5e-3, …, 5e-11: the last is the first ≤
        // tol, and above tol/mu_factor.
        let out = solve_scaled(&sc, n_design, None, &settings, 0.5);
        assert_eq!(out.status, ConicStatus::Solved, "n = {n}");
        assert!(out.iterations >= 1);
        let w = &out.weights;
        assert!(w.iter().all(|&v| v > 0.0 && v < 1.0));
        let s: f64 = w.iter().sum();
        assert!((s - n_design as f64).abs() < 1e-9, "Σ w = {s}");
        let m = sc.information(w);
        let mut d = vec![0.0; n];
        let (ld, _) =
            variances_into(&sc.x, m.as_ref(), &mut VarianceWork::default(), &mut d).unwrap();
        let s_n = top_sum(&d, n_design, &mut Vec::new());
        let gap = certificate(ld, s_n, 3) - ld;
        assert!((0.0..1e-7).contains(&gap), "n = {n}: gap {gap}");
        assert!((out.ln_det_primal - (ld + sc.ln_scale)).abs() < 1e-10 * ld.abs().max(1.0));
        let dual_gap = out.ln_det_dual - out.ln_det_primal;
        // 2nμ ≤ tol, read as a difference of two values O(10): 1e-14
        // of rounding.
        assert!(
            (settings.tol / settings.mu_factor..=settings.tol + 1e-14).contains(&dual_gap),
            "{dual_gap}"
        );
        // Warm-started from the optimum, the same point in fewer steps.
        let again = solve_scaled(&sc, n_design, Some(w), &settings, 1e-6);
        assert!((again.ln_det_primal - out.ln_det_primal).abs() < 1e-7);
        assert!(
            again.iterations <= out.iterations,
            "{} > {}",
            again.iterations,
            out.iterations
        );
    }
}

/// `N` at least the pool: every weight 1, solved in no step, both values
/// `ln det` of the whole pool; a pool whose information is singular
/// (a zero column: a zero pivot) is a numerical error, never a value; one step
/// allowed is a step limit, not a solve.
#[test]
fn the_edge_cases_have_their_status() {
    let sc = scaled(5, 5, 13);
    let out = solve_scaled(&sc, 5, None, &NewtonSettings::default(), 1.0);
    assert_eq!((out.status, out.iterations), (ConicStatus::Solved, 0));
    assert!(out.weights.iter().all(|&v| v == 1.0));
    let ld = ln_det_spd(sc.information(&[1.0; 5]).as_ref()).unwrap() + sc.ln_scale;
    assert_eq!((out.ln_det_primal, out.ln_det_dual), (ld, ld));

    let mut flat = sc.x.mat().to_owned();
    flat.col_mut(1).fill(0.0);
    let bad = Scaled {
        x: Blocks::new(flat, 2),
        s: sc.s.clone(),
        ln_scale: 0.0,
        m0: None,
    };
    for n_design in [2, 5] {
        let out = solve_scaled(&bad, n_design, None, &NewtonSettings::default(), 1.0);
        assert_eq!(out.status, ConicStatus::NumericalError, "N = {n_design}");
        assert!(out.ln_det_primal.is_nan());
    }

    let sc = scaled(12, 4, 14);
    let one = NewtonSettings::builder().max_steps(1).build().unwrap();
    let out = solve_scaled(&sc, 4, None, &one, 1.0);
    assert_eq!(
        (out.status, out.iterations),
        (ConicStatus::MaxIterations, 1)
    );
}

/// The first trial of the line search is the step at 0.99 of the way to
/// the nearest bound (the full step if that is nearer): asked for no
/// rise (`λ² = −∞`), it returns that point. Two directions, one stopped
/// by a weight falling to 0 (w₀ at s = 0.5), one by a weight rising to
/// 1 (w₄ at s = 0.4; no halving of another bound's step lands there);
/// `s_max` recomputed here. One rounding an entry: 1e-15.
#[test]
fn the_first_trial_stops_short_of_the_nearest_bound() {
    let n = 6;
    let sc = scaled(n, 3, 15);
    let w = [0.3, 0.6, 0.5, 0.4, 0.76, 0.5];
    let ld = ln_det_spd(sc.information(&w).as_ref()).unwrap();
    for (delta, nearest) in [
        ([-0.6, 0.2, 0.1, 0.1, 0.1, 0.1], 0.99 * 0.5),
        ([0.1, 0.1, -0.2, -0.1, 0.6, -0.5], 0.99 * 0.4),
    ] {
        let mut s_max = 1.0f64;
        for i in 0..n {
            let room = if delta[i] < 0.0 {
                w[i] / -delta[i]
            } else {
                (1.0 - w[i]) / delta[i]
            };
            s_max = s_max.min(0.99 * room);
        }
        assert!((s_max - nearest).abs() < 1e-15, "{s_max}");
        let t = line_search(&sc, &w, &delta, f64::NEG_INFINITY, 0.1, ld).expect("interior");
        for i in 0..n {
            let want = w[i] + s_max * delta[i];
            assert!(
                (t[i] - want).abs() < 1e-15,
                "{delta:?}: w[{i}] {} vs {want}",
                t[i]
            );
        }
    }
}

/// A step is accepted only where `F_μ` rose by a quarter of `λ²·s`:
/// asked for four times the decrement of a short Newton step (a tenth
/// of it, so that the full step is interior), no trial rises enough at
/// all (`F_μ` is concave: the rise is at most the first-order `s·c·λ²`,
/// the ask `s·c·λ²`), so any point returned (only at a rounding-size
/// step) meets the ask.
#[test]
fn a_step_short_of_the_armijo_rise_is_refused() {
    let n = 8;
    let sc = scaled(n, 3, 16);
    let w = interior(n, 3.0, 17);
    let mu = 0.05;
    let ld = ln_det_spd(sc.information(&w).as_ref()).unwrap();
    let (_, _, delta, lambda2) = newton_step(&sc, &w, mu);
    let short: Vec<f64> = delta.iter().map(|v| 0.1 * v).collect();
    let ask = 4.0 * 0.1 * lambda2;
    let f0 = barrier_value(&sc, &w, mu).unwrap();
    if let Some(t) = line_search(&sc, &w, &short, ask, mu, ld) {
        let s = (t[0] - w[0]) / short[0];
        let f1 = barrier_value(&sc, &t, mu).unwrap();
        assert!(
            f1 >= f0 + 0.25 * s * ask,
            "accepted at s = {s}: {f1} < {f0} + ¼·s·{ask}"
        );
    }
}

/// A first trial that does not rise enough is halved until one does: asked
/// for three times the decrement along the Newton direction (on the
/// quadratic model the rise `s·λ² − s²λ²/2` meets `¼·s·3λ²` only for
/// `s ≤ ½`), the first trial falls short of Armijo (checked here), and the
/// point returned lies at `s_max·2⁻ᵏ`, `k ≥ 1`, and meets the rule. The step is read back from the largest
/// component of the direction: `log₂` within 1e-9 of an integer (a few
/// roundings of an O(1) ratio).
#[test]
fn a_step_too_long_is_halved_until_it_rises() {
    let n = 8;
    let sc = scaled(n, 3, 18);
    let w = interior(n, 3.0, 19);
    let mu = 0.05;
    let ld = ln_det_spd(sc.information(&w).as_ref()).unwrap();
    let (_, _, delta, lambda2) = newton_step(&sc, &w, mu);
    let long = delta;
    let ask = 3.0 * lambda2;
    let mut s_max = 1.0f64;
    for i in 0..n {
        let room = if long[i] < 0.0 {
            w[i] / -long[i]
        } else {
            (1.0 - w[i]) / long[i]
        };
        s_max = s_max.min(0.99 * room);
    }
    let f0 = barrier_value(&sc, &w, mu).unwrap();
    let first: Vec<f64> = (0..n).map(|i| w[i] + s_max * long[i]).collect();
    let f_first = barrier_value(&sc, &first, mu).unwrap();
    assert!(
        f_first < f0 + 0.25 * s_max * ask,
        "the first trial rises enough"
    );
    let t = line_search(&sc, &w, &long, ask, mu, ld).expect("a shorter step rises");
    let k = (0..n)
        .max_by(|&a, &b| long[a].abs().total_cmp(&long[b].abs()))
        .unwrap();
    let s = (t[k] - w[k]) / long[k];
    let halvings = (s_max / s).log2();
    assert!(
        halvings > 0.5 && (halvings - halvings.round()).abs() < 1e-9,
        "s = {s}, s_max = {s_max}"
    );
    let f1 = barrier_value(&sc, &t, mu).unwrap();
    assert!(f1 >= f0 + 0.25 * s * ask, "{f1} < {f0} + ¼·{s}·{ask}");
}

/// The barrier weight starts where its bound `2nμ` is the gap known so
/// far (`gap_hint`): after one step the dual value is the primal plus
/// `gap_hint`, or a `mu_factor`-th of it if that step found the point
/// centred. Two values O(10) subtracted: 1e-12 relative to the hint of 1.
#[test]
fn the_barrier_weight_starts_at_the_gap_hint() {
    let sc = scaled(12, 4, 20);
    let one = NewtonSettings::builder().max_steps(1).build().unwrap();
    let hint = 1.0;
    let out = solve_scaled(&sc, 4, None, &one, hint);
    assert_eq!(out.status, ConicStatus::MaxIterations);
    let gap = out.ln_det_dual - out.ln_det_primal;
    assert!(
        (gap - hint).abs() < 1e-12 || (gap - hint / one.mu_factor).abs() < 1e-12,
        "2nμ = {gap}"
    );
}
