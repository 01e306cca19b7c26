//! Live check of the fisheye camera and the ChArUco target (issue #41;
//! feature `live`, the project venv with opencv-python-headless 4.14):
//! activecal's equidistant projection ([`activecal::measure::fisheye`]),
//! its derivative with respect to the point and to the intrinsics, against
//! OpenCV's `cv2.fisheye.projectPoints` on the same points, from the axis
//! out to 85° off it; and a ChArUco board's corners against
//! `cv2.aruco.CharucoBoard(...).getChessboardCorners()`.

use activecal::io::camera_target::parse_target;
use activecal::measure::pinhole::{Distortion, Intrinsics};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use pyo3::prelude::*;
use pyo3::types::PyModule;
use verify::bridge::Bridge;

const CODE: &std::ffi::CStr = c"
import numpy as np, cv2
def project(points, rvec, tvec, k, dist):
    img, jac = cv2.fisheye.projectPoints(
        np.array(points, dtype=np.float64).reshape(-1, 1, 3),
        np.array(rvec, dtype=np.float64), np.array(tvec, dtype=np.float64),
        np.array(k, dtype=np.float64).reshape(3, 3), np.array(dist, dtype=np.float64))
    return img.reshape(-1, 2).tolist(), jac.tolist(), cv2.__version__
def charuco(rows, cols, square, marker):
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_6X6_250)
    b = cv2.aruco.CharucoBoard((cols, rows), square, marker, d)
    return np.asarray(b.getChessboardCorners(), dtype=np.float64).reshape(-1, 3).tolist()
";

fn module(py: Python<'_>) -> Bound<'_, PyModule> {
    PyModule::from_code(py, CODE, c"live_fisheye.py", c"live_fisheye").unwrap()
}

/// OpenCV's pixels and Jacobian (2n × 15; its columns, as OpenCV's
/// documentation lists them and a probe confirms: fx, fy, cx, cy, k1 … k4,
/// rvec 3, tvec 3, skew α) of `points` (object frame) under `pose`.
fn opencv(
    points: &[Vector3<f64>],
    pose: &Isometry3<f64>,
    c: &Intrinsics,
) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let pts: Vec<[f64; 3]> = points.iter().map(|p| [p.x, p.y, p.z]).collect();
    let rvec: [f64; 3] = pose.rotation.scaled_axis().into();
    let tvec: [f64; 3] = pose.translation.vector.into();
    let k = [c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0];
    let d = c.distortion.coefficients().to_vec();
    Python::attach(|py| {
        let r = module(py)
            .getattr("project")
            .unwrap()
            .call1((pts, rvec, tvec, k, d))
            .unwrap();
        let (img, jac, version): (Vec<Vec<f64>>, Vec<Vec<f64>>, String) = r.extract().unwrap();
        assert!(
            version.starts_with("4.14"),
            "OpenCV {version}: verify/requirements.txt pins 4.14"
        );
        (img, jac)
    })
}

/// A fisheye of focal length ~400 px on a 1280 × 960 image, k's of the
/// size a calibrated wide-angle lens has (a few % of θ at 80°).
fn intrinsics() -> Intrinsics {
    Intrinsics {
        width: 1280,
        height: 960,
        fx: 401.25,
        fy: 399.5,
        cx: 641.3,
        cy: 479.6,
        distortion: Distortion::Equidistant([-0.012, 0.0023, -0.0011, 0.00013]),
    }
}

/// Points in a frame `pose` places, in the optical frame: on the axis,
/// 1e-7 and 1e-3 rad off it (where the scale's series is used), then on
/// rings 5°–85° off it in eight directions, 0.3–1.5 m away.
fn points(pose: &Isometry3<f64>) -> Vec<Vector3<f64>> {
    let mut v = vec![
        Point3::new(0.0, 0.0, 0.7),
        Point3::new(7e-8, 0.0, 0.7),
        Point3::new(4e-4, -5.5e-4, 0.7),
    ];
    for ring in 1..=17 {
        let off = (5.0 * f64::from(ring)).to_radians();
        for dir in 0..8 {
            let az = std::f64::consts::FRAC_PI_4 * f64::from(dir) + 0.1 * f64::from(ring);
            let z = 0.3 + 0.07 * f64::from(ring);
            let r = z * off.tan();
            v.push(Point3::new(r * az.cos(), r * az.sin(), z));
        }
    }
    v.into_iter().map(|p| (pose.inverse() * p).coords).collect()
}

fn pose() -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(0.05, -0.02, 0.1),
        UnitQuaternion::from_euler_angles(0.2, -0.3, 0.4),
    )
}

