//! A pinhole camera with plumb_bob distortion (OpenCV's and ROS's
//! `k1, k2, p1, p2, k3`) or the equidistant fisheye model
//! ([`super::fisheye`]: OpenCV's `cv::fisheye`, ROS's `equidistant`, `k1 …
//! k4`): a point `X = (X, Y, Z)` of the optical frame (x right, y down, z
//! forward) goes to the pixel `(u, v)`; for plumb_bob
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
//! A model maps the angles off its axis one-to-one only up to its field
//! ([`Intrinsics::field_angle`]): past the first angle where the drawn
//! radius stops growing, a point would be drawn back inside the image.
//! [`Intrinsics::sees`] keeps a point only in front of the camera, inside
//! that field and inside the image.
//!
//! Also here: the right Jacobian of SO(3)'s exponential ([`right_jacobian`]),
//! which the camera sensor's rotation charts need.
use nalgebra::{Matrix2x3, Matrix3, Vector3};

/// A camera's distortion model and its coefficients.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(
    tag = "distortion_model",
    content = "distortion",
    rename_all = "snake_case"
)]
pub enum Distortion {
    /// `k1, k2, p1, p2, k3`, OpenCV's order (ROS `plumb_bob`).
    PlumbBob([f64; 5]),
    /// `k1, k2, k3, k4` of the equidistant fisheye model (ROS
    /// `equidistant`, OpenCV's `cv::fisheye`; [`super::fisheye`]).
    Equidistant([f64; 4]),
}

/// The names of plumb_bob's intrinsics as unknowns, in the order of
/// [`Intrinsics::values`].
pub const PLUMB_BOB_NAMES: [&str; 9] = ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"];

/// The names of the equidistant model's intrinsics as unknowns, in the
/// order of [`Intrinsics::values`].
pub const EQUIDISTANT_NAMES: [&str; 8] = ["fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"];

impl Distortion {
    /// The model's name as ROS's `distortion_model` spells it.
    #[must_use]
    pub fn model(&self) -> &'static str {
        match self {
            Distortion::PlumbBob(_) => "plumb_bob",
            Distortion::Equidistant(_) => "equidistant",
        }
    }

    /// The coefficients, in the model's order.
    #[must_use]
    pub fn coefficients(&self) -> &[f64] {
        match self {
            Distortion::PlumbBob(d) => d,
            Distortion::Equidistant(d) => d,
        }
    }

    /// The same model with coefficients `c` (the model's count of them).
    #[must_use]
    pub fn with_coefficients(&self, c: &[f64]) -> Distortion {
        match self {
            Distortion::PlumbBob(_) => Distortion::PlumbBob([c[0], c[1], c[2], c[3], c[4]]),
            Distortion::Equidistant(_) => Distortion::Equidistant([c[0], c[1], c[2], c[3]]),
        }
    }

    /// The names of the intrinsics of a camera with this model, in the
    /// order of [`Intrinsics::values`].
    #[must_use]
    pub fn intrinsic_names(&self) -> &'static [&'static str] {
        match self {
            Distortion::PlumbBob(_) => &PLUMB_BOB_NAMES,
            Distortion::Equidistant(_) => &EQUIDISTANT_NAMES,
        }
    }

    /// `d(drawn radius)/d(angle)` at `theta` rad off the axis, up to a
    /// positive factor: the equidistant model's `dθd/dθ`; plumb_bob's
    /// radial `d(r ρ)/dr = 1 + 3 k1 r² + 5 k2 r⁴ + 7 k3 r⁶` at `r = tan θ`
    /// (the tangential terms, a few 1e-3 of it, left out).
    fn radial_slope(&self, theta: f64) -> f64 {
        match self {
            Distortion::PlumbBob([k1, k2, _, _, k3]) => {
                let t = theta.tan().powi(2);
                1.0 + t * (3.0 * k1 + t * (5.0 * k2 + t * 7.0 * k3))
            }
            Distortion::Equidistant(k) => super::fisheye::slope(k, theta),
        }
    }
}

/// A camera's intrinsics: image size, focal lengths and principal point
/// (pixels) and distortion.
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
    /// The distortion model and its coefficients (JSON:
    /// `distortion_model` and `distortion`, as in ROS).
    #[serde(flatten)]
    pub distortion: Distortion,
}

/// A projected point: its pixel and the derivative of the pixel with
/// respect to the point in the optical frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// `(u, v)`, pixels.
    pub pixel: [f64; 2],
    /// `∂(u, v)/∂(X, Y, Z)`, pixels per metre.
    pub jacobian: Matrix2x3<f64>,
}

