//! Robust losses on a calibration: Huber against gross outliers, and a
//! Huber of large scale equal to least squares.

use crate::data::Measurements;
use crate::identify::{
    LmSettings, Status, ValidationSet, identify, identify_robust, simulate, trial_rng,
};
use crate::lsq::loss::Huber;
use crate::model::Robot;
use crate::pool::Pool;

/// 60 poses of the 5-level PUMA lattice, simulated with σ = 0.1 mm, and
/// 200 held-out poses to measure the calibrated robot's accuracy on.
fn data() -> (Robot, Vec<Vec<f64>>, Measurements, ValidationSet, f64) {
    let robot = Robot::puma560();
    let pool = Pool::full(&robot, 5).expect("pool");
    let qs: Vec<Vec<f64>> = (0..60).map(|k| pool.q(k * 257)).collect();
    let sigma = 1e-4;
    let meas = simulate(&robot, &robot.real, &qs, sigma, &mut trial_rng(11, 0)).expect("sim");
    let held: Vec<Vec<f64>> = (0..200).map(|k| pool.q(k * 73 + 5)).collect();
    let v = ValidationSet::from_qs(&robot, held).expect("validation");
    (robot, qs, meas, v, sigma)
}

#[test]
fn huber_resists_gross_outliers() {
    let (robot, qs, meas, v, sigma) = data();
    // Three gross outliers: 5 cm (500 σ) on one coordinate each.
    let mut points = meas.points().to_vec();
    for (i, c) in [(4, 0), (21, 1), (47, 2)] {
        points[i][c] += 0.05;
    }
    let bad = Measurements::new(&robot, qs, points).expect("measurements");
    let s = LmSettings::default();
    let l2 = identify(&robot, &robot.nominal, &bad, &s).expect("l2");
    let hub = identify_robust(
        &robot,
        &robot.nominal,
        &bad,
        &s,
        Huber::new(3.0 * sigma).expect("scale"),
    )
    .expect("huber");
    assert_eq!(hub.status, Status::Converged);
    let clean = identify(&robot, &robot.nominal, &meas, &s).expect("clean");
    let e_clean = v.rms(&robot, &clean.table);
    let (e_l2, e_hub) = (v.rms(&robot, &l2.table), v.rms(&robot, &hub.table));
    // Least squares spreads each 5 cm outlier over the fit: its held-out
    // error is the outliers' leverage times 5 cm, millimetres (4.6 mm
    // here). Huber caps an outlier's pull at c = 3σ, as if it were a
    // 0.3 mm residual, so its error stays near the noise-limited
    // σ√(p/n) ≈ 0.07 mm of clean data (0.09 mm vs 0.07 mm clean here).
    // The bounds leave a factor ≥ 2 on either side of what we see: Huber
    // at least 20× closer than L2, and within 3× of the clean fit.
    assert!(e_hub * 20.0 < e_l2, "Huber {e_hub:e} vs L2 {e_l2:e}");
    assert!(
        e_hub < 3.0 * e_clean,
        "Huber {e_hub:e} vs clean {e_clean:e}"
    );
}

#[test]
fn huber_with_a_large_scale_is_least_squares() {
    let (robot, _, meas, _, _) = data();
    let s = LmSettings::default();
    let l2 = identify(&robot, &robot.nominal, &meas, &s).expect("l2");
    // Residual norms are ~σ√3 ≈ 2e-4 m: with c = 1 m every weight is 1.
    let hub = identify_robust(
        &robot,
        &robot.nominal,
        &meas,
        &s,
        Huber::new(1.0).expect("c"),
    )
    .expect("huber");
    let worst = l2
        .estimate
        .iter()
        .zip(&hub.estimate)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    // Every weight is exactly 1, so IRLS's first round is the same LM
    // run bit for bit and its second starts at the converged point, where
    // a step is below xtol = 1e-10 relative: 1e-12 absolute on unknowns
    // of size ≤ 20 allows that step and nothing else.
    assert!(worst <= 1e-12, "max |L2 − Huber| = {worst:e}");
    assert!(hub.rss == l2.rss || (hub.rss - l2.rss).abs() <= 1e-12 * l2.rss);
}
