//! A pinhole camera with plumb_bob distortion (OpenCV's and ROS's
//! `k1, k2, p1, p2, k3`): a point `X = (X, Y, Z)` of the optical frame (x
//! right, y down, z forward) goes to the pixel `(u, v)`:
//!
//! `x = X/Z, y = Y/Z, r² = x² + y², ρ = 1 + k1 r² + k2 r⁴ + k3 r⁶`,
//! `x' = x ρ + 2 p1 x y + p2 (r² + 2x²)`,
//! `y' = y ρ + p1 (r² + 2y²) + 2 p2 x y`,
//! `u = fx x' + cx, v = fy y' + cy`
//!
//! (OpenCV's `projectPoints`, Bradski & Kaehler ch. 11). [`Intrinsics::project`]
//! also gives `∂(u, v)/∂X`, the 2 × 3 block every pixel Jacobian row is
//! made of. Pixel coordinates are OpenCV's: `(0, 0)` is the centre of the
//! top-left pixel, so a pixel of an image `w × h` lies in
//! `[−0.5, w − 0.5] × [−0.5, h − 0.5]`.
//!
//! Also here: the right Jacobian of SO(3)'s exponential ([`right_jacobian`]),
//! which the camera sensor's rotation charts need.

use nalgebra::{Matrix2x3, Matrix3, Vector3};

/// A camera's intrinsics: image size, focal lengths and principal point
/// (pixels) and plumb_bob distortion.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Intrinsics {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point, x, pixels.
    pub cx: f64,
    /// Principal point, y, pixels.
    pub cy: f64,
    /// `k1, k2, p1, p2, k3`, OpenCV's order.
    pub distortion: [f64; 5],
}

/// The names of the intrinsics as unknowns, in the order of
/// [`Intrinsics::values`].
pub const INTRINSIC_NAMES: [&str; 9] = ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"];

/// A projected point: its pixel and the derivative of the pixel with
/// respect to the point in the optical frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// `(u, v)`, pixels.
    pub pixel: [f64; 2],
    /// `∂(u, v)/∂(X, Y, Z)`, pixels per metre.
    pub jacobian: Matrix2x3<f64>,
}

