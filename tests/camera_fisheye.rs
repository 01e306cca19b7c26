//! A fisheye camera (the equidistant model, `activecal::measure::fisheye`)
//! as the sensor, against a known true robot: the UR5 of `camera.rs`
//! (identifiable joint origins off by 0.5–2 mm and 0.05–0.3°), a fixed
//! fisheye (eye-to-hand) 0.9 m from the workspace seeing a 7 × 9 board of
//! 40 mm squares on the flange, σ 0.3 px. The camera: fx ≈ fy ≈ 400 px on
//! a 1280 × 960 image (a 180°-class lens: 640 px is θd = 1.6 rad), k =
//! [−0.01, 0.002, −0.001, 0.0001]: calibrated fisheyes are close to
//! equidistant (θd ≈ θ), their k's of this size and alternating in sign,
//! the drawn radius ~1.6 % short of θ at 80° (~10 px at the image's
//! edge). Noise-free pixels recover the truth; noisy ones put every
//! unknown within 3σ; `--refine-intrinsics`' fit recovers fx … k4 within
//! 3σ.

use super::camera::{looking, truth, ur5};
use activecal::data::CameraObservations;
use activecal::identify::LmSettings;
use activecal::identify::camera::simulate::simulate_observations;
use activecal::identify::camera::{CameraFit, camera_robot, fit_camera};
use activecal::io::camera_target::Target;
use activecal::kinematics::Evaluator;
use activecal::measure::camera::{CameraSensor, Mounting};
use activecal::measure::pinhole::{Distortion, Intrinsics};
use activecal::model::{ParamTable, Robot};
use activecal::observability::generic_configurations;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

fn fisheye() -> Intrinsics {
    Intrinsics {
        width: 1280,
        height: 960,
        fx: 400.0,
        fy: 400.5,
        cx: 640.0,
        cy: 480.0,
        distortion: Distortion::Equidistant([-0.01, 0.002, -0.001, 0.0001]),
    }
}

fn board() -> Target {
    Target::checkerboard(7, 9, 0.04)
}

struct Case {
    robot: Robot,
    truth: ParamTable,
    /// The true placements (camera, target).
    placements: (Isometry3<f64>, Isometry3<f64>),
    /// The fit's start: placements 2 cm and ~2° off, the given intrinsics.
    start: CameraSensor,
    own_start: Vec<f64>,
    obs: CameraObservations,
}

/// The true placements: the camera 0.9 m from the workspace's centre, the
/// board's face along the flange's +z, centred on its axis.
fn placements() -> (Isometry3<f64>, Isometry3<f64>) {
    let c = board().centroid();
    let cam = looking(
        Vector3::new(0.85, 0.45, 0.75),
        Vector3::new(0.25, 0.05, 0.25),
    );
    let tgt = Isometry3::from_parts(
        Translation3::new(0.004, -0.003, 0.02),
        UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.03),
    ) * Translation3::from(-c);
    (cam, tgt)
}

/// 40 configurations where the true camera sees the whole board at least
/// 20 px inside the image, at most 60° off its face, 0.3–2 m away (spread
/// over the fisheye's field: the UR5's reach spans it).
fn visible(robot: &Robot, table: &ParamTable, sensor: &CameraSensor, own: &[f64]) -> Vec<Vec<f64>> {
    let mut ev = Evaluator::new(robot, table);
    let out: Vec<Vec<f64>> = generic_configurations(robot, 40_000, 41)
        .into_iter()
        .filter(|q| {
            let v = sensor.view(&ev.end_frame(q), own, 20.0);
            v.seen == sensor.points().len()
                && v.angle < 60f64.to_radians()
                && (0.3..2.0).contains(&v.distance)
        })
        .take(40)
        .collect();
    assert_eq!(out.len(), 40, "too few visible configurations");
    out
}

