//! A camera as the sensor from the command line: `calibrate
//! --observations` on the example files of `fixtures/camera` (written by
//! `cargo run --example camera_simulate`), its refusals of wrong inputs,
//! and `select --camera-info`.

use crate::common;
use nalgebra::Vector3;

const EXAMPLE: [&str; 14] = [
    "calibrate",
    "--robot",
    "fixtures/ur5.urdf",
    "--observations",
    "fixtures/camera/ur5_eye_to_hand.csv",
    "--camera-info",
    "fixtures/camera/camera_info.yaml",
    "--target",
    "fixtures/camera/board.yaml",
    "--mounting",
    "eye-to-hand",
    "--camera-pose=1.1761,0.6096,0.9079,-2.0681,0.0317,2.0826",
    "--target-pose=-0.1047,0.0411,0.0301,3.1111,-0.0192,0.0556",
    "--json",
];

/// The example files (`cargo run --example camera_simulate`: σ 0.3 px, the
/// camera at (1.2, 0.6, 0.9) m) calibrate from the command line: σ
/// estimated within 5 % (3810 degrees of freedom: σ̂'s spread ≈ 1.1 %),
/// the camera placed within 1 mm of the truth (its σ is ≈ 0.2 mm), and
/// the URDF and the frames file (read back by the frames reader) written.
#[test]
fn cli_calibrates_the_example_files() {
    let dir = common::scratch_dir("camera", "cli");
    let (urdf, yaml) = (dir.join("cal.urdf"), dir.join("cal.yaml"));
    let mut args = EXAMPLE.to_vec();
    let (u, y) = (urdf.display().to_string(), yaml.display().to_string());
    args.extend(["--out", &u, "--out", &y]);
    let v = common::json_of(&args);
    assert_eq!(v["converged"], true, "{v}");
    let s = v["sigma_px"].as_f64().unwrap();
    assert!((s / 0.3 - 1.0).abs() < 0.05, "σ {s} px");
    let xyz: Vec<f64> = v["camera"]["camera"]["xyz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let miss = (Vector3::new(xyz[0], xyz[1], xyz[2]) - Vector3::new(1.2, 0.6, 0.9)).norm();
    assert!(miss < 1e-3, "camera {xyz:?}: {} mm off", 1e3 * miss);
    let text = std::fs::read_to_string(&yaml).unwrap();
    assert!(
        text.contains("camera:") && text.contains("pixel_sigma_px"),
        "{text}"
    );
    activecal::io::frames_file::parse(&text, "cal.yaml").expect("the frames reader reads it");
    assert!(
        std::fs::read_to_string(&urdf)
            .unwrap()
            .contains("shoulder_pan_joint")
    );
}

/// Wrong inputs on the command line: an intrinsics file with a negative
/// focal length, one without its distortion model (refused with its
/// line and the accepted values, not read as plumb_bob), degrees in the
/// joint columns, a missing option.
#[test]
fn cli_refuses_wrong_inputs() {
    let dir = common::scratch_dir("camera", "wrong");
    let info = dir.join("bad.yaml");
    let text = std::fs::read_to_string("fixtures/camera/camera_info.yaml").unwrap();
    std::fs::write(&info, text.replace("[1000.0", "[-1000.0")).unwrap();
    let info = info.display().to_string();
    let mut args = EXAMPLE.to_vec();
    args[6] = &info;
    common::fails_with(
        &args,
        "bad.yaml: line 5, column 3 ('camera_matrix'): focal lengths",
    );
    let unnamed = dir.join("unnamed.yaml");
    std::fs::write(&unnamed, text.replace("distortion_model: plumb_bob\n", "")).unwrap();
    let unnamed = unnamed.display().to_string();
    let mut args = EXAMPLE.to_vec();
    args[6] = &unnamed;
    common::fails_with(
        &args,
        "unnamed.yaml: line 9, column 3 ('distortion_coefficients'): no 'distortion_model': name the model of the coefficients, 'distortion_model: plumb_bob' (k1, k2, p1, p2, k3) or 'distortion_model: equidistant'",
    );
    let obs = dir.join("deg.csv");
    let csv = std::fs::read_to_string("fixtures/camera/ur5_eye_to_hand.csv").unwrap();
    let deg: String = csv
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut c: Vec<String> = l.split(',').map(str::to_string).collect();
            if i > 0 {
                for v in &mut c[1..7] {
                    *v = v.parse::<f64>().unwrap().to_degrees().to_string();
                }
            }
            c.join(",") + "\n"
        })
        .collect();
    std::fs::write(&obs, deg).unwrap();
    let obs = obs.display().to_string();
    let mut args = EXAMPLE.to_vec();
    args[4] = &obs;
    common::fails_with(&args, "--angle-unit deg");
    // --camera-pose and --target-pose are optional (the start computed
    // from the pixels, tests/camera_start.rs); --target is not.
    let mut no_target = EXAMPLE.to_vec();
    no_target.drain(7..9);
    common::fails_with(
        &no_target,
        "required arguments were not provided:\n  --target <FILE>",
    );
}

