//! Units that cannot go wrong silently: FIGAROH's UR10 full-pose data with
//! the joint columns in degrees, or the positions in millimetres, are
//! refused with a message naming the unit and the option to give; with the
//! option, the result is the radian-and-metre file's. One rule for every
//! reader of joint values: pool files, `--existing`, `fk --q`.
//!
//! The converted files are written into a scratch directory by the test.

use crate::common;

use common::{json_of, run};
use serde_json::Value;
use std::path::PathBuf;

const UR10: &str = "fixtures/figaroh/ur10_robot.urdf:pose";
const UR10_CSV: &str = "fixtures/figaroh/ur10_full_pose.csv";
const JOINTS: [&str; 6] = [
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
];

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("activecal-units-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// The UR10 CSV with the named columns multiplied by `factor` (full
/// precision: `{:e}` prints the shortest round-trip decimal).
fn converted(name: &str, columns: &[&str], factor: f64) -> String {
    let text = std::fs::read_to_string(UR10_CSV).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let scale: Vec<bool> = header.iter().map(|h| columns.contains(h)).collect();
    let mut out = header.join(",") + "\n";
    for l in lines.filter(|l| !l.trim().is_empty()) {
        let cells: Vec<String> = l
            .split(',')
            .zip(&scale)
            .map(|(c, &s)| {
                let v: f64 = c.trim().parse().unwrap();
                if s {
                    format!("{:e}", v * factor)
                } else {
                    c.to_string()
                }
            })
            .collect();
        out += &(cells.join(",") + "\n");
    }
    let path = scratch(name);
    std::fs::write(&path, out).unwrap();
    path.display().to_string()
}

fn calibrate(file: &str, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "--tip",
        "wrist_3_link",
        "calibrate",
        "--robot",
        UR10,
        "--measurements",
        file,
        "--json",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn evaluate(file: &str, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "--tip",
        "wrist_3_link",
        "evaluate",
        "--robot",
        UR10,
        "--measurements",
        file,
        "--json",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn args(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// Exits 1 (an error, not a panic) with every word in stderr.
fn refused(a: &[String], words: &[&str]) {
    let out = run(&args(a));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{a:?}: {err}");
    for w in words {
        assert!(err.contains(w), "{a:?}: '{err}' lacks '{w}'");
    }
}

/// The numbers of two reports agree to `tol` (relative to max(1, |x|)),
/// recursively, skipping the fields that name the file or time the run.
fn same_numbers(a: &Value, b: &Value, tol: f64, path: &str) {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            // The calibrated frames are in millimetres and degrees (a
            // 1e-9 agreement of metre-size estimates is 1e-6 mm), and
            // their σ come through central differences of step 1e-6
            // (1e-8 relative noise).
            let tol = if path.contains(".frames") {
                tol.max(1e-6)
            } else {
                tol
            };
            if path.contains(".frames") && (path.contains("sigma") || path.contains("max_t")) {
                // A σ is a three-digit figure; a gauge-fixed one is ~1e-5
                // mm of difference-quotient noise.
                assert!(
                    (x - y).abs() <= 1e-3 * x.abs().max(y.abs()) + 1e-4,
                    "{path}: {x} vs {y}"
                );
                return;
            }
            assert!(
                (x - y).abs() <= tol * x.abs().max(1.0),
                "{path}: {x} vs {y}"
            );
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{path}");
            for (i, (p, q)) in x.iter().zip(y).enumerate() {
                same_numbers(p, q, tol, &format!("{path}[{i}]"));
            }
        }
        (Value::Object(x), Value::Object(y)) => {
            for (k, p) in x {
                if ["measurements", "elapsed_seconds", "notes"].contains(&k.as_str()) {
                    continue;
                }
                same_numbers(p, &y[k], tol, &format!("{path}.{k}"));
            }
        }
        _ => assert_eq!(a, b, "{path}"),
    }
}

// Equal to 1e-9: the files hold the same values up to one rounding of the
// conversion (1e-16 relative), which the fit carries to the estimate
// amplified by at most the condition number of the column-scaled problem
// (below 1e6 here): far below 1e-9.
const SAME: f64 = 1e-9;

#[test]
fn joint_columns_in_degrees_are_refused_and_read_with_angle_unit_deg() {
    let deg = converted("ur10_deg.csv", &JOINTS, 180.0 / std::f64::consts::PI);
    for a in [calibrate(&deg, &[]), evaluate(&deg, &[])] {
        refused(
            &a,
            &["degrees", "--angle-unit deg", "ur10_deg.csv", "line "],
        );
    }
    let base = json_of(&args(&calibrate(UR10_CSV, &[])));
    let with = json_of(&args(&calibrate(&deg, &["--angle-unit", "deg"])));
    assert_eq!(base["status"], "converged");
    same_numbers(&base, &with, SAME, "calibrate");
    let base = json_of(&args(&evaluate(UR10_CSV, &[])));
    let with = json_of(&args(&evaluate(&deg, &["--angle-unit", "deg"])));
    same_numbers(&base, &with, SAME, "evaluate");
}

#[test]
fn positions_in_millimetres_are_refused_and_read_with_length_unit_mm() {
    let mm = converted("ur10_mm.csv", &["x1", "y1", "z1"], 1e3);
    for a in [calibrate(&mm, &[]), evaluate(&mm, &[])] {
        refused(
            &a,
            &["millimetres", "--length-unit mm", "ur10_mm.csv", "reach"],
        );
    }
    let base = json_of(&args(&calibrate(UR10_CSV, &[])));
    let with = json_of(&args(&calibrate(&mm, &["--length-unit", "mm"])));
    same_numbers(&base, &with, SAME, "calibrate");
    let base = json_of(&args(&evaluate(UR10_CSV, &[])));
    let with = json_of(&args(&evaluate(&mm, &["--length-unit", "mm"])));
    same_numbers(&base, &with, SAME, "evaluate");
}

#[test]
fn every_reader_of_joint_values_applies_the_same_rule() {
    let deg = converted("ur10_pool_deg.csv", &JOINTS, 180.0 / std::f64::consts::PI);
    let pool = format!("file:{deg}");
    let select = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "--tip",
            "wrist_3_link",
            "select",
            "--robot",
            UR10,
            "--pool",
            &pool,
            "--n",
            "8",
            "--json",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    refused(
        &select(&[]),
        &["degrees", "--angle-unit deg", "ur10_pool_deg.csv"],
    );
    let rad = json_of(&args(&{
        let mut a = select(&[]);
        a[6] = format!("file:{UR10_CSV}");
        a
    }));
    let from_deg = json_of(&args(&select(&["--angle-unit", "deg"])));
    assert_eq!(rad["poses"], from_deg["poses"]);
    // `fk --q`: 143 (degrees) on a joint limited to ±160°.
    let out = run(&["fk", "--robot", "ur5", "--q", "0.1,-0.2,143,0,0,0"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("143") && err.contains("--q") && err.contains("--angle-unit deg"),
        "{err}"
    );
    let a = json_of(&[
        "fk",
        "--robot",
        "ur5",
        "--q",
        "10,-20,143,0,0,0",
        "--angle-unit",
        "deg",
        "--json",
    ]);
    let b = json_of(&[
        "fk",
        "--robot",
        "ur5",
        "--q",
        "10,-20,143,0,0,0",
        "--deg",
        "--json",
    ]);
    assert_eq!(a["position"], b["position"]);
}