/// A simulated eye-to-hand fisheye calibration with pixel noise `sigma`,
/// the fit started with intrinsics `given`.
fn case(sigma: f64, seed: u64, given: Intrinsics) -> Case {
    let robot = camera_robot(&ur5()).unwrap();
    let truth = truth(&robot, seed);
    let (cam, tgt) = placements();
    let m = Mounting::EyeToHand;
    let sensor = CameraSensor::new(fisheye(), m, board().points, &cam, &tgt);
    let own_true = CameraSensor::start_own(&cam, &tgt);
    let qs = visible(&robot, &truth, &sensor, &own_true);
    let mut rng = activecal::identify::trial_rng(seed, 1);
    let obs = simulate_observations(
        &robot, &truth, &sensor, &own_true, &qs, sigma, 0.0, &mut rng,
    );
    let off = Isometry3::from_parts(
        Translation3::new(0.02, -0.015, 0.01),
        UnitQuaternion::from_euler_angles(0.03, -0.02, 0.025),
    );
    let (cam0, tgt0) = (cam * off, tgt * off.inverse());
    Case {
        robot,
        truth,
        placements: (cam, tgt),
        start: CameraSensor::new(given, m, board().points, &cam0, &tgt0),
        own_start: CameraSensor::start_own(&cam0, &tgt0),
        obs,
    }
}

fn fit(c: &Case, sensor: &CameraSensor) -> CameraFit {
    fit_camera(
        &c.robot,
        sensor,
        &c.own_start,
        &c.obs,
        &LmSettings::default(),
    )
    .expect("a simulated case fits")
}

/// The board's centre in the camera's frame, RMS over 1,000 random
/// configurations of the fit against the truth, metres.
fn true_error(c: &Case, fit: &CameraFit) -> f64 {
    let centre = Point3::from(board().centroid());
    let probe = |table: &ParamTable, cam: &Isometry3<f64>, tgt: &Isometry3<f64>, q: &[f64]| {
        let e = Evaluator::new(&c.robot, table).end_frame(q);
        let end =
            Isometry3::from_parts(e.position.into(), UnitQuaternion::from_matrix(&e.rotation));
        cam.inverse() * end * tgt * centre
    };
    let (cam_t, tgt_t) = c.placements;
    let qs = generic_configurations(&c.robot, 1000, 7);
    let ss: f64 = qs
        .iter()
        .map(|q| {
            (probe(&c.truth, &cam_t, &tgt_t, q) - probe(&fit.table, &fit.camera, &fit.target, q))
                .norm_squared()
        })
        .sum();
    (ss / qs.len() as f64).sqrt()
}

/// The truth in the fit's parameters: the robot's true unknowns, the true
/// placements in the fit's charts, then the true intrinsics when refined.
fn truth_vector(c: &Case, fit: &CameraFit) -> Vec<f64> {
    let mut v = c.robot.unknown_values(&c.truth);
    let (cam0, tgt0) = fit.sensor.placements(&[0.0; 12]);
    for (t, t0) in [(c.placements.0, cam0), (c.placements.1, tgt0)] {
        v.extend(t.translation.vector.iter());
        v.extend((t0.rotation.inverse() * t.rotation).scaled_axis().iter());
    }
    if fit.sensor.refines_intrinsics() {
        v.extend(fisheye().values());
    }
    v
}

/// Every unknown of `fit` within 3σ of the truth (its own σ), printing the
/// intrinsics' when refined; the largest |z|.
fn within_three_sigma(c: &Case, fit: &CameraFit) -> f64 {
    let want = truth_vector(c, fit);
    let std = fit.std.as_ref().expect("a regular fit");
    let first_intrinsic = fit.robot.n_unknowns() + 12;
    let mut worst = 0.0f64;
    for (k, name) in fit.names.iter().enumerate() {
        let z = (fit.estimate[k] - want[k]) / std[k];
        if k >= first_intrinsic {
            println!(
                "{name}: {:.6} ± {:.6} (truth {}, {z:+.2}σ)",
                fit.estimate[k], std[k], want[k]
            );
        }
        assert!(z.abs() < 3.0, "{name}: {} off by {z:.2}σ", fit.estimate[k]);
        worst = worst.max(z.abs());
    }
    worst
}

