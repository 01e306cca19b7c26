//! A camera fit started from the pixels (`identify::camera::start`: PnP
//! per pose, then the closed-form hand-eye placements) instead of guessed
//! placements: on the example files (the UR5 eye-to-hand, the TIAGo's head
//! camera) and a simulated UR5 eye-in-hand it converges to the same fit
//! as from the guesses; from the command line the guesses are optional,
//! the text and JSON say the start was computed, and data the closed form
//! cannot solve are refused with what to give.

use crate::common;
use activecal::data::CameraObservations;
use activecal::identify::LmSettings;
use activecal::identify::camera::simulate::simulate_observations;
use activecal::identify::camera::start::start_placements;
use activecal::identify::camera::{CameraFit, camera_robot, fit_camera};
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_observations::read_observations;
use activecal::io::camera_target::{Target, read_target};
use activecal::io::urdf_branch::camera_branch;
use activecal::kinematics::Evaluator;
use activecal::measure::camera::{CameraSensor, Mounting};
use activecal::measure::pinhole::Intrinsics;
use activecal::model::{Robot, Symbol};
use activecal::observability::generic_configurations;
use activecal::units::Units;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use std::path::Path;

fn iso(v: [f64; 6]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_euler_angles(v[3], v[4], v[5]),
    )
}

/// The solver run to its precision (tolerances below rounding: it stops
/// when no step can be measured), so that two fits differ by where
/// rounding leaves them, not by where the default tolerances (1e-10)
/// happen to stop each.
fn tight() -> LmSettings {
    LmSettings::builder()
        .xtol(1e-17)
        .ftol(1e-17)
        .gtol(1e-17)
        .build()
        .unwrap()
}

/// The fit of `obs` from the start placements `start` (camera, target).
fn fit_from(
    robot: &Robot,
    cam: &Intrinsics,
    m: Mounting,
    target: &Target,
    obs: &CameraObservations,
    start: (Isometry3<f64>, Isometry3<f64>),
) -> CameraFit {
    let sensor = CameraSensor::new(cam.clone(), m, target.points.clone(), &start.0, &start.1);
    let own = CameraSensor::start_own(&start.0, &start.1);
    let fit = fit_camera(robot, &sensor, &own, obs, &tight()).expect("fits");
    assert!(fit.converged, "{:?}", fit.stop);
    fit
}

/// How close two fits must be.
#[derive(Clone, Copy, Debug)]
enum Tol {
    /// Every robot unknown to this fraction of its size, each placement's
    /// translation to this fraction of its length and its rotation to
    /// this many radians.
    Relative(f64),
    /// Every unknown, and each placement's translation and rotation, to
    /// this fraction of the first fit's σ (the RSS of the placement's
    /// three σ's).
    Sigma(f64),
}

/// Checks that fits `a` and `b` agree to `tol`; the worst ratio to the
/// tolerance's scale.
fn agree(label: &str, a: &CameraFit, b: &CameraFit, tol: Tol) -> f64 {
    let sd = a.std.as_ref().expect("a covariance");
    let n = a.robot.n_unknowns();
    let (limit, mut worst) = match tol {
        Tol::Relative(t) | Tol::Sigma(t) => (t, 0.0f64),
    };
    for (k, s) in sd.iter().enumerate().take(n) {
        let (x, y) = (a.estimate[k], b.estimate[k]);
        let scale = match tol {
            Tol::Relative(_) => x.abs().max(y.abs()),
            Tol::Sigma(_) => *s,
        };
        let d = (x - y).abs() / scale;
        worst = worst.max(d);
        assert!(d < limit, "{label} {}: {x} vs {y} ({tol:?})", a.names[k]);
    }
    let rss = |k: usize| (sd[k].powi(2) + sd[k + 1].powi(2) + sd[k + 2].powi(2)).sqrt();
    for (what, k, p, q) in [
        ("camera", n, a.camera, b.camera),
        ("target", n + 6, a.target, b.target),
    ] {
        let (t_scale, r_scale) = match tol {
            Tol::Relative(_) => (p.translation.vector.norm(), 1.0),
            Tol::Sigma(_) => (rss(k), rss(k + 3)),
        };
        let t = (p.translation.vector - q.translation.vector).norm() / t_scale;
        let r = p.rotation.angle_to(&q.rotation) / r_scale;
        worst = worst.max(t).max(r);
        assert!(t < limit && r < limit, "{label} {what}: {t}, {r} ({tol:?})");
    }
    worst
}

