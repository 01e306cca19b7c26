//! Where a target is in a camera's optical frame at one pose, from the
//! pixels of its points (perspective-n-point, PnP):
//!
//! 1. each pixel is undistorted to a normalised point `(x, y)` (the
//!    plumb_bob model of [`crate::measure::pinhole`] inverted by Newton's
//!    iteration on its own derivative);
//! 2. a closed-form pose: for a **planar** target (the smallest singular
//!    value of the centred points below [`PLANAR_TOL`] of the largest)
//!    Zhang's decomposition of the plane-to-image homography `H ∝ [r₁ r₂
//!    t]` (Zhang 2000, §2–3), found by the DLT on Hartley-normalised points
//!    (Hartley & Zisserman 2004, alg. 4.2); for a non-planar one (six
//!    points or more) the DLT of the 3 × 4 matrix `[R | t]` up to scale
//!    (ibid., §7.1); either rotation made orthonormal by the SVD (`U Vᵀ`);
//! 3. Gauss–Newton steps on the pixel reprojection error, the rotation in
//!    a chart `R exp([δ]×)` about the current one, a step halved until the
//!    squared error falls.

use crate::measure::pinhole::{Intrinsics, skew};
use nalgebra::{
    DMatrix, Isometry3, Matrix3, Matrix6, Rotation3, Translation3, UnitQuaternion, Vector2,
    Vector3, Vector6,
};

/// A target is planar when the smallest singular value of its centred
/// points is at most this fraction of the largest: a printed board's
/// points lie on a plane to rounding (1e-16 relative), a 3-D rig's are
/// off it by far more than 1e-6 of its size.
pub const PLANAR_TOL: f64 = 1e-6;

/// Most Gauss–Newton steps of the refinement; from the closed form's
/// start (a few tenths of a pixel off with noise) it converges
/// quadratically within five or six.
const MAX_STEPS: usize = 30;

/// Where a target is in the camera's optical frame at one pose.
#[derive(Clone, Debug)]
pub struct TargetView {
    /// The target frame in the optical frame: a target point `s` is at
    /// `pose · s`.
    pub pose: Isometry3<f64>,
    /// RMS over the points' pixel coordinates of the reprojection error
    /// at `pose`, pixels.
    pub rms_px: f64,
    /// `JᵀJ` of the pixel residuals at `pose` in the translation (metres)
    /// and the rotation chart `pose.rotation · exp([δ]×)` (radians): with
    /// pixel noise σ, the pose's covariance is `σ² (JᵀJ)⁻¹`.
    pub information: Matrix6<f64>,
}

/// Why a pose's target could not be placed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PnpError {
    /// Fewer points than the closed form needs.
    #[error("{seen} point(s) seen; placing the target needs {need}")]
    TooFewPoints {
        /// Points seen.
        seen: usize,
        /// Points needed (4 on a planar target, 6 off a plane).
        need: usize,
    },
    /// The target's points seen lie on a line.
    #[error("the points seen lie on a line")]
    Collinear,
    /// A pixel the distortion model cannot undistort.
    #[error("pixel ({u}, {v}) cannot be undistorted with the camera's distortion")]
    Undistort {
        /// The pixel.
        u: f64,
        /// The pixel.
        v: f64,
    },
    /// The closed form gave no pose with the points in front of the camera.
    #[error("no pose puts the points seen in front of the camera")]
    NoPose,
}

/// The normalised point `(x, y)` (on the plane `Z = 1` of the optical
/// frame) whose projection by `cam` is `pixel`: Newton's iteration on the
/// projection and its derivative from the undistorted guess, to 1e-12 px;
/// `None` when it does not converge (a pixel beyond where the distortion
/// polynomial folds back).
#[must_use]
pub fn undistort(cam: &Intrinsics, pixel: [f64; 2]) -> Option<[f64; 2]> {
    let target = Vector2::new(pixel[0], pixel[1]);
    let mut x = Vector2::new((pixel[0] - cam.cx) / cam.fx, (pixel[1] - cam.cy) / cam.fy);
    for _ in 0..50 {
        let p = cam.project(&Vector3::new(x.x, x.y, 1.0))?;
        let r = Vector2::new(p.pixel[0], p.pixel[1]) - target;
        if r.norm() <= 1e-12 * (1.0 + target.norm()) {
            return Some([x.x, x.y]);
        }
        let j = p.jacobian.fixed_columns::<2>(0).into_owned();
        x -= j.try_inverse()? * r;
        if !x.iter().all(|v| v.is_finite()) {
            return None;
        }
    }
    None
}