/// `select` for a camera: the chosen poses each see the whole board, one
/// CSV row a pose with its points seen; an existing --out is refused.
#[test]
fn cli_selects_poses_for_a_camera() {
    let dir = common::scratch_dir("camera", "select");
    let out = dir.join("design.csv");
    let o = out.display().to_string();
    let args = [
        "select",
        "--robot",
        "fixtures/ur5.urdf",
        "--camera-info",
        "fixtures/camera/camera_info.yaml",
        "--target",
        "fixtures/camera/board.yaml",
        "--mounting",
        "eye-to-hand",
        "--camera-pose=1.2,0.6,0.9,-2.0985,0,2.0779",
        "--target-pose=-0.0853,0.0568,0.02,3.1416,0,0.03",
        "--n",
        "12",
        "--count",
        "1500",
        "--out",
        &o,
        "--json",
    ];
    let v = common::json_of(&args);
    assert_eq!(v["n"], 12);
    assert!(
        v["points_seen"].as_array().unwrap().iter().all(|s| s == 48),
        "{v}"
    );
    let csv = std::fs::read_to_string(&out).unwrap();
    assert_eq!(csv.lines().count(), 13);
    assert!(
        csv.starts_with("candidate,shoulder_pan_joint,")
            && csv.lines().next().unwrap().ends_with(",points_seen")
    );
    common::fails_with(&args, "exists");
}

/// A start that puts the seen points behind the camera (the camera turned
/// away from the robot) is refused with what to give, not fitted.
#[test]
fn cli_refuses_a_start_behind_the_camera() {
    let mut args = EXAMPLE.to_vec();
    args[11] = "--camera-pose=1.1761,0.6096,0.9079,-2.0681,0.0317,-1.0590";
    common::fails_with(&args, "lie behind the camera");
}

/// `select --camera-info --gap --out design.json`: the design against
/// its visible pool's certified bound (D-efficiency in (0, 1], the
/// design's `log10 det` below the bound: a design of the pool cannot
/// exceed it), and the design as JSON with the chosen joint values and
/// the figures; options a camera design does not
/// take are refused, not ignored.
#[test]
fn cli_selects_a_camera_design_with_its_bound() {
    let dir = common::scratch_dir("camera", "select-gap");
    let out = dir.join("design.json");
    let o = out.display().to_string();
    let args = [
        "select",
        "--robot",
        "fixtures/ur5.urdf",
        "--camera-info",
        "fixtures/camera/camera_info.yaml",
        "--target",
        "fixtures/camera/board.yaml",
        "--mounting",
        "eye-to-hand",
        "--camera-pose=1.2,0.6,0.9,-2.0985,0,2.0779",
        "--target-pose=-0.0853,0.0568,0.02,3.1416,0,0.03",
        "--n",
        "12",
        "--count",
        "1500",
        "--gap",
        "--out",
        &o,
        "--json",
    ];
    let v = common::json_of(&args);
    let g = &v["gap"];
    let eff = g["d_efficiency"].as_f64().unwrap();
    assert!(eff > 0.0 && eff <= 1.0, "{g}");
    assert!(g["log10_oid"].as_f64().unwrap() <= g["log10_bound"].as_f64().unwrap());
    let ln_det = v["ln_det"].as_f64().unwrap();
    assert!(
        (g["ln_oid"].as_f64().unwrap() - ln_det).abs() < 1e-6 * ln_det.abs(),
        "{v}"
    );
    let d: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(d["poses"], v["poses"]);
    assert_eq!(d["poses"].as_array().unwrap().len(), 12);
    assert_eq!(d["gap"], v["gap"]);
    assert_eq!(d["joint_names"][0], "shoulder_pan_joint");
    let mut existing = args.to_vec();
    existing.truncate(15);
    existing.extend(["--existing", "somewhere.csv"]);
    common::fails_with(&existing, "--existing: not used with --camera-info");
    let mut noise = args.to_vec();
    noise.truncate(15);
    noise.extend(["--noise", "0.0003"]);
    common::fails_with(&noise, "a camera's is --pixel-noise PX");
}