/// Fits from the guesses and from the computed start and checks that the
/// two agree to `tol`; returns both (guessed, computed).
#[allow(clippy::too_many_arguments)]
fn same_fit(
    label: &str,
    robot: &Robot,
    cam: &Intrinsics,
    m: Mounting,
    target: &Target,
    obs: &CameraObservations,
    guess: (Isometry3<f64>, Isometry3<f64>),
    tol: Tol,
) -> (CameraFit, CameraFit) {
    let st = start_placements(robot, cam, m, &target.points, obs, None, None).unwrap();
    assert_eq!(st.poses_placed, obs.qs.len(), "{label}");
    let a = fit_from(robot, cam, m, target, obs, guess);
    let b = fit_from(robot, cam, m, target, obs, (st.camera, st.target));
    let worst = agree(label, &a, &b, tol);
    eprintln!(
        "{label}: start {:.3} px (guess {:.3} px), fits agree to {worst:.1e} ({tol:?})",
        b.given_rms_px, a.given_rms_px
    );
    (a, b)
}

/// The UR5 example (`fixtures/camera/ur5_eye_to_hand.csv`), with the
/// guesses of `docs/cameras.md`.
#[test]
fn ur5_example_converges_to_the_same_fit_without_guesses() {
    let robot = activecal::io::load_robot("fixtures/ur5.urdf").unwrap();
    let cam = read_camera_info(Path::new("fixtures/camera/camera_info.yaml")).unwrap();
    let target = read_target(Path::new("fixtures/camera/board.yaml")).unwrap();
    let obs = read_observations(
        Path::new("fixtures/camera/ur5_eye_to_hand.csv"),
        &robot,
        &target,
        &cam,
        Units::default(),
    )
    .unwrap();
    let guess = (
        iso([1.1761, 0.6096, 0.9079, -2.0681, 0.0317, 2.0826]),
        iso([-0.1047, 0.0411, 0.0301, 3.1111, -0.0192, 0.0556]),
    );
    same_fit(
        "UR5 eye-to-hand",
        &robot,
        &cam,
        Mounting::EyeToHand,
        &target,
        &obs,
        guess,
        Tol::Relative(1e-9),
    );
}

/// The TIAGo's head camera (`fixtures/camera/tiago_head.csv`): the chain
/// from `head_2_link` to the tip, with the guesses of `docs/cameras.md`.
/// The fit from those guesses stops (on the cost tolerance, under heavy
/// damping) 4e-6 σ short of where the computed start's converges (1.4e-7
/// relative on `a_arm_2_joint`, 0.5 mm); a second guess, 1 cm and ~1° off
/// the first, converges to the computed start's fit to 1.5e-11 relative. So:
/// the guessed fit within 1e-5 σ, the second guess's to 1e-9 relative.
#[test]
fn tiago_head_converges_to_the_same_fit_without_guesses() {
    let tiago = activecal::io::load_robot("fixtures/figaroh/tiago.urdf#tip=arm_tool_link").unwrap();
    let robot = camera_branch(&tiago, "head_2_link").unwrap();
    let cam = read_camera_info(Path::new("fixtures/camera/tiago_xtion.yaml")).unwrap();
    let target = read_target(Path::new("fixtures/camera/tiago_board.yaml")).unwrap();
    let obs = read_observations(
        Path::new("fixtures/camera/tiago_head.csv"),
        &robot,
        &target,
        &cam,
        Units::default(),
    )
    .unwrap();
    let guess = (
        iso([0.1008, 0.0950, -0.0020, -2.2154, -1.5388, -0.8959]),
        iso([0.0699, -0.0248, 0.0798, -2.2457, 1.5388, -2.2154]),
    );
    let (_, computed) = same_fit(
        "TIAGo head",
        &robot,
        &cam,
        Mounting::EyeToHand,
        &target,
        &obs,
        guess,
        Tol::Sigma(1e-5),
    );
    let o = iso([0.01, 0.0, -0.01, 0.02, 0.0, -0.01]);
    let second = (guess.0 * o, guess.1 * o);
    let other = fit_from(&robot, &cam, Mounting::EyeToHand, &target, &obs, second);
    let worst = agree(
        "TIAGo head, second guess",
        &other,
        &computed,
        Tol::Relative(1e-9),
    );
    eprintln!("TIAGo head, second guess: fits agree to {worst:.1e} relative");
}

