//! The labelling of a symmetric target's points at each pose. A
//! checkerboard's inner-corner grid maps onto itself when turned 180°
//! (and, seen from behind, when its rows or columns are mirrored), so a
//! detector (OpenCV's `findChessboardCorners`) may return its corners in
//! any of these orders: each pose's PnP fits equally well, but the
//! target's placements then disagree from pose to pose. The labelling of
//! each pose is chosen by the robot's motion: for the relative motion
//! between a reference pose and pose `j`, the hand-eye equation `Aᵢ X = Z
//! Bᵢ` ([`super::hand_eye`]) makes `Aᵣ⁻¹ Aⱼ = X (Bᵣ⁻¹ Bⱼ) X⁻¹`, so both
//! have the same rotation angle and the same translation along their
//! axis, whatever `X` and `Z`. Each labelling of pose `j` is scored by how
//! far these two invariants of its PnP `Bⱼ` are from the robot's; the best
//! is kept when the second best scores [`AMBIGUITY_FACTOR`] times worse;
//! otherwise the pose keeps the detector's order when that is one of the
//! two (a relative motion whose invariants are alike for both: on a UR5
//! eye-to-hand set with 0.3 px of noise one pose in 40 scored 0.006 and
//! 0.007), and is dropped when neither is. The reference is the one of the
//! first [`REFERENCES`] poses with the lowest total score, and the
//! labelling most poses share relative to it is taken as the detector's
//! own (the file's order on a tie), so that only the poses it altered are
//! relabelled. ChArUco
//! boards, aprilgrids and point lists have unique ids and are left as
//! they are.

use super::pnp::place_target;
use crate::data::CameraObservations;
use crate::measure::camera::Mounting;
use crate::measure::pinhole::Intrinsics;
use crate::model::Robot;
use nalgebra::{Isometry3, Vector3};
use serde::Serialize;

/// How much worse the second-best labelling of a pose must score than the
/// best for the pose to be kept. With the nominal robot's end frames a
/// few millimetres and milliradians off and PnP's noise, the right
/// labelling scores ~1e-3 and a wrong one the angle between two board
/// orientations (≥ 0.1 rad for a board seen from a distinct pose); a
/// factor 3 keeps a clear winner and drops a pose whose relative motion
/// to the reference cannot tell the orders apart.
pub const AMBIGUITY_FACTOR: f64 = 3.0;

/// How many of the first poses are tried as the reference.
pub const REFERENCES: usize = 5;

/// An order of a checkerboard grid's corners relative to the file's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Labelling {
    /// As detected.
    Identity,
    /// The grid turned 180° (both rows and columns reversed).
    Turned,
    /// The rows in reverse order (a board seen from behind).
    RowsMirrored,
    /// The columns in reverse order (a board seen from behind).
    ColumnsMirrored,
}

impl Labelling {
    /// All four.
    pub const ALL: [Labelling; 4] = [
        Labelling::Identity,
        Labelling::Turned,
        Labelling::RowsMirrored,
        Labelling::ColumnsMirrored,
    ];

    /// Its name in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Labelling::Identity => "as detected",
            Labelling::Turned => "turned 180°",
            Labelling::RowsMirrored => "rows mirrored",
            Labelling::ColumnsMirrored => "columns mirrored",
        }
    }

    /// Whether rows, and columns, are reversed.
    fn flips(self) -> (bool, bool) {
        match self {
            Labelling::Identity => (false, false),
            Labelling::Turned => (true, true),
            Labelling::RowsMirrored => (true, false),
            Labelling::ColumnsMirrored => (false, true),
        }
    }

    /// The labelling with the given flips.
    fn of(flips: (bool, bool)) -> Self {
        match flips {
            (false, false) => Labelling::Identity,
            (true, true) => Labelling::Turned,
            (true, false) => Labelling::RowsMirrored,
            (false, true) => Labelling::ColumnsMirrored,
        }
    }

    /// `self` after `other` (each is its own inverse).
    #[must_use]
    pub fn then(self, other: Labelling) -> Labelling {
        let (a, b) = (self.flips(), other.flips());
        Labelling::of((a.0 != b.0, a.1 != b.1))
    }

    /// The index, in a `rows × cols` grid stored row by row, that point
    /// `k`'s pixel is read from.
    #[must_use]
    pub fn source(self, k: usize, rows: usize, cols: usize) -> usize {
        let (fr, fc) = self.flips();
        let (i, j) = (k / cols, k % cols);
        let i = if fr { rows - 1 - i } else { i };
        let j = if fc { cols - 1 - j } else { j };
        i * cols + j
    }
}

