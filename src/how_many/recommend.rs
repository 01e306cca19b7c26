//! The sizes a curve runs over and the size it recommends.

use super::CurvePoint;
use serde::Serialize;

/// More poses, in percent (at least one pose), that the knee looks ahead
/// by.
pub const KNEE_MORE_PERCENT: usize = 10;

/// The predicted error's relative gain under which more poses are not
/// worth measuring (at the knee).
pub const KNEE_GAIN: f64 = 0.05;

/// The design size a curve recommends, and why.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(tag = "rule", rename_all = "snake_case")]
pub enum Recommendation {
    /// The smallest size whose predicted position RMS reaches the target.
    Target {
        /// The size.
        n: usize,
        /// The target, mm.
        target_mm: f64,
        /// Its predicted position RMS, mm.
        predicted_mm: f64,
    },
    /// No size of the curve reaches the target: the one that comes
    /// closest.
    TargetNotReached {
        /// The size that comes closest.
        n: usize,
        /// The target, mm.
        target_mm: f64,
        /// Its predicted position RMS, mm.
        predicted_mm: f64,
    },
    /// The knee: the smallest size where [`KNEE_MORE_PERCENT`] more poses gain
    /// less than [`KNEE_GAIN`] of the predicted position RMS.
    Knee {
        /// The size.
        n: usize,
        /// The size it is compared with (at least 10 % more poses).
        next_n: usize,
        /// Its predicted position RMS, mm.
        predicted_mm: f64,
        /// The relative gain of `next_n` over `n` (below [`KNEE_GAIN`]).
        gain: f64,
    },
    /// The curve still gains at its end: its largest size, with the gain
    /// of its last step.
    NoKnee {
        /// The largest size.
        n: usize,
        /// Its predicted position RMS, mm.
        predicted_mm: f64,
    },
}

impl Recommendation {
    /// The recommended size.
    #[must_use]
    pub fn n(&self) -> usize {
        match self {
            Self::Target { n, .. }
            | Self::TargetNotReached { n, .. }
            | Self::Knee { n, .. }
            | Self::NoKnee { n, .. } => *n,
        }
    }
}

/// The size `points` (increasing `n`) recommend: with a target (mm), the
/// smallest whose predicted position RMS reaches it (or the closest when
/// none does); without, the knee — the smallest `n` such that the first
/// size with at least [`KNEE_MORE_PERCENT`] more poses is predicted better by less
/// than [`KNEE_GAIN`]. `None` for an empty curve.
#[must_use]
pub fn recommend(points: &[CurvePoint], target_mm: Option<f64>) -> Option<Recommendation> {
    let rms = |p: &CurvePoint| p.predicted.position_rms_mm;
    if let Some(target_mm) = target_mm {
        if let Some(p) = points.iter().find(|p| rms(p) <= target_mm) {
            return Some(Recommendation::Target {
                n: p.n,
                target_mm,
                predicted_mm: rms(p),
            });
        }
        let p = points.iter().min_by(|a, b| rms(a).total_cmp(&rms(b)))?;
        return Some(Recommendation::TargetNotReached {
            n: p.n,
            target_mm,
            predicted_mm: rms(p),
        });
    }
    for (i, p) in points.iter().enumerate() {
        let want = p.n + (p.n * KNEE_MORE_PERCENT).div_ceil(100).max(1);
        let Some(q) = points[i + 1..].iter().find(|q| q.n >= want) else {
            break;
        };
        let gain = 1.0 - rms(q) / rms(p);
        if gain < KNEE_GAIN {
            return Some(Recommendation::Knee {
                n: p.n,
                next_n: q.n,
                predicted_mm: rms(p),
                gain,
            });
        }
    }
    let last = points.last()?;
    Some(Recommendation::NoKnee {
        n: last.n,
        predicted_mm: rms(last),
    })
}

/// The sizes of the curve: `n_min..=3·n_min` (evenly thinned to at most
/// `max_points`, ends kept) and `also`, increasing, below `pool` poses.
#[must_use]
pub fn curve_sizes(n_min: usize, also: &[usize], max_points: usize, pool: usize) -> Vec<usize> {
    let hi = 3 * n_min;
    let span = hi - n_min;
    let k = max_points.max(2).min(span + 1);
    let mut v: Vec<usize> = (0..k)
        .map(|i| n_min + (i * span + (k - 1) / 2) / (k - 1).max(1))
        .collect();
    v.extend_from_slice(also);
    v.retain(|&n| n >= 1 && n <= pool);
    v.sort_unstable();
    v.dedup();
    v
}

/// The largest step between consecutive `sizes` within `n_min..=3·n_min`
/// (1 when there is at most one).
pub(super) fn sizes_step(sizes: &[usize], n_min: usize) -> usize {
    let range: Vec<usize> = sizes
        .iter()
        .copied()
        .filter(|&n| n >= n_min && n <= 3 * n_min)
        .collect();
    range.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(1)
}
