//! Camera captures that go wrong in ways not tested elsewhere (issue 49,
//! item 5), on the example files of `fixtures/camera` (a UR5 eye-to-hand,
//! σ 0.3 px) with one thing made wrong:
//!
//! * every point of one pose on one pixel (a detector that returned one
//!   corner for all): the gross-error test leaves that pose out, the rest
//!   is fitted as without it;
//! * a joint the model holds locked that the data say moved: refused when
//!   read, naming the line, the column and both values (it was fitted to
//!   145 px and blamed on the target's size);
//! * a fisheye camera_info (four coefficients) without `distortion_model`:
//!   refused naming the file and what to add (it was read as plumb_bob and
//!   fitted to 54.5 px).

use crate::common;

const OBS: &str = "fixtures/camera/ur5_eye_to_hand.csv";
const CAMERA_POSE: &str = "--camera-pose=1.1761,0.6096,0.9079,-2.0681,0.0317,2.0826";
const TARGET_POSE: &str = "--target-pose=-0.1047,0.0411,0.0301,3.1111,-0.0192,0.0556";

fn args<'a>(obs: &'a str, info: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "calibrate",
        "--robot",
        "fixtures/ur5.urdf",
        "--observations",
        obs,
        "--camera-info",
        info,
        "--target",
        "fixtures/camera/board.yaml",
        "--mounting",
        "eye-to-hand",
        CAMERA_POSE,
        TARGET_POSE,
        "--json",
    ];
    a.extend(extra);
    a
}

/// The example's rows with `edit` applied to each (its cells).
fn edited(name: &str, edit: impl Fn(&mut Vec<String>)) -> String {
    let dir = common::scratch_dir("camera_messy", name);
    let text = std::fs::read_to_string(OBS).unwrap();
    let mut lines = text.lines();
    let mut out = vec![lines.next().unwrap().to_string()];
    for l in lines {
        let mut c: Vec<String> = l.split(',').map(String::from).collect();
        edit(&mut c);
        out.push(c.join(","));
    }
    let p = dir.join("obs.csv");
    std::fs::write(&p, out.join("\n") + "\n").unwrap();
    p.display().to_string()
}

#[test]
fn a_pose_whose_points_all_sit_on_one_pixel_is_left_out() {
    let pose = "7";
    let obs = edited("one_pixel", |c| {
        if c[0] == pose {
            let n = c.len();
            c[n - 2] = "640.0".into();
            c[n - 1] = "480.0".into();
        }
    });
    let info = "fixtures/camera/camera_info.yaml";
    let v = common::json_of(&args(&obs, info, &[]));
    let out = v["outliers"]["left_out"].as_array().unwrap();
    assert!(
        out.iter()
            .any(|o| o["pose_id"] == 7 && o["unit"]["kind"] == "pose"),
        "{}",
        v["outliers"]
    );
    assert_eq!(v["exit_status"], 0, "{v}");
    // Left out, the rest fits as the clean file does: σ̂ of a detector.
    let sigma = v["sigma_px"].as_f64().unwrap();
    assert!(sigma < 1.0, "σ̂ {sigma} px");
    // Kept, the pose spoils the fit: σ̂ far above a detector's.
    let kept = common::run(&args(&obs, info, &["--outliers", "keep"]));
    let k: serde_json::Value = serde_json::from_slice(&kept.stdout).unwrap();
    assert!(k["outliers"]["left_out"].as_array().unwrap().is_empty());
    assert!(
        k["sigma_px"].as_f64().unwrap() > 10.0 * sigma,
        "{}",
        k["sigma_px"]
    );
}

#[test]
fn a_locked_joint_the_data_move_is_refused() {
    let info = "fixtures/camera/camera_info.yaml";
    let mut a = args(OBS, info, &["--lock", "shoulder_pan_joint=0"]);
    a.retain(|x| *x != "--json");
    common::fails_with(
        &a,
        "column 2 ('shoulder_pan_joint'): the joint is locked at 0 but this row has it at -1.31",
    );
}

#[test]
fn a_fisheye_camera_info_without_its_model_is_refused() {
    let dir = common::scratch_dir("camera_messy", "fisheye");
    let text = std::fs::read_to_string("fixtures/camera/camera_info.yaml").unwrap();
    let fish = text
        .replace("distortion_model: plumb_bob\n", "")
        .replace("cols: 5", "cols: 4")
        .replace(
            "[-0.08, 0.04, 0.0005, -0.0003, -0.01]",
            "[0.1, -0.02, 0.003, -0.001]",
        );
    assert_ne!(fish, text);
    let info = dir.join("fish.yaml");
    std::fs::write(&info, fish).unwrap();
    let info = info.display().to_string();
    let mut a = args(OBS, &info, &[]);
    a.retain(|x| *x != "--json");
    common::fails_with(&a, "no 'distortion_model'");
    common::fails_with(&a, "fish.yaml");
}