/// The rotation nearest `m` in the Frobenius norm: `U diag(1, 1, det(U
/// Vᵀ)) Vᵀ` of its SVD `U Σ Vᵀ`.
#[must_use]
pub fn nearest_rotation(m: &Matrix3<f64>) -> Matrix3<f64> {
    let svd = m.svd(true, true);
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let d = (u * vt).determinant().signum();
    u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * vt
}

/// Places a target seen by `cam`: `points` (target frame, metres) seen at
/// `pixels`, in the same order (see the module documentation).
pub fn place_target(
    cam: &Intrinsics,
    points: &[Vector3<f64>],
    pixels: &[[f64; 2]],
) -> Result<TargetView, PnpError> {
    let seen = points.len();
    if seen < 4 {
        return Err(PnpError::TooFewPoints { seen, need: 4 });
    }
    let norm: Vec<Vector2<f64>> = pixels
        .iter()
        .map(|&p| {
            undistort(cam, p)
                .map(|x| Vector2::new(x[0], x[1]))
                .ok_or(PnpError::Undistort { u: p[0], v: p[1] })
        })
        .collect::<Result<_, _>>()?;
    let shape = Shape::of(points);
    if shape.sv[1] <= PLANAR_TOL * shape.sv[0] {
        return Err(PnpError::Collinear);
    }
    let pose0 = if shape.sv[2] <= PLANAR_TOL * shape.sv[0] {
        planar_pose(&shape, points, &norm)?
    } else if seen < 6 {
        return Err(PnpError::TooFewPoints { seen, need: 6 });
    } else {
        general_pose(points, &norm)?
    };
    refine(cam, points, pixels, pose0)
}

/// The centred points' principal axes: their centroid, the axes (columns,
/// right-handed, the third the plane's normal for a planar target) and
/// the singular values, largest first.
struct Shape {
    centroid: Vector3<f64>,
    axes: Matrix3<f64>,
    sv: [f64; 3],
}

impl Shape {
    fn of(points: &[Vector3<f64>]) -> Self {
        let centroid = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
        let mut scatter = Matrix3::zeros();
        for p in points {
            let d = p - centroid;
            scatter += d * d.transpose();
        }
        // The scatter's eigenvectors are the centred points' left singular
        // vectors, its eigenvalues their singular values squared.
        let svd = scatter.svd(true, false);
        let mut axes = svd.u.unwrap();
        if axes.determinant() < 0.0 {
            axes.set_column(2, &(-axes.column(2)));
        }
        let s = svd.singular_values.map(f64::sqrt);
        Shape {
            centroid,
            axes,
            sv: [s[0], s[1], s[2]],
        }
    }
}

/// Hartley's normalisation of points (rows of `pts`, `d` coordinates):
/// the similarity that moves their centroid to the origin and their mean
/// distance from it to `√d`, as a `(d+1) × (d+1)` homogeneous matrix.
fn hartley(pts: &[&[f64]], d: usize) -> DMatrix<f64> {
    let n = pts.len() as f64;
    let c: Vec<f64> = (0..d)
        .map(|k| pts.iter().map(|p| p[k]).sum::<f64>() / n)
        .collect();
    let mean = pts
        .iter()
        .map(|p| (0..d).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>().sqrt())
        .sum::<f64>()
        / n;
    let s = (d as f64).sqrt() / mean.max(f64::MIN_POSITIVE);
    let mut t = DMatrix::identity(d + 1, d + 1);
    for k in 0..d {
        t[(k, k)] = s;
        t[(k, d)] = -s * c[k];
    }
    t
}