/// Pixels to 1e-9 px (both evaluate the same closed form in doubles:
/// pixels O(1e3) carry ~1e-13 px of rounding, and the series near the
/// axis agrees with `atan` to ~1e-16), `∂(u, v)/∂X` equal to OpenCV's
/// tvec columns (X = R P + t: ∂/∂t = ∂/∂X) and `∂(u, v)/∂(fx … k4)` to
/// its first eight columns, each to 1e-9 relative to the largest entry of
/// its block.
#[test]
fn fisheye_projection_and_jacobians_equal_opencv() {
    let _bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let c = intrinsics();
    let pose = pose();
    let pts = points(&pose);
    let (img, jac) = opencv(&pts, &pose, &c);
    let (mut dp, mut dj, mut big, mut di, mut bigi) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (k, p) in pts.iter().enumerate() {
        let x = (pose * Point3::from(*p)).coords;
        let ours = c.project(&x).expect("in front");
        let ji = c.intrinsic_jacobian(&x).expect("in front");
        for r in 0..2 {
            dp = dp.max((ours.pixel[r] - img[k][r]).abs());
            for col in 0..3 {
                let theirs = jac[2 * k + r][11 + col];
                big = big.max(theirs.abs());
                dj = dj.max((ours.jacobian[(r, col)] - theirs).abs());
            }
            for (col, ours) in ji[r].iter().enumerate() {
                let theirs = jac[2 * k + r][col];
                bigi = bigi.max(theirs.abs());
                di = di.max((ours - theirs).abs());
            }
        }
    }
    println!(
        "{} points 0–85° off the axis: pixels within {dp:.2e} px, ∂/∂X within {dj:.2e} px/m (largest {big:.0}), ∂/∂(fx…k4) within {di:.2e} (largest {bigi:.0})",
        pts.len()
    );
    assert!(dp < 1e-9, "pixels differ by {dp} px");
    assert!(dj < 1e-9 * big, "∂/∂X differs by {dj} px/m");
    assert!(di < 1e-9 * bigi, "intrinsic Jacobian differs by {di}");
}

/// `∂(u, v)/∂X` against central differences of OpenCV's own pixels (step
/// 1e-6 m on points 0.3–1.5 m away: truncation ~f h²/Z³ ≲ 2e-8 px/m,
/// rounding ~ε u/h ≈ 2e-7 px/m) to 1e-6 px/m of entries up to ~1e3 px/m:
/// an independent check of the derivative, OpenCV's Jacobian aside.
#[test]
fn fisheye_jacobian_equals_central_differences_of_opencv() {
    let _bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let c = intrinsics();
    let id = Isometry3::identity();
    // In the optical frame.
    let pts = points(&id);
    let h = 1e-6;
    let mut worst = 0.0f64;
    for k in 0..3 {
        let shift = |s: f64| -> Vec<Vector3<f64>> {
            pts.iter().map(|p| p + s * Vector3::ith(k, 1.0)).collect()
        };
        let (a, _) = opencv(&shift(h), &id, &c);
        let (b, _) = opencv(&shift(-h), &id, &c);
        for (i, p) in pts.iter().enumerate() {
            let j = c.project(p).expect("in front").jacobian;
            for r in 0..2 {
                let fd = (a[i][r] - b[i][r]) / (2.0 * h);
                worst = worst.max((j[(r, k)] - fd).abs());
            }
        }
    }
    println!("∂(u, v)/∂X against OpenCV's central differences: within {worst:.2e} px/m");
    assert!(worst < 1e-6, "{worst} px/m");
}

/// A ChArUco board's points (`charuco: {rows, cols, square, marker}`)
/// equal OpenCV's `getChessboardCorners()` for `CharucoBoard((cols,
/// rows), square, marker, DICT_6X6_250)`, id by id (OpenCV's corner id is
/// the index into that list), to 1e-7 m (OpenCV keeps them as float32: a
/// 0.3 m coordinate carries ~1e-8 m), odd and even row counts (OpenCV
/// ≥ 4.6 lays out even-row boards differently, the corners stay).
#[test]
fn charuco_corners_equal_opencv() {
    let _bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    for (rows, cols, square, marker) in
        [(5, 7, 0.04, 0.031), (6, 4, 0.025, 0.018), (3, 3, 0.1, 0.07)]
    {
        let yaml = format!(
            "charuco: {{rows: {rows}, cols: {cols}, square: {square}, marker: {marker}}}\n"
        );
        let t = parse_target(&yaml, "charuco.yaml").unwrap();
        let theirs: Vec<Vec<f64>> = Python::attach(|py| {
            module(py)
                .getattr("charuco")
                .unwrap()
                .call1((rows, cols, square, marker))
                .unwrap()
                .extract()
                .unwrap()
        });
        assert_eq!(t.points.len(), theirs.len(), "{yaml}");
        let mut worst = 0.0f64;
        for (id, p) in theirs.iter().enumerate() {
            let k = t.index_of(id as i64).expect("every OpenCV id");
            worst = worst.max((t.points[k] - Vector3::new(p[0], p[1], p[2])).norm());
        }
        println!(
            "charuco {rows}×{cols} squares: {} corners within {worst:.1e} m",
            t.points.len()
        );
        assert!(worst < 1e-7, "{yaml}: {worst} m");
    }
}
