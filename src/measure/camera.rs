//! The camera sensor: a calibrated camera ([`super::pinhole`]: plumb_bob
//! or equidistant fisheye distortion)
//! sees the points of a target (a checkerboard's corners, tags' centres);
//! its residuals are pixels, two rows per target point.
//!
//! # Mountings and own unknowns
//! * **eye-to-hand**: the camera is fixed in the base (the model's
//!   measurement frame), the target rides on the end frame;
//! * **eye-in-hand**: the camera rides on the end frame, the target is
//!   fixed in the base.
//!
//! Either way two placements are unknown, 12 own unknowns in this order:
//! the camera's (`camera_x, camera_y, camera_z` metres, `camera_rx,
//! camera_ry, camera_rz` radians), then the target's (`target_x … target_rz`),
//! each in the frame it is fixed to. A placement's rotation is a chart
//! `R = R₀ exp([r]×)` about a start rotation `R₀` (kept by the sensor,
//! [`CameraSensor::recentred`]): the three `r` stay small, so the chart is
//! regular whatever way the camera looks (a rotation vector of the whole
//! rotation is not, near a half turn). The robot's unknowns that repeat a
//! placement (the base's and the tool's rigid motions) are not among the
//! robot's unknowns ([`crate::identify::camera`] chooses them).
//!
//! With `(R, p)` the end frame, `(R_c, t_c)` the camera's and `(R_t, t_t)`
//! the target's placement and `s_k` a target point, the point in the
//! camera's optical frame is
//!
//! * eye-to-hand: `P = p + R (t_t + R_t s_k)`, `X = R_cᵀ (P − t_c)`;
//! * eye-in-hand: `P = t_t + R_t s_k`, `X = R_cᵀ (Rᵀ (P − p) − t_c)`,
//!
//! and its pixel the projection of `X`.
//!
//! # Jacobian rows
//! Under an elementary motion of the chain (linear velocity `v` of `p`,
//! angular velocity `ω`, [`Motion`]), with `l = P − p`:
//! `dX = R_cᵀ (v + ω × l)` (eye-to-hand) or `dX = −R_cᵀ Rᵀ (v + ω × l)`
//! (eye-in-hand). The own columns: `∂X/∂t_c = −R_cᵀ`, `∂X/∂r_c = [X]×
//! J_r(r_c)`, `∂X/∂t_t = A`, `∂X/∂r_t = −A R_t [s_k]× J_r(r_t)` with `A =
//! R_cᵀ R` (eye-to-hand) or `R_cᵀ Rᵀ` (eye-in-hand) and `J_r` SO(3)'s right
//! Jacobian ([`super::pinhole::right_jacobian`]). Each is multiplied by the
//! projection's `∂(u, v)/∂X`.
//!
//! # Features not seen
//! Every pose has rows for every target point, so that the seam's fixed
//! [`Sensor::rows`] holds; a point a pose did not see has a zero residual
//! and zero Jacobian rows: it adds nothing to the fit or to `XᵀX`. A value
//! holds three numbers per target point, `u, v, seen` (`seen` 1 or 0;
//! [`Observation::points`] carries them as `[u, v, seen]`). Measured
//! values say which points were detected ([`Sensor::residual_rows`],
//! [`Sensor::own_rows_of`]); the design rows ([`Sensor::motion_rows`],
//! [`Sensor::own_rows`]), which have no measured value, keep the points the
//! camera is predicted to see: in front of it, inside its model's field
//! ([`super::pinhole::Intrinsics::field_angle`]) and inside the image at
//! least [`CameraSensor::margin`] pixels from its border. A residual block's
//! redundancy counts the rows seen only ([`CameraSensor::seen_rows`]).

use super::pinhole::{Intrinsics, Projection, right_jacobian, skew};
use super::sensor::{Observation, ObservationBuf, RowKind, Sensor};
use crate::kinematics::{EndFrame, Motion};
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

mod mounting;
pub use mounting::Mounting;

/// Own unknowns of a camera sensor: two placements of 6.
pub const OWN_PARAMS: usize = 12;

