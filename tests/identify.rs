//! Identification: exact recovery without noise from the nominal start,
//! agreement with the linearised covariance, statuses for numerical outcomes,
//! errors for bad input, determinism of the Monte-Carlo, and the command line.

use crate::common;
use activecal::data::{DataError, Measurements};
use activecal::identify::{
    IdentifyError, LmSettings, MonteCarloSettings, Status, StopReason, ValidationSet,
    compare_designs, identify, monte_carlo, paper_tables, simulate, trial_rng,
};
use activecal::io::design::DesignFile;
use activecal::lsq::LsqError;
use activecal::measure::JacobianEvaluator;
use activecal::model::Robot;
use activecal::pool::Pool;
use nalgebra::DMatrix;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;

use common::{eae_design, run};

/// `n` distinct pool positions drawn with a seeded ChaCha8 (partial Fisher–Yates).
fn random_design(pool: &Pool, n: usize, seed: u64) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut all: Vec<usize> = (0..pool.len()).collect();
    for i in 0..n {
        let j = rng.random_range(i..all.len());
        all.swap(i, j);
    }
    all.truncate(n);
    all
}

/// The 30-pose design of the acceptance tests, as pool positions in the
/// 5-level PUMA lattice. To test with a selected (e.g. exchange-add-exchange)
/// design instead, change this one line.
fn acceptance_design(pool: &Pool) -> Vec<usize> {
    random_design(pool, 30, 1)
}

