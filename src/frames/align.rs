//! A first measurement frame from the data: the rigid motion that best maps
//! the nominal model's measured points onto the measured ones (Kabsch's
//! SVD solution of `min Σ ‖y_i − (R p_i + t)‖²`). Identification converges
//! from a frame a few degrees off, not from one 100° and metres away, where
//! a tracker often stands.

use crate::data::Measurements;
use crate::kinematics::pose;
use crate::model::Robot;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// The rigid fit and what it does to the residual.
#[derive(Clone, Debug, PartialEq)]
pub struct Alignment {
    /// The motion to put before the model: the measured point ≈ `K · p`.
    pub motion: Isometry3<f64>,
    /// The tool to put after the model's end frame.
    pub tool: Isometry3<f64>,
    /// RMS distance between measured and nominal points (m) before.
    pub rms_before: f64,
    /// … and after the motion.
    pub rms_after: f64,
}

/// The least-squares rigid motion `K` with `y_i ≈ K p_i` (Kabsch), `None`
/// for fewer than 3 points or points on one line.
#[must_use]
pub fn rigid_fit(p: &[Vector3<f64>], y: &[Vector3<f64>]) -> Option<Isometry3<f64>> {
    let n = p.len();
    if n < 3 || y.len() != n {
        return None;
    }
    let (cp, cy) = (
        p.iter().sum::<Vector3<f64>>() / n as f64,
        y.iter().sum::<Vector3<f64>>() / n as f64,
    );
    let mut h = Matrix3::zeros();
    for (a, b) in p.iter().zip(y) {
        h += (a - cp) * (b - cy).transpose();
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let s = svd.singular_values;
    // Points on a line (or one point) leave a rotation about it free.
    if !(s[1] > 1e-9 * s[0].max(f64::MIN_POSITIVE)) {
        return None;
    }
    let v = vt.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
    let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    let t = cy - rot * cp;
    Some(Isometry3::from_parts(Translation3::from(t), rot))
}

/// Rounds of the alternation in [`measurement_frame`] (each halves the
/// error or better on diverse poses; 30 reach a fixed point).
const ROUNDS: usize = 30;

/// The measurement frame and tool that best map `robot`'s nominal end frames
/// onto the measured points (each pose's mean of its markers: their offsets
/// are not known yet) and orientations: alternately the rigid motion `M`
/// (Kabsch) for the current tool point, and the tool point `t` (linear
/// least squares, `M(R_i t + p_i) ≈ y_i`) for the current `M`; for full
/// poses then the tool's rotation (the mean of `R_iᵀ R_Mᵀ R_measured,i`,
/// projected onto the rotations). The tool is in the end frame's
/// coordinates: compose it after the model's own tool.
#[must_use]
pub fn measurement_frame(robot: &Robot, meas: &Measurements) -> Option<Alignment> {
    let k = meas.markers().max(1);
    let ends: Vec<(nalgebra::Matrix3<f64>, Vector3<f64>)> = meas
        .qs()
        .iter()
        .map(|q| pose(robot, &robot.nominal, q))
        .collect();
    let y: Vec<Vector3<f64>> = meas
        .points()
        .chunks_exact(k)
        .map(|c| c.iter().map(|v| Vector3::from(*v)).sum::<Vector3<f64>>() / k as f64)
        .collect();
    let points =
        |t: &Vector3<f64>| -> Vec<Vector3<f64>> { ends.iter().map(|(r, p)| r * t + p).collect() };
    let rms = |m: &Isometry3<f64>, t: &Vector3<f64>| {
        let s: f64 = points(t)
            .iter()
            .zip(&y)
            .map(|(a, b)| ((m * nalgebra::Point3::from(*a)).coords - b).norm_squared())
            .sum();
        (s / y.len() as f64).sqrt()
    };
    let mut t = Vector3::zeros();
    let mut motion = rigid_fit(&points(&t), &y)?;
    for _ in 0..ROUNDS {
        let inv = motion.inverse();
        t = ends
            .iter()
            .zip(&y)
            .map(|((r, p), yi)| r.transpose() * ((inv * nalgebra::Point3::from(*yi)).coords - p))
            .sum::<Vector3<f64>>()
            / y.len() as f64;
        motion = rigid_fit(&points(&t), &y)?;
    }
    let rotation = tool_rotation(&ends, meas, &motion);
    Some(Alignment {
        rms_before: rms(&Isometry3::identity(), &Vector3::zeros()),
        rms_after: rms(&motion, &t),
        motion,
        tool: Isometry3::from_parts(Translation3::from(t), rotation),
    })
}

/// The tool rotation `T` with `R_measured,i ≈ R_M R_i T`: the mean of
/// `R_iᵀ R_Mᵀ R_measured,i` projected onto the rotations (identity without
/// orientations).
fn tool_rotation(
    ends: &[(nalgebra::Matrix3<f64>, Vector3<f64>)],
    meas: &Measurements,
    motion: &Isometry3<f64>,
) -> UnitQuaternion<f64> {
    if meas.orientations().is_empty() {
        return UnitQuaternion::identity();
    }
    let rm = motion.rotation.to_rotation_matrix().into_inner();
    let sum: Matrix3<f64> = ends
        .iter()
        .zip(meas.orientations())
        .map(|((r, _), o)| r.transpose() * rm.transpose() * Matrix3::from_fn(|i, j| o[i][j]))
        .sum();
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(&sum))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kabsch_recovers_a_motion_exactly() {
        let k = Isometry3::from_parts(
            Translation3::new(3.0, -1.0, 0.5),
            UnitQuaternion::from_euler_angles(0.3, -1.2, 1.745),
        );
        let p: Vec<Vector3<f64>> = (0..7)
            .map(|i| {
                let t = i as f64;
                Vector3::new(t.sin(), (1.3 * t).cos(), 0.1 * t * t)
            })
            .collect();
        let y: Vec<Vector3<f64>> = p
            .iter()
            .map(|v| (k * nalgebra::Point3::from(*v)).coords)
            .collect();
        let got = rigid_fit(&p, &y).unwrap();
        // Noise-free points: the SVD recovers the motion to rounding.
        assert!((got.to_homogeneous() - k.to_homogeneous()).abs().max() < 1e-12);
        // Collinear points leave a rotation free: refused.
        let line: Vec<Vector3<f64>> = (0..5).map(|i| Vector3::x() * i as f64).collect();
        assert!(rigid_fit(&line, &line).is_none());
    }
}