/// A simulated UR5 eye-in-hand (no example file): a camera 6 cm off the
/// flange sees a board on the table; every robot unknown off by 1 mm or
/// 0.1°; σ 0.3 px at 30 configurations that see the whole board; the
/// guesses 2 cm and ~2° off the truth.
#[test]
fn eye_in_hand_converges_to_the_same_fit_without_guesses() {
    let robot = camera_robot(&activecal::io::load_robot("fixtures/ur5.urdf").unwrap()).unwrap();
    let mut truth = robot.nominal.clone();
    for (k, &u) in robot.unknowns.iter().enumerate() {
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        let size = match u.symbol {
            Symbol::A | Symbol::D => 1e-3,
            _ => 0.1f64.to_radians(),
        };
        truth.set(u, truth.get(u) + sign * size);
    }
    let cam = Intrinsics {
        width: 1280,
        height: 960,
        fx: 1000.0,
        fy: 1000.0,
        cx: 640.0,
        cy: 480.0,
        distortion: activecal::measure::pinhole::Distortion::PlumbBob([
            -0.08, 0.04, 5e-4, -3e-4, -0.01,
        ]),
    };
    let target = Target::checkerboard(6, 8, 0.025);
    let c = target.centroid();
    let cam_t = iso([0.06, 0.0, 0.03, 0.0, 0.0, std::f64::consts::FRAC_PI_2]);
    let tgt_t = iso([0.45, 0.15, 0.0, std::f64::consts::PI, 0.0, 0.03]) * Translation3::from(-c);
    let m = Mounting::EyeInHand;
    let sensor = CameraSensor::new(cam.clone(), m, target.points.clone(), &cam_t, &tgt_t);
    let own = CameraSensor::start_own(&cam_t, &tgt_t);
    let mut ev = Evaluator::new(&robot, &truth);
    let qs: Vec<Vec<f64>> = generic_configurations(&robot, 40_000, 41)
        .into_iter()
        .filter(|q| {
            let v = sensor.view(&ev.end_frame(q), &own, 20.0);
            v.seen == target.points.len() && v.angle < 60f64.to_radians()
        })
        .take(30)
        .collect();
    assert_eq!(qs.len(), 30);
    let mut rng = activecal::identify::trial_rng(5, 1);
    let obs = simulate_observations(&robot, &truth, &sensor, &own, &qs, 0.3, 0.0, &mut rng);
    let off = iso([0.02, -0.015, 0.01, 0.03, -0.02, 0.025]);
    let guess = (cam_t * off, tgt_t * off.inverse());
    same_fit(
        "UR5 eye-in-hand",
        &robot,
        &cam,
        m,
        &target,
        &obs,
        guess,
        Tol::Relative(1e-9),
    );
}

const EXAMPLE: [&str; 11] = crate::common::CAMERA_EXAMPLE;

/// From the command line without `--camera-pose` and `--target-pose`:
/// the text says the start was computed, with its pixel RMS, and the
/// calibration is the guessed one's (the camera's placement and σ̂ as
/// printed); JSON `start` says what was computed and gives the computed
/// placements, which given back start the same fit; one guess given, the
/// other is computed.
#[test]
fn cli_calibrates_without_guesses() {
    let out = common::run(&EXAMPLE);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("start: computed from the pixels (PnP + closed-form hand-eye): the target placed at 40 of 40 poses"),
        "{text}"
    );
    assert!(text.contains("px at the computed placements"), "{text}");
    let mut guessed = EXAMPLE.to_vec();
    guessed.extend([
        "--camera-pose=1.1761,0.6096,0.9079,-2.0681,0.0317,2.0826",
        "--target-pose=-0.1047,0.0411,0.0301,3.1111,-0.0192,0.0556",
    ]);
    let g = String::from_utf8_lossy(&common::run(&guessed).stdout).to_string();
    // The lines from σ̂ on (placements, σ, robot unknowns) are the same.
    let tail = |s: &str| s[s.find("pixel σ").unwrap()..].to_string();
    assert_eq!(tail(&text), tail(&g));
    let mut json = EXAMPLE.to_vec();
    json.push("--json");
    let v = common::json_of(&json);
    assert_eq!(v["converged"], true);
    assert_eq!(v["start"]["camera"], "computed");
    assert_eq!(v["start"]["target"], "computed");
    assert_eq!(v["start"]["method"], "PnP + closed-form hand-eye");
    assert_eq!(v["start"]["poses_placed"], 40);
    // The per-pose PnP fits the pixels to their noise (σ 0.3 px, fewer
    // degrees of freedom: 96 rows less 6 a pose).
    let pnp = v["start"]["pnp_rms_px"].as_f64().unwrap();
    assert!((0.25..0.31).contains(&pnp), "{pnp}");
    // The start's placements, as the options read them: given back, they
    // start the same fit.
    let pose = |w: &str| {
        let a: Vec<String> = v["start"][w]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.to_string())
            .collect();
        a.join(",")
    };
    let (cp, tp) = (
        format!("--camera-pose={}", pose("camera_pose")),
        format!("--target-pose={}", pose("target_pose")),
    );
    let mut again = json.clone();
    again.extend([cp.as_str(), tp.as_str()]);
    let w = common::json_of(&again);
    assert_eq!(w["start"]["camera"], "given");
    assert!(
        (w["start_rms_px"].as_f64().unwrap() / v["start_rms_px"].as_f64().unwrap() - 1.0).abs()
            < 1e-9
    );
    // (The same start to rounding of the round trip through roll, pitch
    // and yaw: the robot's unknowns and the camera's position agree far
    // inside 1e-9 relative; the placements' own unknowns are corrections
    // in charts about the start, near 0, not compared.)
    let names: Vec<&str> = v["names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    let num = |v: &serde_json::Value| v.as_f64().unwrap();
    let (x, y) = (
        w["estimate"].as_array().unwrap(),
        v["estimate"].as_array().unwrap(),
    );
    let xyz = |v: &serde_json::Value| v["camera"]["camera"]["xyz"].as_array().unwrap().clone();
    let (cw, cv) = (xyz(&w), xyz(&v));
    let pairs: Vec<(f64, f64)> = (0..names.len())
        .filter(|&k| !names[k].starts_with("camera_") && !names[k].starts_with("target_"))
        .map(|k| (num(&x[k]), num(&y[k])))
        .chain(cw.iter().zip(&cv).map(|(a, b)| (num(a), num(b))))
        .collect();
    assert_eq!(pairs.len(), 21);
    for (x, y) in pairs {
        assert!((x - y).abs() <= 1e-9 * x.abs().max(y.abs()), "{x} vs {y}");
    }
    // One guess: the other computed.
    json.push(guessed[11]);
    let v = common::json_of(&json);
    assert_eq!(v["converged"], true);
    assert_eq!(v["start"]["camera"], "given");
    assert_eq!(v["start"]["target"], "computed");
    assert_eq!(v["start"]["method"], "PnP");
}

