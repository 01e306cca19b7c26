use super::*;
use crate::identify::camera::simulate::simulate_observations;
use crate::identify::trial_rng;
use crate::io::camera_target::Target;
use crate::measure::camera::CameraSensor;
use crate::observability::generic_configurations;
use nalgebra::Translation3;

fn ur5() -> Robot {
    crate::io::load_robot("fixtures/ur5.urdf").expect("the UR5 fixture")
}

fn intrinsics() -> Intrinsics {
    Intrinsics {
        width: 1280,
        height: 960,
        fx: 1000.0,
        fy: 1000.0,
        cx: 640.0,
        cy: 480.0,
        distortion: [-0.08, 0.04, 5e-4, -3e-4, -0.01],
    }
}

fn iso(t: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// The true placements (camera, target) of a mounting (those of
/// `tests/camera.rs`, roughly).
fn truth(m: Mounting) -> (Isometry3<f64>, Isometry3<f64>) {
    match m {
        Mounting::EyeToHand => (
            iso([1.2, 0.6, 0.9], [-2.07, 0.0, 2.08]),
            iso([-0.1, 0.04, 0.03], [3.11, -0.02, 0.06]),
        ),
        Mounting::EyeInHand => (
            iso([0.06, 0.0, 0.03], [0.0, 0.0, std::f64::consts::FRAC_PI_2]),
            iso([0.36, 0.24, 0.0], [std::f64::consts::PI, 0.0, 0.03]),
        ),
    }
}

/// Noise-free observations of the nominal UR5 at 30 configurations that
/// see the whole board, and the sensor at the true placements.
fn observed(m: Mounting, sigma: f64) -> (Robot, CameraSensor, CameraObservations) {
    let robot = ur5();
    let (cam, tgt) = truth(m);
    let board = Target::checkerboard(6, 8, 0.025);
    let sensor = CameraSensor::new(intrinsics(), m, board.points, &cam, &tgt);
    let own = CameraSensor::start_own(&cam, &tgt);
    let mut ev = Evaluator::new(&robot, &robot.nominal);
    let qs: Vec<Vec<f64>> = generic_configurations(&robot, 40_000, 41)
        .into_iter()
        .filter(|q| {
            let v = sensor.view(&ev.end_frame(q), &own, 20.0);
            v.seen == sensor.points().len() && v.angle < 60f64.to_radians()
        })
        .take(30)
        .collect();
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
        let (cam, tgt) = truth(m);
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
/// (the fit's first step converges from 30 cm and 20° off; measured here
/// ≈ 1 mm, 0.05°).
#[test]
fn noisy_pixels_give_a_close_start() {
    for m in [Mounting::EyeToHand, Mounting::EyeInHand] {
        let (robot, s, obs) = observed(m, 0.3);
        let (cam, tgt) = truth(m);
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
