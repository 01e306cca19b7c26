//! Joint compliance under gravity (issue #31): the compliance columns of the
//! calibration Jacobian against central differences of the full residual,
//! for every sensor; and synthetic truth — a Panda with known stiffnesses
//! and geometric errors, simulated with noise — recovered within 3σ, with a
//! held-out error at the noise floor that the geometric model misses.

use activecal::data::Measurements;
use activecal::identify::compliance::{report, with_compliance};
use activecal::identify::{
    Calibration, LmSettings, Residuals, fix_undetermined, identify, residuals, simulate,
};
use activecal::io::inertia::{InertiaOptions, gravity_model};
use activecal::io::urdf::{UrdfOptions, load};
use activecal::model::{MeasurementKind, ParamId, ParamTable, Robot, Symbol};
use faer::Mat;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;
use std::sync::Arc;

const PANDA: &str = "fixtures/example-robot-data/panda.urdf";

fn panda(m: MeasurementKind) -> Robot {
    let opts = UrdfOptions {
        tip: Some("panda_hand_tcp".into()),
        measurement: if m == MeasurementKind::Pose {
            m
        } else {
            MeasurementKind::Point
        },
        ..UrdfOptions::default()
    };
    let r = load(Path::new(PANDA), &opts).unwrap();
    match m {
        MeasurementKind::Markers(_) => r
            .with_markers(&[[0.05, -0.1, 0.12], [0.15, 0.0, 0.05], [-0.06, 0.08, 0.1]])
            .unwrap(),
        _ => r,
    }
}

fn random_qs(robot: &Robot, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            robot
                .limits
                .iter()
                .map(|&[lo, hi]| lo + (hi - lo) * rng.random::<f64>())
                .collect()
        })
        .collect()
}

/// Stiffnesses 5e3–3e4 N·m/rad, the range, one per Panda joint.
const STIFFNESS: [f64; 7] = [3.0e4, 5.0e3, 2.0e4, 8.0e3, 1.2e4, 2.5e4, 1.5e4];

/// The robot with compliance unknowns for `qs` and its real table with the
/// stiffnesses above.
fn compliant(robot: &Robot, qs: &[Vec<f64>]) -> (Robot, ParamTable) {
    let g = Arc::new(gravity_model(robot, &InertiaOptions::default()).unwrap());
    let probe = simulate(
        robot,
        &robot.real,
        qs,
        0.0,
        &mut ChaCha8Rng::seed_from_u64(0),
    )
    .unwrap();
    let (r, _) = with_compliance(robot, &g, &probe);
    let mut real = r.real.clone();
    for (f, frame) in r.frames.iter().enumerate() {
        if let Some(j) = frame.joint {
            real.set(
                ParamId {
                    frame: f,
                    symbol: Symbol::C,
                },
                -1.0 / STIFFNESS[j],
            );
        }
    }
    (r, real)
}