/// Fewest target points a pose must see: a camera places a target from
/// four points or more (three leave up to four solutions, P3P).
pub const MIN_POINTS_PER_POSE: usize = 4;

/// A camera seeing `N` target points: `2N` pixel rows per pose, 12 own
/// unknowns (see the module documentation).
#[derive(Clone, Debug)]
pub struct CameraSensor {
    intrinsics: Intrinsics,
    mounting: Mounting,
    points: Vec<Vector3<f64>>,
    /// The charts' centres `R₀`: the camera's, the target's.
    charts: [Matrix3<f64>; 2],
    margin: f64,
    kinds: Vec<RowKind>,
    ones: Vec<f64>,
    /// Which intrinsics are unknowns (in the order of
    /// [`Intrinsics::values`]; own unknowns from 12 on, the free ones in
    /// that order).
    refine: Vec<bool>,
    /// The given intrinsics' [`Intrinsics::field_angle`], radians.
    field: f64,
    /// The direction, in the target's frame, from its seen face into it
    /// (away from a camera that sees the face): `+z` unless
    /// [`CameraSensor::with_face`] says otherwise.
    face: Vector3<f64>,
}

/// How a camera sees its target at one pose ([`CameraSensor::view`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Points in front of the camera, inside its model's field and inside
    /// the image with the margin.
    pub seen: usize,
    /// The viewing angle, radians: between the target's z axis and the
    /// line of sight from the camera to the points' centroid. 0 when the
    /// camera looks straight at the target's face: a target's z axis
    /// points away from the camera that sees it un-mirrored (OpenCV's
    /// convention: a checkerboard's x along its rows, y down its columns,
    /// z = x × y into the board); above 90° the camera sees its back.
    pub angle: f64,
    /// The distance from the camera to the points' centroid, metres.
    pub distance: f64,
}

/// The frames one pose's rows need.
struct Frames {
    /// The camera's rotation in its parent, transposed.
    rct: Matrix3<f64>,
    tc: Vector3<f64>,
    /// The target's rotation and translation in its parent.
    rt: Matrix3<f64>,
    tt: Vector3<f64>,
    /// `B`: a motion's `v + ω × l` to `dX`.
    b: Matrix3<f64>,
    /// `A`: a change of the target point in its parent to `dX`.
    a: Matrix3<f64>,
    /// The right Jacobians of the two charts.
    jc: Matrix3<f64>,
    jt: Matrix3<f64>,
}

impl CameraSensor {
    /// A camera with `intrinsics` seeing target `points` (target frame,
    /// metres), mounted as `mounting`, its charts centred on the start
    /// placements `camera` and `target` (each in its parent frame, see
    /// [`Mounting`]). Design rows keep the points at least 0 pixels inside
    /// the image ([`CameraSensor::with_margin`]).
    #[must_use]
    pub fn new(
        intrinsics: Intrinsics,
        mounting: Mounting,
        points: Vec<Vector3<f64>>,
        camera: &Isometry3<f64>,
        target: &Isometry3<f64>,
    ) -> Self {
        let n = points.len();
        Self {
            refine: vec![false; intrinsics.values().len()],
            field: intrinsics.field_angle(),
            face: Vector3::z(),
            intrinsics,
            mounting,
            points,
            charts: [
                camera.rotation.to_rotation_matrix().into_inner(),
                target.rotation.to_rotation_matrix().into_inner(),
            ],
            margin: 0.0,
            kinds: vec![RowKind::Pixel; 2 * n],
            ones: vec![1.0; 2 * n],
        }
    }

    /// The sensor whose own unknowns also hold the intrinsics (`fx, fy,
    /// cx, cy` and the distortion's coefficients, [`Intrinsics::values`],
    /// after the 12 placement unknowns, their values rather than
    /// corrections) when `refine` is set.
    #[must_use]
    pub fn with_intrinsics_refined(self, refine: bool) -> Self {
        let n = self.intrinsics.values().len();
        self.with_free_intrinsics(vec![refine; n])
    }

