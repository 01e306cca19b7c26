//! The bound from outside (feature `live`, needs the project venv with
//! cvxpy, Clarabel and SCS): activecal's relaxation
//!
//! `maximise ln det Σ_i w_i X_iᵀX_i  s.t.  0 ≤ w_i ≤ 1,  Σ_i w_i = N`   (R)
//!
//! solved again by cvxpy's `log_det` with Clarabel and with SCS (as installed
//! from PyPI, `verify/requirements.txt`) on three seeded random pools and on
//! the PUMA's 3-level lattice (729 poses, N = 15 as in `tests/reproduce.rs`),
//! and activecal's certificate (eq. C) recomputed in numpy:
//! `ln det M(w) + p·ln(S_N/p)`, `S_N` the sum of the `N` largest
//! `d_i = tr(X_i M(w)⁻¹ X_iᵀ)`, an upper bound on (R) at any `w`.
//!
//! Tolerances:
//! * 1e-6 in ln det between Clarabel (via cvxpy) and activecal's
//!   `ln_primal` / `ln_bound`: activecal's status `Certified` means
//!   `ln_bound − ln_primal ≤ 1e-6` (its default `gap_tol`), the true optimum
//!   lies between them, and Clarabel is run at gap and feasibility tolerance
//!   1e-9 (its optimum is within ~1e-9·|ln det| ≲ 1e-7 of the true one); the
//!   numpy certificate at Clarabel's weights confirms its gap independently.
//! * 1e-4 for SCS: a first-order (ADMM) method, run to eps = 1e-7 relative
//!   residuals; ln det's sensitivity to the weights is
//!   `∂ ln det/∂w_i = d_i ≤ p`, so residuals of 1e-7 on ~200–729 weights
//!   move it by ≲ 729·27·1e-7 ≈ 2e-3 in the worst case and by far less in
//!   practice; 1e-4 is what a converged SCS run reaches here (its objective
//!   is also checked against the certified sandwich, which needs no
//!   tolerance on its side beyond rounding).
//! * 1e-8 where the same quantity is computed twice (numpy's ln det of
//!   activecal's weights vs activecal's `ln_primal`): `δ ln det =
//!   tr(M⁻¹ δM) ≤ p·κ·ε` with κ ≲ 1e6 on the column-scaled matrices and
//!   p ≤ 27, i.e. ≲ 3e-9.
//! * Without any tolerance beyond rounding (1e-9): the sandwich. Every
//!   feasible `w` (cvxpy's, SCS's, activecal's) has `ln det M(w) ≤
//!   activecal's ln_bound`, and every certificate (numpy's at any weights) is
//!   `≥ activecal's ln_primal`: each side is a proof about the other.

use activecal::blocks::Blocks;
use activecal::bound::{BoundSettings, BoundStatus, relaxation_bound};
use activecal::model::Robot;
use activecal::pool::Pool;
use std::time::Instant;
use verify::bridge::{Bridge, CvxSolution, NumpyCertificate};
use verify::sample::SplitMix64;

const CLARABEL_TOL: f64 = 1e-6;
const SCS_TOL: f64 = 1e-4;
const SAME_TOL: f64 = 1e-8;
const ROUNDING: f64 = 1e-9;

/// A seeded random pool: `m` poses of `t` rows and `p` columns, entries
/// standard normal (Box–Muller on SplitMix64) times column scales spread over
/// `10^{±spread}`, so that the pool is not pre-scaled.
fn random_pool(m: usize, t: usize, p: usize, spread: f64, seed: u64) -> Blocks {
    let mut rng = SplitMix64::new(seed);
    let scale: Vec<f64> = (0..p)
        .map(|j| 10f64.powf(spread * (2.0 * j as f64 / (p - 1) as f64 - 1.0)))
        .collect();
    let mut rows = Vec::with_capacity(m * t * p);
    for _ in 0..m * t {
        for s in &scale {
            let (u1, u2) = (1.0 - rng.next_f64(), rng.next_f64());
            let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            rows.push(z * s);
        }
    }
    Blocks::from_row_major(&rows, t, p)
}

/// Weights scaled down to `Σ w ≤ n` if above (stays in `[0, 1]`): with
/// `M(w)` monotone in `w`, every such `w` satisfies `ln det M(w) ≤ max (R)`.
fn feasible(w: &[f64], n: usize) -> Vec<f64> {
    let s: f64 = w.iter().sum();
    let f = if s > n as f64 { n as f64 / s } else { 1.0 };
    w.iter().map(|v| v * f).collect()
}