/// Noise-free pixels recover the truth: the 3-D figure to 1e-9 m (1e-6
/// mm; LM's floor on pixels O(1e3) and lengths O(1) is ~1e-12 relative)
/// and the pixels to 1e-6 px; 30 unknowns.
#[test]
fn fisheye_noise_free_pixels_recover_the_truth() {
    let c = case(0.0, 3, fisheye());
    let f = fit(&c, &c.start);
    assert!(f.converged, "{:?}", f.stop);
    assert!(
        f.given_rms_px > 10.0,
        "the start is off ({} px)",
        f.given_rms_px
    );
    assert!(f.rms_px < 1e-6, "{} px", f.rms_px);
    let e = true_error(&c, &f);
    println!(
        "fisheye, noise-free: true 3-D error {e:.1e} m, {:.1e} px",
        f.rms_px
    );
    assert!(e < 1e-9, "true error {} mm", 1e3 * e);
    assert_eq!(f.estimate.len(), 30);
}

/// With σ 0.3 px every one of the 30 unknowns lies within 3σ of the truth
/// (a 3σ miss has probability 0.27 % per unknown; the seed is fixed) and
/// σ̂ within 5 % of 0.3 px (≈5,000 rows: σ̂'s relative spread ≈ 1 %).
#[test]
fn fisheye_noisy_pixels_put_every_unknown_within_three_sigma() {
    let c = case(0.3, 5, fisheye());
    let f = fit(&c, &c.start);
    assert!(f.converged, "{:?}", f.stop);
    let s = f.sigma_px.unwrap();
    assert!((s / 0.3 - 1.0).abs() < 0.05, "σ {s} px");
    let worst = within_three_sigma(&c, &f);
    let e = true_error(&c, &f);
    println!(
        "fisheye: σ̂ {s:.4} px, largest {worst:.2}σ, true 3-D error {:.4} mm, {} rows",
        1e3 * e,
        f.rows
    );
}

/// `--refine-intrinsics` with a fisheye: started from intrinsics a few
/// pixels off (fx +3, fy −2, cx +4, cy −3 px, k1 +0.005), the fit with
/// fx, fy, cx, cy, k1 … k4 as unknowns recovers each within 3σ of the
/// truth (and every other unknown), σ̂ within 5 % of 0.3 px, none held
/// as undetermined; without refinement the same start leaves σ̂ above 2×
/// 0.3 px.
#[test]
fn fisheye_refined_intrinsics_are_recovered_within_three_sigma() {
    let mut off = fisheye().values();
    for (v, d) in off.iter_mut().zip([3.0, -2.0, 4.0, -3.0, 0.005]) {
        *v += d;
    }
    let c = case(0.3, 5, fisheye().with_values(&off));
    let fixed = fit(&c, &c.start);
    let refined = fit(&c, &c.start.clone().with_intrinsics_refined(true));
    assert!(refined.converged, "{:?}", refined.stop);
    let (s_fixed, s) = (fixed.sigma_px.unwrap(), refined.sigma_px.unwrap());
    println!("fisheye intrinsics off: σ̂ {s_fixed:.3} px fixed, {s:.4} px refined");
    assert!(s_fixed > 0.6, "σ̂ {s_fixed} px without refinement");
    assert!((s / 0.3 - 1.0).abs() < 0.05, "σ̂ {s} px refined");
    assert!(
        refined.fixed_intrinsics.is_empty(),
        "{:?}",
        refined.fixed_intrinsics
    );
    assert_eq!(refined.estimate.len(), refined.robot.n_unknowns() + 12 + 8);
    let worst = within_three_sigma(&c, &refined);
    println!("fisheye refined: largest {worst:.2}σ");
    let n = refined.robot.n_unknowns() + 12;
    assert_eq!(refined.intrinsics().values(), refined.estimate[n..]);
    assert!(matches!(
        refined.intrinsics().distortion,
        Distortion::Equidistant(_)
    ));
}

