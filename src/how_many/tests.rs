//! The curve's sizes, recommendation and predictions.

use super::predict::quantile;
use super::recommend::sizes_step;
use super::*;
use crate::blocks::jacobian_of;
use crate::model::Robot;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

#[test]
fn sizes_run_from_the_fewest_to_three_times_and_include_the_asked() {
    assert_eq!(
        curve_sizes(9, &[30], 20, 15_625),
        (9..=27).chain([30]).collect::<Vec<_>>()
    );
    let v = curve_sizes(20, &[], 5, 15_625);
    assert_eq!(v.first(), Some(&20));
    assert_eq!(v.last(), Some(&60));
    assert_eq!(v.len(), 5);
    // Never above the pool.
    assert_eq!(curve_sizes(4, &[100], 20, 10), vec![4, 5, 6, 7, 8, 9, 10]);
}

/// A curve point of size `n` predicting `rms` mm.
fn point(n: usize, rms: f64) -> CurvePoint {
    CurvePoint {
        n,
        ln_oid: 0.0,
        ln_bound: 0.0,
        d_efficiency: 1.0,
        predicted: PredictedErrors {
            position_rms_mm: rms,
            position_p95_mm: rms,
            position_error_p95_mm: rms,
            orientation_rms_deg: None,
            orientation_p95_deg: None,
        },
        poses: Vec::new(),
    }
}

#[test]
fn the_curve_recommends_the_target_s_smallest_size_or_its_knee() {
    // 1/√N-like, then flat from N = 14 on.
    let pts: Vec<CurvePoint> = [
        (10, 0.20),
        (11, 0.18),
        (12, 0.165),
        (13, 0.155),
        (14, 0.150),
        (15, 0.149),
        (16, 0.148),
        (17, 0.147),
    ]
    .iter()
    .map(|&(n, r)| point(n, r))
    .collect();
    // Knee: 12 → 14 (≥ 10 % more) gains 9 %; 13 → 15 gains 3.9 %.
    match recommend(&pts, None).unwrap() {
        Recommendation::Knee {
            n, next_n, gain, ..
        } => {
            assert_eq!((n, next_n), (13, 15));
            assert!((gain - (1.0 - 0.149 / 0.155)).abs() < 1e-12);
        }
        r => panic!("{r:?}"),
    }
    assert_eq!(recommend(&pts, Some(0.16)).unwrap().n(), 13);
    assert_eq!(recommend(&pts, Some(0.2)).unwrap().n(), 10);
    assert!(matches!(
        recommend(&pts, Some(0.1)).unwrap(),
        Recommendation::TargetNotReached { n: 17, .. }
    ));
    // Still steep at the end: no knee, the largest size.
    let steep: Vec<CurvePoint> = (10..=20)
        .map(|n| point(n, 100.0 / (n * n) as f64))
        .collect();
    assert!(matches!(
        recommend(&steep, None).unwrap(),
        Recommendation::NoKnee { n: 20, .. }
    ));
    assert!(recommend(&[], None).is_none());
}

#[test]
fn the_step_is_that_of_the_thinned_range() {
    assert_eq!(sizes_step(&curve_sizes(9, &[30], 20, 15_625), 9), 1);
    assert_eq!(sizes_step(&curve_sizes(20, &[], 5, 15_625), 20), 10);
    assert_eq!(sizes_step(&curve_sizes(20, &[], 20, 15_625), 20), 3);
}

#[test]
fn predicted_errors_scale_with_the_noise_and_shrink_with_more_poses() {
    let robot = Robot::puma560();
    let qs = random_configurations(&robot, 60, 3);
    let x = jacobian_of(&robot, &robot.nominal, qs.len(), |k, q| {
        q.copy_from_slice(&qs[k])
    });
    let eval = x.select(&(0..20).collect::<Vec<_>>());
    let few = x.information(&(20..40).collect::<Vec<_>>());
    let many = x.information(&(20..60).collect::<Vec<_>>());
    let a = predicted_errors(&robot, &eval, few.as_ref(), 1e-3).unwrap();
    let b = predicted_errors(&robot, &eval, few.as_ref(), 2e-3).unwrap();
    let c = predicted_errors(&robot, &eval, many.as_ref(), 1e-3).unwrap();
    // Linear in σ (up to rounding).
    assert!((b.position_rms_mm / a.position_rms_mm - 2.0).abs() < 1e-12);
    // Adding poses adds information: the error cannot grow.
    assert!(c.position_rms_mm < a.position_rms_mm);
    assert!(a.position_p95_mm >= a.position_rms_mm * 0.5);
    assert!(a.orientation_rms_deg.is_none());
}