/// `select --camera-info --report DIR`: the "how many poses" curve on the
/// pixel Jacobian. A pose's pixels move only with the target's rigid
/// placement in the camera, so a pose gives 6 independent rows and the
/// curve starts at ⌈p / 6⌉ poses; at the design's own size the curve's
/// selection (same settings and seed) finds the design `select` chose,
/// with its D-efficiency and the true error `select` predicts at
/// `--pixel-noise` (the same covariance carried to the same 1,000
/// configurations: equal to rounding, 1e-9 relative).
#[test]
fn cli_reports_how_many_poses_for_a_camera() {
    let dir = common::scratch_dir("camera", "select-report");
    let report = dir.join("report");
    let r = report.display().to_string();
    let args = [
        "select",
        "--robot",
        "fixtures/ur5.urdf",
        "--camera-info",
        "fixtures/camera/camera_info.yaml",
        "--target",
        "fixtures/camera/board.yaml",
        "--mounting",
        "eye-to-hand",
        "--camera-pose=1.2,0.6,0.9,-2.0985,0,2.0779",
        "--target-pose=-0.0853,0.0568,0.02,3.1416,0,0.03",
        "--n",
        "12",
        "--count",
        "1500",
        "--gap",
        "--pixel-noise",
        "0.25",
        "--report",
        &r,
        "--json",
    ];
    let v = common::json_of(&args);
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("report.json")).unwrap())
            .unwrap();
    let c = &j["how_many_poses"];
    let p = v["unknowns"].as_array().unwrap().len();
    assert_eq!(c["p"], p);
    assert_eq!(c["rows_per_pose"], 6, "{c}");
    assert_eq!(c["n_min"], p.div_ceil(6));
    assert_eq!(c["noise_px"], 0.25);
    assert!(c.get("noise_m").is_none());
    let at12 = c["points"]
        .as_array()
        .unwrap()
        .iter()
        .find(|q| q["n"] == 12)
        .expect("the asked size is on the curve");
    let close = |a: &serde_json::Value, b: &serde_json::Value| {
        let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
        assert!((a - b).abs() <= 1e-9 * b.abs(), "{a} against {b}");
    };
    close(
        &at12["predicted"]["position_rms_mm"],
        &v["predicted_error_mm"],
    );
    let per_px = v["predicted_error_mm_per_px"].as_f64().unwrap();
    close(&v["predicted_error_mm"], &serde_json::json!(per_px * 0.25));
    close(&at12["d_efficiency"], &v["gap"]["d_efficiency"]);
    close(&at12["ln_oid"], &v["ln_det"]);
    let mut a: Vec<u64> = at12["poses"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    let mut b: Vec<u64> = v["chosen_candidates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    a.sort_unstable();
    b.sort_unstable();
    assert_eq!(a, b);
    assert_eq!(j["selection"]["chosen_candidates"], v["chosen_candidates"]);
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains("Sensor noise σ = 0.25 px."), "{md}");
    for f in [
        "how_many_poses.png",
        "how_many_poses.svg",
        "joints_vs_limits.png",
    ] {
        assert!(report.join(f).is_file(), "{f}");
    }
    common::fails_with(&args, "exists and is not empty");
}

