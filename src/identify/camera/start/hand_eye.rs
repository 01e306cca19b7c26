//! The closed form of the robot-world/hand-eye problem `Aᵢ X = Z Bᵢ`: the
//! `Aᵢ` known (the flange's poses), the `Bᵢ` measured (the target's pose
//! in the camera's frame, or its inverse), the two rigid motions `X`, `Z`
//! unknown.
//!
//! As Shah (2013, "Solving the robot-world/hand-eye calibration problem
//! using the Kronecker product", J. Mech. Robot. 5(3)): the rotations
//! satisfy `R_Aᵢ R_X R_Bᵢᵀ = R_Z`, in column-major vectors `(R_Bᵢ ⊗ R_Aᵢ)
//! vec R_X = vec R_Z`, so `vec R_X` and `vec R_Z` are (up to one scale)
//! the right and left singular vectors of the largest singular value of
//! `K = Σᵢ R_Bᵢ ⊗ R_Aᵢ` (exactly `n` noise-free); each is made a rotation
//! by the SVD (`U Vᵀ`, the scale's sign taken so that the determinant is
//! positive). Then the translations by linear least squares: `R_Aᵢ t_X −
//! t_Z = R_Z t_Bᵢ − t_Aᵢ`, `3n` rows, 6 unknowns.
//!
//! The problem is determined only when the `R_Aᵢ` do not all turn about
//! one common axis (Shah, §3; Li et al. 2010): when they do, `X` and `Z`
//! may both turn about that axis and still fit. [`orientation_spread`]
//! measures how far they are from that: `acos σ₂` of `(1/n) Σᵢ R_Aᵢ ⊗ R_Aᵢ`
//! (its largest singular value is 1, on `vec I`; the second is 1 exactly
//! when the rotations share an axis, and falls as they spread: ≈ 0.8 θ
//! for rotations spread θ about random axes).

use super::pnp::nearest_rotation;
use nalgebra::{
    DMatrix, DVector, Isometry3, Matrix3, Rotation3, SMatrix, Translation3, UnitQuaternion, Vector3,
};

/// The least orientation spread ([`orientation_spread`], degrees) the
/// closed form accepts: below it the rotations are all but undetermined
/// (a pose's rotation from its pixels is good to a few hundredths of a
/// degree; spread over less than half a degree that leaves errors of
/// several degrees in `X` and `Z`).
pub const MIN_SPREAD_DEG: f64 = 0.5;

/// Why the closed form has no solution.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HandEyeError {
    /// Too few poses.
    #[error("{poses} pose(s) placed; the closed form needs 3 or more")]
    TooFewPoses {
        /// Poses given.
        poses: usize,
    },
    /// The flange's orientations turn about one axis or not at all.
    #[error(
        "the flange's orientations over the poses turn about one axis or not at all (spread {spread_deg:.3}°, at least {MIN_SPREAD_DEG}° needed): the camera's and the target's placements cannot be told apart from a turn about that axis; observe poses whose flange orientations differ about two axes or more"
    )]
    OneAxis {
        /// The orientation spread, degrees ([`orientation_spread`]).
        spread_deg: f64,
    },
}

fn rotation(m: &Isometry3<f64>) -> Matrix3<f64> {
    m.rotation.to_rotation_matrix().into_inner()
}

fn isometry(r: &Matrix3<f64>, t: Vector3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(t),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r)),
    )
}

/// `(1/n) Σᵢ Rᵢ ⊗ Rᵢ`'s second singular value as an angle, degrees (see
/// the module documentation): 0 when the rotations share an axis.
#[must_use]
pub fn orientation_spread(rotations: &[Matrix3<f64>]) -> f64 {
    let mut m = SMatrix::<f64, 9, 9>::zeros();
    for r in rotations {
        m += r.kronecker(r);
    }
    m /= rotations.len().max(1) as f64;
    let mut s: Vec<f64> = m.singular_values().iter().copied().collect();
    s.sort_by(|a, b| b.total_cmp(a));
    s[1].clamp(-1.0, 1.0).acos().to_degrees()
}

