//! Live check of the camera's projection (issue #41; feature `live`, needs
//! the project venv with opencv-python-headless, verify/requirements.txt):
//! activecal's pinhole projection with plumb_bob distortion and its
//! derivative with respect to the point, and the camera sensor's predicted
//! pixels (eye-to-hand and eye-in-hand: the placements and the end frame
//! composed), against OpenCV's `cv2.projectPoints` on the same points.

use activecal::kinematics::EndFrame;
use activecal::measure::Sensor;
use activecal::measure::camera::{CameraSensor, Mounting};
use activecal::measure::pinhole::{Distortion, Intrinsics};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use pyo3::prelude::*;
use pyo3::types::PyModule;
use verify::bridge::Bridge;

const CODE: &std::ffi::CStr = c"
import numpy as np, cv2
def project(points, rvec, tvec, k, dist):
    img, jac = cv2.projectPoints(
        np.array(points, dtype=np.float64).reshape(-1, 1, 3),
        np.array(rvec, dtype=np.float64), np.array(tvec, dtype=np.float64),
        np.array(k, dtype=np.float64).reshape(3, 3), np.array(dist, dtype=np.float64))
    return img.reshape(-1, 2).tolist(), jac.tolist(), cv2.__version__
";

/// OpenCV's pixels and Jacobian (2n × (6 + 4 + 5): rvec, tvec, fx fy cx
/// cy, distortion) of `points` (object frame) under `rvec, tvec`.
fn opencv(
    points: &[Vector3<f64>],
    pose: &Isometry3<f64>,
    c: &Intrinsics,
) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let pts: Vec<[f64; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
    let rvec: [f64; 3] = pose.rotation.scaled_axis().into();
    let tvec: [f64; 3] = pose.translation.vector.into();
    let k = [c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0];
    Python::attach(|py| {
        let m = PyModule::from_code(py, CODE, c"live_camera.py", c"live_camera").unwrap();
        let r = m
            .getattr("project")
            .unwrap()
            .call1((pts, rvec, tvec, k, c.distortion.coefficients().to_vec()))
            .unwrap();
        let (img, jac, version): (Vec<Vec<f64>>, Vec<Vec<f64>>, String) = r.extract().unwrap();
        assert!(
            version.starts_with("4.14"),
            "OpenCV {version}: verify/requirements.txt pins 4.14"
        );
        (img, jac)
    })
}

fn intrinsics() -> Intrinsics {
    Intrinsics {
        width: 1280,
        height: 960,
        fx: 1012.5,
        fy: 1009.25,
        cx: 641.3,
        cy: 479.6,
        distortion: Distortion::PlumbBob([-0.21, 0.13, 8e-4, -6e-4, -0.04]),
    }
}

/// Points spread over the image (out to its corners, where distortion is
/// largest) 0.4–1.6 m in front of the camera, in a frame `pose` places.
fn points(pose: &Isometry3<f64>) -> Vec<Vector3<f64>> {
    let mut v = Vec::new();
    for i in 0..9 {
        for j in 0..7 {
            let z = 0.4 + 0.15 * ((i + j) % 9) as f64;
            let x = (i as f64 - 4.0) / 4.0 * 0.6 * z;
            let y = (j as f64 - 3.0) / 3.0 * 0.45 * z;
            v.push(pose.inverse() * nalgebra::Point3::new(x, y, z));
        }
    }
    v.into_iter().map(|p| p.coords).collect()
}

/// Pixels to 1e-9 px (both compute the same closed form in doubles: pixels
/// O(1e3) carry rounding of ~1e-13 px), and `∂(u, v)/∂X` equal to OpenCV's
/// tvec columns (X = R P + t, so ∂/∂t = ∂/∂X) to 1e-9 relative to the
/// largest entry (~2e3 px/m).
#[test]
fn projection_and_its_jacobian_equal_opencv() {
    let _bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let c = intrinsics();
    let pose = Isometry3::from_parts(
        Translation3::new(0.05, -0.02, 0.1),
        UnitQuaternion::from_euler_angles(0.2, -0.3, 0.4),
    );
    let pts = points(&pose);
    let (img, jac) = opencv(&pts, &pose, &c);
    let (mut dp, mut dj, mut big) = (0.0f64, 0.0f64, 0.0f64);
    for (k, p) in pts.iter().enumerate() {
        let x = pose * nalgebra::Point3::from(*p);
        let ours = c.project(&x.coords).expect("in front");
        for r in 0..2 {
            dp = dp.max((ours.pixel[r] - img[k][r]).abs());
            for col in 0..3 {
                let theirs = jac[2 * k + r][3 + col];
                big = big.max(theirs.abs());
                dj = dj.max((ours.jacobian[(r, col)] - theirs).abs());
            }
        }
    }
    println!(
        "{} points: pixels within {dp:.2e} px, Jacobian within {dj:.2e} px/m (largest {big:.0})",
        pts.len()
    );
    assert!(dp < 1e-9, "pixels differ by {dp} px");
    assert!(dj < 1e-9 * big, "Jacobian differs by {dj} px/m");
}

