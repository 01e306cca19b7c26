use super::*;
use crate::identify::camera::simulate::simulate_observations;
use crate::identify::simulate::fill_standard_normal;
use crate::identify::trial_rng;
use crate::measure::camera::CameraSensor;
use nalgebra::{Rotation3, Translation3, UnitQuaternion};

/// The built-in UR5 (its DH model; the layers below `io` cannot read the
/// URDF fixture).
fn ur5() -> Robot {
    Robot::builtin("ur5").expect("the built-in UR5")
}

/// A 6 × 8 board of 25 mm squares (inner corners, row by row, z = 0).
fn board() -> Vec<Vector3<f64>> {
    (0..6)
        .flat_map(|r| {
            (0..8).map(move |c| Vector3::new(0.025 * f64::from(c), 0.025 * f64::from(r), 0.0))
        })
        .collect()
}

fn intrinsics() -> Intrinsics {
    Intrinsics {
        width: 1280,
        height: 960,
        fx: 1000.0,
        fy: 1000.0,
        cx: 640.0,
        cy: 480.0,
        distortion: crate::measure::pinhole::Distortion::PlumbBob([
            -0.08, 0.04, 5e-4, -3e-4, -0.01,
        ]),
    }
}

fn iso(t: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// The configuration the poses are spread about.
const Q_REF: [f64; 6] = [0.3, -1.0, 1.2, -0.8, 1.1, 0.4];

fn end_at(robot: &Robot, q: &[f64]) -> Isometry3<f64> {
    let e = Evaluator::new(robot, &robot.nominal).end_frame(q);
    Isometry3::from_parts(
        e.position.into(),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(e.rotation)),
    )
}

/// The true placements (camera, target) of a mounting: the moving one
/// 3–6 cm off the flange, the fixed one such that at [`Q_REF`] the camera
/// looks straight at the board's centre from 0.7 m (eye-to-hand) or 0.4 m
/// (eye-in-hand).
fn truth(robot: &Robot, m: Mounting) -> (Isometry3<f64>, Isometry3<f64>) {
    let c = board().iter().sum::<Vector3<f64>>() / 48.0;
    // The board in the camera's frame at Q_REF: its centre on the optical
    // axis, its z (into the board) along the camera's z.
    let seen_at = |d: f64| iso([0.0, 0.0, d], [0.0, 0.0, 0.2]) * Translation3::from(-c);
    let e = end_at(robot, &Q_REF);
    match m {
        Mounting::EyeToHand => {
            let tgt = iso([0.004, -0.003, 0.03], [0.1, -0.05, 0.03]);
            (e * tgt * seen_at(0.7).inverse(), tgt)
        }
        Mounting::EyeInHand => {
            let cam = iso([0.06, 0.0, 0.03], [0.05, -0.1, std::f64::consts::FRAC_PI_2]);
            (cam, e * cam * seen_at(0.4))
        }
    }
}

/// Observations of the nominal UR5 (pixel noise `sigma`) at 30
/// configurations about [`Q_REF`] (each joint N(0, 0.25²) rad off) that
/// see the whole board 20 px inside the image within 60° of its face, and
/// the sensor at the true placements.
fn observed(m: Mounting, sigma: f64) -> (Robot, CameraSensor, CameraObservations) {
    let robot = ur5();
    let (cam, tgt) = truth(&robot, m);
    let sensor = CameraSensor::new(intrinsics(), m, board(), &cam, &tgt);
    let own = CameraSensor::start_own(&cam, &tgt);
    let mut ev = Evaluator::new(&robot, &robot.nominal);
    let mut rng = trial_rng(3, 0);
    let mut qs = Vec::new();
    let mut d = [0.0; 6];
    for _ in 0..2000 {
        fill_standard_normal(&mut rng, &mut d);
        let q: Vec<f64> = Q_REF.iter().zip(&d).map(|(q, d)| q + 0.25 * d).collect();
        let v = sensor.view(&ev.end_frame(&q), &own, 20.0);
        if v.seen == sensor.points().len() && v.angle < 60f64.to_radians() {
            qs.push(q);
        }
        if qs.len() == 30 {
            break;
        }
    }
    assert_eq!(qs.len(), 30, "too few visible configurations");
    let obs = simulate_observations(
        &robot,
        &robot.nominal,
        &sensor,
        &own,
        &qs,
        sigma,
        0.0,
        &mut trial_rng(3, 1),
    );
    (robot, sensor, obs)
}

