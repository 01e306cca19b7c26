//! Rest periods: the poses of a calibration run are the periods where every
//! joint's speed stays under a threshold for a minimum time. Each
//! measurement is averaged over its rest after a settling time, with its
//! scatter (a measured noise figure); a rest whose measurement has a gap,
//! or whose scatter is far above the others', is left out with the reason.

use super::timeseries::{JointSeries, MeasSeries};
use serde::Serialize;

/// How rests are found and measurements averaged.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RestSettings {
    /// Largest speed of any joint at rest (rad/s, m/s for prismatic joints).
    pub speed: f64,
    /// Shortest rest (s).
    pub min_duration: f64,
    /// Time left out at the start of each rest, while the arm settles (s).
    pub settle: f64,
    /// A joint's speed is its change over this window, centred (s): a
    /// window of many samples keeps the encoders' noise out of the speed.
    pub window: f64,
    /// A rest whose scatter exceeds this many times the median rest's is
    /// left out (a glitch, a vibration).
    pub max_scatter_ratio: f64,
    /// A rest whose measurement stream stops for longer than this many
    /// median sample intervals is left out (a gap).
    pub max_gap_intervals: f64,
}

impl Default for RestSettings {
    fn default() -> Self {
        Self {
            speed: 0.005,
            min_duration: 0.5,
            settle: 0.2,
            window: 0.1,
            max_scatter_ratio: 3.0,
            max_gap_intervals: 10.0,
        }
    }
}

impl RestSettings {
    /// Checks the settings: positive, finite, a settling time shorter than
    /// the shortest rest.
    pub fn check(&self) -> Result<(), String> {
        for (name, v) in [
            ("rest speed", self.speed),
            ("shortest rest", self.min_duration),
            ("speed window", self.window),
            ("scatter ratio", self.max_scatter_ratio),
            ("gap limit", self.max_gap_intervals),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("the {name} must be a positive number, not {v}"));
            }
        }
        if !(self.settle.is_finite()
            && self.settle >= 0.0
            && self.settle + self.window / 2.0 < self.min_duration)
        {
            return Err(format!(
                "the settling time ({} s) must be at least 0 and, with the {} s trimmed at a rest's end, shorter than the shortest rest ({} s)",
                self.settle,
                self.window / 2.0,
                self.min_duration
            ));
        }
        Ok(())
    }
}

/// A rest: the first and last joint stamps of a period at rest (s).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Rest {
    /// Its first stamp (joint clock, s).
    pub start: f64,
    /// Its last stamp (joint clock, s).
    pub end: f64,
}

/// The index of the first stamp `>= x` in increasing `t`.
pub(crate) fn lower_bound(t: &[f64], x: f64) -> usize {
    t.partition_point(|&v| v < x)
}

/// Each sample's largest joint speed: the change over the centred window
/// `w` (at the ends, the window is cut).
#[must_use]
pub fn joint_speeds(j: &JointSeries, w: f64) -> Vec<f64> {
    let n = j.t.len();
    let (mut a, mut b) = (0usize, 0usize);
    (0..n)
        .map(|i| {
            while j.t[a] < j.t[i] - w / 2.0 {
                a += 1;
            }
            while b + 1 < n && j.t[b + 1] <= j.t[i] + w / 2.0 {
                b += 1;
            }
            let dt = j.t[b] - j.t[a];
            if dt <= 0.0 {
                return 0.0;
            }
            j.q[a]
                .iter()
                .zip(&j.q[b])
                .map(|(x, y)| (y - x).abs() / dt)
                .fold(0.0, f64::max)
        })
        .collect()
}

