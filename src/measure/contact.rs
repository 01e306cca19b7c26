//! The contact sensor: no instrument, only the tool touching fixed points
//! again and again (MUKCa's ball in a socket). A pose's "measurement" is
//! the name of the point it touches; 3 rows per pose.
//!
//! The tool point is `t = p + R o`, with `(R, p)` the chain's end frame
//! and `o` an offset in the end frame (an own unknown: the ball's centre is
//! not known to a calibration's precision). Rows with the same point `g`
//! touch one fixed but unknown point `P_g` of the base frame (3 own
//! unknowns a point). The residual of a pose touching `g` is `t − P_g`.
//!
//! Own unknowns, in order: `o` (3), then `P_0, P_1, …` (3 each), then
//! `a, b, d` of each unknown plane.
//!
//! # Planes
//! A pose may touch a plane instead ([`ContactSensor::with_planes`]; its
//! tag is `G + l` for plane `l` after the `G` points): its residual is
//! `n · t − d` in the first of its 3 rows, the other two are zero (so that
//! every pose keeps 3 rows; they add nothing to `XᵀX`). A known plane
//! (`PlaneKind::Known`) has no unknowns; an unknown one has a minimal
//! chart: `n = (n₀ + a e₁ + b e₂)/‖…‖` about a start normal `n₀`, and `d`.
//!
//! Under an elementary motion of the chain (linear velocity `v` of `p`,
//! angular velocity `ω`), `t` moves with `v + ω × (R o)`; `∂t/∂o = R`,
//! `∂r/∂P_g = −I`, and the other points' columns are zero.
//!
//! # Known distances
//! A distance `d` known between points `A` and `B` (two sockets of one
//! printed block) adds one row `w (‖P_A − P_B‖ − d)` after every pose's
//! rows ([`Sensor::constraints`]). Every pose row carries the contact noise
//! σ (metres, per coordinate); the distance row carries σ / w. The weight
//! is [`DISTANCE_WEIGHT`] = 10: a block's socket distance is known to a
//! tenth of a contact's repeatability or better, and each point itself is
//! known from `n ≈ 30` contacts to σ/√n ≈ σ/5.5 per coordinate, so the
//! constraint dominates the distance between the two points without making
//! the problem stiff (it is one row in ~100).

use super::sensor::{Observation, ObservationBuf, RowKind, Sensor};
use crate::kinematics::{EndFrame, Motion};
use nalgebra::Vector3;

/// The weight of a known-distance row (see the module documentation).
pub const DISTANCE_WEIGHT: f64 = 10.0;

/// Own unknowns before the first point: the tool offset `o`.
pub const TOOL_OFFSET_PARAMS: usize = 3;

/// A distance known between two contact points.
#[derive(Clone, Debug, PartialEq)]
pub struct KnownDistance {
    /// The first point's index.
    pub a: usize,
    /// The second point's index.
    pub b: usize,
    /// The distance, metres.
    pub metres: f64,
}

/// A plane the tool touches.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    /// Its name.
    pub name: String,
    /// Known or unknown.
    pub kind: PlaneKind,
}

/// A contact plane `n · x = d` (base frame, metres).
#[derive(Clone, Debug, PartialEq)]
pub enum PlaneKind {
    /// Given: its normal (any non-zero length) and offset `d`.
    Known {
        /// The normal.
        normal: [f64; 3],
        /// The offset, metres.
        offset: f64,
    },
    /// Unknown: 3 own unknowns `a, b, d`, the normal `n = (n₀ + a e₁ +
    /// b e₂)/‖…‖` in a chart about `n₀` (`e₁, e₂` orthonormal to it: a
    /// minimal parametrisation, regular near `n₀`), and the offset `d`.
    Unknown {
        /// The chart's centre (a start normal, non-zero).
        n0: [f64; 3],
    },
}