fn start(
    robot: &Robot,
    s: &CameraSensor,
    obs: &CameraObservations,
    given: (Option<&Isometry3<f64>>, Option<&Isometry3<f64>>),
) -> Result<CameraStart, StartError> {
    start_placements(
        robot,
        s.intrinsics(),
        s.mounting(),
        s.points(),
        obs,
        given.0,
        given.1,
    )
}

fn miss(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    (
        (a.translation.vector - b.translation.vector).norm(),
        a.rotation.angle_to(&b.rotation),
    )
}

/// Noise-free pixels of the nominal robot give both true placements, for
/// both mountings, and with either one given the other: PnP and the
/// closed form are exact, so the miss is rounding (≈ 1e-14); 1e-9 fails
/// any wrong role or inverse (which miss by centimetres or more).
#[test]
fn noise_free_pixels_give_the_true_placements() {
    for m in [Mounting::EyeToHand, Mounting::EyeInHand] {
        let (robot, s, obs) = observed(m, 0.0);
        let (cam, tgt) = truth(&robot, m);
        for given in [(None, None), (Some(&cam), None), (None, Some(&tgt))] {
            let st = start(&robot, &s, &obs, given).unwrap();
            assert_eq!(st.poses_placed, 30);
            assert_eq!(
                (st.camera_computed, st.target_computed),
                (given.0.is_none(), given.1.is_none())
            );
            for (what, e, t) in [("camera", st.camera, cam), ("target", st.target, tgt)] {
                let (dt, dr) = miss(&e, &t);
                assert!(dt < 1e-9 && dr < 1e-9, "{m:?} {what}: {dt} m, {dr} rad");
            }
        }
    }
}

/// With σ 0.3 px the start is a start: within 5 mm and 0.5° of the truth
/// (the fit's first step converges from 30 cm and 20° off; measured
/// here 0.4–2.7 mm and 0.06–0.12°, the poses only ±0.25 rad apart).
#[test]
fn noisy_pixels_give_a_close_start() {
    for m in [Mounting::EyeToHand, Mounting::EyeInHand] {
        let (robot, s, obs) = observed(m, 0.3);
        let (cam, tgt) = truth(&robot, m);
        let st = start(&robot, &s, &obs, (None, None)).unwrap();
        assert!((st.pnp_rms_px / 0.3 - 1.0).abs() < 0.1, "{}", st.pnp_rms_px);
        for (what, e, t) in [("camera", st.camera, cam), ("target", st.target, tgt)] {
            let (dt, dr) = miss(&e, &t);
            eprintln!("{m:?} {what}: {:.3} mm, {:.4}°", 1e3 * dt, dr.to_degrees());
            assert!(
                dt < 5e-3 && dr < 0.5f64.to_radians(),
                "{m:?} {what}: {dt} m, {dr} rad"
            );
        }
    }
}

/// One configuration observed again and again (the flange never turns):
/// refused with the reason, the pixels' noise notwithstanding; poses none
/// of which can be placed: refused with the first pose's reason.
#[test]
fn unsolvable_starts_are_refused() {
    let (robot, s, mut obs) = observed(Mounting::EyeToHand, 0.3);
    let one = obs.qs[0].clone();
    obs.qs.iter_mut().for_each(|q| q.clone_from(&one));
    let err = start(&robot, &s, &obs, (None, None)).unwrap_err();
    assert!(
        matches!(err, StartError::HandEye(HandEyeError::OneAxis { .. })),
        "{err}"
    );
    assert!(
        err.to_string()
            .contains("turn about one axis or not at all"),
        "{err}"
    );
    // Only the first row of the board seen: collinear at every pose.
    let (robot, s, mut obs) = observed(Mounting::EyeToHand, 0.0);
    for seen in &mut obs.seen {
        seen.iter_mut().skip(8).for_each(|p| *p = None);
    }
    let err = start(&robot, &s, &obs, (None, None)).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "the target could be placed from its pixels at 0 of 30 poses, 3 needed (pose {}: the points seen lie on a line)",
            obs.pose_ids[0]
        )
    );
}
