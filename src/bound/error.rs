//! Bad input to the relaxation bound: an [`BoundError`] names the offending
//! value. Numerical outcomes (a solver that stalls, a gap above the target)
//! are statuses of the result instead.

use thiserror::Error;

/// Everything that can be wrong with what a caller gave the bound.
#[derive(Debug, Error)]
pub enum BoundError {
    /// More poses requested than the pool has.
    #[error("N = {n} poses requested but the pool has only {pool}")]
    TooManyPoses {
        /// Poses per design requested.
        n: usize,
        /// Poses in the pool.
        pool: usize,
    },
    /// `N·t < p`: no design of `N` poses can determine the unknowns, so every
    /// design is singular (ln OI_D = −∞) and there is nothing to bound.
    #[error(
        "N = {n} poses give N·t = {rows} measurement rows (t = {t}) for p = {p} unknowns: \
         every design is singular; need N ≥ {need}"
    )]
    TooFewRows {
        /// Poses per design requested.
        n: usize,
        /// Rows per pose.
        t: usize,
        /// `n·t`.
        rows: usize,
        /// Unknowns.
        p: usize,
        /// Smallest `N` with `N·t ≥ p`.
        need: usize,
    },
    /// The certified upper bound came out below the primal value it must
    /// bound: a solver or certificate bug, never reported as "certified
    /// with gap 0".
    #[error(
        "internal error: the certificate ln bound {ln_bound} is below the primal ln det {ln_primal} \
         by {excess:.3e} (more than rounding, {tolerance:.1e}); the bound is not valid"
    )]
    CertificateBelowPrimal {
        /// The certificate's value.
        ln_bound: f64,
        /// The primal value.
        ln_primal: f64,
        /// `ln_primal − ln_bound`.
        excess: f64,
        /// The rounding allowance.
        tolerance: f64,
    },
    /// The whole pool does not determine the unknowns: every design is
    /// singular, and the relaxation's optimum is −∞.
    #[error(
        "the pool's Jacobian is rank deficient (numerical rank {rank} of p = {p}; \
         column-scaled eigenvalue ratio {ratio:.3e}): every design is singular"
    )]
    RankDeficient {
        /// Numerical rank of the column-scaled pool Jacobian.
        rank: usize,
        /// Unknowns.
        p: usize,
        /// Smallest over largest eigenvalue of the column-scaled Gram matrix.
        ratio: f64,
    },
    /// A NaN or infinite Jacobian entry.
    #[error("the Jacobian entry at row {row}, column {col} is not finite ({value})")]
    NonFinite {
        /// Row of the stacked Jacobian.
        row: usize,
        /// Column (unknown).
        col: usize,
        /// The value.
        value: f64,
    },
    /// A setting outside its valid range.
    #[error("invalid bound setting {name} = {value}: {reason}")]
    InvalidSetting {
        /// Name of the setting.
        name: &'static str,
        /// Its value, as text.
        value: String,
        /// What the valid range is.
        reason: &'static str,
    },
    /// A design that does not fit the pool or the bound it is compared to.
    #[error("invalid design: {0}")]
    InvalidDesign(String),
    /// A weight vector of the wrong length or outside `0 ≤ w`.
    #[error("invalid weights: {0}")]
    InvalidWeights(String),
    /// Bad input found by the rest of the crate (robot, pool, design file).
    #[error(transparent)]
    Input(#[from] crate::Error),
}

/// `Ok` when a setting is finite and positive, else
/// [`BoundError::InvalidSetting`] naming it.
pub(crate) fn positive(name: &'static str, v: f64) -> Result<(), BoundError> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(BoundError::InvalidSetting {
            name,
            value: v.to_string(),
            reason: "must be finite and > 0",
        })
    }
}
