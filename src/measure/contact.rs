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
//! Own unknowns, in order: `o` (3), then `P_0, P_1, …` (3 each).
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
use crate::model::MeasurementKind;
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

/// Contact with named fixed points, `3` rows per pose, own unknowns the
/// tool offset and the points.
#[derive(Clone, Debug)]
pub struct ContactSensor {
    points: Vec<String>,
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
        }
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
    /// A point of the tool is what the chain places (the contact points are
    /// the sensor's own).
    fn kind(&self) -> MeasurementKind {
        MeasurementKind::Point
    }

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
        TOOL_OFFSET_PARAMS + 3 * self.points.len()
    }

    fn own_param_names(&self) -> Vec<String> {
        let tool = ["x", "y", "z"].map(|c| format!("tool_{c}"));
        let pts = self
            .points
            .iter()
            .flat_map(|n| ["x", "y", "z"].map(|c| format!("point[{n}]_{c}")));
        tool.into_iter().chain(pts).collect()
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

    fn own_rows_of(
        &self,
        end: &EndFrame,
        own: &[f64],
        measured: &[f64],
        out: &mut [f64],
        ld: usize,
    ) {
        self.own_rows(end, own, out, ld);
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
