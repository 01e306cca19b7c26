//! The head camera's truth gate (issue #41; feature `live`, needs the
//! project venv with Pinocchio and OpenCV, and `target/debug/activecal`):
//! Pinocchio plays the real TIAGo (FIGAROH's `tiago.urdf`, the whole tree:
//! every moving joint on the paths from the root to `head_2_link` and to
//! `arm_tool_link`, the torso's lift too, off by 0.5–2 mm and 0.05–0.3° in
//! random directions, seeded), OpenCV's `projectPoints` its head camera
//! (the Xtion's RGB optical frame on `head_2_link`, a 5 × 7 board of 20 mm
//! squares 8 cm past the tool), `verify/python/head_truth.py`. The poses
//! are those `select --camera-link head_2_link` chooses (30 of 20,000
//! candidates; the torso's lift random in the file, which the camera
//! cannot see); `activecal calibrate --camera-link head_2_link` writes the
//! URDF and the frames file from start placements 2 cm and ~2° off;
//! Pinocchio measures, on the calibrated URDF's whole tree with the frames
//! file's placements, the true error of the board's origin in the
//! camera's frame at 1,000 random configurations of every joint (head,
//! torso, arm). Asserted: noise-free pixels recover the truth to 1e-6 mm;
//! with σ 0.3 px the true RMS over 20 draws is within 1.3× of `select`'s
//! prediction for the design (one draw's error is a quadratic form
//! dominated by a few directions; 20 draws pool about 20× the degrees of
//! freedom).

use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_target::read_target;
use activecal::io::urdf_branch::camera_branch;
use activecal::measure::camera::Mounting;
use activecal::observability::generic_configurations;
use activecal::pool::camera_view::CameraView;
use activecal::select::camera::camera_design;
use serde_json::Value;

use std::process::Command;
use verify::bridge::{python, repo_root as root, run};

/// The true placements (the Xtion's RGB optical frame in `head_2_link`,
/// the board in `arm_tool_link`) and the fit's start (2 cm and ~2° off),
/// as `X,Y,Z,ROLL,PITCH,YAW`.
const CAMERA: &str = "0.0908,0.08,-0.022,-3.141592653589793,-1.5707963267948966,0";
const TARGET: &str = "0.08,-0.04,0.06,0,1.5707963267948966,0";
const CAMERA_START: &str = "0.1008,0.0950,-0.0020,-2.2154,-1.5388,-0.8959";
const TARGET_START: &str = "0.0699,-0.0248,0.0798,-2.2457,1.5388,-2.2154";

/// Noise draws at σ 0.3 px.
const DRAWS: u64 = 20;

