//! The few rotation-group maps that full-pose identification needs: the
//! exponential and logarithm of SO(3) and the inverse of its left Jacobian.
//!
//! Orientation residuals are `φ = log(R(θ) R_measᵀ)` (a rotation vector in
//! the base frame). A change `dθ` of the unknowns turns the model's
//! orientation by the angular velocity `ω dθ` (the orientation rows of
//! `crate::kinematics::Evaluator::eval`), `R(θ + dθ) ≈ exp([ω dθ]×) R(θ)`,
//! so `φ(θ + dθ) ≈ φ + J_l⁻¹(φ) ω dθ`: the residual's exact Jacobian is the
//! evaluator's block premultiplied by [`left_jacobian_inverse`].

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// `exp([v]×)`: the rotation by `|v|` radians about `v`.
#[must_use]
pub fn exp(v: &Vector3<f64>) -> Matrix3<f64> {
    Rotation3::new(*v).into_inner()
}

/// A rotation matrix (orthonormal to rounding, as the kinematics make it)
/// as a unit quaternion: Shepperd's direct formula, then normalised.
#[must_use]
pub fn to_quaternion(m: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*m))
}

/// The nearest rotation to a measured matrix `m` (orthonormal only to the
/// measurement's precision, see `ROTATION_TOLERANCE`) as a unit quaternion:
/// nalgebra's iterative projection.
#[must_use]
pub fn nearest_rotation(m: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_matrix(m)
}

/// `log(R_a R_bᵀ)` as a rotation vector (angle in `[0, π]` times the unit
/// axis), through quaternions so that it is accurate at small angles.
#[must_use]
pub fn difference(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> Vector3<f64> {
    (a * b.inverse()).scaled_axis()
}

/// `J_l⁻¹(φ) = I − ½[φ]× + (1/θ² − (1 + cos θ)/(2θ sin θ)) [φ]×²`, `θ = |φ|`,
/// the inverse left Jacobian of SO(3): `log(exp(δ) exp(φ)) = φ + J_l⁻¹(φ) δ +
/// O(|δ|²)`. Below θ = 1e-3 the coefficient is its series `1/12 + θ²/720`
/// (next term θ⁴/30240 < 4e-17), avoiding the cancellation of the closed form.
#[must_use]
pub fn left_jacobian_inverse(phi: &Vector3<f64>) -> Matrix3<f64> {
    let th = phi.norm();
    let k = phi.cross_matrix();
    let c = if th < 1e-3 {
        1.0 / 12.0 + th * th / 720.0
    } else {
        1.0 / (th * th) - (1.0 + th.cos()) / (2.0 * th * th.sin())
    };
    Matrix3::identity() - 0.5 * k + c * k * k
}

/// Why `m` is not a rotation matrix, if it is not one to `tol` (entries of
/// `mᵀm − I`, and the determinant's sign).
pub(crate) fn check_rotation(m: &Matrix3<f64>, tol: f64) -> Result<(), String> {
    if let Some(v) = m.iter().find(|v| !v.is_finite()) {
        return Err(format!("an entry is not a finite number ({v})"));
    }
    let dev = (m.transpose() * m - Matrix3::identity()).amax();
    if dev > tol {
        return Err(format!(
            "not orthonormal: max |RᵀR − I| = {dev:.3e} > {tol:e}"
        ));
    }
    if m.determinant() < 0.0 {
        return Err("determinant −1: a reflection, not a rotation".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_inverts_exp() {
        for v in [
            Vector3::new(1e-9, -2e-9, 3e-10),
            Vector3::new(0.3, -0.2, 0.1),
            Vector3::new(-1.0, 2.0, 0.5),
        ] {
            let q = to_quaternion(&exp(&v));
            let back = difference(&q, &UnitQuaternion::identity());
            // Round-off of a product of 3×3 rotations: a few ulps of |v| ≤ 2.3.
            assert!(
                (back - v).amax() < 1e-14 * v.norm().max(1.0),
                "{v} → {back}"
            );
        }
    }

    /// `log(exp(δ) exp(φ)) − φ` against `J_l⁻¹(φ) δ` by central differences,
    /// on both sides of the series switch.
    #[test]
    fn left_jacobian_inverse_matches_differences() {
        for phi in [
            Vector3::new(2e-4, -1e-4, 3e-4),
            Vector3::new(0.4, 0.1, -0.3),
            Vector3::new(1.5, -1.0, 0.7),
        ] {
            let e = to_quaternion(&exp(&phi));
            let jinv = left_jacobian_inverse(&phi);
            let h = 1e-6;
            for c in 0..3 {
                let mut d = Vector3::zeros();
                d[c] = h;
                let plus = difference(&(to_quaternion(&exp(&d)) * e), &UnitQuaternion::identity());
                let minus =
                    difference(&(to_quaternion(&exp(&-d)) * e), &UnitQuaternion::identity());
                let fd = (plus - minus) / (2.0 * h);
                // Central differences: truncation O(h²) ≈ 1e-12, round-off
                // ε/h ≈ 2e-10; 1e-8 leaves a factor 50.
                assert!((fd - jinv.column(c)).amax() < 1e-8, "φ = {phi}, column {c}");
            }
        }
    }

    #[test]
    fn rotation_checks() {
        let r = exp(&Vector3::new(0.1, 0.2, 0.3));
        assert!(check_rotation(&r, 1e-6).is_ok());
        assert!(
            check_rotation(&(-r), 1e-6)
                .unwrap_err()
                .contains("reflection")
        );
        assert!(
            check_rotation(&(1.01 * r), 1e-6)
                .unwrap_err()
                .contains("orthonormal")
        );
        let mut nan = r;
        nan[(1, 2)] = f64::NAN;
        assert!(check_rotation(&nan, 1e-6).unwrap_err().contains("finite"));
    }
}
