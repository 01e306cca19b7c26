use super::*;
use crate::measure::pinhole::Distortion;
use nalgebra::Rotation3;

fn intrinsics() -> Intrinsics {
    Intrinsics {
        width: 1280,
        height: 960,
        fx: 900.0,
        fy: 905.0,
        cx: 640.0,
        cy: 480.0,
        distortion: Distortion::PlumbBob([-0.1, 0.05, 1e-3, -5e-4, -0.01]),
    }
}

fn end() -> EndFrame {
    EndFrame {
        rotation: *Rotation3::from_euler_angles(0.3, -0.7, 1.1).matrix(),
        position: Vector3::new(0.4, -0.2, 0.9),
    }
}

/// A 3 × 4 grid of 30 mm squares about the target's origin.
fn grid() -> Vec<Vector3<f64>> {
    (0..12)
        .map(|k| {
            Vector3::new(
                0.03 * (k % 4) as f64 - 0.045,
                0.03 * (k / 4) as f64 - 0.03,
                0.0,
            )
        })
        .collect()
}

fn iso(t: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// A sensor of `mounting` whose camera sees the target's centre about
/// 0.7 m straight ahead at end frame [`end`], and own unknowns with
/// rotations off their charts' centres (so that `J_r` is exercised).
fn setup(mounting: Mounting) -> (CameraSensor, Vec<f64>) {
    setup_with(mounting, intrinsics())
}

/// [`setup`] with the camera `c`.
fn setup_with(mounting: Mounting, c: Intrinsics) -> (CameraSensor, Vec<f64>) {
    let e = end();
    let ahead = Vector3::new(0.04, -0.03, 0.7);
    let (camera, target) = match mounting {
        Mounting::EyeToHand => {
            let target = iso([0.02, 0.01, 0.12], [0.2, -0.1, 0.4]);
            let centre = e.position + e.rotation * target.translation.vector;
            let rc = UnitQuaternion::from_euler_angles(2.0, 0.3, -0.5);
            let camera = Isometry3::from_parts((centre - rc * ahead).into(), rc);
            (camera, target)
        }
        Mounting::EyeInHand => {
            let camera = iso([0.05, 0.0, 0.08], [0.1, 0.2, -0.3]);
            let at = e.position + e.rotation * camera.translation.vector;
            let centre = at + e.rotation * (camera.rotation * ahead);
            let target = Isometry3::from_parts(
                centre.into(),
                UnitQuaternion::from_euler_angles(3.0, 0.1, 0.2),
            );
            (camera, target)
        }
    };
    let s = CameraSensor::new(c, mounting, grid(), &camera, &target);
    let mut own = CameraSensor::start_own(&camera, &target);
    for (k, d) in [
        (3, 0.02),
        (4, -0.01),
        (5, 0.015),
        (9, -0.03),
        (10, 0.02),
        (11, 0.01),
    ] {
        own[k] = d;
    }
    (s, own)
}

/// Each Jacobian row is the derivative of the predicted pixel, for both
/// mountings: central differences of `predict` under a rigid motion of
/// the end frame (robot columns) and under each own unknown. Step 1e-6
/// (metres, radians) on pixels whose derivatives are 10²–10³ px per unit:
/// truncation O(h² · 10³) ≈ 1e-9, rounding ε · 10³ / h ≈ 1e-7 px per unit;
/// 1e-4 tells a right entry from a wrong one (a wrong sign or frame is off
/// by O(10²)).
#[test]
fn rows_are_derivatives_of_the_prediction() {
    for mounting in [Mounting::EyeToHand, Mounting::EyeInHand] {
        let (s, own) = setup(mounting);
        let e = end();
        let motions = [
            Motion {
                lin: Vector3::new(0.3, -0.1, 0.2),
                ang: Vector3::zeros(),
            },
            Motion {
                lin: Vector3::new(0.0, 0.5, 0.0),
                ang: Vector3::new(0.2, -0.4, 0.7),
            },
        ];
        let (p, n, t) = (motions.len(), motions.len() + OWN_PARAMS, s.rows());
        let mut jac = vec![0.0; t * n];
        s.motion_rows(&e, &own, &motions, &mut jac, n);
        s.own_rows(&e, &own, &mut jac[p..], n);
        let pixels = |c: usize, h: f64| {
            let (mut ee, mut o) = (e, own.clone());
            if c < p {
                let m = &motions[c];
                ee.rotation = Rotation3::new(h * m.ang).matrix() * ee.rotation;
                ee.position += h * m.lin;
            } else {
                o[c - p] += h;
            }
            let mut out = vec![0.0; s.value_len()];
            s.predict(&ee, &o, &mut out);
            out
        };
        let mut seen = 0;
        for c in 0..n {
            let (a, b) = (pixels(c, 1e-6), pixels(c, -1e-6));
            for k in 0..s.points().len() {
                assert_eq!(a[3 * k + 2], 1.0, "{mounting:?}: point {k} in front");
                for r in 0..2 {
                    let fd = (a[3 * k + r] - b[3 * k + r]) / 2e-6;
                    let j = jac[(2 * k + r) * n + c];
                    assert!(
                        (j - fd).abs() < 1e-4,
                        "{mounting:?} row {} col {c}: {j} vs {fd}",
                        2 * k + r
                    );
                    seen += usize::from(j.abs() > 1.0);
                }
            }
        }
        // The rows are not trivially zero: most entries are pixels per unit.
        assert!(seen > t * n / 2, "{mounting:?}: {seen} of {}", t * n);
    }
}

/// A point not seen has zero residual and zero rows; one seen has its
/// pixel error; the residual rows of a measured value agree with the
/// design rows where every point is seen (the design rows keep every
/// point: they are all inside the image).
#[test]
fn points_not_seen_have_no_rows() {
    let (s, own) = setup(Mounting::EyeToHand);
    let e = end();
    let mut pred = vec![0.0; s.value_len()];
    s.predict(&e, &own, &mut pred);
    let mut seen: Vec<Option<[f64; 2]>> = pred
        .chunks_exact(3)
        .map(|c| Some([c[0] + 0.5, c[1] - 0.25]))
        .collect();
    seen[3] = None;
    let measured = CameraSensor::value_of(&seen);
    assert_eq!(s.seen_rows(&measured), 22);
    let mut r = vec![0.0; s.rows()];
    s.residual(&pred, &measured, &mut r);
    assert_eq!((r[0], r[1]), (-0.5, 0.25));
    assert_eq!((r[6], r[7]), (0.0, 0.0));
    let m = [Motion {
        lin: Vector3::new(0.1, 0.2, 0.3),
        ang: Vector3::new(0.3, 0.0, -0.2),
    }];
    let n = 1 + OWN_PARAMS;
    let (mut a, mut b) = (vec![0.0; s.rows() * n], vec![0.0; s.rows() * n]);
    s.motion_rows(&e, &own, &m, &mut a, n);
    s.own_rows(&e, &own, &mut a[1..], n);
    s.residual_rows(&e, &own, &m, &measured, &mut b, n);
    s.own_rows_of(&e, &own, &measured, &mut b[1..], n);
    for row in 0..s.rows() {
        for c in 0..n {
            let want = if row / 2 == 3 { 0.0 } else { a[row * n + c] };
            assert_eq!(b[row * n + c], want, "row {row} col {c}");
        }
    }
    assert!(a[6 * n].abs() > 1.0);
}

/// The design rows keep only points inside the image with the margin: a
/// margin larger than half the image drops every point.
#[test]
fn design_rows_keep_points_inside_the_image() {
    let (s, own) = setup(Mounting::EyeInHand);
    let s = s.with_margin(600.0);
    let m = [Motion {
        lin: Vector3::new(0.1, 0.2, 0.3),
        ang: Vector3::zeros(),
    }];
    let mut a = vec![1.0; s.rows() * (1 + OWN_PARAMS)];
    s.motion_rows(&end(), &own, &m, &mut a, 1 + OWN_PARAMS);
    s.own_rows(&end(), &own, &mut a[1..], 1 + OWN_PARAMS);
    assert!(a.iter().all(|v| *v == 0.0));
}

/// Re-centring the charts keeps the placements; names are the camera's
/// then the target's.
#[test]
fn recentring_keeps_the_placements() {
    let (s, own) = setup(Mounting::EyeToHand);
    let (r, own2) = s.recentred(&own);
    let (a, b) = (s.placements(&own), r.placements(&own2));
    assert!(
        (a.0.inverse() * b.0)
            .to_homogeneous()
            .iter()
            .zip(nalgebra::Matrix4::<f64>::identity().iter())
            .all(|(x, y)| (x - y).abs() < 1e-14)
    );
    assert!((a.1.inverse() * b.1).rotation.angle() < 1e-14);
    assert_eq!(own2[3..6], [0.0; 3]);
    let names = s.own_param_names();
    assert_eq!(
        (names[0].as_str(), names[5].as_str(), names[6].as_str()),
        ("camera_x", "camera_rz", "target_x")
    );
    assert_eq!(s.rows(), 24);
}

/// A fisheye whose 8 intrinsics are unknowns: its own rows (placements and
/// fx … k4) are derivatives of the predicted pixels, central differences
/// with step 1e-6 as in [`rows_are_derivatives_of_the_prediction`] (the
/// k's columns run to ~1e2 px per unit), both mountings.
#[test]
fn fisheye_own_rows_are_derivatives_of_the_prediction() {
    let fish = Intrinsics {
        fx: 400.0,
        fy: 401.0,
        distortion: Distortion::Equidistant([-0.01, 0.002, -0.001, 0.0001]),
        ..intrinsics()
    };
    for mounting in [Mounting::EyeToHand, Mounting::EyeInHand] {
        let (s, mut own) = setup_with(mounting, fish.clone());
        let s = s.with_intrinsics_refined(true);
        own.extend(s.free_intrinsic_values());
        let n = s.n_own_params();
        assert_eq!(n, OWN_PARAMS + 8);
        assert_eq!(s.own_param_names()[n - 1], "camera_k4");
        let mut jac = vec![0.0; s.rows() * n];
        s.own_rows(&end(), &own, &mut jac, n);
        let pixels = |c: usize, h: f64| {
            let mut o = own.clone();
            o[c] += h;
            let mut out = vec![0.0; s.value_len()];
            s.predict(&end(), &o, &mut out);
            out
        };
        for c in 0..n {
            let (a, b) = (pixels(c, 1e-6), pixels(c, -1e-6));
            for row in 0..s.rows() {
                let (k, r) = (row / 2, row % 2);
                let fd = (a[3 * k + r] - b[3 * k + r]) / 2e-6;
                let j = jac[row * n + c];
                assert!(
                    (j - fd).abs() < 1e-4,
                    "{mounting:?} row {row} col {c}: {j} vs {fd}"
                );
            }
        }
    }
}

/// The viewing angle is measured from the target's face direction: a
/// target seen from its −z side (Kalibr's aprilgrid, `with_face(−z)`)
/// has the supplement of the angle it has seen from +z.
#[test]
fn the_face_direction_turns_the_viewing_angle() {
    let (s, own) = setup(Mounting::EyeToHand);
    let a = s.view(&end(), &own, 0.0);
    let b = s.clone().with_face(-Vector3::z()).view(&end(), &own, 0.0);
    // (The setup's board is seen 81° off its face: the two differ.)
    assert!((a.angle - b.angle).abs() > 0.1, "{a:?} {b:?}");
    assert!(
        (a.angle + b.angle - std::f64::consts::PI).abs() < 1e-12,
        "{a:?} {b:?}"
    );
    assert_eq!((a.seen, a.distance), (b.seen, b.distance));
}