/// The right singular vector of `a`'s smallest singular value (rows of
/// zeros added up to a square, so that the SVD holds the null space).
fn null_vector(mut a: DMatrix<f64>) -> nalgebra::DVector<f64> {
    let cols = a.ncols();
    if a.nrows() < cols {
        a = a.resize_vertically(cols, 0.0);
    }
    let svd = a.svd(false, true);
    let vt = svd.v_t.unwrap();
    let k = svd.singular_values.imin();
    vt.row(k).transpose()
}

/// The DLT matrix `m` (rows × `d+1`, row-major in `h`) that maps the
/// homogeneous `from` points to the `to` points, both normalised.
fn dlt(from: &[Vec<f64>], to: &[Vector2<f64>], d: usize) -> DMatrix<f64> {
    let f: Vec<&[f64]> = from.iter().map(Vec::as_slice).collect();
    let t: Vec<&[f64]> = to.iter().map(|p| p.as_slice()).collect();
    let (tf, tt) = (hartley(&f, d), hartley(&t, 2));
    let w = d + 1;
    let mut a = DMatrix::zeros(2 * from.len(), 3 * w);
    for (i, (p, q)) in from.iter().zip(to).enumerate() {
        let mut ph = nalgebra::DVector::from_element(w, 1.0);
        ph.rows_mut(0, d).copy_from_slice(p);
        let x = &tf * ph;
        let y = &tt * nalgebra::DVector::from_vec(vec![q.x, q.y, 1.0]);
        let (u, v) = (y[0] / y[2], y[1] / y[2]);
        for k in 0..w {
            a[(2 * i, k)] = -x[k];
            a[(2 * i, 2 * w + k)] = u * x[k];
            a[(2 * i + 1, w + k)] = -x[k];
            a[(2 * i + 1, 2 * w + k)] = v * x[k];
        }
    }
    let h = null_vector(a);
    let hn = DMatrix::from_row_slice(3, w, h.as_slice());
    tt.try_inverse().expect("a similarity is invertible") * hn * tf
}

/// Zhang's pose from the plane-to-image homography (module documentation).
fn planar_pose(
    shape: &Shape,
    points: &[Vector3<f64>],
    norm: &[Vector2<f64>],
) -> Result<Isometry3<f64>, PnpError> {
    let e = shape.axes;
    let plane: Vec<Vec<f64>> = points
        .iter()
        .map(|p| {
            let l = e.transpose() * (p - shape.centroid);
            vec![l.x, l.y]
        })
        .collect();
    let h = dlt(&plane, norm, 2);
    let (h1, h2, h3) = (
        Vector3::new(h[(0, 0)], h[(1, 0)], h[(2, 0)]),
        Vector3::new(h[(0, 1)], h[(1, 1)], h[(2, 1)]),
        Vector3::new(h[(0, 2)], h[(1, 2)], h[(2, 2)]),
    );
    let mut lambda = 2.0 / (h1.norm() + h2.norm());
    // The plane's origin (the points' centroid) lies in front of the camera.
    if h3.z < 0.0 {
        lambda = -lambda;
    }
    let (r1, r2) = (lambda * h1, lambda * h2);
    let rp = nearest_rotation(&Matrix3::from_columns(&[r1, r2, r1.cross(&r2)]));
    let tp = lambda * h3;
    // X = R_p Eᵀ (s − c) + t_p.
    let r = rp * e.transpose();
    let t = tp - r * shape.centroid;
    finite_pose(r, t)
}

