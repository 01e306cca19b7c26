//! The bound–gap report of one design: its `ln OI_D`, the bound, the
//! D-efficiency
//!
//! `eff_D = exp((ln det M_design − ln_bound) / p) ≤ (det M_design / det M*)^{1/p} ≤ 1`   (G)
//!
//! (a certified lower bound on the design's true D-efficiency against the
//! relaxation optimum `M*`, since `ln_bound ≥ ln det M*`), and which of its
//! poses carry relaxation weight.

use super::variance::information;
use super::{Bound, BoundError, BoundStatus};
use crate::blocks::Blocks;
use crate::criterion::Prior;
pub use crate::criterion::design_ln_det;
use crate::linalg::chol::ln_det_spd_equilibrated;

use serde::Serialize;

/// Relaxation weight above which a design pose is reported as weighted.
pub const WEIGHT_TOL: f64 = 1e-3;

/// The gap of one design to the relaxation bound.
#[derive(Clone, Debug, Serialize)]
pub struct DesignGap {
    /// Poses in the design.
    pub n: usize,
    /// Unknowns.
    pub p: usize,
    /// `ln det M_design` (`ln det(M0 + M_design)` with a prior); `None`
    /// when the design is singular.
    pub ln_oid: Option<f64>,
    /// `log10 det M_design`; `None` when singular.
    pub log10_oid: Option<f64>,
    /// The bound on `ln OI_D` of every `n`-pose design.
    pub ln_bound: f64,
    /// `log10` of the bound.
    pub log10_bound: f64,
    /// D-efficiency (eq. G), in `[0, 1]`; 0 for a singular design.
    pub d_efficiency: f64,
    /// Status of the bound.
    pub bound_status: BoundStatus,
    /// The bound's own certificate gap (ln det).
    pub certificate_gap: f64,
    /// Positions (in the design's pose list) of the poses whose relaxation
    /// weight exceeds [`WEIGHT_TOL`].
    pub weighted: Vec<usize>,
    /// The relaxation weight of every design pose, in design order.
    pub weights: Vec<f64>,
}

/// A design's D-efficiency against a bound on `p` unknowns:
/// `(OI_D / bound)^(1/p) = exp((ln OI_D − ln bound) / p)`, the fraction of
/// the best possible per-parameter information (1 at the bound); 0 for a
/// singular design (`ln_oid = None`). The one place this formula lives.
#[must_use]
pub fn d_efficiency(ln_oid: Option<f64>, ln_bound: f64, p: usize) -> f64 {
    ln_oid.map_or(0.0, |l| ((l - ln_bound) / p as f64).exp())
}

/// The gap report of a design (pool positions) against the bound for its
/// size. Errors when the design's size differs from the bound's `n`, a
/// position is outside the pool, or a pose repeats.
///
/// With prior information (`prior`), the design's `ln det(M0 + Σ X_iᵀX_i)`
/// against a bound computed with the same prior
/// ([`super::relaxation_bound`]); a bound made with a prior used without
/// one, or the reverse, is an error.
pub fn design_gap(
    x: &Blocks,
    prior: Option<&Prior>,
    design: &[usize],
    bound: &Bound,
) -> Result<DesignGap, BoundError> {
    if prior.is_some() != bound.with_prior {
        return Err(BoundError::InvalidDesign(format!(
            "the bound was computed {} prior information, the design is scored {} it",
            if bound.with_prior { "with" } else { "without" },
            if prior.is_some() { "with" } else { "without" },
        )));
    }
    if design.len() != bound.n {
        return Err(BoundError::InvalidDesign(format!(
            "the design has {} poses, the bound is for N = {}",
            design.len(),
            bound.n
        )));
    }
    if x.n_poses() != bound.pool_size || x.p() != bound.p {
        return Err(BoundError::InvalidDesign(format!(
            "the bound is for a pool of {} poses and {} unknowns, the Jacobian has {} and {}",
            bound.pool_size,
            bound.p,
            x.n_poses(),
            x.p()
        )));
    }
    let mut seen = vec![false; x.n_poses()];
    for &i in design {
        if i >= x.n_poses() {
            return Err(BoundError::InvalidDesign(format!(
                "pose position {i} is outside the pool of {} poses",
                x.n_poses()
            )));
        }
        if std::mem::replace(&mut seen[i], true) {
            return Err(BoundError::InvalidDesign(format!(
                "pose position {i} appears more than once"
            )));
        }
    }
    let ln_oid = design_ln_det(x, prior, design);
    let d_efficiency = d_efficiency(ln_oid, bound.ln_bound, bound.p);
    let weights: Vec<f64> = design.iter().map(|&i| bound.weights[i]).collect();
    Ok(DesignGap {
        n: design.len(),
        p: bound.p,
        ln_oid,
        log10_oid: ln_oid.map(|l| l / std::f64::consts::LN_10),
        ln_bound: bound.ln_bound,
        log10_bound: bound.log10_bound(),
        d_efficiency,
        bound_status: bound.status,
        certificate_gap: bound.certificate_gap,
        // `>` or `≥` differ only for a weight exactly equal to WEIGHT_TOL
        // (an equivalent mutant for cargo-mutants: no solver lands there).
        weighted: (0..design.len())
            .filter(|&k| weights[k] > WEIGHT_TOL)
            .collect(),
        weights,
    })
}

/// `ln det M(w)` of relaxation weights on a pool (unscaled), or `None` if
/// singular. For checks and reports.
#[must_use]
pub fn weights_ln_det(x: &Blocks, w: &[f64]) -> Option<f64> {
    ln_det_spd_equilibrated(information(x, w).as_ref())
}