/// Two unit vectors orthonormal to unit `n` (and to each other).
fn chart(n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = n.cross(&helper).normalize();
    (e1, n.cross(&e1))
}

/// Contact with named fixed points, `3` rows per pose, own unknowns the
/// tool offset and the points.
#[derive(Clone, Debug)]
pub struct ContactSensor {
    points: Vec<String>,
    planes: Vec<Plane>,
    distances: Vec<KnownDistance>,
    distance_weight: f64,
}

const KINDS: [RowKind; 3] = [RowKind::Position; 3];
const ONES: [f64; 3] = [1.0; 3];

impl ContactSensor {
    /// A sensor of the named points and the distances known between them
    /// (indices into `points`, checked by the caller).
    #[must_use]
    pub fn new(points: Vec<String>, distances: Vec<KnownDistance>) -> Self {
        Self {
            points,
            distances,
            distance_weight: DISTANCE_WEIGHT,
            planes: Vec::new(),
        }
    }

    /// The sensor with contact planes too: a pose tagged `G + l` (`G`
    /// points) touches plane `l`. Errors on a known plane whose normal is
    /// zero or not finite, or an unknown plane's chart normal likewise.
    pub fn with_planes(mut self, planes: Vec<Plane>) -> Result<Self, String> {
        for p in &planes {
            let n = match &p.kind {
                PlaneKind::Known { normal, offset } if offset.is_finite() => *normal,
                PlaneKind::Known { .. } => [f64::NAN; 3],
                PlaneKind::Unknown { n0 } => *n0,
            };
            let v = Vector3::from(n);
            if !(v.iter().all(|c| c.is_finite()) && v.norm() > 0.0) {
                return Err(format!(
                    "plane '{}': normal ({}, {}, {}) is zero or not finite (a plane needs a direction)",
                    p.name, n[0], n[1], n[2]
                ));
            }
        }
        self.planes = planes;
        Ok(self)
    }

    /// The start of own unknown index of plane `l` (its `a, b, d`), when
    /// it is unknown.
    fn plane_own(&self, l: usize) -> Option<usize> {
        if !matches!(self.planes[l].kind, PlaneKind::Unknown { .. }) {
            return None;
        }
        let before = self.planes[..l]
            .iter()
            .filter(|p| matches!(p.kind, PlaneKind::Unknown { .. }))
            .count();
        Some(TOOL_OFFSET_PARAMS + 3 * self.points.len() + 3 * before)
    }

    /// The plane a tag names, if it names a plane.
    fn plane_of(&self, measured: &[f64]) -> Option<usize> {
        Self::group(measured).checked_sub(self.points.len())
    }

    /// Plane `l`'s unit normal, offset and, for an unknown plane, the
    /// derivatives of the normal along its chart (`∂n/∂a`, `∂n/∂b`).
    fn plane(&self, own: &[f64], l: usize) -> (Vector3<f64>, f64, Option<[Vector3<f64>; 2]>) {
        match (&self.planes[l].kind, self.plane_own(l)) {
            (PlaneKind::Known { normal, offset }, _) => {
                let n = Vector3::from(*normal);
                (n / n.norm(), *offset, None)
            }
            (PlaneKind::Unknown { n0 }, Some(k)) => {
                let n0 = Vector3::from(*n0).normalize();
                let (e1, e2) = chart(&n0);
                let v = n0 + own[k] * e1 + own[k + 1] * e2;
                let len = v.norm();
                let n = v / len;
                let d = |e: Vector3<f64>| (e - n * n.dot(&e)) / len;
                (n, own[k + 2], Some([d(e1), d(e2)]))
            }
            (PlaneKind::Unknown { .. }, None) => unreachable!("an unknown plane has own unknowns"),
        }
    }

    /// Plane `l`'s unit normal and offset `d` (metres) at own unknowns
    /// `own`.
    #[must_use]
    pub fn plane_at(&self, own: &[f64], l: usize) -> ([f64; 3], f64) {
        let (n, d, _) = self.plane(own, l);
        (n.into(), d)
    }