/// The rest periods of the joint stream: maximal runs of samples whose
/// speed is under `s.speed`, with no joint-stream gap longer than the
/// speed window inside, lasting at least `s.min_duration`.
#[must_use]
pub fn find_rests(j: &JointSeries, s: &RestSettings) -> Vec<Rest> {
    let speed = joint_speeds(j, s.window);
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    let close = |from: usize, to: usize, out: &mut Vec<Rest>| {
        if j.t[to] - j.t[from] >= s.min_duration {
            out.push(Rest {
                start: j.t[from],
                end: j.t[to],
            });
        }
    };
    for i in 0..j.t.len() {
        let still = speed[i] < s.speed;
        let gap = i > 0 && j.t[i] - j.t[i - 1] > s.window;
        match (start, still) {
            (Some(a), _) if gap => {
                close(a, i - 1, &mut out);
                start = still.then_some(i);
            }
            (None, true) => start = Some(i),
            (Some(a), false) => {
                close(a, i - 1, &mut out);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(a) = start {
        close(a, j.t.len() - 1, &mut out);
    }
    out
}

/// One rest's averages: joint values, measurement and scatter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Averaged {
    /// The averaging window's start and end (joint clock, s).
    pub window: [f64; 2],
    /// Mean joint values over the window.
    pub q: Vec<f64>,
    /// Measurement samples averaged.
    pub samples: usize,
    /// Mean position (m).
    pub position: [f64; 3],
    /// Mean orientation `[w, x, y, z]` (poses only).
    pub orientation: Option<[f64; 4]>,
    /// Scatter of the samples about their mean, per coordinate (RMS, m).
    pub scatter: f64,
    /// Scatter of the orientations about their mean, per axis (RMS, rad).
    pub orientation_scatter: Option<f64>,
    /// The longest time without a measurement in the window, its ends
    /// counted (s).
    pub longest_gap: f64,
}

/// Averages the joints and the measurement over `rest` after the settling
/// time `settle` and before its last `trim` seconds (half the speed
/// window: a rest's last samples see the next move starting);
/// measurement stamps are moved by `-offset` onto the joint clock. `None`
/// when the window holds no measurement sample.
#[must_use]
pub fn average(
    j: &JointSeries,
    m: &MeasSeries,
    rest: &Rest,
    [settle, trim]: [f64; 2],
    offset: f64,
) -> Option<Averaged> {
    let (t0, t1) = (rest.start + settle, rest.end - trim);
    let (a, b) = (lower_bound(&j.t, t0), lower_bound(&j.t, t1 + 1e-12));
    let dof = j.q.first().map_or(0, Vec::len);
    let mut q = vec![0.0; dof];
    for row in &j.q[a..b] {
        for (s, v) in q.iter_mut().zip(row) {
            *s += v;
        }
    }
    q.iter_mut().for_each(|s| *s /= (b - a).max(1) as f64);
    let (ma, mb) = (
        lower_bound(&m.t, t0 + offset),
        lower_bound(&m.t, t1 + offset + 1e-12),
    );
    if mb <= ma {
        return None;
    }
    let n = mb - ma;
    let mut mean = [0.0; 3];
    for p in &m.p[ma..mb] {
        (0..3).for_each(|k| mean[k] += p[k] / n as f64);
    }
    let ss: f64 = m.p[ma..mb]
        .iter()
        .map(|p| (0..3).map(|k| (p[k] - mean[k]).powi(2)).sum::<f64>())
        .sum();
    let dof_s = (3 * n.saturating_sub(1)).max(1) as f64;
    let mut longest_gap = (m.t[ma] - offset - t0).max(t1 - (m.t[mb - 1] - offset));
    for w in m.t[ma..mb].windows(2) {
        longest_gap = longest_gap.max(w[1] - w[0]);
    }
    let (orientation, orientation_scatter) = if m.r.is_empty() {
        (None, None)
    } else {
        let (r, s) = mean_rotation(&m.r[ma..mb]);
        (Some(r), Some(s))
    };
    Some(Averaged {
        window: [t0, t1],
        q,
        samples: n,
        position: mean,
        orientation,
        scatter: (ss / dof_s).sqrt(),
        orientation_scatter,
        longest_gap,
    })
}

/// The mean of unit quaternions `[w, x, y, z]` (signs aligned with the
/// first, summed and normalised: the chordal mean, exact to second order in
/// the scatter) and the RMS angle about it per axis (rad).
fn mean_rotation(r: &[[f64; 4]]) -> ([f64; 4], f64) {
    use nalgebra::{Quaternion, UnitQuaternion};
    let first = r[0];
    let mut sum = [0.0; 4];
    for x in r {
        let dot: f64 = (0..4).map(|k| x[k] * first[k]).sum();
        let s = if dot < 0.0 { -1.0 } else { 1.0 };
        (0..4).for_each(|k| sum[k] += s * x[k]);
    }
    let mean = UnitQuaternion::from_quaternion(Quaternion::new(sum[0], sum[1], sum[2], sum[3]));
    let ss: f64 = r
        .iter()
        .map(|x| {
            let u = UnitQuaternion::from_quaternion(Quaternion::new(x[0], x[1], x[2], x[3]));
            u.angle_to(&mean).powi(2)
        })
        .sum();
    let dof = (3 * r.len().saturating_sub(1)).max(1) as f64;
    ([mean.w, mean.i, mean.j, mean.k], (ss / dof).sqrt())
}

/// The median of `v` (0 when empty).
#[must_use]
pub fn median(v: &[f64]) -> f64 {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return 0.0;
    }
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two rests of 1 s joined by a 1 s move at 0.5 rad/s, sampled at
    /// 500 Hz: two rests found, each within the speed window's half-width
    /// of the true still periods.
    #[test]
    fn rests_are_the_still_periods() {
        let mut j = JointSeries::default();
        for k in 0..1500 {
            let t = k as f64 / 500.0;
            let q = if t < 1.0 {
                0.0
            } else if t < 2.0 {
                0.5 * (t - 1.0)
            } else {
                0.5
            };
            j.t.push(t);
            j.q.push(vec![q, 0.1]);
        }
        let s = RestSettings::default();
        let rests = find_rests(&j, &s);
        assert_eq!(rests.len(), 2, "{rests:?}");
        let half = s.window / 2.0;
        assert!((rests[0].start - 0.0).abs() < 1e-9);
        assert!((rests[0].end - (1.0 - half)).abs() < 0.01, "{rests:?}");
        assert!((rests[1].start - (2.0 + half)).abs() < 0.01, "{rests:?}");
        // A measurement 2 s ahead of the joints: found with the offset.
        let m = MeasSeries {
            t: (0..300).map(|k| 2.0 + k as f64 / 100.0).collect(),
            p: (0..300)
                .map(|k| [if k < 150 { 1.0 } else { 2.0 }, 0.0, 0.0])
                .collect(),
            r: Vec::new(),
        };
        let a = average(&j, &m, &rests[0], [0.2, 0.05], 2.0).unwrap();
        assert!((a.position[0] - 1.0).abs() < 1e-12, "{a:?}");
        assert_eq!(a.position[1..], [0.0, 0.0]);
        assert!(a.scatter < 1e-12, "{a:?}");
        assert!(a.longest_gap <= 0.011, "{a:?}");
        assert!(average(&j, &m, &rests[1], [0.2, 0.05], 10.0).is_none());
    }
}
