//! A checkerboard's corners detected in another order (OpenCV's
//! `findChessboardCorners` on a 180°-symmetric board reverses them in
//! about half the images; a board seen from behind has its rows
//! mirrored): each pose's labelling is chosen by the robot's motion
//! (`activecal::identify::camera::start::labels`), and the calibration
//! equals the one from the file in the right order.

use crate::common;
use std::collections::BTreeSet;

const ROWS: i64 = 6;
const COLS: i64 = 8;

/// The example's `calibrate --json` on `observations`, the start computed
/// from the pixels.
fn calibrate(observations: &str) -> serde_json::Value {
    common::json_of(&[
        "calibrate",
        "--robot",
        "fixtures/ur5.urdf",
        "--observations",
        observations,
        "--camera-info",
        "fixtures/camera/camera_info.yaml",
        "--target",
        "fixtures/camera/board.yaml",
        "--mounting",
        "eye-to-hand",
        "--json",
    ])
}

/// The example's observations with the corners of the poses `turned`
/// labelled turned 180° and those of `mirrored` with their rows
/// mirrored, written to the scratch directory `name`.
fn altered(name: &str, turned: &BTreeSet<i64>, mirrored: &BTreeSet<i64>) -> String {
    let text = std::fs::read_to_string("fixtures/camera/ur5_eye_to_hand.csv").unwrap();
    let mut lines = text.lines();
    let mut out = lines.next().unwrap().to_string() + "\n";
    for l in lines {
        let mut c: Vec<String> = l.split(',').map(str::to_string).collect();
        let (pose, k): (i64, i64) = (c[0].parse().unwrap(), c[7].parse().unwrap());
        let (i, j) = (k / COLS, k % COLS);
        if turned.contains(&pose) {
            c[7] = ((ROWS - 1 - i) * COLS + (COLS - 1 - j)).to_string();
        } else if mirrored.contains(&pose) {
            c[7] = ((ROWS - 1 - i) * COLS + j).to_string();
        }
        out += &(c.join(",") + "\n");
    }
    let dir = common::scratch_dir("camera_labels", name);
    let path = dir.join("altered.csv");
    std::fs::write(&path, out).unwrap();
    path.display().to_string()
}

/// Half the 40 poses altered (18 turned 180°, 2 with their rows
/// mirrored): the report lists exactly those poses with their labelling,
/// none is dropped, and the calibration equals the one on the file in
/// the right order to 1e-6 of each unknown's σ and σ̂ to 1e-9 relative
/// (the relabelled observations are the same pixels at the same points,
/// so the fit sees the same numbers: only rounding in the start's
/// per-pose PnP may differ, far below 1e-6 σ).
#[test]
fn reversed_and_mirrored_poses_are_relabelled() {
    let mirrored: BTreeSet<i64> = [1, 5].into();
    let turned: BTreeSet<i64> = (1..40)
        .step_by(2)
        .filter(|p| !mirrored.contains(p))
        .collect();
    let right = calibrate("fixtures/camera/ur5_eye_to_hand.csv");
    assert_eq!(
        right["relabelled"].as_array().map(Vec::len),
        Some(0),
        "{right}"
    );
    let v = calibrate(&altered("half", &turned, &mirrored));
    let listed: Vec<(i64, String)> = v["relabelled"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["pose"].as_i64().unwrap(),
                r["labelling"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    let expected: Vec<(i64, String)> = (1..40)
        .step_by(2)
        .map(|p| {
            let l = if mirrored.contains(&p) {
                "rows mirrored"
            } else {
                "turned 180°"
            };
            (p, l.to_string())
        })
        .collect();
    assert_eq!(listed, expected);
    assert_eq!(v["dropped_poses"].as_array().map(Vec::len), Some(0), "{v}");
    assert_eq!(v["exit_status"], 0, "{v}");
    let (s0, s1) = (
        right["sigma_px"].as_f64().unwrap(),
        v["sigma_px"].as_f64().unwrap(),
    );
    assert!((s1 / s0 - 1.0).abs() < 1e-9, "σ̂ {s1} vs {s0}");
    let f = |v: &serde_json::Value, k: &str| -> Vec<f64> {
        v[k].as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let (e0, e1, sd) = (f(&right, "estimate"), f(&v, "estimate"), f(&right, "std"));
    for k in 0..e0.len() {
        assert!(
            (e1[k] - e0[k]).abs() <= 1e-6 * sd[k],
            "unknown {k}: {} vs {} (σ {})",
            e1[k],
            e0[k],
            sd[k]
        );
    }
}

/// One pose of 40 turned 180°: just that pose is relabelled (the
/// majority's order is kept as the detector's).
#[test]
fn a_single_turned_pose_is_found() {
    let v = calibrate(&altered("one", &[7].into(), &BTreeSet::new()));
    let r = v["relabelled"].as_array().unwrap();
    assert_eq!(r.len(), 1, "{v}");
    assert_eq!(
        (r[0]["pose"].as_i64(), r[0]["labelling"].as_str()),
        (Some(7), Some("turned 180°"))
    );
}