/// Robot, pool and the joint vectors of the acceptance design.
fn data() -> (Robot, Pool, Vec<usize>, Vec<Vec<f64>>) {
    let robot = Robot::puma560();
    let pool = Pool::full(&robot, 5).unwrap();
    let design = acceptance_design(&pool);
    let qs = design.iter().map(|&k| pool.q(k)).collect();
    (robot, pool, design, qs)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn zero_noise_recovers_real_parameters_from_nominal() {
    let (robot, _, _, qs) = data();
    let meas = simulate(&robot, &robot.real, &qs, 0.0, &mut trial_rng(0, 0)).unwrap();
    let truth = robot.unknown_values(&robot.real);
    let nominal = robot.unknown_values(&robot.nominal);
    // The start really is far: up to ~0.3 rad and 0.15 m off.
    assert!(max_abs_diff(&nominal, &truth) > 0.25);
    let id = identify(&robot, &robot.nominal, &meas, &LmSettings::default()).unwrap();
    assert_eq!(id.status, Status::Converged, "{:?}", id.stop);
    let err = max_abs_diff(&id.estimate, &truth);
    assert!(err <= 1e-9, "largest error {err:e}");
    assert!(
        id.iterations >= 1 && id.iterations <= 30,
        "{} iterations",
        id.iterations
    );
    assert!(id.rss < 1e-18 && id.initial_rss > 1.0);
    assert!(id.rss_history.len() >= 2 && id.rss_history.len() <= id.iterations + 1);
    assert!(
        id.rss_history.windows(2).all(|w| w[1] <= w[0]),
        "cost must never increase"
    );
    assert_eq!((id.rank, id.dof), (27, 90 - 27));
    // The table carries the estimate, the other parameters stay nominal.
    assert_eq!(robot.unknown_values(&id.table), id.estimate);
    assert_eq!(id.table.rows[7], robot.nominal.rows[7]);
}

#[test]
fn zero_noise_recovery_also_without_geodesic_and_from_twice_as_far() {
    let (robot, _, _, qs) = data();
    let meas = simulate(&robot, &robot.real, &qs, 0.0, &mut trial_rng(0, 0)).unwrap();
    let truth = robot.unknown_values(&robot.real);
    let nominal = robot.unknown_values(&robot.nominal);
    let plain = identify(
        &robot,
        &robot.nominal,
        &meas,
        &LmSettings::builder().geodesic(false).build().unwrap(),
    )
    .unwrap();
    assert_eq!(plain.status, Status::Converged);
    assert!(max_abs_diff(&plain.estimate, &truth) <= 1e-9);
    // Start at real + 2·(nominal − real): up to ~0.6 rad off.
    let far: Vec<f64> = truth
        .iter()
        .zip(&nominal)
        .map(|(t, n)| t + 2.0 * (n - t))
        .collect();
    let start = robot.with_unknowns(&robot.nominal, &far);
    let id = identify(&robot, &start, &meas, &LmSettings::default()).unwrap();
    assert_eq!(id.status, Status::Converged);
    let err = max_abs_diff(&id.estimate, &truth);
    assert!(
        err <= 1e-9,
        "largest error {err:e} after {} iterations",
        id.iterations
    );
}

#[test]
fn angles_are_reported_nearest_the_start() {
    // A start shifted by 2π in γ_a is the same robot; the estimate stays on
    // the start's branch instead of wandering.
    let (robot, _, _, qs) = data();
    let meas = simulate(&robot, &robot.real, &qs, 0.0, &mut trial_rng(0, 0)).unwrap();
    let mut start = robot.nominal.clone();
    start.rows[0][0] += std::f64::consts::TAU;
    let id = identify(&robot, &start, &meas, &LmSettings::default()).unwrap();
    assert_eq!(id.status, Status::Converged);
    assert!((id.estimate[0] - (robot.real.rows[0][0] + std::f64::consts::TAU)).abs() < 1e-9);
}

/// σ̂² (XᵀX)⁻¹ computed independently: normal equations in nalgebra.
fn reference_covariance(
    robot: &Robot,
    id: &activecal::identify::Identification,
    qs: &[Vec<f64>],
) -> DMatrix<f64> {
    let p = robot.n_unknowns();
    let mut x = DMatrix::<f64>::zeros(3 * qs.len(), p);
    let mut ev = JacobianEvaluator::new(robot, &id.table);
    let mut block = vec![0.0; 3 * p];
    for (i, q) in qs.iter().enumerate() {
        ev.eval(q, &mut block);
        for r in 0..3 {
            for c in 0..p {
                x[(3 * i + r, c)] = block[r * p + c];
            }
        }
    }
    let s2 = id.sigma_hat.unwrap().powi(2);
    (x.transpose() * &x).try_inverse().unwrap() * s2
}

#[test]
fn noisy_estimate_agrees_with_its_covariance() {
    let (robot, _, _, qs) = data();
    let sigma = 0.01;
    let meas = simulate(&robot, &robot.real, &qs, sigma, &mut trial_rng(5, 0)).unwrap();
    let id = identify(&robot, &robot.nominal, &meas, &LmSettings::default()).unwrap();
    assert_eq!(id.status, Status::Converged);
    // σ̂² ~ σ² χ²₆₃/63: relative sd of σ̂ ≈ 1/√126 ≈ 0.09; allow 4 sd.
    let s = id.sigma_hat.unwrap();
    assert!((s / sigma - 1.0).abs() < 0.36, "σ̂ = {s}");
    let cov = id.covariance.as_ref().unwrap();
    let truth = robot.unknown_values(&robot.real);
    for (k, name) in id.names.iter().enumerate() {
        let z = (id.estimate[k] - truth[k]) / cov.std[k];
        // 27 parameters: P(any |z| > 5) ≈ 27 · 6e-7.
        assert!(z.abs() < 5.0, "{name}: z = {z}");
    }
    // Covariance against the normal equations: relative agreement limited by
    // cond(XᵀX)·ε in the reference.
    let reference = reference_covariance(&robot, &id, &qs);
    for i in 0..27 {
        for j in 0..27 {
            let tol = 1e-6 * (reference[(i, i)] * reference[(j, j)]).sqrt();
            assert!(
                (cov.matrix[i][j] - reference[(i, j)]).abs() <= tol,
                "C[{i}][{j}] = {} vs {}",
                cov.matrix[i][j],
                reference[(i, j)]
            );
        }
        assert!((cov.std[i] - reference[(i, i)].sqrt()).abs() <= 1e-6 * cov.std[i]);
    }
    // The correlation matrix is labelled, symmetric, with unit diagonal.
    assert_eq!(cov.correlation.names, robot.parameter_names());
    for i in 0..27 {
        assert!((cov.correlation.matrix[i][i] - 1.0).abs() < 1e-12);
        for j in 0..27 {
            let c = cov.correlation.matrix[i][j];
            assert!(c.abs() <= 1.0 + 1e-12);
            assert!((c - cov.correlation.matrix[j][i]).abs() < 1e-12);
        }
    }
}

#[test]
fn rank_deficient_designs_are_a_status() {
    let (robot, pool, design, _) = data();
    // 8 poses: 24 equations for 27 unknowns.
    let qs: Vec<Vec<f64>> = design[..8].iter().map(|&k| pool.q(k)).collect();
    let meas = simulate(&robot, &robot.real, &qs, 0.0, &mut trial_rng(0, 0)).unwrap();
    let id = identify(&robot, &robot.nominal, &meas, &LmSettings::default()).unwrap();
    assert_eq!(id.status, Status::RankDeficient);
    assert!(id.rank <= 24 && !id.unidentifiable.is_empty());
    assert!(id.covariance.is_none() && id.sigma_hat.is_none());
    // 5 distinct poses measured 6 times each: 90 equations, rank ≤ 15.
    let qs: Vec<Vec<f64>> = (0..30).map(|i| pool.q(design[i % 5])).collect();
    let meas = simulate(&robot, &robot.real, &qs, 0.01, &mut trial_rng(0, 0)).unwrap();
    let id = identify(&robot, &robot.nominal, &meas, &LmSettings::default()).unwrap();
    assert_eq!(id.status, Status::RankDeficient);
    assert!(id.rank <= 15, "rank {}", id.rank);
    assert!(id.covariance.is_none());
}

#[test]
fn iteration_limit_and_divergence_are_statuses() {
    let (robot, _, _, qs) = data();
    let meas = simulate(&robot, &robot.real, &qs, 0.01, &mut trial_rng(0, 0)).unwrap();
    let id = identify(
        &robot,
        &robot.nominal,
        &meas,
        &LmSettings::builder().max_iterations(2).build().unwrap(),
    )
    .unwrap();
    assert_eq!(
        (id.status, id.stop, id.iterations),
        (Status::MaxIterations, StopReason::MaxIterations, 2)
    );
    assert!(id.rss < id.initial_rss);
    // Points 1e160 m away: finite input whose squared residuals overflow.
    let far = Measurements::new(&robot, qs.clone(), vec![[1e160, 0.0, 0.0]; qs.len()]).unwrap();
    let id = identify(&robot, &robot.nominal, &far, &LmSettings::default()).unwrap();
    assert_eq!(
        (id.status, id.stop),
        (Status::Diverged, StopReason::NonFinite)
    );
    assert_eq!(id.iterations, 0);
    assert!(id.covariance.is_none());
}

#[test]
fn bad_input_is_an_error() {
    let (robot, _, _, qs) = data();
    let good = simulate(&robot, &robot.real, &qs, 0.0, &mut trial_rng(0, 0)).unwrap();
    let mut points = good.points().to_vec();
    points[4][1] = f64::NAN;
    let e = Measurements::new(&robot, qs.clone(), points).unwrap_err();
    assert!(
        matches!(
            e,
            DataError::NonFiniteMeasurement {
                pose: 4,
                coordinate: 'y',
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("measurement 4, coordinate y"));

    let e = Measurements::new(&robot, qs.clone(), good.points()[..29].to_vec()).unwrap_err();
    assert!(matches!(
        e,
        DataError::MeasurementCount {
            poses: 30,
            measurements: 29,
            per_pose: 1
        }
    ));
    assert!(e.to_string().contains("missing measurements"));

    let mut short = qs.clone();
    short[3].pop();
    let e = Measurements::new(&robot, short, good.points().to_vec()).unwrap_err();
    assert!(
        e.to_string()
            .contains("pose 3: expected 6 joint angles, got 5"),
        "{e}"
    );
    let mut nan_q = qs.clone();
    nan_q[2][0] = f64::INFINITY;
    assert!(matches!(
        Measurements::new(&robot, nan_q, good.points().to_vec()),
        Err(DataError::Pose { pose: 2, .. })
    ));
    assert!(matches!(
        Measurements::new(&robot, vec![], vec![]),
        Err(DataError::Empty)
    ));

    // Measurements deserialized without the constructor are checked again.
    let json = serde_json::json!({ "qs": [vec![0.0; 6]], "points": [] });
    let raw: Measurements = serde_json::from_value(json).unwrap();
    assert!(matches!(
        identify(&robot, &robot.nominal, &raw, &LmSettings::default()),
        Err(IdentifyError::Data(DataError::MeasurementCount { .. }))
    ));

    let mut start = robot.nominal.clone();
    start.rows[2][1] = f64::NAN;
    let e = identify(&robot, &start, &good, &LmSettings::default()).unwrap_err();
    assert!(e.to_string().contains("alpha_1"), "{e}");

    let e = LmSettings::builder().xtol(-1.0).build().unwrap_err();
    assert!(matches!(e, LsqError::Setting { name: "xtol", .. }));
    // Public fields can still be set out of range: `identify` checks too.
    let mut bad = LmSettings::default();
    bad.xtol = -1.0;
    let e = identify(&robot, &robot.nominal, &good, &bad).unwrap_err();
    assert!(matches!(
        e,
        IdentifyError::Lsq(LsqError::Setting { name: "xtol", .. })
    ));
    assert!(simulate(&robot, &robot.real, &qs, -0.01, &mut trial_rng(0, 0)).is_err());
    assert!(MonteCarloSettings::builder().trials(0).build().is_err());
}

/// Every settings builder starts from the documented defaults and refuses
/// an out-of-range field in `build`, naming it.
#[test]
fn settings_builders_start_from_the_defaults_and_validate() {
    use activecal::identify::HoldoutSettings;
    let h = HoldoutSettings::builder().build().unwrap();
    assert_eq!((h.fraction, h.splits, h.seed, h.prune), (0.2, 4, 0, false));
    for f in [0.0, 1.0, f64::NAN] {
        let e = HoldoutSettings::builder().fraction(f).build().unwrap_err();
        assert!(
            matches!(
                e,
                IdentifyError::Setting {
                    name: "held-out fraction",
                    ..
                }
            ),
            "{f}: {e}"
        );
    }
    let e = HoldoutSettings::builder().splits(0).build().unwrap_err();
    assert!(matches!(
        e,
        IdentifyError::Setting {
            name: "held-out splits",
            ..
        }
    ));
    // into_builder keeps the other fields.
    let h2 = h.into_builder().seed(9).build().unwrap();
    assert_eq!((h2.fraction, h2.splits, h2.seed), (0.2, 4, 9));
    let lm = LmSettings::builder().max_iterations(7).build().unwrap();
    assert_eq!(lm, {
        let mut d = LmSettings::default();
        d.max_iterations = 7;
        d
    });
    let e = LmSettings::builder().max_iterations(0).build().unwrap_err();
    assert!(matches!(
        e,
        LsqError::Setting {
            name: "max_iterations",
            ..
        }
    ));
    let e = MonteCarloSettings::builder()
        .sigma(-1.0)
        .build()
        .unwrap_err();
    assert!(matches!(e, IdentifyError::Setting { name: "sigma", .. }));
}

/// A full-pose robot (UR5, 30 unknowns) and a 30-pose selected design in
/// its 3-level lattice, with orientation rows weighted by `w`.
fn pose_data(w: f64) -> (Robot, Pool, Vec<usize>, Vec<Vec<f64>>) {
    let mut robot = Robot::builtin("ur5:pose").unwrap();
    robot.orientation_scale = w;
    let pool = Pool::full(&robot, 3).unwrap();
    let x = pool.jacobian(&robot, &robot.nominal);
    let sel = eae_design(&x);
    let qs = sel.poses.iter().map(|&k| pool.q(k)).collect();
    (robot, pool, sel.poses, qs)
}

#[test]
fn pose_measurements_are_checked() {
    let (robot, _, _, qs) = pose_data(1.0);
    let good = simulate(&robot, &robot.real, &qs, 0.001, &mut trial_rng(0, 0)).unwrap();
    let pts = good.points().to_vec();
    let rots = good.orientations().to_vec();
    assert_eq!(rots.len(), qs.len());

    // Missing orientations; orientations for a point robot.
    let e = Measurements::new(&robot, qs.clone(), pts.clone()).unwrap_err();
    assert!(
        matches!(
            e,
            DataError::OrientationCount {
                given: 0,
                poses: 30,
                ..
            }
        ),
        "{e}"
    );
    let e = Measurements::with_orientations(&robot, qs.clone(), pts.clone(), rots[..29].to_vec())
        .unwrap_err();
    assert!(e.to_string().contains("29 orientations"), "{e}");
    let point = Robot::ur5();
    let e =
        Measurements::with_orientations(&point, qs.clone(), pts.clone(), rots.clone()).unwrap_err();
    assert!(e.to_string().contains("measures points"), "{e}");

    // Not rotations: a reflection, a scaled matrix, a NaN — each named by pose.
    type Spoil = fn(&mut [[f64; 3]; 3]);
    let cases: [(Spoil, &str); 3] = [
        (|r| r[2].iter_mut().for_each(|v| *v = -*v), "reflection"),
        (|r| r[0][0] *= 1.001, "not orthonormal"),
        (|r| r[1][2] = f64::NAN, "not a finite number"),
    ];
    for (spoil, needle) in cases {
        let mut bad = rots.clone();
        spoil(&mut bad[7]);
        let e = Measurements::with_orientations(&robot, qs.clone(), pts.clone(), bad).unwrap_err();
        assert!(matches!(e, DataError::NotARotation { pose: 7, .. }), "{e}");
        assert!(e.to_string().contains(needle), "'{e}' lacks '{needle}'");
    }
    // Rounding to 7 significant digits (a sensor's export) is accepted.
    let rounded: Vec<[[f64; 3]; 3]> = rots
        .iter()
        .map(|r| r.map(|row| row.map(|v| format!("{v:.7}").parse().unwrap())))
        .collect();
    assert!(Measurements::with_orientations(&robot, qs.clone(), pts.clone(), rounded).is_ok());

    // JSON: round trip, and unknown keys are refused.
    let text = serde_json::to_string(&good).unwrap();
    let back: Measurements = serde_json::from_str(&text).unwrap();
    assert_eq!(back, good);
    let typo = text.replacen("\"orientations\"", "\"orientation\"", 1);
    assert!(serde_json::from_str::<Measurements>(&typo).is_err());

    // Quaternions [w, x, y, z] instead of matrices: the same rotations to
    // rounding (a few ulps of entries ≤ 1), hence the same estimate.
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let quats: Vec<[f64; 4]> = rots
        .iter()
        .map(|r| {
            let m = nalgebra::Matrix3::from_fn(|i, j| r[i][j]);
            let q = nalgebra::UnitQuaternion::from_matrix(&m);
            [q.w, q.i, q.j, q.k]
        })
        .collect();
    let obj = v.as_object_mut().unwrap();
    obj.remove("orientations");
    obj.insert("quaternions".into(), serde_json::json!(quats));
    let from_q: Measurements = serde_json::from_value(v.clone()).unwrap();
    for (a, b) in from_q.orientations().iter().zip(&rots) {
        for i in 0..3 {
            for j in 0..3 {
                assert!((a[i][j] - b[i][j]).abs() < 1e-14);
            }
        }
    }
    let lm = LmSettings::default();
    let e1 = identify(&robot, &robot.nominal, &good, &lm)
        .unwrap()
        .estimate;
    let e2 = identify(&robot, &robot.nominal, &from_q, &lm)
        .unwrap()
        .estimate;
    // Both stop within LM's step tolerance (1e-10 relative, θ up to 2 m) of
    // the same minimum, not at the same bits; the estimates' standard
    // deviations are ~1e-4, so 1e-7 is "the same estimate".
    assert!(max_abs_diff(&e1, &e2) < 1e-7, "{}", max_abs_diff(&e1, &e2));
    let mut bad = v.clone();
    bad["quaternions"][3] = serde_json::json!([1.0, 0.1, 0.0, 0.0]);
    let e = serde_json::from_value::<Measurements>(bad)
        .unwrap_err()
        .to_string();
    assert!(e.contains("quaternion 3: norm"), "{e}");
    let mut both = v;
    both["orientations"] = serde_json::json!(rots);
    let e = serde_json::from_value::<Measurements>(both)
        .unwrap_err()
        .to_string();
    assert!(e.contains("not both"), "{e}");
}

/// Simulated orientation noise is N(0, (σ/w)²) per axis of the rotation
/// vector `log(R_meas R_trueᵀ)`.
#[test]
fn simulated_orientation_noise_has_the_stated_spread() {
    let (robot, pool, _, _) = pose_data(0.25);
    let qs: Vec<Vec<f64>> = (0..pool.len())
        .cycle()
        .take(3000)
        .map(|k| pool.q(k))
        .collect();
    let sigma = 0.002;
    let meas = simulate(&robot, &robot.real, &qs, sigma, &mut trial_rng(5, 0)).unwrap();
    let s_rot = sigma / robot.orientation_scale;
    let mut z = Vec::new();
    for (q, r) in qs.iter().zip(meas.orientations()) {
        let (truth, _) = activecal::kinematics::pose(&robot, &robot.real, q);
        let m = nalgebra::Matrix3::from_fn(|i, j| r[i][j]);
        let phi = nalgebra::Rotation3::from_matrix_unchecked(m * truth.transpose()).scaled_axis();
        z.extend(phi.iter().map(|v| v / s_rot));
    }
    let n = z.len() as f64;
    let mean = z.iter().sum::<f64>() / n;
    let var = z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    // 9,000 standard normals: standard errors 0.011 (mean), 0.015 (variance);
    // bounds at 5 of them. Orientation noise of σ instead of σ/w would give
    // a variance of 1/16.
    assert!(mean.abs() < 0.055, "mean {mean}");
    assert!((var - 1.0).abs() < 0.075, "variance {var}");
}

/// Full-pose Monte-Carlo with orientation weight w = 0.2 m/rad (orientation
/// noise 5× the position noise in rad vs m): the weighted estimate is
/// efficient, so its spread matches `σ² (XᵀWX)⁻¹`, and calibration cuts
/// both the position and the orientation error to what that predicts.
#[test]
fn pose_monte_carlo_agrees_with_linear_theory() {
    let (robot, pool, design, qs) = pose_data(0.2);
    let settings = MonteCarloSettings::builder()
        .trials(150)
        .sigma(0.001)
        .seed(3)
        .validation_poses(150)
        .bootstrap(0)
        .build()
        .unwrap();
    let validation = ValidationSet::sample(&robot, &pool, &design, 150, 3).unwrap();
    let s = monte_carlo(&robot, "ur5-pose", &qs, &validation, &settings).unwrap();
    assert_eq!((s.trials, s.converged), (150, 150));
    // rmse/predicted per unknown: relative sd ≈ 1/√300 ≈ 0.06; the median over
    // 30 unknowns is tighter still. A wrong weight (w² on the covariance but
    // not on the fit) moves it by a factor of several.
    let r = s.rmse_over_predicted.as_ref().unwrap();
    println!("rmse/predicted {r:?}");
    assert!((0.85..1.15).contains(&r.median), "{r:?}");
    assert!(r.max < 1.4, "{r:?}");
    let g = s.generalized_variance.as_ref().unwrap();
    println!("generalised variance {g:?}");
    assert!(g.z.abs() < 4.0, "{g:?}");
    let after = s.validation_rms_after.as_ref().unwrap();
    let predicted = s.validation_rms_predicted.unwrap();
    assert!(s.validation_rms_before > 10.0 * after.max, "{after:?}");
    assert!(
        (after.median / predicted - 1.0).abs() < 0.3,
        "{after:?} vs {predicted}"
    );
    let rot_before = s.validation_orientation_rms_before.unwrap();
    let rot_after = s.validation_orientation_rms_after.as_ref().unwrap();
    let rot_pred = s.validation_orientation_rms_predicted.unwrap();
    println!("orientation: before {rot_before:.3e}, after {rot_after:?}, predicted {rot_pred:.3e}");
    // The UR5's real tool orientation is only ~0.013 rad off nominal, and the
    // orientation noise here is 5 mrad per axis: calibration predicts 2.8 mrad.
    assert!(rot_before > 3.0 * rot_after.median, "{rot_after:?}");
    assert!(
        (rot_after.median / rot_pred - 1.0).abs() < 0.3,
        "{rot_after:?} vs {rot_pred}"
    );
}

/// The orientation weight is what makes the fit efficient: with orientation
/// noise 10× the position noise (w = 0.1), the weighted fit has a smaller
/// generalised variance than the same data fitted with w = 1.
#[test]
fn weighting_the_orientation_rows_improves_the_estimate() {
    let (robot, _, _, qs) = pose_data(0.1);
    let mut unweighted = robot.clone();
    unweighted.orientation_scale = 1.0;
    let truth = robot.unknown_values(&robot.real);
    let trials = 60;
    let (mut sq_w, mut sq_u) = (0.0, 0.0);
    for t in 0..trials {
        let meas = simulate(&robot, &robot.real, &qs, 0.001, &mut trial_rng(9, t)).unwrap();
        for (r, acc) in [(&robot, &mut sq_w), (&unweighted, &mut sq_u)] {
            let id = identify(r, &r.nominal, &meas, &LmSettings::default()).unwrap();
            assert!(id.converged());
            *acc += id
                .estimate
                .iter()
                .zip(&truth)
                .map(|(e, t)| (e - t).powi(2))
                .sum::<f64>();
        }
    }
    println!("Σ squared error over {trials} trials: weighted {sq_w:.3e}, unweighted {sq_u:.3e}");
    // Gauss–Markov: the weighted fit is the efficient one. Its total squared
    // error is smaller in expectation; over 60 trials the margin (about 2×
    // here) is far outside the sampling spread (≈ 10% of each sum).
    assert!(
        sq_w < 0.8 * sq_u,
        "weighted {sq_w:e} vs unweighted {sq_u:e}"
    );
}

#[test]
fn designs_that_do_not_match_the_robot_are_errors() {
    // The path `calibrate` takes: read, build the design's pool, place the poses.
    let robot = Robot::puma560();
    let pool = Pool::full(&robot, 5).unwrap();
    let cases = [
        (DesignFile::new("ur5", 5, vec![1, 2]), "robot 'ur5'"),
        (DesignFile::new("puma560", 4, vec![1, 2]), "4-level lattice"),
        (DesignFile::new("puma560", 5, vec![1, 15_625]), "pose 15625"),
        (DesignFile::new("puma560", 5, vec![7, 7]), "more than once"),
    ];
    for (d, needle) in cases {
        let e = d.positions_in(&robot, &pool).unwrap_err().to_string();
        assert!(e.contains(needle), "'{e}' lacks '{needle}'");
    }
}

#[test]
fn monte_carlo_agrees_with_linear_theory() {
    let (robot, pool, design, qs) = data();
    let settings = MonteCarloSettings::builder()
        .trials(120)
        .seed(11)
        .validation_poses(200)
        .bootstrap(50)
        .build()
        .unwrap();
    let validation = ValidationSet::sample(&robot, &pool, &design, 200, 11).unwrap();
    assert!(
        validation
            .lattice_indices
            .iter()
            .all(|i| !design.contains(i))
    );
    let s = monte_carlo(&robot, "acceptance", &qs, &validation, &settings).unwrap();
    assert_eq!((s.trials, s.converged), (120, 120));
    // rmse/predicted for one parameter has relative sd ≈ 1/√240 ≈ 0.065; the
    // median over 27 is much tighter.
    let r = s.rmse_over_predicted.as_ref().unwrap();
    assert!((0.85..1.15).contains(&r.median), "{r:?}");
    assert!(r.max < 1.4, "{r:?}");
    let g = s.generalized_variance.as_ref().unwrap();
    assert!(g.z.abs() < 4.0, "{g:?}");
    assert!(g.sd_bootstrap.unwrap() > 0.0);
    // Calibration cuts the validation error from ~1 m to ~1 cm, as predicted.
    let after = s.validation_rms_after.as_ref().unwrap();
    assert!(s.validation_rms_before > 0.5);
    assert!(after.max < 0.03, "{after:?}");
    let predicted = s.validation_rms_predicted.unwrap();
    assert!(
        (after.median / predicted - 1.0).abs() < 0.3,
        "{} vs {predicted}",
        after.median
    );
}

#[test]
fn monte_carlo_does_not_depend_on_thread_count() {
    let (robot, pool, design, qs) = data();
    let settings = MonteCarloSettings::builder()
        .trials(30)
        .seed(3)
        .validation_poses(50)
        .bootstrap(20)
        .build()
        .unwrap();
    let run = |threads: usize| {
        let tp = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        tp.install(|| {
            let v = ValidationSet::sample(&robot, &pool, &design, 50, 3).unwrap();
            serde_json::to_string(&monte_carlo(&robot, "d", &qs, &v, &settings).unwrap()).unwrap()
        })
    };
    let one = run(1);
    assert_eq!(one, run(3));
    // And trial 0 is the single calibration `paper_tables` reports.
    let t = paper_tables(&robot, &qs, 0.01, 3, &LmSettings::default()).unwrap();
    let meas = simulate(&robot, &robot.real, &qs, 0.01, &mut trial_rng(3, 0)).unwrap();
    let id = identify(&robot, &robot.nominal, &meas, &LmSettings::default()).unwrap();
    assert_eq!(t.identification.estimate, id.estimate);
}

#[test]
fn paper_tables_have_the_papers_layout() {
    let (robot, _, _, qs) = data();
    let t = paper_tables(&robot, &qs, 0.01, 2, &LmSettings::default()).unwrap();
    assert_eq!(t.estimate.frames, ["a", "0", "1", "2", "3", "4", "5"]);
    assert_eq!(t.estimate.symbols, ["gamma", "alpha", "a", "d", "beta"]);
    // Not unknowns: d_a, β of DH frames, α_5.
    assert!(t.estimate.rows[0][3].is_none() && t.estimate.rows[1][4].is_none());
    assert!(t.estimate.rows[6][1].is_none() && t.estimate.rows[0][4].is_some());
    let est = t.estimate.rows[2][2].unwrap(); // a_1
    let res = t.residual.rows[2][2].unwrap();
    assert!((res - (0.4318 - est)).abs() < 1e-15);
    assert!(t.std.as_ref().unwrap().rows[0][0].unwrap() > 0.0);
    let text = t.residual.to_text(6);
    assert_eq!(text.lines().count(), 8);
    assert!(text.lines().next().unwrap().contains("gamma"));
}

#[test]
fn comparison_shares_validation_and_checks_designs() {
    let (robot, pool, design, _) = data();
    let other = random_design(&pool, 30, 2);
    let settings = MonteCarloSettings::builder()
        .trials(3)
        .validation_poses(40)
        .bootstrap(0)
        .build()
        .unwrap();
    let c = compare_designs(
        &robot,
        &pool,
        &[("a".into(), design.clone()), ("b".into(), other.clone())],
        &settings,
    )
    .unwrap();
    assert_eq!(c.designs.len(), 2);
    assert_eq!(c.validation_indices.len(), 40);
    assert!(
        c.validation_indices
            .iter()
            .all(|i| !design.contains(i) && !other.contains(i))
    );
    assert_eq!(
        c.designs[0].validation_rms_before,
        c.designs[1].validation_rms_before
    );
    assert!(c.designs[0].generalized_variance.is_none()); // 3 trials ≤ 27 unknowns
    let e = compare_designs(&robot, &pool, &[("x".into(), vec![99_999])], &settings).unwrap_err();
    assert!(e.to_string().contains("design 'x'"), "{e}");
    assert!(compare_designs(&robot, &pool, &[], &settings).is_err());
}

// ---- command line ------------------------------------------------------------

fn write_design(name: &str, d: &DesignFile) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("activecal-identify-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    d.write(&path, true).unwrap();
    path
}

#[test]
fn cli_calibrate_reports_estimate_and_monte_carlo() {
    let (robot, pool, design, _) = data();
    let indices = design.iter().map(|&k| pool.ids[k]).collect();
    let path = write_design("good.json", &DesignFile::new(&robot.name, 5, indices));
    let p = path.to_str().unwrap();
    let out = run(&["calibrate", "--design", p, "--noise", "0", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(v["converged"], true);
    assert!(v["iterations"].as_u64().unwrap() >= 1);
    for name in robot.parameter_names() {
        assert!(
            v["residual"][&name].as_f64().unwrap().abs() < 1e-9,
            "{name}"
        );
        assert!(v["estimate"][&name].is_f64() && v["std"][&name].is_f64());
    }
    assert!(v["validation_rms_after"].as_f64().unwrap() < 1e-9);
    assert!(v["validation_rms_before"].as_f64().unwrap() > 0.5);
    assert!(v["monte_carlo"].is_null());

    let out = run(&[
        "calibrate",
        "--design",
        p,
        "--trials",
        "30",
        "--seed",
        "4",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let mc = &v["monte_carlo"];
    assert_eq!(mc["trials"], 30);
    assert_eq!(mc["parameters"].as_array().unwrap().len(), 27);
    assert!(mc["generalized_variance"]["ln_ratio"].is_f64());
    assert!(mc["validation_rms_after"]["median"].as_f64().unwrap() < 0.03);
    // Text output: the two tables.
    let out = run(&["calibrate", "--design", p, "--noise", "0.01"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("Table III") && text.contains("Table IV"),
        "{text}"
    );
}

#[test]
fn cli_calibrate_rejects_bad_designs_and_options() {
    let bad_robot = write_design("ur5.json", &DesignFile::new("ur5", 5, vec![1, 2, 3]));
    let bad_pose = write_design("pose.json", &DesignFile::new("puma560", 5, vec![1, 15_625]));
    let cases: [(&[&str], &str); 4] = [
        (&["--design", bad_robot.to_str().unwrap()], "robot 'ur5'"),
        (&["--design", bad_pose.to_str().unwrap()], "pose 15625"),
        (&["--design", "/nonexistent/d.json"], "/nonexistent/d.json"),
        (
            &["--design", bad_pose.to_str().unwrap(), "--robot", "foo"],
            "unknown robot 'foo'",
        ),
    ];
    for (args, needle) in cases {
        let mut all = vec!["calibrate"];
        all.extend_from_slice(args);
        let out = run(&all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{all:?}: {err}");
        assert!(
            !err.contains("panicked") && err.contains(needle),
            "{all:?}: '{err}' lacks '{needle}'"
        );
    }
    let good = write_design(
        "ok.json",
        &DesignFile::new("puma560", 5, (0..30).map(|i| i * 500).collect()),
    );
    let out = run(&[
        "calibrate",
        "--design",
        good.to_str().unwrap(),
        "--noise=-1",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("--noise -1"), "{err}");
    // `--noise -1` (a negative number as the next word) reads the same.
    let out = run(&[
        "calibrate",
        "--design",
        good.to_str().unwrap(),
        "--noise",
        "-1",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("--noise -1"), "{err}");
}
