//! The offset between the joint stream's clock and the measurement
//! stream's, from the moves: the measured point's speed against the speed
//! the nominal model predicts from the joints. Speeds are compared, not
//! positions, because a speed is the same in every frame: no frame has to
//! be fitted first, and the nominal model's millimetre errors change the
//! speed profile by a part in a thousand.
//!
//! The offset `S` is the measurement's stamp minus the joint stamp of the
//! same instant. A coarse search over `±max` at 10 ms steps, then a
//! Gauss–Newton refinement on each move between two rests separately: the
//! estimate is the moves' mean and its uncertainty their standard error
//! (the moves are independent, so no noise model is assumed).

use super::rest::{Rest, lower_bound};
use super::timeseries::{JointSeries, MeasSeries};
use crate::model::Robot;
use serde::Serialize;

/// The estimated offset.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Offset {
    /// Measurement stamp minus joint stamp (s).
    pub seconds: f64,
    /// Its standard uncertainty (s): the standard error of the per-move
    /// estimates.
    pub uncertainty: f64,
    /// Moves used.
    pub moves: usize,
}

/// Half-width of the centred difference that gives a speed (s).
const H: f64 = 0.05;
/// Step of the uniform grid the predicted speed is tabulated on (s).
const GRID: f64 = 0.002;

/// A speed profile tabulated on a uniform grid from `t0`.
struct Profile {
    t0: f64,
    v: Vec<f64>,
}

impl Profile {
    fn at(&self, t: f64) -> Option<f64> {
        let x = (t - self.t0) / GRID;
        if x < 0.0 {
            return None;
        }
        let k = x.floor() as usize;
        let f = x - k as f64;
        Some(self.v.get(k)? * (1.0 - f) + self.v.get(k + 1)? * f)
    }

    fn slope(&self, t: f64) -> Option<f64> {
        Some((self.at(t + GRID)? - self.at(t - GRID)?) / (2.0 * GRID))
    }
}

/// Linear interpolation of a position series at `t`.
fn lerp(t: &[f64], p: &[[f64; 3]], x: f64) -> Option<[f64; 3]> {
    let k = lower_bound(t, x);
    if k == 0 || k >= t.len() {
        return (k < t.len() && t[k] == x).then(|| p[k]);
    }
    let f = (x - t[k - 1]) / (t[k] - t[k - 1]);
    Some(std::array::from_fn(|c| {
        p[k - 1][c] * (1.0 - f) + p[k][c] * f
    }))
}

fn speed(t: &[f64], p: &[[f64; 3]], x: f64) -> Option<f64> {
    let (a, b) = (lerp(t, p, x - H)?, lerp(t, p, x + H)?);
    Some((0..3).map(|c| (b[c] - a[c]).powi(2)).sum::<f64>().sqrt() / (2.0 * H))
}

/// The nominal model's speed of the measured point, on the grid.
fn predicted(robot: &Robot, j: &JointSeries) -> Option<Profile> {
    let (first, last) = (*j.t.first()?, *j.t.last()?);
    // The positions at ≤ 500 Hz (every joint sample of a faster stream is
    // not needed for a 0.1 s difference).
    let mut t = Vec::new();
    let mut p = Vec::new();
    let mut ev = crate::kinematics::Evaluator::new(robot, &robot.nominal);
    for (tk, q) in j.t.iter().zip(&j.q) {
        if t.last().is_some_and(|&l: &f64| tk - l < GRID) {
            continue;
        }
        let e = ev.end_frame(q).position;
        t.push(*tk);
        p.push([e.x, e.y, e.z]);
    }
    let n = ((last - first) / GRID) as usize + 1;
    let v = (0..n)
        .map(|k| speed(&t, &p, first + k as f64 * GRID).unwrap_or(0.0))
        .collect();
    Some(Profile { t0: first, v })
}