#[test]
fn head_camera_calibration_matches_a_true_tiago() {
    let dir = std::env::temp_dir().join(format!("activecal-camera-head-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let r = root();
    let urdf = r.join("fixtures/figaroh/tiago.urdf");
    let info = r.join("fixtures/camera/tiago_xtion.yaml");
    let board = r.join("fixtures/camera/tiago_board.yaml");
    let robot_ref = format!("{}#tip=arm_tool_link", urdf.display());
    let script = r.join("verify/python/head_truth.py");
    let truth = dir.join("truth.json");
    run(python()
        .arg(&script)
        .args([
            "make",
            "--camera-link",
            "head_2_link",
            "--tip",
            "arm_tool_link",
            "--seed",
            "3",
        ])
        .arg("--urdf")
        .arg(&urdf)
        .arg(format!("--camera={CAMERA}"))
        .arg(format!("--target={TARGET}"))
        .arg("--out")
        .arg(&truth));
    // The design select chooses, and its prediction.
    let arm = activecal::io::load_robot(&robot_ref).unwrap();
    let branch = camera_branch(&arm, "head_2_link").unwrap();
    let nums = |s: &str| -> [f64; 6] {
        let v: Vec<f64> = s.split(',').map(|x| x.parse().unwrap()).collect();
        v.try_into().unwrap()
    };
    let view = CameraView {
        intrinsics: read_camera_info(&info).unwrap(),
        mounting: Mounting::EyeToHand,
        face: [0.0, 0.0, 1.0],
        points: read_target(&board)
            .unwrap()
            .points
            .iter()
            .map(|p| [p.x, p.y, p.z])
            .collect(),
        camera: nums(CAMERA),
        target: nums(TARGET),
        min_fraction: 1.0,
        margin_px: 20.0,
        max_view_angle: 60f64.to_radians(),
        distance: [0.25, 1.5],
    };
    let candidates = generic_configurations(&branch, 20_000, 13);
    let settings = activecal::select::Settings::builder()
        .n(30)
        .build()
        .unwrap();
    let d = camera_design(&branch, &view, &candidates, &settings).unwrap();
    let predicted = 1e3 * 0.3 * d.predicted_error_per_px.expect("a regular design");
    let names = activecal::units::joint_names(&branch);
    let mut csv = format!("torso_lift_joint,{}\n", names.join(","));
    for (k, q) in d.qs.iter().enumerate() {
        let lift = 0.35 * ((k * 7919) % 100) as f64 / 100.0;
        let v: Vec<String> = q.iter().map(|v| format!("{v:.17}")).collect();
        csv += &format!("{lift},{}\n", v.join(","));
    }
    let configs = dir.join("q.csv");
    std::fs::write(&configs, csv).unwrap();
    let true_error = |noise: f64, seed: u64| -> f64 {
        let obs = dir.join(format!("obs{seed}.csv"));
        run(python()
            .arg(&script)
            .arg("observe")
            .arg("--truth")
            .arg(&truth)
            .arg("--camera-info")
            .arg(&info)
            .args(["--board", "5,7,0.02", "--noise", &noise.to_string()])
            .args(["--seed", &seed.to_string()])
            .arg("--configs")
            .arg(&configs)
            .arg("--out")
            .arg(&obs));
        let (u, y) = (
            dir.join(format!("cal{seed}.urdf")),
            dir.join(format!("cal{seed}.yaml")),
        );
        run(Command::new(r.join("target/debug/activecal"))
            .args(["calibrate", "--robot", &robot_ref])
            .args(["--camera-link", "head_2_link", "--json", "--force"])
            .arg("--observations")
            .arg(&obs)
            .arg("--camera-info")
            .arg(&info)
            .arg("--target")
            .arg(&board)
            .arg(format!("--camera-pose={CAMERA_START}"))
            .arg(format!("--target-pose={TARGET_START}"))
            .arg("--out")
            .arg(&u)
            .arg("--out")
            .arg(&y));
        let cmp: Value = serde_json::from_str(&run(python()
            .arg(&script)
            .arg("compare")
            .arg("--truth")
            .arg(&truth)
            .arg("--urdf")
            .arg(&u)
            .arg("--frames")
            .arg(&y)
            .args(["--n", "1000", "--seed", "1"])))
        .unwrap();
        cmp["rms_mm"].as_f64().unwrap()
    };
    let exact = true_error(0.0, 0);
    println!("head camera, noise-free: true error {exact:.2e} mm");
    assert!(exact < 1e-6, "noise-free pixels leave {exact} mm");
    let mut ss = 0.0;
    for seed in 1..=DRAWS {
        let t = true_error(0.3, seed);
        println!("σ 0.3 px, draw {seed}: true {t:.4} mm");
        ss += t * t;
    }
    let t = (ss / DRAWS as f64).sqrt();
    println!(
        "head camera: {} of {} candidates visible; RMS over {DRAWS} draws: true {t:.4} mm, select predicts {predicted:.4} mm (ratio {:.2})",
        d.visible,
        candidates.len(),
        t / predicted
    );
    assert!(
        t < 1.3 * predicted && predicted < 1.3 * t,
        "true {t} mm against predicted {predicted} mm"
    );
}