    /// The points' names.
    #[must_use]
    pub fn points(&self) -> &[String] {
        &self.points
    }

    /// The known distances.
    #[must_use]
    pub fn distances(&self) -> &[KnownDistance] {
        &self.distances
    }

    /// The measured value of a pose touching point `g`.
    #[must_use]
    pub fn value_of(g: usize) -> [f64; 3] {
        [g as f64, 0.0, 0.0]
    }

    /// The tool point `p + R o` of end frame `end` with own unknowns `own`.
    #[must_use]
    pub fn tool_point(end: &EndFrame, own: &[f64]) -> Vector3<f64> {
        end.position + Self::lever(end, own)
    }

    /// Point `g` among the own unknowns.
    #[must_use]
    pub fn point(own: &[f64], g: usize) -> Vector3<f64> {
        let k = TOOL_OFFSET_PARAMS + 3 * g;
        Vector3::new(own[k], own[k + 1], own[k + 2])
    }

    /// The offset rotated into the base frame, `R o`.
    fn lever(end: &EndFrame, own: &[f64]) -> Vector3<f64> {
        end.rotation * Vector3::new(own[0], own[1], own[2])
    }

    /// The point index a measured value names.
    fn group(measured: &[f64]) -> usize {
        measured[0] as usize
    }
}

