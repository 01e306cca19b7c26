//! A camera's images in a ROS 2 bag against a known truth (issue #52's
//! camera topics; feature `live`, the project venv with Pinocchio, OpenCV
//! and `rosbags`, and `target/debug/activecal`). The scene is the images'
//! gate's UR5 eye-in-hand (`live_images`: the true robot of
//! `camera_truth.py make`, a 6 × 9 board of 25 mm squares, images rendered
//! exactly at 1280 × 960 with blur, gamma and noise, 2 draws of the
//! noise); `bag_truth.py images` drives the true arm through the
//! renders' configurations (rests of 1.6–2.4 s, quintic moves between,
//! `/joint_states` at 500 Hz with 2e-6 rad of encoder noise) and records
//! the camera as PNG-compressed `sensor_msgs/CompressedImage` frames, six
//! evenly over each rest (a 30 Hz camera during the rests only would add
//! 10× the bytes and nothing else: each frame of a rest is the same
//! render), with its `CameraInfo`.
//!
//! [`live_bag_calibrate_camera_images`]: `calibrate --bag --images TOPIC
//! --camera-info TOPIC` → URDF + frames, the true error (`truth.py
//! compare`, 1,000 random configurations) RMS over the draws within
//! [`RATIO`] of the same images read as files (`calibrate --images DIR
//! --joints joints.csv`, exact joint values) and of the same poses' true
//! pixels given Gaussian noise of the detected corners' own σ (the
//! images' gate's reference); every image of a rest found, every corner
//! labelled as the truth.

use super::live_images::{
    RATIO, Scene, calibrate, checkerboard, corner_errors, from_images, noisy_truth, read_pixels,
    rms, scene, truth_labelled, ur5_eye_in_hand, write_pixels,
};
use serde_json::Value;
use std::process::Command;
use verify::bridge::{python, repo_root as root, run};

/// Images (and rests) in the run.
const IMAGES: usize = 14;
/// Draws of the noise on the same renders.
const DRAWS: usize = 2;

/// `calibrate --bag` of draw `d`'s bag, saving the pixels detected: the
/// report and the true error, mm.
fn from_bag(s: &Scene, d: usize) -> (Value, f64) {
    let r = root();
    let draw = &s.draws[d];
    let bag = s.dir.join(format!("run{d}.mcap.d"));
    let _ = std::fs::remove_dir_all(&bag);
    println!(
        "bag {d}: {}",
        run(python()
            .arg(r.join("verify/python/bag_truth.py"))
            .args(["images", "--dir"])
            .arg(draw)
            .arg("--camera-info")
            .arg(r.join("fixtures/camera/camera_info.yaml"))
            .args(["--per-rest", "6", "--seed", &(d + 1).to_string(), "--out"])
            .arg(&bag))
        .trim()
    );
    let (u, y) = (
        s.dir.join(format!("bag{d}.urdf")),
        s.dir.join(format!("bag{d}.yaml")),
    );
    let saved = s.dir.join(format!("bag{d}.csv"));
    let out = run(Command::new(r.join("target/debug/activecal"))
        .arg("calibrate")
        .arg("--robot")
        .arg(s.rig.robot_ref())
        .arg("--bag")
        .arg(&bag)
        .args([
            "--images",
            "/camera/image",
            "--camera-info",
            "/camera/camera_info",
        ])
        .arg("--target")
        .arg(&s.board)
        .args(["--mounting", s.rig.mounting.name()])
        .arg("--save-observations")
        .arg(&saved)
        .args(["--json", "--force", "--out"])
        .arg(&u)
        .arg("--out")
        .arg(&y));
    let report: Value = serde_json::from_str(&out).unwrap();
    let cmp: Value = serde_json::from_str(&run(python()
        .arg(r.join("verify/python/truth.py"))
        .args(["compare", "--truth"])
        .arg(&s.truth)
        .arg("--urdf")
        .arg(&u)
        .arg("--frames")
        .arg(&y)
        .args(["--n", "1000", "--seed", "1"])))
    .unwrap();
    let _ = std::fs::remove_dir_all(&bag);
    (report, cmp["random"]["rms_mm"].as_f64().unwrap())
}

#[test]
fn live_bag_calibrate_camera_images() {
    let s = scene(
        ur5_eye_in_hand("bag-camera", 6, 9, false),
        &checkerboard(6, 9),
        false,
        (IMAGES, false),
        DRAWS,
    );
    let (mut b2, mut f2, mut r2) = (0.0, 0.0, 0.0);
    for d in 0..DRAWS {
        let (report, bag_mm) = from_bag(&s, d);
        let rests = report["bag"]["rests"].as_array().unwrap();
        assert_eq!(rests.len(), IMAGES, "draw {d}: {}", report["bag"]);
        let found = rests
            .iter()
            .filter(|x| x["image"]["status"] == "found")
            .count();
        assert_eq!(found, IMAGES, "draw {d}: {}", report["bag"]);
        let detected = read_pixels(&s.dir.join(format!("bag{d}.csv")));
        let truth = read_pixels(&s.draws[d].join("truth.csv"));
        let (_, misordered) = truth_labelled(&detected, &truth);
        assert!(misordered.is_empty(), "draw {d}: {misordered:?}");
        let (_, files_mm, _) = from_images(&s, &s.draws[d], &format!("files{d}"));
        let e = corner_errors(&detected, &truth);
        let sigma = rms(&e) / 2f64.sqrt();
        let reference = s.dir.join(format!("truth{d}.csv"));
        write_pixels(
            &noisy_truth(&detected, &truth, sigma, d as u64 + 1),
            &reference,
        );
        let (_, ref_mm) = calibrate(
            &s,
            &["--observations".as_ref(), reference.as_os_str()],
            &format!("truth{d}"),
        );
        println!(
            "draw {d}: bag {bag_mm:.4} mm, the images as files {files_mm:.4} mm, true pixels + σ {sigma:.3} px {ref_mm:.4} mm"
        );
        b2 += bag_mm * bag_mm;
        f2 += files_mm * files_mm;
        r2 += ref_mm * ref_mm;
    }
    let n = DRAWS as f64;
    let (b, f, r) = ((b2 / n).sqrt(), (f2 / n).sqrt(), (r2 / n).sqrt());
    println!(
        "RMS over {DRAWS} draws: bag {b:.4} mm, files {f:.4} mm ({:.2}×), true pixels + σ {r:.4} mm ({:.2}×)",
        b / f,
        b / r
    );
    assert!(b < RATIO * f, "bag {b} mm against {f} mm from the files");
    assert!(
        b < RATIO * r,
        "bag {b} mm against {r} mm from the true pixels"
    );
}