    /// The sensor whose own unknowns hold the intrinsics `free` marks (in
    /// the order of [`Intrinsics::values`], one flag each); the others
    /// stay as given.
    #[must_use]
    pub fn with_free_intrinsics(mut self, free: Vec<bool>) -> Self {
        assert_eq!(
            free.len(),
            self.intrinsics.values().len(),
            "one flag per intrinsic"
        );
        self.refine = free;
        self
    }

    /// Which intrinsics are unknowns ([`CameraSensor::with_free_intrinsics`]).
    #[must_use]
    pub fn free_intrinsics(&self) -> &[bool] {
        &self.refine
    }

    /// The sensor whose target is seen from the side `face` points away
    /// from (a direction in the target's frame, into the target): `+z` for
    /// OpenCV's boards (the default), `−z` for Kalibr's aprilgrid (its z
    /// points out of the printed face). Only the viewing angle
    /// ([`CameraSensor::view`]) uses it.
    #[must_use]
    pub fn with_face(mut self, face: Vector3<f64>) -> Self {
        self.face = face.normalize();
        self
    }

    /// Whether any intrinsic is an unknown ([`CameraSensor::with_intrinsics_refined`]).
    #[must_use]
    pub fn refines_intrinsics(&self) -> bool {
        self.refine.iter().any(|f| *f)
    }

    /// The values of the free intrinsics as the sensor holds them (the
    /// start of their unknowns).
    #[must_use]
    pub fn free_intrinsic_values(&self) -> Vec<f64> {
        let v = self.intrinsics.values();
        v.iter()
            .zip(&self.refine)
            .filter(|(_, free)| **free)
            .map(|(v, _)| *v)
            .collect()
    }

    /// The intrinsics at own unknowns `own`: the sensor's, with the free
    /// ones those `own` holds after the placements.
    #[must_use]
    pub fn intrinsics_at(&self, own: &[f64]) -> Intrinsics {
        let mut v = self.intrinsics.values();
        let mut k = OWN_PARAMS;
        for (j, free) in self.refine.iter().enumerate() {
            if *free && k < own.len() {
                v[j] = own[k];
                k += 1;
            }
        }
        self.intrinsics.with_values(&v)
    }

    /// The sensor whose design rows keep the points at least `margin`
    /// pixels inside the image.
    #[must_use]
    pub fn with_margin(mut self, margin: f64) -> Self {
        self.margin = margin;
        self
    }

    /// The margin (pixels) of the points the design rows keep.
    #[must_use]
    pub fn margin(&self) -> f64 {
        self.margin
    }

    /// The intrinsics.
    #[must_use]
    pub fn intrinsics(&self) -> &Intrinsics {
        &self.intrinsics
    }

    /// The mounting.
    #[must_use]
    pub fn mounting(&self) -> Mounting {
        self.mounting
    }

    /// The target's points (target frame, metres).
    #[must_use]
    pub fn points(&self) -> &[Vector3<f64>] {
        &self.points
    }

    /// The own unknowns that stand for the start placements the charts
    /// are centred on (zero rotations).
    #[must_use]
    pub fn start_own(camera: &Isometry3<f64>, target: &Isometry3<f64>) -> Vec<f64> {
        let mut own = vec![0.0; OWN_PARAMS];
        own[..3].copy_from_slice(camera.translation.vector.as_slice());
        own[6..9].copy_from_slice(target.translation.vector.as_slice());
        own
    }

    /// The placements (camera, target) that own unknowns `own` stand for.
    #[must_use]
    pub fn placements(&self, own: &[f64]) -> (Isometry3<f64>, Isometry3<f64>) {
        let at = |k: usize| {
            let r = Rotation3::from_matrix_unchecked(self.charts[k / 6])
                * Rotation3::new(Vector3::new(own[k + 3], own[k + 4], own[k + 5]));
            Isometry3::from_parts(
                Translation3::new(own[k], own[k + 1], own[k + 2]),
                UnitQuaternion::from_rotation_matrix(&r),
            )
        };
        (at(0), at(6))
    }