/// The error percentile against simulated calibrations: a PUMA
/// calibrated from 40 poses with σ = 0.1 mm, 40 noise draws, each
/// calibrated model judged at 200 other configurations. The predicted
/// 95th percentile of the error is that of the errors seen (within
/// 10 %), and closer to it than the percentile of the per-configuration
/// RMS.
#[test]
fn the_error_percentile_is_that_of_simulated_calibrations() {
    use crate::identify::{LmSettings, identify, simulate};
    let robot = Robot::puma560();
    let qs = random_configurations(&robot, 240, 11);
    let (design, judged) = qs.split_at(40);
    let x = jacobian_of(&robot, &robot.real, 40, |k, q| {
        q.copy_from_slice(&design[k])
    });
    let eval = jacobian_of(&robot, &robot.real, 200, |k, q| {
        q.copy_from_slice(&judged[k])
    });
    let sigma = 1e-4;
    let info = x.information(&(0..40).collect::<Vec<_>>());
    let p = predicted_errors(&robot, &eval, info.as_ref(), sigma).unwrap();
    let truth = simulate(
        &robot,
        &robot.real,
        judged,
        0.0,
        &mut ChaCha8Rng::seed_from_u64(0),
    )
    .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut seen = Vec::new();
    for _ in 0..40 {
        let meas = simulate(&robot, &robot.real, design, sigma, &mut rng).unwrap();
        let id = identify(&robot, &robot.nominal, &meas, &LmSettings::default()).unwrap();
        let got = simulate(&robot, &id.table, judged, 0.0, &mut rng).unwrap();
        for (a, b) in got.points().iter().zip(truth.points()) {
            let d: f64 = (0..3).map(|c| (a[c] - b[c]).powi(2)).sum();
            seen.push(d.sqrt() * 1e3);
        }
    }
    let rms = (seen.iter().map(|v| v * v).sum::<f64>() / seen.len() as f64).sqrt();
    let p95 = quantile(&mut seen, 0.95);
    eprintln!(
        "RMS {} predicted, {rms} seen; 95th percentile of the error {} predicted, {p95} seen (of the RMS: {})",
        p.position_rms_mm, p.position_error_p95_mm, p.position_p95_mm
    );
    assert!(
        (p.position_rms_mm / rms - 1.0).abs() < 0.1,
        "{} {rms}",
        p.position_rms_mm
    );
    assert!(
        (p.position_error_p95_mm / p95 - 1.0).abs() < 0.1,
        "{} {p95}",
        p.position_error_p95_mm
    );
    assert!(
        (p.position_error_p95_mm - p95).abs() < (p.position_p95_mm - p95).abs(),
        "error p95 {} and RMS p95 {} against {p95} seen",
        p.position_error_p95_mm,
        p.position_p95_mm
    );
}

#[test]
fn a_singular_design_predicts_nothing() {
    let robot = Robot::puma560();
    let qs = random_configurations(&robot, 5, 1);
    let x = jacobian_of(&robot, &robot.nominal, 5, |k, q| q.copy_from_slice(&qs[k]));
    // 5 poses × 3 rows < 27 unknowns.
    assert!(predicted_errors(&robot, &x, x.information(&[0, 1, 2, 3, 4]).as_ref(), 1e-3).is_none());
}

#[test]
fn the_predicted_rms_matches_the_trace_of_the_covariance() {
    // One configuration, one design: E‖e‖² = σ² tr(J M⁻¹ Jᵀ).
    let robot = Robot::puma560();
    let qs = random_configurations(&robot, 41, 9);
    let x = jacobian_of(&robot, &robot.nominal, 41, |k, q| q.copy_from_slice(&qs[k]));
    let m = x.information(&(1..41).collect::<Vec<_>>());
    let e = predicted_errors(&robot, &x.select(&[0]), m.as_ref(), 1e-3).unwrap();
    let inv = crate::linalg::qr::inverse_information(x.select(&(1..41).collect::<Vec<_>>()).mat())
        .unwrap();
    let j = x.block(0);
    let tr: f64 = (0..3)
        .map(|r| {
            (0..j.ncols())
                .flat_map(|a| (0..j.ncols()).map(move |b| (a, b)))
                .map(|(a, b)| j[(r, a)] * inv[(a, b)] * j[(r, b)])
                .sum::<f64>()
        })
        .sum();
    let want = (1e-6 * tr).sqrt() * 1e3;
    // Two inverses (Cholesky, QR) of a matrix of condition ~1e8: 1e-6.
    assert!(
        (e.position_rms_mm / want - 1.0).abs() < 1e-6,
        "{} {want}",
        e.position_rms_mm
    );
}