#[test]
fn compliance_columns_match_central_differences_for_every_sensor() {
    for m in [
        MeasurementKind::Point,
        MeasurementKind::Pose,
        MeasurementKind::Markers(3),
    ] {
        let base = panda(m);
        let qs = random_qs(&base, 12, 1);
        let (r, real) = compliant(&base, &qs);
        let n_c = r.unknowns.iter().filter(|u| u.symbol == Symbol::C).count();
        // The Panda's joint 1 is vertical, and joint 7 turns the hand about
        // an axis through its centre of mass (its torque varies by under
        // 1 % of joint 2's): five compliances.
        assert_eq!(n_c, 5, "{m:?}");
        let meas = simulate(&r, &real, &qs, 1e-4, &mut ChaCha8Rng::seed_from_u64(2)).unwrap();
        // Evaluate at a point off the truth (compliances and geometry moved).
        let theta: Vec<f64> = r
            .unknown_values(&real)
            .iter()
            .enumerate()
            .map(|(k, v)| v * (1.0 + 0.1 * ((k % 5) as f64 - 2.0)) + 1e-4)
            .collect();
        let mut prob = Calibration::new(&r, &r.nominal, &meas).unwrap();
        let (mres, p) = (prob.n_residuals(), prob.n_params());
        let mut res = vec![0.0; mres];
        let mut jac = Mat::<f64>::zeros(mres, p);
        assert!(prob.eval(&theta, &mut res, Some(&mut jac)));
        let (mut rp, mut rm) = (vec![0.0; mres], vec![0.0; mres]);
        for (k, u) in r.unknowns.iter().enumerate() {
            if u.symbol != Symbol::C {
                continue;
            }
            // c is ~1e-4 rad/(N·m) and τ up to ~40 N·m: a step of 1e-7
            // moves a joint by up to 4 µrad, where the residual is smooth.
            let h = 1e-7;
            let (mut a, mut b) = (theta.clone(), theta.clone());
            a[k] += h;
            b[k] -= h;
            prob.eval(&a, &mut rp, None);
            prob.eval(&b, &mut rm, None);
            let mut worst = 0.0f64;
            let mut scale = 0.0f64;
            for i in 0..mres {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                worst = worst.max((fd - jac[(i, k)]).abs());
                scale = scale.max(jac[(i, k)].abs());
            }
            // Truncation O(h²·f''') with f''' ~ τ³·(1 m) ~ 1e5: 1e-9; rounding
            // 1e-16·1 m / 1e-7 = 1e-9; columns are of order 10 m/(rad/N·m).
            // Rounding: 1e-16 × residuals of ~1 m over h = 1e-7, a few 1e-9.
            assert!(
                scale > 0.0 && worst < 1e-6 * scale + 1e-8,
                "{m:?} {}: |Δ| {worst:e} against column scale {scale:e}",
                r.param_name(*u)
            );
        }
    }
}

/// Held-out position RMS (mm) of `robot` at `table` on `meas`.
fn held_out_mm(robot: &Robot, table: &ParamTable, meas: &Measurements) -> f64 {
    residuals(robot, table, meas).unwrap().position_rms_mm
}

#[test]
fn a_panda_with_known_stiffnesses_is_recovered_and_reaches_the_noise_floor() {
    let base = panda(MeasurementKind::Point);
    let train = random_qs(&base, 80, 11);
    let test = random_qs(&base, 40, 12);
    let (r, real) = compliant(&base, &train);
    let sigma = 5e-5; // 0.05 mm per coordinate, a laser tracker's
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let mtr = simulate(&r, &real, &train, sigma, &mut rng).unwrap();
    let mte = simulate(&r, &real, &test, sigma, &mut rng).unwrap();
    let lm = LmSettings::default();
    // With compliances.
    let det = fix_undetermined(&r, &r.nominal, &mtr, &[]).unwrap();
    let fc = identify(&det.robot, &r.nominal, &mtr, &lm).unwrap();
    let cov = fc.covariance.as_ref().expect("a covariance");
    let mut recovered = 0;
    for (k, u) in det.robot.unknowns.iter().enumerate() {
        if u.symbol != Symbol::C {
            continue;
        }
        let truth = real.get(*u);
        let (est, sd) = (fc.estimate[k], cov.std[k]);
        // 3σ: a 99.7 % band for a normal estimate, seven parameters.
        assert!(
            (est - truth).abs() < 3.0 * sd,
            "{}: {est:e} vs truth {truth:e} (σ {sd:e})",
            det.robot.param_name(*u)
        );
        recovered += 1;
    }
    assert!(recovered >= 5, "{recovered} compliances identified");
    let rep = report(&det.robot, &fc, &mtr, Vec::new());
    assert!(rep.max_tool_deflection_mm > 1.0, "{rep:?}");
    // The geometric model alone.
    let det_g = fix_undetermined(&base, &base.nominal, &mtr, &[]).unwrap();
    let fg = identify(&det_g.robot, &base.nominal, &mtr, &lm).unwrap();
    let floor = sigma * 3f64.sqrt() * 1e3; // RMS of a 3-D noise vector, mm
    let with_c = held_out_mm(&det.robot, &fc.table, &mte);
    let without = held_out_mm(&det_g.robot, &fg.table, &mte);
    eprintln!(
        "held-out position RMS: {with_c:.4} mm with compliance, {without:.4} mm geometric, noise floor {floor:.4} mm"
    );
    // Prediction error of a fitted model on new poses: √(1 + p/n) × the floor
    // for p ≈ 40 unknowns and n = 240 rows, ≈ 1.08: 1.25 leaves room for
    // the noise of 40 poses' RMS.
    assert!(
        with_c < 1.25 * floor,
        "with compliance {with_c} mm, floor {floor} mm"
    );
    assert!(
        without > 2.0 * floor,
        "geometric {without} mm, floor {floor} mm"
    );
}