/// `X` and `Z` of `Aᵢ X = Z Bᵢ` in closed form (module documentation).
pub fn solve_ax_zb(
    a: &[Isometry3<f64>],
    b: &[Isometry3<f64>],
) -> Result<(Isometry3<f64>, Isometry3<f64>), HandEyeError> {
    let n = a.len().min(b.len());
    if n < 3 {
        return Err(HandEyeError::TooFewPoses { poses: n });
    }
    let ra: Vec<Matrix3<f64>> = a.iter().map(rotation).collect();
    let spread_deg = orientation_spread(&ra);
    // NaN (non-finite poses) refused too.
    if spread_deg.is_nan() || spread_deg < MIN_SPREAD_DEG {
        return Err(HandEyeError::OneAxis { spread_deg });
    }
    let mut k = SMatrix::<f64, 9, 9>::zeros();
    for (ra, b) in ra.iter().zip(b) {
        k += rotation(b).kronecker(ra);
    }
    let svd = k.svd(true, true);
    let i = svd.singular_values.imax();
    let u = svd.u.unwrap().column(i).into_owned();
    let v = svd.v_t.unwrap().row(i).transpose();
    let (mut mx, mut mz) = (
        Matrix3::from_column_slice(v.as_slice()),
        Matrix3::from_column_slice(u.as_slice()),
    );
    if mx.determinant() < 0.0 {
        mx = -mx;
        mz = -mz;
    }
    let (rx, rz) = (nearest_rotation(&mx), nearest_rotation(&mz));
    // R_Aᵢ t_X − t_Z = R_Z t_Bᵢ − t_Aᵢ.
    let mut m = DMatrix::zeros(3 * n, 6);
    let mut rhs = DVector::zeros(3 * n);
    for (i, (ra, (a, b))) in ra.iter().zip(a.iter().zip(b)).enumerate() {
        m.view_mut((3 * i, 0), (3, 3)).copy_from(ra);
        m.view_mut((3 * i, 3), (3, 3))
            .copy_from(&(-Matrix3::identity()));
        let r = rz * b.translation.vector - a.translation.vector;
        rhs.rows_mut(3 * i, 3).copy_from(&r);
    }
    let t = m
        .svd(true, true)
        .solve(&rhs, 0.0)
        .expect("the SVD holds both factors");
    Ok((
        isometry(&rx, Vector3::new(t[0], t[1], t[2])),
        isometry(&rz, Vector3::new(t[3], t[4], t[5])),
    ))
}

/// The least-squares mean of rigid motions: the rotation nearest the sum
/// of their rotations (the chordal mean), the mean translation.
fn mean(ms: impl Iterator<Item = Isometry3<f64>>) -> Isometry3<f64> {
    let (mut r, mut t, mut n) = (Matrix3::zeros(), Vector3::zeros(), 0.0);
    for m in ms {
        r += rotation(&m);
        t += m.translation.vector;
        n += 1.0;
    }
    isometry(&nearest_rotation(&r), t / n)
}

/// `X` of `Aᵢ X = Z Bᵢ` with `Z` known: the mean of `Aᵢ⁻¹ Z Bᵢ` (the
/// translation's least-squares solution, the rotations' chordal mean).
#[must_use]
pub fn solve_x_given_z(
    a: &[Isometry3<f64>],
    b: &[Isometry3<f64>],
    z: &Isometry3<f64>,
) -> Isometry3<f64> {
    mean(a.iter().zip(b).map(|(a, b)| a.inverse() * z * b))
}

/// `Z` of `Aᵢ X = Z Bᵢ` with `X` known: the mean of `Aᵢ X Bᵢ⁻¹`.
#[must_use]
pub fn solve_z_given_x(
    a: &[Isometry3<f64>],
    b: &[Isometry3<f64>],
    x: &Isometry3<f64>,
) -> Isometry3<f64> {
    mean(a.iter().zip(b).map(|(a, b)| a * x * b.inverse()))
}

#[cfg(test)]
mod tests;
