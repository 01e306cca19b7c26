//! The equidistant fisheye model (OpenCV's `cv::fisheye`, ROS's
//! `distortion_model: equidistant`; Kannala & Brandt 2006 with four
//! coefficients): a normalised point `(x, y) = (X/Z, Y/Z)` at `r = √(x² +
//! y²)` lies `θ = atan r` off the optical axis and is drawn at
//!
//! `θd = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸)`, `x' = (θd/r) x`,
//! `y' = (θd/r) y`
//!
//! (then `u = fx x' + cx`, `v = fy y' + cy`; OpenCV's skew α is 0 here).
//! [`radial`] gives the scale `s = θd/r` as a function of `r²` with its
//! derivative, exact to rounding as `r → 0` (where `s → 1`), the pieces
//! [`super::pinhole`] builds the pixel and its Jacobians from.

/// Below this `r²` the ratios `θ/r` and `d(θ/r)/d(r²)` come from their
/// series (10 terms each: the first ones left out are below 1e-18 here),
/// above it from `atan` (whose cancellation in `r/(1 + r²) − θ` costs
/// `ε/r² ≤ 2.2e-14` relative at `r² = 0.01`).
const SERIES_BELOW: f64 = 0.01;

/// The radial scale of the equidistant model at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Radial {
    /// `θ = atan r`, radians off the optical axis.
    pub theta: f64,
    /// `θ/r` (1 at `r = 0`).
    pub theta_over_r: f64,
    /// `s = θd/r`, the factor `(x, y)` is multiplied by (1 at `r = 0`).
    pub scale: f64,
    /// `ds/d(r²)`.
    pub dscale: f64,
}

/// `θ/r = atan(r)/r` and its derivative with respect to `r²`.
fn atan_ratio(r2: f64) -> (f64, f64) {
    if r2 < SERIES_BELOW {
        // atan(r)/r = Σ (−r²)ⁿ/(2n + 1); its r²-derivative term by term.
        let (mut a, mut da, mut p) = (0.0, 0.0, 1.0);
        for n in 0..10 {
            let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
            let m = f64::from(n + 1);
            a += sign * p / f64::from(2 * n + 1);
            da -= sign * m * p / (2.0 * m + 1.0);
            p *= r2;
        }
        (a, da)
    } else {
        let r = r2.sqrt();
        let t = r.atan();
        // d(θ/r)/dr = (r/(1 + r²) − θ)/r², and d/d(r²) = (d/dr)/(2r).
        (t / r, (r / (1.0 + r2) - t) / (2.0 * r2 * r))
    }
}

/// The scale `s = θd/r` at `r²` for coefficients `k` (`k1 … k4`) and its
/// derivative with respect to `r²`:
/// `s = (θ/r) P(θ²)`, `P(t) = 1 + k1 t + k2 t² + k3 t³ + k4 t⁴`,
/// `ds/d(r²) = d(θ/r)/d(r²) P + (θ/r) P'(θ²) dθ²/d(r²)` with
/// `dθ²/d(r²) = (θ/r)/(1 + r²)`.
#[must_use]
pub fn radial(k: &[f64; 4], r2: f64) -> Radial {
    let (a, da) = atan_ratio(r2);
    let theta = a * r2.sqrt();
    let t = theta * theta;
    let p = 1.0 + t * (k[0] + t * (k[1] + t * (k[2] + t * k[3])));
    let dp = k[0] + t * (2.0 * k[1] + t * (3.0 * k[2] + t * 4.0 * k[3]));
    Radial {
        theta,
        theta_over_r: a,
        scale: a * p,
        dscale: da * p + a * dp * a / (1.0 + r2),
    }
}

/// `dθd/dθ = 1 + 3 k1 θ² + 5 k2 θ⁴ + 7 k3 θ⁶ + 9 k4 θ⁸`: where it is
/// positive the model draws farther angles farther out.
#[must_use]
pub fn slope(k: &[f64; 4], theta: f64) -> f64 {
    let t = theta * theta;
    1.0 + t * (3.0 * k[0] + t * (5.0 * k[1] + t * (7.0 * k[2] + t * 9.0 * k[3])))
}

#[cfg(test)]
mod tests {
    use super::*;

    const K: [f64; 4] = [-0.013, 0.0021, -0.0009, 0.00012];

    /// The series and the closed form meet at the switch: both sides of
    /// `r² = 0.01` agree to 1e-14 (each is within ~2e-14 of the truth
    /// there, see [`SERIES_BELOW`]), and `r = 0` gives the limit exactly.
    #[test]
    fn series_and_closed_form_agree() {
        let below = radial(&K, SERIES_BELOW * (1.0 - 1e-15));
        let above = radial(&K, SERIES_BELOW);
        assert!((below.scale - above.scale).abs() < 1e-14);
        assert!(
            (below.dscale - above.dscale).abs() < 1e-13,
            "{below:?} {above:?}"
        );
        let zero = radial(&K, 0.0);
        assert_eq!((zero.scale, zero.theta, zero.theta_over_r), (1.0, 0.0, 1.0));
        // d(θ/r)/d(r²) → −1/3 and dP/d(r²) → k1 at 0.
        assert!((zero.dscale - (-1.0 / 3.0 + K[0])).abs() < 1e-16);
    }

    /// `ds/d(r²)` is the derivative of `s`: central differences in `r²`
    /// (step 1e-6; truncation ~h² s''' ≈ 1e-12, rounding ε/h ≈ 2e-10)
    /// agree to 1e-9 from near the axis out to 80°, on both sides of the
    /// series' switch.
    #[test]
    fn dscale_is_the_derivative() {
        for r2 in [2e-6, 0.004, 0.0099, 0.0101, 0.3, 1.0, 4.0, 32.0] {
            let h = 1e-6;
            let fd = (radial(&K, r2 + h).scale - radial(&K, r2 - h).scale) / (2.0 * h);
            let d = radial(&K, r2).dscale;
            assert!((d - fd).abs() < 1e-9, "r² {r2}: {d} vs {fd}");
        }
    }
}
