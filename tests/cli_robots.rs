//! The whole command-line pipeline — `select`, `bound`, `gap` and
//! `calibrate` — on every built-in arm and on imported URDFs, for point and
//! for full-pose measurements: one test per robot, each going from a robot
//! name or file to a calibrated model.
//!
//! Tolerances. Zero-noise calibration recovers the unknowns to ~1e-12 (the
//! step tolerance is 1e-10 relative); 1e-8 separates that from a wrong
//! residual or row, which stalls at ≥ 1e-6. The bound is solved to a gap of
//! 1e-2 in ln det by the first-order solver alone (it is an upper bound at
//! any gap; the exact solve is tested in `tests/bound.rs`), which keeps each
//! robot's pipeline to a few seconds.

use crate::common;

use common::{fails_with, json_of, run};
use serde_json::Value;
use std::path::PathBuf;

fn f(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing in {v}"))
}

/// A fresh scratch directory for one robot's files.
fn scratch(tag: &str) -> PathBuf {
    common::scratch_dir("cli-robots", tag)
}

/// select → bound → gap → calibrate (exact and noisy) for one robot with
/// `p` unknowns. `exact`: the real robot differs from the nominal one in the
/// unknowns only, so zero-noise calibration must return the real values;
/// otherwise (a description with deviations in parameters that the minimal
/// set absorbs) it must reproduce the real robot's positions.
fn pipeline(robot: &str, tag: &str, pose: bool, p: usize) {
    pipeline_with(robot, tag, pose, p, true);
}