/// Poses whose flange never turns (every pose's joint values those of
/// the first) leave the closed form undetermined: refused, naming the
/// file and what to give, before any fit.
#[test]
fn cli_refuses_a_start_the_pixels_cannot_give() {
    let dir = common::scratch_dir("camera_start", "one-orientation");
    let csv = std::fs::read_to_string("fixtures/camera/ur5_eye_to_hand.csv").unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    let first: Vec<String> = csv
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    let mut out = format!("{header}\n");
    for l in lines {
        let mut f: Vec<&str> = l.split(',').collect();
        f[1..7].clone_from_slice(&first[1..7].iter().map(String::as_str).collect::<Vec<_>>());
        out.push_str(&f.join(","));
        out.push('\n');
    }
    let path = dir.join("one.csv");
    std::fs::write(&path, out).unwrap();
    let p = path.display().to_string();
    let mut args = EXAMPLE.to_vec();
    args[4] = &p;
    common::fails_with(
        &args,
        "one.csv: no start computed from the pixels; give --camera-pose and --target-pose",
    );
    common::fails_with(&args, "turn about one axis or not at all");
}

/// Four of the example's 40 poses with a wrong joint value (the shoulder
/// pan 1.2 rad off, as a pose logged with another configuration): the
/// start's per-pose disagreement
/// (`activecal::identify::camera::start::disagreeing_poses`, named when
/// the start computed from the pixels fails) ranks exactly those four
/// first. The pan is off by 1.2 rad (69°), so a wrong pose's PnP is
/// turned by about that from the start's prediction: more than half of it
/// (35°) for the four, less for every right pose (measured: the four 64–72°
/// and 0.17–0.74 m, the right ones ≤ 4.6° and 63 mm: the start, a
/// least-squares compromise, is pulled off them by the four).
#[test]
fn the_start_names_the_poses_that_disagree() {
    let robot = activecal::io::load_robot("fixtures/ur5.urdf").unwrap();
    let cam = read_camera_info(Path::new("fixtures/camera/camera_info.yaml")).unwrap();
    let target = read_target(Path::new("fixtures/camera/board.yaml")).unwrap();
    let mut obs = read_observations(
        Path::new("fixtures/camera/ur5_eye_to_hand.csv"),
        &robot,
        &target,
        &cam,
        Units::default(),
    )
    .unwrap();
    let bad = [2_i64, 9, 17, 25];
    for (i, q) in obs.qs.iter_mut().enumerate() {
        if bad.contains(&obs.pose_ids[i]) {
            q[0] += if q[0] > 0.0 { -1.2 } else { 1.2 };
        }
    }
    let m = Mounting::EyeToHand;
    let st = start_placements(&robot, &cam, m, &target.points, &obs, None, None).unwrap();
    let d = activecal::identify::camera::start::disagreeing_poses(
        &robot,
        &cam,
        m,
        &target.points,
        &obs,
        &st,
    );
    assert_eq!(d.len(), obs.qs.len());
    let mut top: Vec<i64> = d[..4].iter().map(|x| x.0).collect();
    top.sort_unstable();
    assert_eq!(top, bad, "{d:?}");
    assert!(d[..4].iter().all(|x| x.2 > 35.0), "{d:?}");
    assert!(d[4..].iter().all(|x| x.2 < 35.0), "{d:?}");
}