impl Intrinsics {
    /// Projects `p` (optical frame, metres), or `None` when it is not in
    /// front of the camera (`Z ≤ 1e-9` m: the projection has no meaning
    /// there).
    #[must_use]
    pub fn project(&self, p: &Vector3<f64>) -> Option<Projection> {
        if !(p.z > 1e-9) {
            return None;
        }
        let [k1, k2, p1, p2, k3] = self.distortion;
        let iz = 1.0 / p.z;
        let (x, y) = (p.x * iz, p.y * iz);
        let r2 = x * x + y * y;
        let rho = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
        // dρ/d(r²)
        let drho = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);
        let xd = x * rho + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
        let yd = y * rho + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
        // ∂(x', y')/∂(x, y), with ∂ρ/∂x = 2x dρ, ∂ρ/∂y = 2y dρ.
        let dxx = rho + 2.0 * x * x * drho + 2.0 * p1 * y + 6.0 * p2 * x;
        let dxy = 2.0 * x * y * drho + 2.0 * p1 * x + 2.0 * p2 * y;
        let dyx = 2.0 * x * y * drho + 2.0 * p1 * x + 2.0 * p2 * y;
        let dyy = rho + 2.0 * y * y * drho + 6.0 * p1 * y + 2.0 * p2 * x;
        // ∂(x, y)/∂(X, Y, Z) = [[1/Z, 0, −x/Z], [0, 1/Z, −y/Z]].
        let n = Matrix2x3::new(iz, 0.0, -x * iz, 0.0, iz, -y * iz);
        let d = nalgebra::Matrix2::new(self.fx * dxx, self.fx * dxy, self.fy * dyx, self.fy * dyy);
        Some(Projection {
            pixel: [self.fx * xd + self.cx, self.fy * yd + self.cy],
            jacobian: d * n,
        })
    }

    /// The intrinsics as a vector: `fx, fy, cx, cy, k1, k2, p1, p2, k3`
    /// (the order of [`INTRINSIC_NAMES`]).
    #[must_use]
    pub fn values(&self) -> [f64; 9] {
        let d = self.distortion;
        [
            self.fx, self.fy, self.cx, self.cy, d[0], d[1], d[2], d[3], d[4],
        ]
    }

    /// The same camera (image size kept) with the values `v` in the order
    /// of [`Intrinsics::values`].
    #[must_use]
    pub fn with_values(&self, v: &[f64]) -> Intrinsics {
        Intrinsics {
            fx: v[0],
            fy: v[1],
            cx: v[2],
            cy: v[3],
            distortion: [v[4], v[5], v[6], v[7], v[8]],
            ..self.clone()
        }
    }

    /// `∂(u, v)/∂(fx, fy, cx, cy, k1, k2, p1, p2, k3)` at `p` (optical
    /// frame), or `None` behind the camera (as [`Intrinsics::project`]).
    #[must_use]
    pub fn intrinsic_jacobian(&self, p: &Vector3<f64>) -> Option<[[f64; 9]; 2]> {
        if !(p.z > 1e-9) {
            return None;
        }
        let [k1, k2, p1, p2, k3] = self.distortion;
        let (x, y) = (p.x / p.z, p.y / p.z);
        let r2 = x * x + y * y;
        let (r4, r6) = (r2 * r2, r2 * r2 * r2);
        let rho = 1.0 + k1 * r2 + k2 * r4 + k3 * r6;
        let xd = x * rho + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
        let yd = y * rho + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
        let (fx, fy) = (self.fx, self.fy);
        Some([
            [
                xd,
                0.0,
                1.0,
                0.0,
                fx * x * r2,
                fx * x * r4,
                fx * 2.0 * x * y,
                fx * (r2 + 2.0 * x * x),
                fx * x * r6,
            ],
            [
                0.0,
                yd,
                0.0,
                1.0,
                fy * y * r2,
                fy * y * r4,
                fy * (r2 + 2.0 * y * y),
                fy * 2.0 * x * y,
                fy * y * r6,
            ],
        ])
    }

    /// Whether a pixel lies inside the image, at least `margin` pixels
    /// from its border (OpenCV's pixel centres: the image spans
    /// `[−0.5, w − 0.5] × [−0.5, h − 0.5]`).
    #[must_use]
    pub fn inside(&self, pixel: [f64; 2], margin: f64) -> bool {
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        pixel[0] >= -0.5 + margin
            && pixel[0] <= w - 0.5 - margin
            && pixel[1] >= -0.5 + margin
            && pixel[1] <= h - 0.5 - margin
    }

    /// Checks the values a file gave: a positive image size, finite
    /// positive focal lengths, a finite principal point inside the image
    /// and finite distortion. Returns what is wrong.
    pub fn check(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err(format!(
                "image size {}×{}: width and height must be > 0 pixels",
                self.width, self.height
            ));
        }
        if !(self.fx.is_finite() && self.fx > 0.0 && self.fy.is_finite() && self.fy > 0.0) {
            return Err(format!(
                "focal lengths fx = {}, fy = {}: must be finite and > 0 pixels",
                self.fx, self.fy
            ));
        }
        if !self.inside([self.cx, self.cy], 0.0) {
            return Err(format!(
                "principal point ({}, {}) px lies outside the {}×{} image",
                self.cx, self.cy, self.width, self.height
            ));
        }
        if let Some(k) = self.distortion.iter().position(|d| !d.is_finite()) {
            let name = ["k1", "k2", "p1", "p2", "k3"][k];
            return Err(format!("distortion {name} is not a finite number"));
        }
        Ok(())
    }
}