fn pipeline_with(robot: &str, tag: &str, pose: bool, p: usize, exact: bool) {
    let dir = scratch(tag);
    let design = dir.join("design.json");
    let d = design.to_str().unwrap();

    // ---- select: a 30-pose design of the 3-level lattice, written to a file.
    let sel = json_of(&[
        "select",
        "--robot",
        robot,
        "--levels",
        "3",
        "--out",
        d,
        "--gap",
        "--gap-solver",
        "newton",
        "--json",
    ]);
    assert_eq!(sel["bound_status"], "certified", "{robot}");
    assert_eq!(sel["poses"].as_array().unwrap().len(), 30, "{robot}");
    let ln_oid = f(&sel, "ln_oid");
    assert!(ln_oid.is_finite(), "{robot}: {sel}");
    let file: Value = serde_json::from_str(&std::fs::read_to_string(&design).unwrap()).unwrap();
    assert_eq!(file["robot"], robot);

    // ---- bound over the same pool, and the design's gap to it.
    let b = json_of(&[
        "bound",
        "--robot",
        robot,
        "--levels",
        "3",
        "--first-order",
        "--gap-tol",
        "1e-2",
        "--json",
    ]);
    assert_eq!(b["p"].as_u64(), Some(p as u64), "{robot}");
    let ln_bound = f(&b, "ln_bound");
    assert!(
        ln_bound >= ln_oid - 1e-9,
        "{robot}: bound {ln_bound} < design {ln_oid}"
    );
    let g = json_of(&[
        "gap",
        "--design",
        d,
        "--first-order",
        "--gap-tol",
        "1e-2",
        "--json",
    ]);
    let eff = f(&g, "d_efficiency");
    assert!(eff > 0.0 && eff <= 1.0, "{robot}: D-efficiency {eff}");
    // `select --gap` (Newton, certified to 1e-6) and `gap` (first order,
    // 1e-2) bound the same relaxation: their D-efficiencies differ by at
    // most the looser gap, e^(1e-2/p) − 1 < 1e-2/p relative.
    let eff_sel = f(&sel, "d_efficiency");
    assert!(
        eff_sel >= eff && eff_sel <= eff * (1.0 + 1e-2 / p as f64) + 1e-12,
        "{robot}: {eff_sel} vs {eff}"
    );
    println!("{robot}: p = {p}, ln OI_D {ln_oid:.3} ≤ bound {ln_bound:.3}, D-eff {eff:.4}");

    // ---- calibrate without noise: the real unknowns, exactly.
    let c = json_of(&[
        "calibrate",
        "--robot",
        robot,
        "--design",
        d,
        "--noise",
        "0",
        "--validation",
        "50",
        "--json",
    ]);
    assert_eq!(c["converged"], true, "{robot}: {c}");
    assert_eq!(c["measurement"], if pose { "pose" } else { "point" });
    let residual = c["residual"].as_object().unwrap();
    assert_eq!(residual.len(), p);
    let worst = residual
        .values()
        .map(|v| v.as_f64().unwrap().abs())
        .fold(0.0, f64::max);
    if exact {
        assert!(worst < 1e-8, "{robot}: max |real − estimate| {worst:e}");
    }
    assert!(f(&c, "rss") < 1e-16, "{robot}: rss {}", c["rss"]);
    assert!(f(&c, "validation_rms_after") < 1e-8, "{robot}");
    assert!(f(&c, "validation_rms_before") > 1e-4, "{robot}");
    if pose {
        assert!(f(&c, "validation_orientation_rms_after") < 1e-8, "{robot}");
        assert!(f(&c, "validation_orientation_rms_before") > 1e-4, "{robot}");
    } else {
        assert!(c["validation_orientation_rms_after"].is_null(), "{robot}");
    }

    // ---- calibrate with 0.2 mm noise, a few Monte-Carlo trials: the error
    // after calibration is what the covariance predicts (within 50% on 10
    // trials × 50 poses) and far below the nominal model's.
    let c = json_of(&[
        "calibrate",
        "--robot",
        robot,
        "--design",
        d,
        "--noise",
        "0.0002",
        "--trials",
        "10",
        "--validation",
        "50",
        "--json",
    ]);
    let mc = &c["monte_carlo"];
    assert_eq!(mc["converged"], 10, "{robot}: {mc}");
    let after = f(&mc["validation_rms_after"], "median");
    let predicted = f(mc, "validation_rms_predicted");
    assert!(
        (after / predicted - 1.0).abs() < 0.5,
        "{robot}: {after} vs predicted {predicted}"
    );
    assert!(after < 0.2 * f(mc, "validation_rms_before"), "{robot}");
    if pose {
        let after = f(&mc["validation_orientation_rms_after"], "median");
        let predicted = f(mc, "validation_orientation_rms_predicted");
        assert!(
            (after / predicted - 1.0).abs() < 0.5,
            "{robot}: orientation {after} vs predicted {predicted}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn puma560_point() {
    pipeline("puma560", "puma", false, 27);
}

#[test]
fn puma560_pose() {
    pipeline("puma560:pose", "puma-pose", true, 30);
}

#[test]
fn ur5_point() {
    pipeline("ur5", "ur5", false, 27);
}

#[test]
fn ur5_pose() {
    pipeline("ur5:pose", "ur5-pose", true, 30);
}

#[test]
fn stanford_point() {
    pipeline("stanford", "stanford", false, 25);
}

#[test]
fn stanford_pose() {
    pipeline("stanford:pose", "stanford-pose", true, 28);
}

#[test]
fn imported_ur5_urdf_point() {
    pipeline("fixtures/ur5.urdf", "ur5-urdf", false, 27);
}

#[test]
fn imported_stanford_urdf_point() {
    pipeline("fixtures/stanford.urdf", "stanford-urdf", false, 25);
}

/// A description that imports `ur5.urdf` with full-pose measurements and a
/// visibility region.
#[test]
fn imported_ur5_urdf_pose() {
    pipeline("fixtures/ur5_pose.toml", "ur5-urdf-pose", true, 30);
}

/// A URDF imported for full poses by the `:pose` suffix on its path.
#[test]
fn imported_stanford_urdf_pose_by_suffix() {
    pipeline(
        "fixtures/stanford.urdf:pose",
        "stanford-urdf-pose",
        true,
        28,
    );
}

/// The hand-written SCARA description: parallel axes, a prismatic quill,
/// and real deviations in parameters outside the automatic minimal set
/// (which the unknowns absorb: the fit is exact, the values differ).
#[test]
fn scara_description_point() {
    pipeline_with("fixtures/scara.toml", "scara", false, 17, false);
}

/// Real data: simulated full-pose measurements saved to a file and
/// calibrated from it give the same estimate as the simulation run; the
/// calibrated robot written as a description reproduces the real robot;
/// nothing is overwritten without `--force`; bad measurement files are
/// clear errors naming the file.
#[test]
fn calibrate_from_a_measurement_file_and_write_the_calibrated_robot() {
    let dir = scratch("measurements");
    let path = |n: &str| dir.join(n).to_str().unwrap().to_string();
    let (design, meas, out1, out2) = (
        path("d.json"),
        path("m.json"),
        path("cal1.toml"),
        path("cal2.toml"),
    );
    json_of(&[
        "select", "--robot", "ur5:pose", "--levels", "3", "--out", &design, "--json",
    ]);
    let sim = json_of(&[
        "calibrate",
        "--robot",
        "ur5:pose",
        "--design",
        &design,
        "--noise",
        "0.001",
        "--validation",
        "20",
        "--save-measurements",
        &meas,
        "--out",
        &out1,
        "--json",
    ]);
    // The simulation weighs orientations by the robot's fixed scale (its
    // noise is known); the same weights on the measured side.
    let real = json_of(&[
        "calibrate",
        "--robot",
        "ur5:pose",
        "--measurements",
        &meas,
        "--weights",
        "fixed",
        "--out",
        &out2,
        "--json",
    ]);
    assert_eq!(real["converged"], true);
    assert_eq!(real["poses"], 30);
    // Same data, same solver: the same estimate to the last bit (JSON
    // numbers round-trip f64 exactly).
    assert_eq!(sim["estimate"], real["estimate"]);
    assert_eq!(sim["std"], real["std"]);
    assert!(f(&real, "rms_residual") < f(&real, "initial_rms_residual"));
    // Both written models are the same robot; with 1 mm noise its positions
    // are within a few mm of the real robot's (the nominal is ~1 cm off).
    assert_eq!(
        std::fs::read_to_string(&out1)
            .unwrap()
            .lines()
            .skip(2)
            .collect::<Vec<_>>(),
        std::fs::read_to_string(&out2)
            .unwrap()
            .lines()
            .skip(2)
            .collect::<Vec<_>>()
    );
    let q = "0.3,-1.1,0.7,0.2,-0.5,1.0";
    let fk = |robot: &str, params: &str| -> Vec<f64> {
        let v = json_of(&[
            "fk", "--robot", robot, "--q", q, "--params", params, "--json",
        ]);
        v["position"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let (cal, truth, nominal) = (
        fk(&out2, "nominal"),
        fk("ur5:pose", "real"),
        fk("ur5:pose", "nominal"),
    );
    let dist = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    println!(
        "calibrated model {:.2e} m from the real robot, nominal {:.2e} m",
        dist(&cal, &truth),
        dist(&nominal, &truth)
    );
    assert!(dist(&cal, &truth) < 0.3 * dist(&nominal, &truth));

    // Nothing is overwritten without asking, and the refusal comes first.
    let before = std::fs::read_to_string(&out2).unwrap();
    fails_with(
        &[
            "calibrate",
            "--robot",
            "ur5:pose",
            "--measurements",
            &meas,
            "--out",
            &out2,
        ],
        "pass --force",
    );
    assert_eq!(std::fs::read_to_string(&out2).unwrap(), before);
    json_of(&[
        "calibrate",
        "--robot",
        "ur5:pose",
        "--measurements",
        &meas,
        "--out",
        &out2,
        "--force",
        "--json",
    ]);

    // An estimate that did not converge is reported but never written as a
    // calibrated model, and the exit status says so.
    let unconverged = path("unconverged.toml");
    let out = run(&[
        "calibrate",
        "--robot",
        "ur5:pose",
        "--measurements",
        &meas,
        "--max-iterations",
        "1",
        "--out",
        &unconverged,
        "--json",
    ]);
    // 3: calibrate's own status for a fit that did not converge (README).
    assert_eq!(out.status.code(), Some(3));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["converged"], false);
    assert_eq!(v["exit_status"], 3);
    assert!(v["out"].is_null());
    assert!(String::from_utf8_lossy(&out.stderr).contains("was not written"));
    assert!(!std::path::Path::new(&unconverged).exists());

    // Bad measurement files.
    let text = std::fs::read_to_string(&meas).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let bad = |name: &str, body: String| {
        let p = path(name);
        std::fs::write(&p, body).unwrap();
        p
    };
    let not_json = bad("broken.json", text[..text.len() / 2].to_string());
    fails_with(
        &[
            "calibrate",
            "--robot",
            "ur5:pose",
            "--measurements",
            &not_json,
        ],
        "broken.json: EOF",
    );
    let typo = bad("typo.json", text.replacen("\"points\"", "\"pionts\"", 1));
    fails_with(
        &["calibrate", "--robot", "ur5:pose", "--measurements", &typo],
        "unknown field `pionts`",
    );
    v["orientations"][4][0][0] = serde_json::json!(-1.0);
    let reflected = bad("reflected.json", v.to_string());
    fails_with(
        &[
            "calibrate",
            "--robot",
            "ur5:pose",
            "--measurements",
            &reflected,
        ],
        "measurement 4: the orientation is not a rotation matrix",
    );
    fails_with(
        &["calibrate", "--robot", "ur5", "--measurements", &meas],
        "m.json: the measurements are of robot 'ur5:pose', not 'ur5'",
    );
    // Without the robot's name the file is read on its content alone: its
    // orientations make the point robot's calibration a full-pose one (by
    // construction, with a note), fitting the same 30 unknowns as ur5:pose.
    let mut anon: serde_json::Value = serde_json::from_str(&text).unwrap();
    anon.as_object_mut().unwrap().remove("robot");
    let anon = bad("anonymous.json", anon.to_string());
    let adapted = json_of(&[
        "calibrate",
        "--robot",
        "ur5",
        "--measurements",
        &anon,
        "--json",
    ]);
    assert_eq!(adapted["measurement"], "pose");
    assert_eq!(adapted["parameters"].as_array().unwrap().len(), 30);
    assert!(
        adapted["notes"][0]
            .as_str()
            .unwrap()
            .contains("calibrated from full poses"),
        "{}",
        adapted["notes"]
    );
    json_of(&[
        "calibrate",
        "--robot",
        "ur5:pose",
        "--measurements",
        &anon,
        "--json",
    ]);
    fails_with(
        &[
            "calibrate",
            "--robot",
            "puma560:pose",
            "--measurements",
            &meas,
        ],
        "m.json: the measurements are of robot 'ur5:pose', not 'puma560:pose'",
    );
    fails_with(
        &[
            "calibrate",
            "--robot",
            "ur5:pose",
            "--measurements",
            &meas,
            "--trials",
            "5",
        ],
        "cannot be used with",
    );
    fails_with(&["calibrate", "--robot", "ur5:pose"], "--design");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `robots --export` writes a description that loads back as the same robot;
/// editing its `orientation_scale` changes the design criterion the way the
/// weighting says (orientation rows × w), and exports never overwrite
/// without `--force`.
#[test]
fn exported_descriptions_load_and_carry_the_orientation_scale() {
    let dir = scratch("export");
    let file = dir.join("ur5pose.toml");
    let f_str = file.to_str().unwrap();
    let out = run(&["robots", "--export", "ur5:pose", "--out", f_str]);
    assert!(out.status.success() && out.stdout.is_empty());
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.contains("orientation_scale = 1.0"), "{text}");
    let score = |robot: &str| {
        let v = json_of(&[
            "score",
            "--robot",
            robot,
            "--levels",
            "3",
            "--poses",
            "0,5,17,40,77,101,150,222,300,333,400,444,500,555,600,650,700,710,720,728",
            "--json",
        ]);
        f(&v, "ln_oid")
    };
    let builtin = score("ur5:pose");
    assert_eq!(score(f_str), builtin, "the export is the same robot");
    std::fs::write(
        &file,
        text.replace("orientation_scale = 1.0", "orientation_scale = 0.5"),
    )
    .unwrap();
    let weighted = score(f_str);
    // Halving the orientation rows lowers ln det XᵀX, and by at most
    // 2p ln 2 (XᵀD²X ⪰ w² XᵀX with D = diag(1, 1, 1, w, w, w), p = 30).
    assert!(weighted < builtin - 1.0, "{weighted} vs {builtin}");
    assert!(weighted > builtin - 30.0 * 2.0 * std::f64::consts::LN_2);
    fails_with(
        &["robots", "--export", "ur5", "--out", f_str],
        "pass --force",
    );
    assert!(
        std::fs::read_to_string(&file)
            .unwrap()
            .contains("orientation_scale = 0.5")
    );
    fails_with(&["robots", "--export", "nosuch"], "unknown robot 'nosuch'");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `robots` on a URDF says that its "real" rows are made up (a URDF has
/// no measured values), within the bound it states; the paper's PUMA,
/// whose real values are the paper's, has no such line.
#[test]
fn robots_explains_a_urdf_s_made_up_real_rows() {
    let out = run(&[
        "robots",
        "--robot",
        "fixtures/example-robot-data/ur5_robot.urdf",
        "--tip",
        "tool0",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("real: not your robot — the URDF's values with a made-up error of at most 5 mm or 5 mrad on each unknown"),
        "{text}"
    );
    // Each frame's real row, then its nominal row: the differences are
    // within the stated 5 mm / 5 mrad, and some are not zero.
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| l.contains(" real ") || l.contains(" nom "))
        .map(|l| {
            let tail = l
                .split(if l.contains(" real ") {
                    " real "
                } else {
                    " nom "
                })
                .nth(1)
                .unwrap();
            tail.split_whitespace()
                .map(|v| v.parse().unwrap())
                .collect()
        })
        .collect();
    assert!(rows.len() >= 14 && rows.len() % 2 == 0, "{text}");
    let mut largest: f64 = 0.0;
    for pair in rows.chunks(2) {
        for (r, n) in pair[0].iter().zip(&pair[1]) {
            largest = largest.max((r - n).abs());
        }
    }
    // Printed to 1e-4.
    assert!(largest > 1e-3 && largest <= 5e-3 + 1e-4, "{largest}");
    let out = run(&["robots", "--robot", "puma560"]);
    assert!(!String::from_utf8_lossy(&out.stdout).contains("made-up"));
}