/// The distorted normalised point `(x', y')` and `∂(x', y')/∂(x, y)`.
struct Distorted {
    xd: f64,
    yd: f64,
    d: nalgebra::Matrix2<f64>,
}

/// plumb_bob at the normalised point `(x, y)`.
fn plumb_bob(k: &[f64; 5], x: f64, y: f64) -> Distorted {
    let [k1, k2, p1, p2, k3] = *k;
    let r2 = x * x + y * y;
    let rho = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    // dρ/d(r²)
    let drho = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);
    // ∂(x', y')/∂(x, y), with ∂ρ/∂x = 2x dρ, ∂ρ/∂y = 2y dρ.
    let dxx = rho + 2.0 * x * x * drho + 2.0 * p1 * y + 6.0 * p2 * x;
    let dxy = 2.0 * x * y * drho + 2.0 * p1 * x + 2.0 * p2 * y;
    let dyy = rho + 2.0 * y * y * drho + 6.0 * p1 * y + 2.0 * p2 * x;
    Distorted {
        xd: x * rho + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
        yd: y * rho + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
        d: nalgebra::Matrix2::new(dxx, dxy, dxy, dyy),
    }
}

/// The equidistant model at the normalised point `(x, y)`: `x' = s x`,
/// `∂x'/∂x = s + 2x² s'`, `∂x'/∂y = 2xy s'` (`s' = ds/d(r²)`).
fn equidistant(k: &[f64; 4], x: f64, y: f64) -> Distorted {
    let f = super::fisheye::radial(k, x * x + y * y);
    let (s, ds) = (f.scale, f.dscale);
    let dxy = 2.0 * x * y * ds;
    Distorted {
        xd: s * x,
        yd: s * y,
        d: nalgebra::Matrix2::new(s + 2.0 * x * x * ds, dxy, dxy, s + 2.0 * y * y * ds),
    }
}

impl Intrinsics {
    /// The distorted normalised point of `(x, y)`.
    fn distort(&self, x: f64, y: f64) -> Distorted {
        match &self.distortion {
            Distortion::PlumbBob(k) => plumb_bob(k, x, y),
            Distortion::Equidistant(k) => equidistant(k, x, y),
        }
    }

    /// Projects `p` (optical frame, metres), or `None` when it is not in
    /// front of the camera (`Z ≤ 1e-9` m: the projection has no meaning
    /// there). The model's formula, whether or not `p` is inside its
    /// field ([`Intrinsics::sees`] checks that).
    #[must_use]
    pub fn project(&self, p: &Vector3<f64>) -> Option<Projection> {
        if p.z.is_nan() || p.z <= 1e-9 {
            return None;
        }
        let iz = 1.0 / p.z;
        let (x, y) = (p.x * iz, p.y * iz);
        let m = self.distort(x, y);
        // ∂(x, y)/∂(X, Y, Z) = [[1/Z, 0, −x/Z], [0, 1/Z, −y/Z]].
        let n = Matrix2x3::new(iz, 0.0, -x * iz, 0.0, iz, -y * iz);
        let f = nalgebra::Matrix2::new(self.fx, 0.0, 0.0, self.fy);
        Some(Projection {
            pixel: [self.fx * m.xd + self.cx, self.fy * m.yd + self.cy],
            jacobian: f * m.d * n,
        })
    }

