//! Issue #50 item 2, the proof that a sensor is one folder behind the
//! trait: the height sensor (`src/measure/height/`, one registration line
//! in `src/measure/mod.rs`) is selected, bounded, fitted on simulated data
//! of the perturbed real robot and reported through the library's
//! pipelines alone, which never name it.

use activecal::bound::BoundSettings;
use activecal::experiment::select::{SelectRun, run};
use activecal::experiment::visiting::Visiting;
use activecal::identify::{LmSettings, Status, identify, simulate, trial_rng};
use activecal::kinematics::Evaluator;
use activecal::measure::height;
use activecal::model::{ParamSet, ParamTable, Robot};
use activecal::pool::Pool;
use activecal::select::{Algorithm, CriterionKind, Settings};

/// The UR5 (its real table perturbed from the nominal) measured by its end
/// point's height.
fn robot() -> Robot {
    Robot::ur5().with_measurement(height::KIND).unwrap()
}

/// RMS over `qs` of the end point's height under `a` minus under `b`, m.
pub(crate) fn height_rms(robot: &Robot, a: &ParamTable, b: &ParamTable, qs: &[Vec<f64>]) -> f64 {
    let (mut ea, mut eb) = (Evaluator::new(robot, a), Evaluator::new(robot, b));
    let ss: f64 = qs
        .iter()
        .map(|q| (ea.end_frame(q).position.z - eb.end_frame(q).position.z).powi(2))
        .sum();
    (ss / qs.len() as f64).sqrt()
}

/// Selected (exchange-add-exchange on D, the pool's 3-level lattice),
/// bounded (the certified relaxation bound: the design's ln det below it),
/// its error predicted and reported (`SelectReport`); then fitted on
/// simulated heights of the real robot over `T` noise draws: the mean
/// squared height error of the calibrated model at the prediction's 1000
/// random configurations matches the predicted `σ² tr(M (XᵀX)⁻¹)` (the
/// report's RMS squared) within 4 standard errors of the trials' mean
/// (the trials are independent, so the mean's spread is their sample
/// deviation over √T; 4 of them leave a chance below 1e-4 of a false
/// failure).
#[test]
fn height_sensor_is_selected_bounded_fitted_and_reported() {
    let robot = robot();
    assert_eq!(robot.measurement.name(), "height");
    let pool = Pool::full(&robot, 3).unwrap();
    let x = pool.jacobian(&robot, &robot.nominal);
    assert_eq!((x.t(), x.p()), (1, robot.n_params()));
    let (n, sigma) = (48, 1e-4);
    let select_run = SelectRun {
        criterion: CriterionKind::Det,
        algorithm: Algorithm::Eae,
        settings: Settings::builder().n(n).build().unwrap(),
        visiting: Visiting::default(),
        gap: Some(BoundSettings::default()),
        refine: None,
        noise: Some(sigma),
        params: ParamSet::Nominal,
    };
    let out = run(&robot, &pool, &x, None, &select_run).unwrap();
    assert_eq!(out.selection.poses.len(), n);

    // Bounded: the design under the certified bound of every n-pose design.
    let bound = activecal::bound::relaxation_bound(&x, None, n, &BoundSettings::default()).unwrap();
    let gap = activecal::bound::design_gap(&x, None, &out.selection.poses, &bound).unwrap();
    assert!(gap.ln_oid.unwrap() <= bound.ln_bound + 1e-9 * bound.ln_bound.abs());
    assert!(gap.d_efficiency > 0.0 && gap.d_efficiency <= 1.0 + 1e-12);
    assert_eq!(out.report.d_efficiency, Some(gap.d_efficiency));

    // Reported: the typed report carries the gap and the predicted error
    // (of the sensor's rows: the height, m → mm), and serializes.
    let json = serde_json::to_value(&out.report).unwrap();
    assert_eq!(json["poses"].as_array().map(Vec::len), Some(n));
    let predicted = out.report.predicted.as_ref().unwrap();
    let p_m = predicted.errors.position_rms_mm * 1e-3;
    assert!(p_m > 0.0, "predicted {p_m} m");

    // Fitted: the real robot's heights recovered within the prediction.
    let qs: Vec<Vec<f64>> = out.selection.poses.iter().map(|&k| pool.q(k)).collect();
    let at = activecal::how_many::random_configurations(&robot, predicted.configurations, 0);
    let before = height_rms(&robot, &robot.nominal, &robot.real, &at);
    let trials = 40;
    let mut ms = Vec::with_capacity(trials);
    for t in 0..trials {
        let meas = simulate(&robot, &robot.real, &qs, sigma, &mut trial_rng(7, t as u64)).unwrap();
        let id = identify(&robot, &robot.nominal, &meas, &LmSettings::default()).unwrap();
        assert_eq!(id.status, Status::Converged);
        ms.push(height_rms(&robot, &id.table, &robot.real, &at).powi(2));
    }
    assert_recovered_as_predicted("height", &ms, p_m, before);
}