    /// The same sensor with its charts centred on the placements `own`
    /// stands for, and the own unknowns that stand for them there (zero
    /// rotations).
    #[must_use]
    pub fn recentred(&self, own: &[f64]) -> (Self, Vec<f64>) {
        let (c, t) = self.placements(own);
        let mut s = self.clone();
        s.charts = [
            c.rotation.to_rotation_matrix().into_inner(),
            t.rotation.to_rotation_matrix().into_inner(),
        ];
        let mut own1 = Self::start_own(&c, &t);
        own1.extend_from_slice(&own[OWN_PARAMS.min(own.len())..]);
        (s, own1)
    }

    /// The pixel rows of a measured value that hold a seen point (2 per
    /// seen point): what a residual block's redundancy counts.
    #[must_use]
    pub fn seen_rows(&self, measured: &[f64]) -> usize {
        2 * measured.chunks_exact(3).filter(|c| c[2] != 0.0).count()
    }

    /// The measured value of one pose: `seen[k]` the pixel of point `k`,
    /// if it was seen.
    #[must_use]
    pub fn value_of(seen: &[Option<[f64; 2]>]) -> Vec<f64> {
        seen.iter()
            .flat_map(|s| match s {
                Some([u, v]) => [*u, *v, 1.0],
                None => [0.0, 0.0, 0.0],
            })
            .collect()
    }

    /// How the camera sees the target at end frame `end` and own unknowns
    /// `own`: how many points it sees (in front of it, inside the model's
    /// field and the image at least `margin` pixels from its border,
    /// [`Intrinsics::sees`]), the viewing angle and the distance of the
    /// points' centroid.
    #[must_use]
    pub fn view(&self, end: &EndFrame, own: &[f64], margin: f64) -> View {
        let f = self.frames(end, own);
        let cam = self.intrinsics_at(own);
        let mut seen = 0;
        let mut centroid = Vector3::zeros();
        for k in 0..self.points.len() {
            let (x, _) = self.point(end, &f, k);
            centroid += x;
            seen += usize::from(cam.sees(&x, self.field, margin).is_some());
        }
        centroid /= self.points.len().max(1) as f64;
        // The target's z axis in the optical frame: A maps a direction of
        // the target's parent to the optical frame (up to the sign of
        // eye-in-hand's B, which a direction does not share).
        let normal = f.a * f.rt * self.face;
        let distance = centroid.norm();
        View {
            seen,
            angle: (normal.dot(&centroid) / distance.max(f64::MIN_POSITIVE))
                .clamp(-1.0, 1.0)
                .acos(),
            distance,
        }
    }

    fn frames(&self, end: &EndFrame, own: &[f64]) -> Frames {
        let rot = |k: usize| Vector3::new(own[k + 3], own[k + 4], own[k + 5]);
        let (rc_, rt_) = (rot(0), rot(6));
        let rc = self.charts[0] * Rotation3::new(rc_).matrix();
        let rt = self.charts[1] * Rotation3::new(rt_).matrix();
        let rct = rc.transpose();
        let (b, a) = match self.mounting {
            Mounting::EyeToHand => (rct, rct * end.rotation),
            Mounting::EyeInHand => {
                let a = rct * end.rotation.transpose();
                (-a, a)
            }
        };
        Frames {
            rct,
            tc: Vector3::new(own[0], own[1], own[2]),
            rt,
            tt: Vector3::new(own[6], own[7], own[8]),
            b,
            a,
            jc: right_jacobian(&rc_),
            jt: right_jacobian(&rt_),
        }
    }

    /// Point `k` in the optical frame, and its lever `l = P − p`.
    fn point(&self, end: &EndFrame, f: &Frames, k: usize) -> (Vector3<f64>, Vector3<f64>) {
        let s = f.tt + f.rt * self.points[k];
        match self.mounting {
            Mounting::EyeToHand => {
                let l = end.rotation * s;
                (f.rct * (end.position + l - f.tc), l)
            }
            Mounting::EyeInHand => {
                let l = s - end.position;
                (f.rct * (end.rotation.transpose() * l - f.tc), l)
            }
        }
    }