use crate::common;

const UR10: &str = "fixtures/figaroh/ur10_robot.urdf:pose";
const UR10_CSV: &str = "fixtures/figaroh/ur10_full_pose.csv";

#[test]
fn calibrate_reports_compliances_and_the_joints_without_one() {
    let v = common::json_of(&[
        "calibrate",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--measurements",
        UR10_CSV,
        "--compliance",
        "--json",
    ]);
    let c = &v["compliance"];
    let names: Vec<&str> = c["estimates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["joint"].as_str().unwrap())
        .collect();
    // The shoulder and elbow carry the arm; the base joint is vertical.
    assert!(
        names.contains(&"shoulder_lift_joint") && names.contains(&"elbow_joint"),
        "{names:?}"
    );
    let without = c["without"].as_array().unwrap();
    assert!(without.iter().any(|w| w["joint"] == "shoulder_pan_joint"
        && w["reason"].as_str().unwrap().contains("no gravity torque")));
    for e in c["estimates"].as_array().unwrap() {
        let (cc, k) = (
            e["c"].as_f64().unwrap(),
            e["stiffness_nm_per_rad"].as_f64().unwrap(),
        );
        assert!((k * cc + 1.0).abs() < 1e-12, "k = −1/c: {e}");
        assert!(e["std"].as_f64().unwrap() > 0.0);
    }
    // Each compliance is a parameter of the fit, with its verdict.
    assert!(
        v["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .any(|p| p["name"] == "c_shoulder_lift_joint")
    );
}

#[test]
fn compare_compliance_fits_both_models_on_the_same_splits() {
    let args = [
        "calibrate",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--measurements",
        UR10_CSV,
        "--holdout",
        "0.25",
        "--splits",
        "3",
        "--json",
    ];
    let plain = common::json_of(&args);
    let mut with = args.to_vec();
    with.push("--compare-compliance");
    let v = common::json_of(&with);
    let c = &v["compliance_comparison"];
    // The geometric side is the plain held-out run: same splits, same fits.
    assert_eq!(
        c["geometric_position_rms_mm"],
        plain["holdout"]["position_rms_mm"]["per_split"]
    );
    assert_eq!(c["compliant_position_rms_mm"].as_array().unwrap().len(), 3);
    assert!(c["verdict"].as_str().unwrap().contains("compliance"));
}

#[test]
fn compliance_inputs_are_checked() {
    common::fails_with(
        &[
            "calibrate",
            "--robot",
            "ur5",
            "--measurements",
            UR10_CSV,
            "--compliance",
        ],
        "needs a URDF robot",
    );
    common::fails_with(
        &[
            "calibrate",
            "--robot",
            UR10,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
            "--payload",
            "2@0,0",
        ],
        "three finite numbers",
    );
    common::fails_with(
        &[
            "calibrate",
            "--robot",
            UR10,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
            "--payload",
            "2",
        ],
        "--inertia and --payload are for --compliance",
    );
}

#[test]
fn a_payload_and_other_inertials_change_the_torques() {
    let base = [
        "calibrate",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--measurements",
        UR10_CSV,
        "--compliance",
        "--json",
    ];
    let range = |v: &serde_json::Value| v["compliance"]["estimates"][0]["torque_range_nm"].clone();
    let plain = common::json_of(&base);
    let mut same = base.to_vec();
    same.extend(["--inertia", "fixtures/figaroh/ur10_robot.urdf"]);
    assert_eq!(range(&common::json_of(&same)), range(&plain));
    let mut heavy = base.to_vec();
    heavy.extend(["--payload", "5@0,0,0.1"]);
    assert_ne!(range(&common::json_of(&heavy)), range(&plain));
}

#[test]
fn bound_and_select_take_the_compliance_columns() {
    let args = [
        "bound",
        "--robot",
        "fixtures/example-robot-data/panda.urdf:pose",
        "--tip",
        "panda_hand_tcp",
        "--pool",
        "sobol",
        "--count",
        "256",
        "--n",
        "40",
        "--json",
    ];
    let plain = common::json_of(&args);
    let mut with = args.to_vec();
    with.push("--compliance");
    let v = common::json_of(&with);
    // Five compliances (joints 2–6; joint 1 is vertical, joint 7's torque
    // too small) on top of the 34 geometric unknowns.
    assert_eq!(plain["p"], 34);
    assert_eq!(v["p"], 39);
    assert_eq!(v["status"], "certified");
    // A design chosen for them names its compliant joints; gap and score
    // give them their columns again.
    let d = common::scratch_dir("compliance", "design");
    let design = d.join("d.json");
    common::json_of(&[
        "select",
        "--robot",
        "fixtures/example-robot-data/panda.urdf:pose",
        "--tip",
        "panda_hand_tcp",
        "--pool",
        "sobol",
        "--count",
        "256",
        "--n",
        "40",
        "--starts",
        "1",
        "--ils",
        "0",
        "--compliance",
        "--out",
        design.to_str().unwrap(),
        "--json",
    ]);
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&design).unwrap()).unwrap();
    assert_eq!(
        file["compliance"].as_array().unwrap().len(),
        5,
        "{}",
        file["compliance"]
    );
    let gap = common::json_of(&["gap", "--design", design.to_str().unwrap(), "--json"]);
    let score = common::json_of(&["score", "--design", design.to_str().unwrap(), "--json"]);
    assert_eq!(
        (gap["p"].as_u64(), score["p"].as_u64()),
        (Some(39), Some(39))
    );
    assert!(gap["d_efficiency"].as_f64().unwrap() <= 1.0 + 1e-9);
}