/// `[v]×`, the cross-product matrix (`[v]× w = v × w`).
#[must_use]
pub fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The right Jacobian of SO(3)'s exponential at `φ`: `exp(φ + ε) ≈ exp(φ)
/// exp(J_r(φ) ε)`, `J_r(φ) = I − (1 − cos θ)/θ² [φ]× + (θ − sin θ)/θ³
/// [φ]×²`, `θ = ‖φ‖` (Chirikjian 2011, eq. 10.86); the series `I − ½[φ]× +
/// ⅙[φ]×²` below θ = 1e-4, where it is exact to O(θ³) ≈ 1e-12.
#[must_use]
pub fn right_jacobian(phi: &Vector3<f64>) -> Matrix3<f64> {
    let t = phi.norm();
    let k = skew(phi);
    let (a, b) = if t < 1e-4 {
        (0.5, 1.0 / 6.0)
    } else {
        ((1.0 - t.cos()) / (t * t), (t - t.sin()) / (t * t * t))
    };
    Matrix3::identity() - a * k + b * k * k
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn camera() -> Intrinsics {
        Intrinsics {
            width: 1280,
            height: 960,
            fx: 900.0,
            fy: 910.0,
            cx: 640.5,
            cy: 480.2,
            distortion: [-0.12, 0.08, 1.5e-3, -0.8e-3, -0.02],
        }
    }

    /// `∂(u, v)/∂X` is the derivative of the pixel: central differences
    /// with step 1e-6 m on a point 0.8 m away (truncation ≈ f·h²/Z³ ≈
    /// 1e-9 px/m relative, rounding ε·u/h ≈ 1e-7 px/m) against entries of
    /// 100–1000 px/m: 1e-4 px/m tells a right entry from a wrong one.
    #[test]
    fn projection_jacobian_is_the_derivative() {
        let c = camera();
        let p = Vector3::new(0.21, -0.13, 0.8);
        let j = c.project(&p).unwrap().jacobian;
        let h = 1e-6;
        for k in 0..3 {
            let mut a = p;
            let mut b = p;
            a[k] += h;
            b[k] -= h;
            let (pa, pb) = (c.project(&a).unwrap().pixel, c.project(&b).unwrap().pixel);
            for r in 0..2 {
                let fd = (pa[r] - pb[r]) / (2.0 * h);
                assert!(
                    (j[(r, k)] - fd).abs() < 1e-4,
                    "({r},{k}): {} vs {fd}",
                    j[(r, k)]
                );
            }
        }
    }

    /// Without distortion a point on the optical axis lands on the
    /// principal point, and one at `x = Z` one focal length to its right.
    #[test]
    fn undistorted_projection_is_the_pinhole() {
        let mut c = camera();
        c.distortion = [0.0; 5];
        let a = c.project(&Vector3::new(0.0, 0.0, 2.0)).unwrap().pixel;
        assert_eq!(a, [c.cx, c.cy]);
        let b = c.project(&Vector3::new(2.0, 0.0, 2.0)).unwrap().pixel;
        assert!((b[0] - (c.cx + c.fx)).abs() < 1e-12 && (b[1] - c.cy).abs() < 1e-12);
        assert!(c.project(&Vector3::new(0.0, 0.0, -1.0)).is_none());
    }

    /// `exp(φ + ε) ≈ exp(φ) exp(J_r ε)` to second order: for ε of 1e-6 the
    /// two rotations differ by O(ε²) ≈ 1e-11; a wrong J_r (the left
    /// Jacobian, say) misses by O(θ ε) ≈ 1e-6.
    #[test]
    fn right_jacobian_linearises_the_exponential() {
        for phi in [
            Vector3::new(0.3, -1.2, 2.1),
            Vector3::new(1e-6, 2e-6, 0.0),
            Vector3::new(3.0, 0.1, 0.0),
        ] {
            let eps = Vector3::new(1e-6, -2e-6, 1.5e-6);
            let a = Rotation3::new(phi + eps);
            let b = Rotation3::new(phi) * Rotation3::new(right_jacobian(&phi) * eps);
            // Matrix entries, not an angle from acos (which loses half the
            // digits near 0).
            let d = (a.matrix() - b.matrix()).norm();
            assert!(d < 1e-11, "{phi:?}: {d}");
        }
    }

    #[test]
    fn bad_intrinsics_are_named() {
        let mut c = camera();
        c.fx = -1.0;
        assert!(c.check().unwrap_err().contains("focal"));
        let mut c = camera();
        c.cx = 5000.0;
        assert!(c.check().unwrap_err().contains("principal point"));
        let mut c = camera();
        c.height = 0;
        assert!(c.check().unwrap_err().contains("image size"));
        assert!(camera().check().is_ok());
    }
}