    /// The largest angle off the optical axis (radians, below π/2) up to
    /// which the model draws farther angles farther from the principal
    /// point: the first zero of the radial slope (see the module
    /// documentation), found on a grid of 0.05° and refined by bisection to
    /// 1e-12 rad, or π/2 when it has none.
    #[must_use]
    pub fn field_angle(&self) -> f64 {
        let half = std::f64::consts::FRAC_PI_2;
        let steps = 1800;
        let at = |i: usize| half * i as f64 / steps as f64;
        let Some(i) = (1..steps).find(|&i| self.distortion.radial_slope(at(i)) <= 0.0) else {
            return half;
        };
        let (mut lo, mut hi) = (at(i - 1), at(i));
        while hi - lo > 1e-12 {
            let mid = 0.5 * (lo + hi);
            if self.distortion.radial_slope(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    /// The projection of `p` (optical frame) when the camera sees it: in
    /// front of it, less than `field` rad off its axis (the model's
    /// [`Intrinsics::field_angle`], which the caller computes once), and
    /// inside the image at least `margin` pixels from its border.
    #[must_use]
    pub fn sees(&self, p: &Vector3<f64>, field: f64, margin: f64) -> Option<Projection> {
        let off_axis = p.x.hypot(p.y).atan2(p.z);
        self.project(p)
            .filter(|pr| off_axis < field && self.inside(pr.pixel, margin))
    }

    /// The intrinsics as a vector: `fx, fy, cx, cy`, then the distortion's
    /// coefficients (the order of [`Distortion::intrinsic_names`]).
    #[must_use]
    pub fn values(&self) -> Vec<f64> {
        let mut v = vec![self.fx, self.fy, self.cx, self.cy];
        v.extend_from_slice(self.distortion.coefficients());
        v
    }

    /// The names of [`Intrinsics::values`].
    #[must_use]
    pub fn names(&self) -> &'static [&'static str] {
        self.distortion.intrinsic_names()
    }

    /// The same camera (image size and model kept) with the values `v` in
    /// the order of [`Intrinsics::values`].
    #[must_use]
    pub fn with_values(&self, v: &[f64]) -> Intrinsics {
        Intrinsics {
            fx: v[0],
            fy: v[1],
            cx: v[2],
            cy: v[3],
            distortion: self.distortion.with_coefficients(&v[4..]),
            ..self.clone()
        }
    }

    /// `∂(u, v)/∂(values)` at `p` (optical frame): the two rows, each in
    /// the order of [`Intrinsics::values`], or `None` behind the camera (as
    /// [`Intrinsics::project`]).
    #[must_use]
    pub fn intrinsic_jacobian(&self, p: &Vector3<f64>) -> Option<[Vec<f64>; 2]> {
        if p.z.is_nan() || p.z <= 1e-9 {
            return None;
        }
        let (x, y) = (p.x / p.z, p.y / p.z);
        let r2 = x * x + y * y;
        let m = self.distort(x, y);
        let (fx, fy) = (self.fx, self.fy);
        let mut u = vec![m.xd, 0.0, 1.0, 0.0];
        let mut v = vec![0.0, m.yd, 0.0, 1.0];
        match &self.distortion {
            Distortion::PlumbBob(_) => {
                let (r4, r6) = (r2 * r2, r2 * r2 * r2);
                u.extend([
                    fx * x * r2,
                    fx * x * r4,
                    fx * 2.0 * x * y,
                    fx * (r2 + 2.0 * x * x),
                    fx * x * r6,
                ]);
                v.extend([
                    fy * y * r2,
                    fy * y * r4,
                    fy * (r2 + 2.0 * y * y),
                    fy * 2.0 * x * y,
                    fy * y * r6,
                ]);
            }
            Distortion::Equidistant(k) => {
                // x' = x (θ/r) (1 + k1 θ² + …): ∂x'/∂kj = x (θ/r) θ^(2j).
                let f = super::fisheye::radial(k, r2);
                let t = f.theta * f.theta;
                let mut pow = f.theta_over_r;
                for _ in 0..4 {
                    pow *= t;
                    u.push(fx * x * pow);
                    v.push(fy * y * pow);
                }
            }
        }
        Some([u, v])
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
        let c = self.distortion.coefficients();
        if let Some(k) = c.iter().position(|d| !d.is_finite()) {
            return Err(format!(
                "{} distortion {} is not a finite number",
                self.distortion.model(),
                self.names()[4 + k]
            ));
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
            distortion: Distortion::PlumbBob([-0.12, 0.08, 1.5e-3, -0.8e-3, -0.02]),
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
        c.distortion = Distortion::PlumbBob([0.0; 5]);
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

    fn fisheye() -> Intrinsics {
        Intrinsics {
            fx: 400.0,
            fy: 401.5,
            distortion: Distortion::Equidistant([-0.01, 0.002, -0.001, 0.0001]),
            ..camera()
        }
    }

    /// The central difference of `f` (a pixel of a vector) along each of
    /// `n` coordinates of `v`, step `h`.
    fn differences(v: &[f64], h: f64, f: impl Fn(&[f64]) -> [f64; 2]) -> Vec<[f64; 2]> {
        (0..v.len())
            .map(|k| {
                let (mut a, mut b) = (v.to_vec(), v.to_vec());
                a[k] += h;
                b[k] -= h;
                let (pa, pb) = (f(&a), f(&b));
                [(pa[0] - pb[0]) / (2.0 * h), (pa[1] - pb[1]) / (2.0 * h)]
            })
            .collect()
    }

    /// The fisheye's `∂(u, v)/∂X` is the pixel's derivative from the axis
    /// (on it, 1e-7 rad and 1e-3 rad off it: the series' side of
    /// [`super::super::fisheye`]) out to 80° off it: central differences
    /// with step 1e-6 m at 0.8 m (truncation ~f h²/Z³ ≈ 1e-9 px/m,
    /// rounding ε u/h ≈ 1e-7 px/m) against entries of ~500 px/m: 1e-5
    /// px/m.
    #[test]
    fn fisheye_jacobian_is_the_derivative() {
        let c = fisheye();
        for p in [
            Vector3::new(0.0, 0.0, 0.8),
            Vector3::new(8e-8, -5e-8, 0.8),
            Vector3::new(8e-4, 3e-4, 0.8),
            Vector3::new(0.21, -0.13, 0.8),
            Vector3::new(0.8 * 80f64.to_radians().tan(), 0.05, 0.8),
        ] {
            let j = c.project(&p).unwrap().jacobian;
            let fd = differences(p.as_slice(), 1e-6, |v| {
                c.project(&Vector3::from_column_slice(v)).unwrap().pixel
            });
            for (k, d) in fd.iter().enumerate() {
                for r in 0..2 {
                    assert!(
                        (j[(r, k)] - d[r]).abs() < 1e-5,
                        "{p:?} ({r},{k}): {} vs {}",
                        j[(r, k)],
                        d[r]
                    );
                }
            }
        }
        // On the axis the pixel is the principal point, whatever the k's.
        assert_eq!(
            c.project(&Vector3::new(0.0, 0.0, 2.0)).unwrap().pixel,
            [c.cx, c.cy]
        );
    }

    /// `∂(u, v)/∂(values)` of both models is the pixel's derivative in its
    /// intrinsics: central differences (step 1e-7 of each value: the
    /// pixel is linear in fx … cy and in the k's, so only rounding, ε
    /// u/h ≈ 1e-6 px, remains) agree to 1e-5 px per unit.
    #[test]
    fn intrinsic_jacobians_are_the_derivatives() {
        // Near the image's corner for plumb_bob (past it its polynomial
        // runs to 1e4 px and rounding with it), 75° off the axis for the
        // fisheye.
        for (c, far) in [
            (camera(), Vector3::new(0.45, 0.33, 0.8)),
            (fisheye(), Vector3::new(1.9, 0.7, 0.6)),
        ] {
            for p in [Vector3::new(0.21, -0.13, 0.8), far] {
                let ji = c.intrinsic_jacobian(&p).unwrap();
                let fd = differences(&c.values(), 1e-7, |v| {
                    c.with_values(v).project(&p).unwrap().pixel
                });
                assert_eq!(ji[0].len(), c.names().len());
                for (k, d) in fd.iter().enumerate() {
                    for r in 0..2 {
                        assert!(
                            (ji[r][k] - d[r]).abs() < 1e-5,
                            "{} {}: {} vs {}",
                            c.distortion.model(),
                            c.names()[k],
                            ji[r][k],
                            d[r]
                        );
                    }
                }
            }
        }
    }

    /// The field: π/2 when the radius grows all the way (the fisheye's
    /// real k's, the mild plumb_bob); a fisheye whose k1 = −0.2 folds
    /// where `1 − 0.6 θ² = 0` nearly (the other k's 0: θ = 1/√0.6), and a
    /// point past it is not seen though the formula draws it inside the
    /// image, nor one behind the camera.
    #[test]
    fn points_past_the_field_are_not_seen() {
        let half = std::f64::consts::FRAC_PI_2;
        assert_eq!(fisheye().field_angle(), half);
        let mut c = fisheye();
        c.distortion = Distortion::Equidistant([-0.2, 0.0, 0.0, 0.0]);
        let field = c.field_angle();
        assert!((field - (1.0 / 0.6f64).sqrt()).abs() < 1e-11, "{field}");
        let past = Vector3::new((field + 0.1).tan(), 0.0, 1.0);
        let before = Vector3::new((field - 0.1).tan(), 0.0, 1.0);
        let drawn = c.project(&past).unwrap().pixel;
        assert!(c.inside(drawn, 0.0), "{drawn:?}");
        assert!(c.sees(&past, field, 0.0).is_none());
        assert!(c.sees(&before, field, 0.0).is_some());
        assert!(c.sees(&Vector3::new(0.1, 0.0, -1.0), field, 0.0).is_none());
        // plumb_bob: 1 + 3 k1 r² = 0 at r = 1/√0.36 with k1 = −0.12 alone.
        let mut p = camera();
        p.distortion = Distortion::PlumbBob([-0.12, 0.0, 0.0, 0.0, 0.0]);
        let r = p.field_angle().tan();
        assert!((r - (1.0 / 0.36f64).sqrt()).abs() < 1e-9, "{r}");
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