#[test]
fn the_frames_file_carries_the_compliances_and_reading_it_back_applies_them() {
    let d = common::scratch_dir("compliance", "frames");
    let (yaml, urdf) = (d.join("c.yaml"), d.join("c.urdf"));
    let v = common::json_of(&[
        "calibrate",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--measurements",
        UR10_CSV,
        "--compliance",
        // Every pose kept: `evaluate` below judges the written model on all.
        "--outliers",
        "keep",
        "--out",
        yaml.to_str().unwrap(),
        "--out",
        urdf.to_str().unwrap(),
        "--json",
    ]);
    let text = std::fs::read_to_string(&yaml).unwrap();
    assert!(
        text.contains("\ncompliance:\n  elbow_joint:\n    c: "),
        "{text}"
    );
    let robot = format!("{}:pose", urdf.display());
    let eval = |frames: &std::path::Path| {
        common::json_of(&[
            "evaluate",
            "--robot",
            &robot,
            "--frames",
            frames.to_str().unwrap(),
            "--measurements",
            UR10_CSV,
            "--json",
        ])["residuals"]["position_rms_mm"]
            .as_f64()
            .unwrap()
    };
    // The written URDF and frames file predict what the fit predicted;
    // without the compliance block they do not. The torques are recomputed
    // from the calibrated URDF, whose origins moved by millimetres: c·Δτ
    // moves a prediction by about a micrometre (0.5 µm seen on the RMS),
    // against the compliance's own 0.1 mm.
    let fitted = v["residuals"]["position_rms_mm"].as_f64().unwrap();
    let with = eval(&yaml);
    assert!((with - fitted).abs() < 5e-3, "{with} vs fitted {fitted}");
    let rigid = d.join("rigid.yaml");
    std::fs::write(&rigid, &text[..text.find("\ncompliance:").unwrap() + 1]).unwrap();
    assert!((eval(&rigid) - fitted).abs() > 5e-2);
    // A compliance for a joint the chain does not have is refused.
    let bad = d.join("bad.yaml");
    // (In the compliance block only: a joint unknown in `joints:` is
    // refused first, naming that block.)
    let at = text.find("\ncompliance:").unwrap();
    let bad_text = format!(
        "{}{}",
        &text[..at],
        text[at..].replace("  elbow_joint:\n", "  elbow_jiont:\n")
    );
    std::fs::write(&bad, bad_text).unwrap();
    common::fails_with(
        &[
            "fk",
            "--robot",
            &robot,
            "--frames",
            bad.to_str().unwrap(),
            "--q",
            "0,0,0,0,0,0",
        ],
        "compliance.elbow_jiont: not a revolute joint of the chain",
    );
}