impl Serialize for Labelling {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// A pose whose points were relabelled.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Relabelled {
    /// The pose's id.
    pub pose: i64,
    /// The labelling applied.
    pub labelling: Labelling,
}

/// A pose left out, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DroppedPose {
    /// The pose's id.
    pub pose: i64,
    /// Why.
    pub reason: String,
}

/// What [`relabel`] did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Labels {
    /// The poses relabelled.
    pub relabelled: Vec<Relabelled>,
    /// The poses whose labelling could not be told, left out.
    pub dropped: Vec<DroppedPose>,
}

/// The rotation angle and the translation along the rotation's axis of
/// a rigid motion: invariant under conjugation.
fn invariants(m: &Isometry3<f64>) -> (f64, f64) {
    let angle = m.rotation.angle();
    let along = m.rotation.axis().map_or(m.translation.vector.norm(), |a| {
        m.translation.vector.dot(&a).abs()
    });
    (angle, along)
}

/// How far the relative motion `b` of the target is from the robot's `a`
/// (radians, and metres over `length`).
fn mismatch(a: &Isometry3<f64>, b: &Isometry3<f64>, length: f64) -> f64 {
    let (ia, ib) = (invariants(a), invariants(b));
    (ia.0 - ib.0).abs() + (ia.1 - ib.1).abs() / length
}

/// Each pose's `Bᵢ` under each labelling ([`Labelling::ALL`]), `None`
/// where PnP fails.
fn placements(
    intrinsics: &Intrinsics,
    mounting: Mounting,
    points: &[Vector3<f64>],
    (rows, cols): (usize, usize),
    obs: &CameraObservations,
) -> Vec<[Option<Isometry3<f64>>; 4]> {
    obs.seen
        .iter()
        .map(|seen| {
            Labelling::ALL.map(|l| {
                let (pts, px): (Vec<Vector3<f64>>, Vec<[f64; 2]>) = (0..points.len())
                    .filter_map(|k| seen[l.source(k, rows, cols)].map(|p| (points[k], p)))
                    .unzip();
                let p = place_target(intrinsics, &pts, &px).ok()?.pose;
                Some(match mounting {
                    Mounting::EyeToHand => p,
                    Mounting::EyeInHand => p.inverse(),
                })
            })
        })
        .collect()
}

/// A pose's best labelling relative to the reference, its score, the
/// second best's score and labelling (`None`: no labelling placed the
/// target).
type Choice = Option<(Labelling, f64, f64, Option<Labelling>)>;

/// The best labelling of each pose relative to the reference `r`, its
/// score and the second best's, and the total of the best scores.
fn relative(
    a: &[Isometry3<f64>],
    b: &[[Option<Isometry3<f64>>; 4]],
    r: usize,
    length: f64,
) -> Option<(Vec<Choice>, f64)> {
    let br = b[r][0]?;
    let mut total = 0.0;
    let rel = (0..b.len())
        .map(|j| {
            if j == r {
                return Some((Labelling::Identity, 0.0, f64::INFINITY, None));
            }
            let am = a[r].inverse() * a[j];
            let mut s: Vec<(f64, Labelling)> = Labelling::ALL
                .iter()
                .zip(&b[j])
                .filter_map(|(l, bj)| {
                    bj.map(|bj| (mismatch(&am, &(br.inverse() * bj), length), *l))
                })
                .collect();
            s.sort_by(|x, y| x.0.total_cmp(&y.0));
            let (best, l) = *s.first()?;
            total += best;
            let second = s.get(1);
            Some((
                l,
                best,
                second.map_or(f64::INFINITY, |x| x.0),
                second.map(|x| x.1),
            ))
        })
        .collect();
    Some((rel, total))
}