/// The held-out validation of a height robot is in the sensor's row: at
/// 200 random configurations, `ValidationSet::rms` and
/// `ValidationSet::position_errors` of the nominal model against the real
/// robot are the end point's height error computed here through the
/// kinematics (equal to 1e-12 relative: the same differences, summed in
/// another order), not its 3-D distance (larger by the unobservable `x`
/// and `y`, here by more than 10 %); a point robot's validation is that
/// 3-D distance.
#[test]
fn a_height_robot_is_validated_by_its_height_error() {
    use activecal::identify::ValidationSet;
    let robot = robot();
    let qs = activecal::how_many::random_configurations(&robot, 200, 3);
    let v = ValidationSet::from_qs(&robot, qs.clone()).unwrap();
    let (rms, height) = (
        v.rms(&robot, &robot.nominal),
        height_rms(&robot, &robot.nominal, &robot.real, &qs),
    );
    assert!((rms - height).abs() < 1e-12 * height, "{rms} vs {height}");
    let errors = v.position_errors(&robot, &robot.nominal);
    let (mut en, mut er) = (
        Evaluator::new(&robot, &robot.nominal),
        Evaluator::new(&robot, &robot.real),
    );
    for (e, q) in errors.iter().zip(&qs) {
        let dz = (en.end_frame(q).position.z - er.end_frame(q).position.z).abs();
        assert!((e - dz).abs() <= 1e-15 + 1e-12 * dz, "{e} vs {dz}");
    }
    let point = Robot::ur5();
    let distance = ValidationSet::from_qs(&point, qs.clone())
        .unwrap()
        .rms(&point, &point.nominal);
    let (mut pn, mut pr) = (
        Evaluator::new(&point, &point.nominal),
        Evaluator::new(&point, &point.real),
    );
    let ss: f64 = qs
        .iter()
        .map(|q| (pn.end_frame(q).position - pr.end_frame(q).position).norm_squared())
        .sum();
    let d3 = (ss / qs.len() as f64).sqrt();
    assert!((distance - d3).abs() < 1e-12 * d3, "{distance} vs {d3}");
    assert!(d3 > 1.1 * height, "3-D {d3} m, height {height} m");
}

/// Every Rust file under `dir` (recursively), relative to the root.
fn rust_files(root: &std::path::Path, dir: &str, out: &mut Vec<std::path::PathBuf>) {
    let Ok(entries) = std::fs::read_dir(root.join(dir)) else {
        return;
    };
    for e in entries {
        let p = e.expect("entry").path();
        let rel = p.strip_prefix(root).expect("under the root").to_path_buf();
        if p.is_dir() {
            rust_files(root, &rel.display().to_string(), out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(rel);
        }
    }
}

/// Whether `line` names `word` as a whole identifier.
fn names(line: &str, word: &str) -> bool {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    line.match_indices(word)
        .any(|(i, _)| !line[..i].ends_with(ident) && !line[i + word.len()..].starts_with(ident))
}

/// The sensor is one folder: outside `src/measure/height/`, no library,
/// front-end or verify source names its type, its module or its key after
/// a robot (`ur5:height`: the command line and robot files find it in the
/// registry), except the one registration line in `src/measure/mod.rs`
/// (tests may use it, as users do).
#[test]
fn the_height_sensor_lives_in_its_folder_and_one_registration_line() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for dir in ["src", "python/src", "verify/src"] {
        rust_files(root, dir, &mut files);
    }
    let mut naming = Vec::new();
    for rel in &files {
        if rel.starts_with("src/measure/height") {
            continue;
        }
        let text = std::fs::read_to_string(root.join(rel)).expect("readable");
        for (k, line) in text.lines().enumerate() {
            let registration = rel.as_path() == std::path::Path::new("src/measure/mod.rs");
            if names(line, "HeightSensor")
                || line.contains("height::")
                || line.contains(":height")
                || (registration && names(line, "height"))
            {
                naming.push(format!("{}:{}: {}", rel.display(), k + 1, line.trim()));
            }
        }
    }
    assert!(files.len() > 100, "walked {} files only", files.len());
    assert_eq!(naming.len(), 1, "{}", naming.join("\n"));
    assert!(
        naming[0].starts_with("src/measure/mod.rs:"),
        "{}",
        naming[0]
    );
}

/// Asserts that the mean of the squared errors `squares` of independent
/// calibrations (m²) equals the predicted error `predicted` (m) squared
/// within 4 standard errors of that mean, and that the nominal model was
/// off (`before`, m) by more than 10 times it; prints the figures as
/// `label`.
pub(crate) fn assert_recovered_as_predicted(
    label: &str,
    squares: &[f64],
    predicted: f64,
    before: f64,
) {
    let trials = squares.len();
    let mean = squares.iter().sum::<f64>() / trials as f64;
    let sd = (squares.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (trials - 1) as f64).sqrt();
    let se = sd / (trials as f64).sqrt();
    eprintln!(
        "{label}: before {:.4} mm, after {:.4} mm RMS, predicted {:.4} mm (±{:.4} mm² s.e. of the mean square)",
        before * 1e3,
        mean.sqrt() * 1e3,
        predicted * 1e3,
        se * 1e6
    );
    assert!(
        (mean - predicted * predicted).abs() < 4.0 * se,
        "mean square {mean:e} m² vs predicted {:e} m² (s.e. {se:e})",
        predicted * predicted
    );
    assert!(
        before > 10.0 * predicted,
        "the real robot is off by {before} m only"
    );
}