impl Sensor for ContactSensor {
    fn describe(&self) -> &'static str {
        "contacts with fixed points"
    }

    fn rows(&self) -> usize {
        3
    }

    fn row_kinds(&self) -> &[RowKind] {
        &KINDS
    }

    fn weights(&self) -> &[f64] {
        &ONES
    }

    fn observed_dof(&self) -> usize {
        3
    }

    fn observes_orientation(&self) -> bool {
        false
    }

    fn points_per_pose(&self) -> usize {
        0
    }

    fn value_len(&self) -> usize {
        3
    }

    fn n_own_params(&self) -> usize {
        let unknown = self
            .planes
            .iter()
            .filter(|p| matches!(p.kind, PlaneKind::Unknown { .. }))
            .count();
        TOOL_OFFSET_PARAMS + 3 * self.points.len() + 3 * unknown
    }

    fn own_param_names(&self) -> Vec<String> {
        let tool = ["x", "y", "z"].map(|c| format!("tool_{c}"));
        let pts = self
            .points
            .iter()
            .flat_map(|n| ["x", "y", "z"].map(|c| format!("point[{n}]_{c}")));
        let planes = self
            .planes
            .iter()
            .filter(|p| matches!(p.kind, PlaneKind::Unknown { .. }))
            .flat_map(|p| ["a", "b", "d"].map(|c| format!("plane[{}]_{c}", p.name)));
        tool.into_iter().chain(pts).chain(planes).collect()
    }

    fn encode(&self, obs: &Observation<'_>, out: &mut [f64]) {
        out[..3].copy_from_slice(&Self::value_of(obs.tag.unwrap_or(0)));
    }

    fn decode(&self, value: &[f64]) -> ObservationBuf {
        ObservationBuf {
            points: Vec::new(),
            orientation: None,
            tag: Some(Self::group(value)),
        }
    }

    fn predict(&self, end: &EndFrame, own: &[f64], out: &mut [f64]) {
        out[..3].copy_from_slice(Self::tool_point(end, own).as_slice());
    }

    /// A contact has no measured coordinate to move: unchanged.
    fn retract(&self, value: &mut [f64], delta: &[f64]) {
        let _ = (value, delta);
    }

    /// Without the points (own unknowns) a contact has no residual: NaN, so
    /// that a caller that should have used [`Sensor::residual_own`] fails
    /// its finiteness check.
    fn residual(&self, _predicted: &[f64], _measured: &[f64], out: &mut [f64]) {
        out[..3].fill(f64::NAN);
    }

    fn residual_own(&self, predicted: &[f64], measured: &[f64], own: &[f64], out: &mut [f64]) {
        if let Some(l) = self.plane_of(measured) {
            let (n, d, _) = self.plane(own, l);
            let t = Vector3::new(predicted[0], predicted[1], predicted[2]);
            out[..3].copy_from_slice(&[n.dot(&t) - d, 0.0, 0.0]);
            return;
        }
        let pg = Self::point(own, Self::group(measured));
        for c in 0..3 {
            out[c] = predicted[c] - pg[c];
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
        let l = Self::lever(end, own);
        for (c, m) in motions.iter().enumerate() {
            let v = m.lin + m.ang.cross(&l);
            out[c] = v.x;
            out[ld + c] = v.y;
            out[2 * ld + c] = v.z;
        }
    }

    /// The offset's columns (`R`); the points' are zero: without a measured
    /// value no point is named.
    fn own_rows(&self, end: &EndFrame, _own: &[f64], out: &mut [f64], ld: usize) {
        let n = self.n_own_params();
        for i in 0..3 {
            let row = &mut out[i * ld..i * ld + n];
            row.fill(0.0);
            for c in 0..3 {
                row[c] = end.rotation[(i, c)];
            }
        }
    }

    /// A point contact's rows are [`Sensor::motion_rows`]; a plane
    /// contact's first row is the normal's component of them, the other
    /// two are zero.
    fn residual_rows(
        &self,
        end: &EndFrame,
        own: &[f64],
        motions: &[Motion],
        measured: &[f64],
        out: &mut [f64],
        ld: usize,
    ) {
        self.motion_rows(end, own, motions, out, ld);
        if let Some(l) = self.plane_of(measured) {
            let (n, _, _) = self.plane(own, l);
            for c in 0..motions.len() {
                let v = Vector3::new(out[c], out[ld + c], out[2 * ld + c]);
                out[c] = n.dot(&v);
                out[ld + c] = 0.0;
                out[2 * ld + c] = 0.0;
            }
        }
    }

    fn own_rows_of(
        &self,
        end: &EndFrame,
        own: &[f64],
        measured: &[f64],
        out: &mut [f64],
        ld: usize,
    ) {
        self.own_rows(end, own, out, ld);
        if let Some(l) = self.plane_of(measured) {
            let (n, _, dn) = self.plane(own, l);
            let nr = end.rotation.transpose() * n;
            let t = Self::tool_point(end, own);
            let width = self.n_own_params();
            for i in 1..3 {
                out[i * ld..i * ld + width].fill(0.0);
            }
            out[..3].copy_from_slice(nr.as_slice());
            if let (Some(k), Some([da, db])) = (self.plane_own(l), dn) {
                out[k] = da.dot(&t);
                out[k + 1] = db.dot(&t);
                out[k + 2] = -1.0;
            }
            return;
        }
        let k = TOOL_OFFSET_PARAMS + 3 * Self::group(measured);
        for i in 0..3 {
            out[i * ld + k + i] = -1.0;
        }
    }

    fn constraint_rows(&self) -> usize {
        self.distances.len()
    }

    fn constraints(&self, own: &[f64], r: &mut [f64], jac: Option<&mut [f64]>, ld: usize) {
        let w = self.distance_weight;
        let mut jac = jac;
        for (i, d) in self.distances.iter().enumerate() {
            let diff = Self::point(own, d.a) - Self::point(own, d.b);
            let len = diff.norm();
            r[i] = w * (len - d.metres);
            if let Some(j) = jac.as_deref_mut() {
                let u = diff / len;
                let row = &mut j[i * ld..];
                let (ka, kb) = (TOOL_OFFSET_PARAMS + 3 * d.a, TOOL_OFFSET_PARAMS + 3 * d.b);
                for c in 0..3 {
                    row[ka + c] = w * u[c];
                    row[kb + c] = -w * u[c];
                }
            }
        }
    }
}
