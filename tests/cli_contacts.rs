//! `calibrate --measurements` on a contact file (a `point` column): the
//! JSON report, held out by placement, and bad inputs with their messages.

use crate::common;
use common::{fails_with, json_of};

const URDF: &str = "fixtures/mukca/panda.urdf";
const DATA: &str = "fixtures/mukca/panda_2.csv";

/// `--point-distance P/0,P/1=0.05` for every placement of `panda_2`.
fn distances() -> Vec<String> {
    [
        "back_left",
        "back_right",
        "front_center",
        "front_left",
        "front_right",
        "high",
        "mid-high",
        "mid_left",
        "mid_right",
    ]
    .iter()
    .flat_map(|p| ["--point-distance".to_string(), format!("{p}/0,{p}/1=0.05")])
    .collect()
}

/// The JSON names the gauge among the fixed unknowns, gives in-sample and
/// held-out figures in mm, and exit status 0. Leave-one-out held-out mean
/// 0.420 mm (the bar 0.42 mm; `tests/point_coincidence.rs` checks
/// the figures in detail).
#[test]
fn contacts_calibrate_and_hold_out_by_placement() {
    let mut args = vec![
        "calibrate",
        "--robot",
        URDF,
        "--tip",
        "ball_link",
        "--measurements",
        DATA,
        "--holdout-by",
        "placement",
        "--json",
    ];
    let d = distances();
    args.extend(d.iter().map(String::as_str));
    let v = json_of(&args);
    assert_eq!(v["exit_status"], 0);
    assert_eq!(v["rows"], 559);
    let fixed = v["fit"]["fixed"].as_array().unwrap();
    assert!(fixed.iter().any(|f| f["name"] == "gamma_panda_joint1"
        && f["reason"].as_str().unwrap().contains("rigid motion")));
    assert!(v["in_sample"]["nominal_mm"].as_f64().unwrap() > 8.0);
    assert!(v["in_sample"]["calibrated_mm"].as_f64().unwrap() < 0.6);
    let h = &v["holdout"];
    assert_eq!(h["folds"].as_array().unwrap().len(), 9);
    assert!(h["mean_calibrated_mm"].as_f64().unwrap() <= 0.42);
}

/// Bad inputs: a distance naming no point of the file, a holding out on a
/// file of measured points, a malformed distance.
#[test]
fn contact_bad_inputs() {
    let base = [
        "calibrate",
        "--robot",
        URDF,
        "--tip",
        "ball_link",
        "--measurements",
        DATA,
    ];
    let mut a = base.to_vec();
    a.extend(["--point-distance", "front_left/0,front_left/7=0.05"]);
    fails_with(&a, "has no point 'front_left/7'");
    let mut a = base.to_vec();
    a.extend(["--point-distance", "front_left/0=0.05"]);
    fails_with(&a, "expected A,B=METRES");
    fails_with(
        &[
            "calibrate",
            "--robot",
            "fixtures/ur5.urdf",
            "--measurements",
            "fixtures/figaroh/ur10_full_pose.csv",
            "--holdout-by",
            "placement",
        ],
        "are for contact files",
    );
}
