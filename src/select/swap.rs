//! A design pose exchanged for another of the pool, ranked by what the
//! design keeps: when a tour cannot leave (or reach) a pose without a
//! collision, the pose is replaced by the pool pose that loses the least
//! `ln OI_D`, among those whose moves are free.
//!
//! The ranking prices every candidate `c` by the matrix determinant lemma
//! on the design without the pose, `M₋ = M0 + Σ_{i≠k} X_iᵀX_i`:
//! `ln det(M₋ + X_cᵀX_c) = ln det M₋ + ln det(I + X_c M₋⁻¹ X_cᵀ)`, with
//! `M₋ = L Lᵀ` factored once (a ridge of 1e-12 of its mean diagonal when the
//! design without the pose is singular): `O(p²t)` a candidate.

use crate::blocks::Blocks;
use crate::collision::ContactPair;
use crate::criterion::Prior;
use nalgebra::DMatrix;
use serde::Serialize;

/// Pool positions of the `tries` best replacements of `design[k]` (not in
/// the design), best first, each with the design's `ln OI_D` after the
/// exchange (`ln det(M0 + XᵀX)` with a prior). Empty when the pool has no
/// other pose.
#[must_use]
pub fn ranked_replacements(
    x: &Blocks,
    prior: Option<&Prior>,
    design: &[usize],
    k: usize,
    tries: usize,
) -> Vec<(usize, f64)> {
    let p = x.p();
    let rest: Vec<usize> = design
        .iter()
        .enumerate()
        .filter(|&(j, _)| j != k)
        .map(|(_, &i)| i)
        .collect();
    let info = x.information(&rest);
    let mut m = DMatrix::from_fn(p, p, |r, c| info[(r, c)]);
    if let Some(pr) = prior {
        let m0 = pr.matrix();
        m += DMatrix::from_fn(p, p, |r, c| m0[(r, c)]);
    }
    let ridge = 1e-12 * m.trace() / p as f64;
    let Some(l) = m
        .clone()
        .cholesky()
        .or_else(|| (m + DMatrix::identity(p, p) * ridge).cholesky())
    else {
        return Vec::new();
    };
    let ln_det_rest: f64 = 2.0 * l.l().diagonal().iter().map(|d| d.ln()).sum::<f64>();
    let mut scored: Vec<(usize, f64)> = (0..x.n_poses())
        .filter(|i| !design.contains(i))
        .map(|i| {
            let b = x.block(i);
            let bt = DMatrix::from_fn(p, b.nrows(), |r, c| b[(c, r)]);
            let y = l.l().solve_lower_triangular(&bt).unwrap_or(bt);
            let s = DMatrix::identity(b.nrows(), b.nrows()) + y.transpose() * y;
            let gain = s.cholesky().map_or(f64::NEG_INFINITY, |c| {
                2.0 * c.l().diagonal().iter().map(|d| d.ln()).sum::<f64>()
            });
            (i, ln_det_rest + gain)
        })
        .collect();
    scored.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    scored.truncate(tries);
    scored
}

/// A design pose the tour could not leave or reach without a collision,
/// exchanged for a pool pose whose moves are free.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SwappedPose {
    /// Position in the visiting order (0-based) of the pose replaced.
    pub pose: usize,
    /// Pool id of the pose removed.
    pub removed_id: usize,
    /// Pool id of the pose that replaces it.
    pub added_id: usize,
    /// The design's `ln OI_D` before the exchange.
    pub ln_oid_before: f64,
    /// The design's `ln OI_D` after it.
    pub ln_oid_after: f64,
    /// What the colliding move touched.
    pub pair: ContactPair,
}