    /// Whether the camera sees `x` (optical frame) with its given
    /// intrinsics, at least `margin` pixels inside the image
    /// ([`Intrinsics::sees`] with the model's field).
    #[must_use]
    pub fn sees(&self, x: &Vector3<f64>, margin: f64) -> bool {
        self.intrinsics.sees(x, self.field, margin).is_some()
    }

    /// Whether point `k` (at `x`, optical frame) keeps its rows: seen in
    /// `measured` when given, else predicted seen with the margin.
    fn kept(
        &self,
        k: usize,
        x: &Vector3<f64>,
        proj: Option<&Projection>,
        measured: Option<&[f64]>,
    ) -> bool {
        match (measured, proj) {
            (Some(m), Some(_)) => m[3 * k + 2] != 0.0,
            (None, Some(_)) => self.sees(x, self.margin),
            (_, None) => false,
        }
    }

    /// The robot's columns of every point (zero rows for points not kept).
    fn motion_rows_masked(
        &self,
        end: &EndFrame,
        own: &[f64],
        motions: &[Motion],
        measured: Option<&[f64]>,
        out: &mut [f64],
        ld: usize,
    ) {
        let f = self.frames(end, own);
        let cam = self.intrinsics_at(own);
        for k in 0..self.points.len() {
            let (x, l) = self.point(end, &f, k);
            let proj = cam.project(&x);
            let rows = &mut out[2 * k * ld..];
            match proj.filter(|p| self.kept(k, &x, Some(p), measured)) {
                Some(p) => {
                    let jb = p.jacobian * f.b;
                    for (c, m) in motions.iter().enumerate() {
                        let d = jb * (m.lin + m.ang.cross(&l));
                        rows[c] = d.x;
                        rows[ld + c] = d.y;
                    }
                }
                None => {
                    rows[..motions.len()].fill(0.0);
                    rows[ld..ld + motions.len()].fill(0.0);
                }
            }
        }
    }

    /// The own columns of every point (zero rows for points not kept).
    fn own_rows_masked(
        &self,
        end: &EndFrame,
        own: &[f64],
        measured: Option<&[f64]>,
        out: &mut [f64],
        ld: usize,
    ) {
        let f = self.frames(end, own);
        let cam = self.intrinsics_at(own);
        let n_own = self.n_own_params();
        for k in 0..self.points.len() {
            let (x, _) = self.point(end, &f, k);
            let proj = cam.project(&x);
            let rows = &mut out[2 * k * ld..];
            let Some(p) = proj.filter(|p| self.kept(k, &x, Some(p), measured)) else {
                rows[..n_own].fill(0.0);
                rows[ld..ld + n_own].fill(0.0);
                continue;
            };
            if self.refines_intrinsics()
                && let Some(ji) = cam.intrinsic_jacobian(&x)
            {
                let free = (0..self.refine.len()).filter(|&j| self.refine[j]);
                for (c, j) in (OWN_PARAMS..n_own).zip(free) {
                    rows[c] = ji[0][j];
                    rows[ld + c] = ji[1][j];
                }
            }
            let blocks = [
                -f.rct,
                skew(&x) * f.jc,
                f.a,
                -f.a * f.rt * skew(&self.points[k]) * f.jt,
            ];
            for (b, m) in blocks.iter().enumerate() {
                let d = p.jacobian * m;
                for c in 0..3 {
                    rows[3 * b + c] = d[(0, c)];
                    rows[ld + 3 * b + c] = d[(1, c)];
                }
            }
        }
    }
}