/// The DLT pose of a non-planar target (module documentation).
fn general_pose(
    points: &[Vector3<f64>],
    norm: &[Vector2<f64>],
) -> Result<Isometry3<f64>, PnpError> {
    let from: Vec<Vec<f64>> = points.iter().map(|p| vec![p.x, p.y, p.z]).collect();
    let mut p = dlt(&from, norm, 3);
    let m = p.fixed_view::<3, 3>(0, 0).into_owned();
    // P = λ [R | t], det(M) = λ³: the sign of λ.
    if m.determinant() < 0.0 {
        p = -p;
    }
    let m = p.fixed_view::<3, 3>(0, 0).into_owned();
    let lambda = m.svd(false, false).singular_values.mean();
    let r = nearest_rotation(&m);
    let t = Vector3::new(p[(0, 3)], p[(1, 3)], p[(2, 3)]) / lambda;
    finite_pose(r, t)
}

fn finite_pose(r: Matrix3<f64>, t: Vector3<f64>) -> Result<Isometry3<f64>, PnpError> {
    if !(r.iter().chain(t.iter()).all(|v| v.is_finite())) {
        return Err(PnpError::NoPose);
    }
    Ok(Isometry3::from_parts(
        Translation3::from(t),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r)),
    ))
}

/// The squared pixel error of `pose`, and when `normal` is given `JᵀJ`
/// and `Jᵀr` there (module documentation); `None` when a point is not in
/// front of the camera.
fn cost(
    cam: &Intrinsics,
    points: &[Vector3<f64>],
    pixels: &[[f64; 2]],
    pose: &Isometry3<f64>,
    mut normal: Option<(&mut Matrix6<f64>, &mut Vector6<f64>)>,
) -> Option<f64> {
    let r = pose.rotation.to_rotation_matrix().into_inner();
    let mut sum = 0.0;
    for (s, m) in points.iter().zip(pixels) {
        let p = cam.project(&(r * s + pose.translation.vector))?;
        let res = Vector2::new(p.pixel[0] - m[0], p.pixel[1] - m[1]);
        sum += res.norm_squared();
        if let Some((n, g)) = normal.as_mut() {
            // dX = dt − R [s]× δ.
            let mut dx = nalgebra::Matrix3x6::zeros();
            dx.fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&Matrix3::identity());
            dx.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-r * skew(s)));
            let j = p.jacobian * dx;
            **n += j.transpose() * j;
            **g += j.transpose() * res;
        }
    }
    Some(sum)
}

/// Gauss–Newton refinement of `pose` on the pixel error (module
/// documentation), from the closed form's `pose`: refused when that puts
/// a point behind the camera.
fn refine(
    cam: &Intrinsics,
    points: &[Vector3<f64>],
    pixels: &[[f64; 2]],
    mut pose: Isometry3<f64>,
) -> Result<TargetView, PnpError> {
    let mut n = Matrix6::zeros();
    let mut g = Vector6::zeros();
    let mut c = cost(cam, points, pixels, &pose, Some((&mut n, &mut g))).ok_or(PnpError::NoPose)?;
    for _ in 0..MAX_STEPS {
        let Some(step) = n.cholesky().map(|ch| -ch.solve(&g)) else {
            break;
        };
        let mut scale = 1.0;
        let mut better = None;
        for _ in 0..20 {
            let d = scale * step;
            let cand = Isometry3::from_parts(
                Translation3::from(pose.translation.vector + d.fixed_rows::<3>(0)),
                pose.rotation * UnitQuaternion::new(d.fixed_rows::<3>(3).into_owned()),
            );
            match cost(cam, points, pixels, &cand, None) {
                Some(c1) if c1 <= c => {
                    better = Some((cand, c1));
                    break;
                }
                _ => scale *= 0.5,
            }
        }
        let Some((cand, c1)) = better else { break };
        pose = cand;
        let small = step.norm() * scale <= 1e-14 * (1.0 + pose.translation.vector.norm());
        (n, g) = (Matrix6::zeros(), Vector6::zeros());
        c = cost(cam, points, pixels, &pose, Some((&mut n, &mut g))).unwrap_or(c1);
        if small || c == 0.0 {
            break;
        }
    }
    Ok(TargetView {
        pose,
        rms_px: (c / (2 * points.len()) as f64).sqrt(),
        information: n,
    })
}

#[cfg(test)]
mod tests;