/// Mean squared speed difference at offset `s` over samples `idx`, and the
/// count used.
fn cost(pred: &Profile, mt: &[f64], ms: &[Option<f64>], s: f64) -> (f64, usize) {
    let (mut sum, mut n) = (0.0, 0usize);
    for (t, v) in mt.iter().zip(ms) {
        if let (Some(v), Some(p)) = (v, pred.at(t - s)) {
            sum += (v - p).powi(2);
            n += 1;
        }
    }
    (if n > 0 { sum / n as f64 } else { f64::INFINITY }, n)
}

/// Estimates the offset within `±max` seconds from the moves between
/// `rests`; `None` when fewer than two moves are seen by both streams.
#[must_use]
pub fn estimate(
    robot: &Robot,
    j: &JointSeries,
    m: &MeasSeries,
    rests: &[Rest],
    max: f64,
) -> Option<Offset> {
    let pred = predicted(robot, j)?;
    let ms: Vec<Option<f64>> = m.t.iter().map(|&t| speed(&m.t, &m.p, t)).collect();
    // Coarse: the best 10 ms step, among offsets that overlap half the
    // measurement samples.
    let steps = (max / 0.01).ceil() as i64;
    let need = m.t.len() / 2;
    let mut best = (f64::INFINITY, 0.0);
    for k in -steps..=steps {
        let s = k as f64 * 0.01;
        let (c, n) = cost(&pred, &m.t, &ms, s);
        if n >= need.max(1) && c < best.0 {
            best = (c, s);
        }
    }
    if !best.0.is_finite() {
        return None;
    }
    let s0 = best.1;
    // Fine: each move on its own, Gauss–Newton from the coarse offset.
    let mut per_move = Vec::new();
    for w in rests.windows(2) {
        let (a, b) = (w[0].end - 0.3, w[1].start + 0.3);
        let idx: Vec<usize> = (lower_bound(&m.t, a + s0)..lower_bound(&m.t, b + s0)).collect();
        if let Some(s) = refine(&pred, &m.t, &ms, &idx, s0) {
            per_move.push(s);
        }
    }
    let n = per_move.len();
    if n < 2 {
        return None;
    }
    let mean = per_move.iter().sum::<f64>() / n as f64;
    let var = per_move.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    Some(Offset {
        seconds: mean,
        uncertainty: (var / n as f64).sqrt(),
        moves: n,
    })
}

/// Gauss–Newton on one move's samples; `None` when the move is not seen
/// (too few samples, no motion) or the step does not settle.
fn refine(pred: &Profile, mt: &[f64], ms: &[Option<f64>], idx: &[usize], s0: f64) -> Option<f64> {
    let peak = idx
        .iter()
        .filter_map(|&i| pred.at(mt[i] - s0))
        .fold(0.0, f64::max);
    if idx.len() < 10 || peak < 0.01 {
        return None;
    }
    // Slow samples are left out: a measured speed is the magnitude of a
    // noisy difference, biased up by about σ²/(2v) where v is small.
    let idx: Vec<usize> = idx
        .iter()
        .copied()
        .filter(|&i| pred.at(mt[i] - s0).is_some_and(|p| p > 0.2 * peak))
        .collect();
    // Unknowns: the offset and a scale of the predicted speed (the nominal
    // model's point is not the true one: millimetres over half a metre).
    let (mut s, mut k) = (s0, 1.0);
    for _ in 0..30 {
        let (mut a, mut b, mut c, mut gk, mut gs) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for &i in &idx {
            let (Some(v), Some(p), Some(d)) = (ms[i], pred.at(mt[i] - s), pred.slope(mt[i] - s))
            else {
                continue;
            };
            // r = v - k p(t - s); dr/dk = -p, dr/ds = k p'(t - s).
            let (jk, js, r) = (-p, k * d, v - k * p);
            a += jk * jk;
            b += jk * js;
            c += js * js;
            gk += jk * r;
            gs += js * r;
        }
        let det = a * c - b * b;
        if det <= 0.0 {
            return None;
        }
        let dk = -(c * gk - b * gs) / det;
        let ds = -(a * gs - b * gk) / det;
        k += dk;
        s += ds.clamp(-0.02, 0.02);
        if ds.abs() < 1e-7 {
            return ((s - s0).abs() < 0.05).then_some(s);
        }
    }
    None
}