/// Chooses each pose's labelling of a checkerboard's `points` (its
/// inner-corner `grid`, rows × columns, stored row by row) by the robot's
/// motion and relabels `obs` in place; poses whose labelling cannot be told
/// apart are removed (see the module documentation). A target without a
/// grid (ChArUco, aprilgrid, a point list: unique ids) is left as it is.
pub fn relabel(
    robot: &Robot,
    intrinsics: &Intrinsics,
    mounting: Mounting,
    points: &[Vector3<f64>],
    grid: Option<(usize, usize)>,
    obs: &mut CameraObservations,
) -> Labels {
    let Some(grid) = grid else {
        return Labels::default();
    };
    let a = super::end_frames(robot, obs);
    let b = placements(intrinsics, mounting, points, grid, obs);
    let length = crate::units::reach(robot).max(1e-3);
    let Some((rel, _)) = (0..b.len().min(REFERENCES))
        .filter_map(|r| relative(&a, &b, r, length))
        .min_by(|x, y| x.1.total_cmp(&y.1))
    else {
        return Labels::default();
    };
    // The detector's own labelling: the one most poses share, the file's
    // order on a tie.
    let own = Labelling::ALL
        .into_iter()
        .max_by_key(|l| {
            let n = rel.iter().flatten().filter(|x| x.0 == *l).count();
            (n, *l == Labelling::Identity)
        })
        .unwrap_or(Labelling::Identity);
    let mut labels = Labels::default();
    let mut keep = vec![true; obs.seen.len()];
    for (i, r) in rel.iter().enumerate() {
        let Some((l, best, second, runner_up)) = *r else {
            continue;
        };
        let pose = obs.pose_ids[i];
        // Two labellings the motion cannot tell apart, one of them the
        // detector's own: the pose keeps the detector's order (a motion
        // whose invariants are alike for both, not evidence of a flip).
        let own_close = l == own || runner_up == Some(own);
        if second < AMBIGUITY_FACTOR * best && own_close {
            continue;
        }
        if second < AMBIGUITY_FACTOR * best {
            keep[i] = false;
            labels.dropped.push(DroppedPose {
                pose,
                reason: format!(
                    "its points' order cannot be told from the robot's motion: the best labelling ({}) matches it to {best:.3}, the next to {second:.3} (within a factor {AMBIGUITY_FACTOR})",
                    l.then(own).name()
                ),
            });
            continue;
        }
        let fix = l.then(own);
        if fix != Labelling::Identity {
            let seen = &obs.seen[i];
            obs.seen[i] = (0..seen.len())
                .map(|k| seen[fix.source(k, grid.0, grid.1)])
                .collect();
            labels.relabelled.push(Relabelled {
                pose,
                labelling: fix,
            });
        }
    }
    retain(obs, &keep);
    labels
}

/// Keeps the poses of `obs` marked in `keep`.
fn retain(obs: &mut CameraObservations, keep: &[bool]) {
    let mut k = keep.iter();
    obs.qs.retain(|_| *k.next().unwrap_or(&true));
    let mut k = keep.iter();
    obs.pose_ids.retain(|_| *k.next().unwrap_or(&true));
    let mut k = keep.iter();
    obs.seen.retain(|_| *k.next().unwrap_or(&true));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a 3 × 4 grid: each labelling is its own inverse, two of them
    /// compose to the third (the Klein four-group a rectangle's symmetries
    /// form), and turned 180° maps corner 0 to the last, rows mirrored
    /// maps it to the last row's first.
    #[test]
    fn labellings_are_the_rectangles_symmetries() {
        let (rows, cols) = (3, 4);
        for l in Labelling::ALL {
            assert_eq!(l.then(l), Labelling::Identity);
            for k in 0..rows * cols {
                assert_eq!(l.source(l.source(k, rows, cols), rows, cols), k);
            }
        }
        assert_eq!(
            Labelling::RowsMirrored.then(Labelling::ColumnsMirrored),
            Labelling::Turned
        );
        assert_eq!(Labelling::Turned.source(0, rows, cols), 11);
        assert_eq!(Labelling::RowsMirrored.source(0, rows, cols), 8);
        assert_eq!(Labelling::ColumnsMirrored.source(0, rows, cols), 3);
    }
}