impl Sensor for CameraSensor {
    fn describe(&self) -> &'static str {
        "target points seen by a camera (pixels)"
    }

    fn rows(&self) -> usize {
        2 * self.points.len()
    }

    fn row_kinds(&self) -> &[RowKind] {
        &self.kinds
    }

    fn weights(&self) -> &[f64] {
        &self.ones
    }

    /// Four or more points of a target off a line fix the whole frame.
    fn observed_dof(&self) -> usize {
        6
    }

    fn observes_orientation(&self) -> bool {
        true
    }

    fn measures_orientation(&self) -> bool {
        false
    }

    fn points_per_pose(&self) -> usize {
        self.points.len()
    }

    fn value_len(&self) -> usize {
        3 * self.points.len()
    }

    fn n_own_params(&self) -> usize {
        OWN_PARAMS + self.refine.iter().filter(|f| **f).count()
    }

    fn own_param_names(&self) -> Vec<String> {
        let mut names: Vec<String> = ["camera", "target"]
            .iter()
            .flat_map(|w| ["x", "y", "z", "rx", "ry", "rz"].map(|c| format!("{w}_{c}")))
            .collect();
        names.extend(
            self.intrinsics
                .names()
                .iter()
                .zip(&self.refine)
                .filter(|(_, free)| **free)
                .map(|(n, _)| format!("camera_{n}")),
        );
        names
    }

    fn encode(&self, obs: &Observation<'_>, out: &mut [f64]) {
        for (o, p) in out.chunks_exact_mut(3).zip(obs.points) {
            o.copy_from_slice(p);
        }
    }

    fn decode(&self, value: &[f64]) -> ObservationBuf {
        ObservationBuf {
            points: value.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            orientation: None,
            tag: None,
        }
    }

    /// `u, v, 1` for a point in front of the camera and inside its model's
    /// field (inside the image or not), `NaN, NaN, 0` for one behind it or
    /// beyond the field ([`Intrinsics::field_angle`]: the model's formula
    /// would draw it back towards the image).
    fn predict(&self, end: &EndFrame, own: &[f64], out: &mut [f64]) {
        let f = self.frames(end, own);
        let cam = self.intrinsics_at(own);
        for k in 0..self.points.len() {
            let (x, _) = self.point(end, &f, k);
            let o = &mut out[3 * k..3 * k + 3];
            let off_axis = x.x.hypot(x.y).atan2(x.z);
            match cam.project(&x).filter(|_| off_axis < self.field) {
                Some(p) => o.copy_from_slice(&[p.pixel[0], p.pixel[1], 1.0]),
                None => o.copy_from_slice(&[f64::NAN, f64::NAN, 0.0]),
            }
        }
    }

    /// Moves each pixel by `delta` (pixels); the `seen` flags stay.
    fn retract(&self, value: &mut [f64], delta: &[f64]) {
        for (v, d) in value.chunks_exact_mut(3).zip(delta.chunks_exact(2)) {
            v[0] += d[0];
            v[1] += d[1];
        }
    }

    /// `predicted − measured` in pixels for the points measured as seen, 0
    /// for the others (NaN for a seen point predicted behind the camera).
    fn residual(&self, predicted: &[f64], measured: &[f64], out: &mut [f64]) {
        for ((o, p), m) in out
            .chunks_exact_mut(2)
            .zip(predicted.chunks_exact(3))
            .zip(measured.chunks_exact(3))
        {
            if m[2] == 0.0 {
                o.fill(0.0);
            } else {
                o[0] = p[0] - m[0];
                o[1] = p[1] - m[1];
            }
        }
    }

    fn motion_rows(
        &self,
        end: &EndFrame,
        own: &[f64],
        motions: &[Motion],
        out: &mut [f64],
        ld: usize,
    ) {
        self.motion_rows_masked(end, own, motions, None, out, ld);
    }

    fn residual_rows(
        &self,
        end: &EndFrame,
        own: &[f64],
        motions: &[Motion],
        measured: &[f64],
        out: &mut [f64],
        ld: usize,
    ) {
        self.motion_rows_masked(end, own, motions, Some(measured), out, ld);
    }

    fn own_rows(&self, end: &EndFrame, own: &[f64], out: &mut [f64], ld: usize) {
        self.own_rows_masked(end, own, None, out, ld);
    }

    fn own_rows_of(
        &self,
        end: &EndFrame,
        own: &[f64],
        measured: &[f64],
        out: &mut [f64],
        ld: usize,
    ) {
        self.own_rows_masked(end, own, Some(measured), out, ld);
    }
}

#[cfg(test)]
mod tests;