#[test]
fn an_unmodelled_sag_is_warned_of_when_the_noise_is_stated() {
    use activecal::experiment::measured::{MeasuredSettings, calibrate_measurements};
    let base = panda(MeasurementKind::Point);
    let train = random_qs(&base, 60, 21);
    let (r, real) = compliant(&base, &train);
    let sigma = 5e-5;
    let meas = simulate(&r, &real, &train, sigma, &mut ChaCha8Rng::seed_from_u64(22)).unwrap();
    let settings = |stated: Option<f64>| MeasuredSettings {
        lm: LmSettings::default(),
        loss: activecal::identify::LossChoice::L2,
        fix: Vec::new(),
        restriction: activecal::identify::restriction::Restriction::All,
        free: Vec::new(),
        holdout: None,
        units: activecal::units::Units::default(),
        gravity: None,
        fit_compliance: false,
        compare_compliance: false,
        weights: activecal::identify::Weights::default(),
        outliers: activecal::lsq::outliers::OutlierChoice::default(),
        stated_noise: stated,
        stated_orientation_noise: None,
    };
    // The geometric model only, the tracker's σ stated.
    let c = calibrate_measurements(
        &base,
        &meas,
        "sag",
        Vec::new(),
        &settings(Some(sigma)),
        &mut |_| {},
    )
    .unwrap();
    let t = c.report.noise_test.as_ref().expect("a noise test");
    eprintln!(
        "sag: σ̂ {:.4} mm against the stated {:.4} mm, {:?}",
        t.estimated_m * 1e3,
        sigma * 1e3,
        c.report.outliers.left_out.len()
    );
    assert!(t.rejected && t.ratio > 1.5, "{t:?}");
    let w = c.report.warnings.join(" ");
    assert!(w.contains(activecal::names::phrase::COMPLIANCE), "{w}");
    // The sag is a misfit of every pose, not a glitch: no pose left out.
    assert!(
        c.report.outliers.left_out.is_empty(),
        "{:?}",
        c.report.outliers.left_out
    );
    // The same data from the compliant robot's geometry without sag: no
    // warning (the control: the warning is about the data, not the test).
    let clean = simulate(
        &base,
        &base.real,
        &train,
        sigma,
        &mut ChaCha8Rng::seed_from_u64(22),
    )
    .unwrap();
    let c = calibrate_measurements(
        &base,
        &clean,
        "clean",
        Vec::new(),
        &settings(Some(sigma)),
        &mut |_| {},
    )
    .unwrap();
    assert!(c.report.warnings.is_empty(), "{:?}", c.report.warnings);
}