/// `X,Y,Z,ROLL,PITCH,YAW` of a placement.
fn six(t: &Isometry3<f64>) -> String {
    let (r, p, y) = t.rotation.euler_angles();
    let v = t.translation.vector;
    format!("{},{},{},{r},{p},{y}", v.x, v.y, v.z)
}

/// The command line with a fisheye: the simulated case (σ 0.3 px) as
/// files (a ROS `equidistant` camera_info, the board, the pixels), fitted
/// by `calibrate --refine-intrinsics --out-camera-info`: 8 intrinsics
/// named `camera_fx … camera_k4`, the written file an `equidistant`
/// camera_info that reads back to the estimate; a fisheye file with 5
/// coefficients and an unknown model are refused naming the file and
/// what is wrong.
#[test]
fn fisheye_from_the_command_line() {
    use crate::common;
    use activecal::io::camera_info::{read_camera_info, render_camera_info};
    let dir = common::scratch_dir("camera", "fisheye");
    let c = case(0.3, 5, fisheye());
    let path = |name: &str| dir.join(name).display().to_string();
    let (info, board_file, obs, out) = (
        path("fish.yaml"),
        path("board.yaml"),
        path("obs.csv"),
        path("refined.yaml"),
    );
    std::fs::write(&info, render_camera_info(&fisheye(), "fish", "")).unwrap();
    std::fs::write(
        &board_file,
        "checkerboard: {rows: 7, cols: 9, square: 0.04}\n",
    )
    .unwrap();
    let csv = activecal::io::camera_observations::observations_csv(&c.obs, &c.robot, &board());
    std::fs::write(&obs, csv).unwrap();
    let (cam0, tgt0) = c.start.placements(&c.own_start);
    let (cp, tp) = (
        format!("--camera-pose={}", six(&cam0)),
        format!("--target-pose={}", six(&tgt0)),
    );
    let args = [
        "calibrate",
        "--robot",
        "fixtures/ur5.urdf",
        "--mounting",
        "eye-to-hand",
        "--camera-info",
        &info,
        "--target",
        &board_file,
        "--observations",
        &obs,
        &cp,
        &tp,
        "--refine-intrinsics",
        "--out-camera-info",
        &out,
        "--json",
    ];
    let v = common::json_of(&args);
    assert_eq!(v["converged"], true, "{v}");
    let names: Vec<&str> = v["names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    let k0 = names.iter().position(|n| *n == "camera_fx").unwrap();
    assert_eq!(
        names[k0..].join(" "),
        "camera_fx camera_fy camera_cx camera_cy camera_k1 camera_k2 camera_k3 camera_k4"
    );
    assert_eq!(v["intrinsics"]["distortion_model"], "equidistant", "{v}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("distortion_model: equidistant\n"), "{text}");
    let read = read_camera_info(std::path::Path::new(&out)).unwrap();
    for (j, r) in read.values().iter().enumerate() {
        assert_eq!(
            *r,
            v["estimate"][k0 + j].as_f64().unwrap(),
            "{}",
            names[k0 + j]
        );
    }
    // The refined file's own lines (a comment heads it) for the places.
    let line = |key: &str| 1 + text.lines().position(|l| l.starts_with(key)).unwrap();
    let five = text.replace("cols: 4\n  data: [", "cols: 5\n  data: [0.0, ");
    std::fs::write(&info, five).unwrap();
    let mut wrong = args.to_vec();
    wrong.truncate(13);
    common::fails_with(
        &wrong,
        &format!(
            "fish.yaml: line {}, column 3 ('distortion_coefficients'): 5 coefficients; equidistant (fisheye) has 4",
            line("distortion_coefficients") + 1
        ),
    );
    std::fs::write(&info, text.replace("equidistant", "kannala_brandt")).unwrap();
    common::fails_with(
        &wrong,
        &format!(
            "fish.yaml: line {}, column 19 ('distortion_model'): 'kannala_brandt' is not supported",
            line("distortion_model")
        ),
    );
}