/// `∂(u, v)/∂(fx, fy, cx, cy, k1, k2, p1, p2, k3)`
/// ([`Intrinsics::intrinsic_jacobian`], the columns `--refine-intrinsics`
/// fits with) equal to OpenCV's focal, principal-point and distortion
/// columns (6..15 of `projectPoints`' Jacobian) to 1e-9 relative to the
/// largest entry (the same closed form in doubles).
#[test]
fn intrinsic_jacobian_equals_opencv() {
    let _bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let c = intrinsics();
    let pose = Isometry3::from_parts(
        Translation3::new(0.05, -0.02, 0.1),
        UnitQuaternion::from_euler_angles(0.2, -0.3, 0.4),
    );
    let pts = points(&pose);
    let (_, jac) = opencv(&pts, &pose, &c);
    let (mut dj, mut big) = (0.0f64, 0.0f64);
    for (k, p) in pts.iter().enumerate() {
        let x = pose * nalgebra::Point3::from(*p);
        let ours = c.intrinsic_jacobian(&x.coords).expect("in front");
        for r in 0..2 {
            for col in 0..9 {
                let theirs = jac[2 * k + r][6 + col];
                big = big.max(theirs.abs());
                dj = dj.max((ours[r][col] - theirs).abs());
            }
        }
    }
    println!("intrinsic Jacobian within {dj:.2e} (largest entry {big:.0})");
    assert!(dj < 1e-9 * big, "intrinsic Jacobian differs by {dj}");
}

/// The sensor's predicted pixels of a target, both mountings, equal
/// OpenCV's projection of the target's points under the camera-from-target
/// transform the placements and the end frame compose (eye-to-hand:
/// `T_c⁻¹ T_end T_t`; eye-in-hand: `(T_end T_c)⁻¹ T_t`), to 1e-9 px.
#[test]
fn camera_sensor_pixels_equal_opencv() {
    let _bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let c = intrinsics();
    let end = Isometry3::from_parts(
        Translation3::new(0.45, -0.1, 0.6),
        UnitQuaternion::from_euler_angles(0.4, 0.7, -1.2),
    );
    let frame = EndFrame {
        rotation: *end.rotation.to_rotation_matrix().matrix(),
        position: end.translation.vector,
    };
    for m in [Mounting::EyeToHand, Mounting::EyeInHand] {
        let placed = Isometry3::from_parts(
            Translation3::new(0.03, -0.01, 0.05),
            UnitQuaternion::from_euler_angles(3.0, 0.1, 0.2),
        );
        // The camera-from-target transform the test wants, and the other
        // placement that gives it.
        let want = Isometry3::from_parts(
            Translation3::new(-0.05, 0.04, 0.8),
            UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3),
        );
        let (camera, target) = match m {
            Mounting::EyeToHand => ((end * placed) * want.inverse(), placed),
            Mounting::EyeInHand => (placed, end * placed * want),
        };
        let target_pts: Vec<Vector3<f64>> = (0..20)
            .map(|k| {
                Vector3::new(
                    0.03 * (k % 5) as f64 - 0.06,
                    0.03 * (k / 5) as f64 - 0.045,
                    0.0,
                )
            })
            .collect();
        let s = CameraSensor::new(c.clone(), m, target_pts.clone(), &camera, &target);
        let mut own = CameraSensor::start_own(&camera, &target);
        // Off the charts' centres, as during a fit.
        own[4] = 0.01;
        own[10] = -0.02;
        let (cam, tgt) = s.placements(&own);
        let cam_from_target = match m {
            Mounting::EyeToHand => cam.inverse() * end * tgt,
            Mounting::EyeInHand => (end * cam).inverse() * tgt,
        };
        let (img, _) = opencv(&target_pts, &cam_from_target, &c);
        let mut pred = vec![0.0; s.value_len()];
        s.predict(&frame, &own, &mut pred);
        let d = img
            .iter()
            .enumerate()
            .map(|(k, px)| {
                (pred[3 * k] - px[0])
                    .abs()
                    .max((pred[3 * k + 1] - px[1]).abs())
            })
            .fold(0.0f64, f64::max);
        println!("{}: {} points within {d:.2e} px", m.name(), img.len());
        assert!(d < 1e-9, "{m:?}: {d} px");
    }
}