fn run(bridge: &Bridge, name: &str, x: &Blocks, n: usize) {
    let start = Instant::now();
    let b = relaxation_bound(x, None, n, &BoundSettings::default()).unwrap();
    let ac_seconds = start.elapsed().as_secs_f64();
    assert_eq!(b.status, BoundStatus::Certified, "{name}");
    assert!(b.certificate_gap <= 1e-6, "{name}: {}", b.certificate_gap);
    let sum: f64 = b.weights.iter().sum();
    assert!(
        (sum - n as f64).abs() <= 1e-9 * n as f64,
        "{name}: Σw = {sum}"
    );
    assert!(
        b.weights.iter().all(|&w| (0.0..=1.0).contains(&w)),
        "{name}"
    );

    let cl: CvxSolution = bridge.relaxation_cvxpy(x, n, "CLARABEL", 1e-9).unwrap();
    let scs: CvxSolution = bridge.relaxation_cvxpy(x, n, "SCS", 1e-7).unwrap();
    assert_eq!(cl.status, "optimal", "{name}: Clarabel via cvxpy");
    assert!(
        scs.status.starts_with("optimal"),
        "{name}: SCS via cvxpy: {}",
        scs.status
    );

    let cert = |w: &[f64]| -> NumpyCertificate { bridge.relaxation_certificate(x, w, n).unwrap() };
    let at_ac = cert(&b.weights);
    let at_cl = cert(&feasible(&cl.weights, n));
    let at_scs = cert(&feasible(&scs.weights, n));

    println!(
        "{name}: {} poses, t = {}, p = {}, N = {n}\n  \
         activecal   ln_primal {:.10}  ln_bound {:.10}  ({:.3} s)\n  \
         cvxpy+Clarabel ln det {:.10}  Δ vs ln_primal {:+.2e}, vs ln_bound {:+.2e}  (solve {:.3} s, wall {:.3} s)\n  \
         cvxpy+SCS      ln det {:.10}  Δ vs ln_primal {:+.2e}  (solve {:.3} s, wall {:.3} s)\n  \
         numpy eq. C at activecal's w {:.10} (ln det {:.10}, Δ ln_primal {:+.2e}), at Clarabel's w {:.10} (gap {:.2e}), at SCS's w {:.10} (gap {:.2e})",
        x.n_poses(),
        x.t(),
        x.p(),
        b.ln_primal,
        b.ln_bound,
        ac_seconds,
        cl.ln_det,
        cl.ln_det - b.ln_primal,
        cl.ln_det - b.ln_bound,
        cl.solve_seconds,
        cl.wall_seconds,
        scs.ln_det,
        scs.ln_det - b.ln_primal,
        scs.solve_seconds,
        scs.wall_seconds,
        at_ac.bound,
        at_ac.ln_det,
        at_ac.ln_det - b.ln_primal,
        at_cl.bound,
        at_cl.bound - at_cl.ln_det,
        at_scs.bound,
        at_scs.bound - at_scs.ln_det,
    );

    // Agreement of the optima.
    assert!(
        (cl.ln_det - b.ln_primal).abs() <= CLARABEL_TOL,
        "{name}: Clarabel vs ln_primal"
    );
    assert!(
        (cl.ln_det - b.ln_bound).abs() <= CLARABEL_TOL,
        "{name}: Clarabel vs ln_bound"
    );
    assert!(
        (scs.ln_det - b.ln_primal).abs() <= SCS_TOL,
        "{name}: SCS vs ln_primal"
    );
    // activecal's primal value and certificate, recomputed.
    assert!(
        (at_ac.ln_det - b.ln_primal).abs() <= SAME_TOL,
        "{name}: ln det of activecal's w"
    );
    assert!(
        at_ac.bound >= b.ln_bound - SAME_TOL,
        "{name}: activecal's bound is the smallest certificate seen"
    );
    assert!(
        at_ac.bound - at_ac.ln_det <= 1e-6 + SAME_TOL,
        "{name}: activecal's point, certified in numpy"
    );
    // Clarabel's point certified independently. Looser than its ln det:
    // ln det is stationary at the optimum (error second order in the
    // weights' error), the certificate's p·ln(S_N/p) is first order, and an
    // interior-point solution leaves weights ~1e-7 inside their bounds
    // (2.8e-5 seen on the PUMA lattice).
    assert!(
        at_cl.bound - at_cl.ln_det <= SCS_TOL,
        "{name}: Clarabel's point gap"
    );
    // The sandwich: feasible values below activecal's bound, numpy's
    // certificates above activecal's feasible value.
    for (who, c) in [
        ("Clarabel", &at_cl),
        ("SCS", &at_scs),
        ("activecal", &at_ac),
    ] {
        assert!(c.weight_sum <= n as f64 * (1.0 + 1e-12), "{name}: {who} Σw");
        assert!(
            c.ln_det <= b.ln_bound + ROUNDING,
            "{name}: {who}'s ln det {} above activecal's bound {}",
            c.ln_det,
            b.ln_bound
        );
        assert!(
            c.bound >= b.ln_primal - ROUNDING,
            "{name}: numpy certificate at {who}'s w {} below activecal's ln_primal {}",
            c.bound,
            b.ln_primal
        );
    }
}

#[test]
fn relaxation_agrees_with_cvxpy_on_random_pools() {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    run(
        &bridge,
        "random t=3 p=8",
        &random_pool(200, 3, 8, 1.0, 41),
        6,
    );
    run(
        &bridge,
        "random t=6 p=12",
        &random_pool(200, 6, 12, 1.0, 42),
        4,
    );
    run(
        &bridge,
        "random t=3 p=10",
        &random_pool(200, 3, 10, 2.0, 43),
        12,
    );
}

#[test]
fn relaxation_agrees_with_cvxpy_on_the_puma_3_level_lattice() {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let robot = Robot::puma560();
    let pool = Pool::full(&robot, 3).unwrap();
    assert_eq!(pool.len(), 729);
    let x = pool.jacobian(&robot, &robot.nominal);
    run(&bridge, "puma560 3-level lattice", &x, 15);
}