/// The head camera's example (`cargo run --example camera_head_simulate`)
/// from the command line: `--camera-link head_2_link` fits 30 + 12
/// unknowns, σ within 5 % of 0.3 px (2758 degrees of freedom), and writes
/// the TIAGo URDF with only the head's and the arm's origins changed (the
/// torso's and the first head joint's kept); a camera link on the arm's
/// own chain, a link the URDF lacks, and `--mounting` beside it are
/// refused.
#[test]
fn cli_calibrates_a_head_camera() {
    let dir = common::scratch_dir("camera", "head");
    let u = dir.join("tiago.urdf");
    let us = u.display().to_string();
    let args = [
        "calibrate",
        "--robot",
        "fixtures/figaroh/tiago.urdf#tip=arm_tool_link",
        "--camera-link",
        "head_2_link",
        "--observations",
        "fixtures/camera/tiago_head.csv",
        "--camera-info",
        "fixtures/camera/tiago_xtion.yaml",
        "--target",
        "fixtures/camera/tiago_board.yaml",
        "--camera-pose=0.1008,0.0950,-0.0020,-2.2154,-1.5388,-0.8959",
        "--target-pose=0.0699,-0.0248,0.0798,-2.2457,1.5388,-2.2154",
        "--json",
        "--out",
        &us,
    ];
    let v = common::json_of(&args);
    assert_eq!(v["converged"], true, "{v}");
    assert_eq!(v["names"].as_array().unwrap().len(), 42);
    assert_eq!(v["camera_link"], "head_2_link");
    assert_eq!(v["camera"]["camera_link"], "head_2_link");
    assert_eq!(v["camera"]["camera"]["parent"], "head_2_link");
    let s = v["sigma_px"].as_f64().unwrap();
    assert!((s / 0.3 - 1.0).abs() < 0.05, "σ {s} px");
    let before = std::fs::read_to_string("fixtures/figaroh/tiago.urdf").unwrap();
    let after = std::fs::read_to_string(&u).unwrap();
    let changed: Vec<usize> = before
        .lines()
        .zip(after.lines())
        .enumerate()
        .filter(|(_, (a, b))| a != b)
        .map(|(k, _)| k)
        .collect();
    // head_2_joint's origin and the seven arm joints' origins.
    assert_eq!(changed.len(), 8, "{changed:?}");
    for k in changed {
        assert!(
            before.lines().nth(k).unwrap().contains("<origin"),
            "line {}",
            k + 1
        );
    }
    let mut wrong = args[..14].to_vec();
    wrong[4] = "arm_3_link";
    common::fails_with(&wrong, "is eye-in-hand");
    wrong[4] = "no_such_link";
    common::fails_with(&wrong, "is not a link of the URDF");
    let mut both = args[..14].to_vec();
    both.extend(["--mounting", "eye-to-hand"]);
    common::fails_with(&both, "cannot be used with");
    let mut neither = args[..14].to_vec();
    neither.drain(3..5);
    common::fails_with(&neither, "needs --mounting or --camera-link");
}

/// `calibrate --refine-intrinsics --out-camera-info refined.yaml`: nine
/// more unknowns, each with a σ; the refined file is a camera_info that
/// reads back to the estimate and lies within 3σ of the intrinsics the
/// example was simulated with (`fixtures/camera/camera_info.yaml`, which
/// the fit starts from); an existing file is refused without --force, a
/// non-YAML name refused before any work.
#[test]
fn cli_refines_intrinsics_and_writes_them() {
    let dir = common::scratch_dir("camera", "refine-intrinsics");
    let out = dir.join("refined.yaml");
    let mut args = EXAMPLE.to_vec();
    let o = out.to_str().unwrap();
    args.extend(["--refine-intrinsics", "--out-camera-info", o]);
    let v = common::json_of(&args);
    assert_eq!(v["converged"], true);
    let names: Vec<&str> = v["names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    let k0 = names.iter().position(|n| *n == "camera_fx").unwrap();
    assert_eq!(names.len(), k0 + 9);
    let read = activecal::io::camera_info::read_camera_info(&out).unwrap();
    let given = activecal::io::camera_info::read_camera_info(std::path::Path::new(
        "fixtures/camera/camera_info.yaml",
    ))
    .unwrap();
    for (j, (r, g)) in read.values().iter().zip(given.values()).enumerate() {
        assert_eq!(*r, v["estimate"][k0 + j].as_f64().unwrap());
        let sd = v["std"][k0 + j].as_f64().unwrap();
        assert!(
            (r - g).abs() < 3.0 * sd,
            "{}: {r} against {g}, σ {sd}",
            names[k0 + j]
        );
    }
    common::fails_with(&args, "exists");
    let mut bad = EXAMPLE.to_vec();
    let txt = dir.join("refined.txt");
    bad.extend([
        "--refine-intrinsics",
        "--out-camera-info",
        txt.to_str().unwrap(),
    ]);
    common::fails_with(&bad, "camera_info .yaml");
}
