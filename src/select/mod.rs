//! Pose selection: random search, DETMAX, Fedorov exchange and the paper's
//! exchange-add-exchange (§IV, §V-D), written once against the
//! [`Criterion`](crate::criterion::Criterion) trait so the determinant
//! criterion and the eigenvalue OI run through the same code.
//!
//! Every algorithm works on pool positions (rows of the pool's [`Blocks`]);
//! poses removed by the pool's visibility filter are not in the pool, so they
//! are never chosen. Fixed poses are in every design and never removed.
//!
//! # Prior information
//!
//! With [`Settings::prior`] (`M0`, the information of poses measured
//! before), every state is `M = M0 + XᵀX` and every algorithm maximises
//! `ln det(M0 + XᵀX)`: the `N` poses that add the most to what is already
//! known. A design that is singular on its own may then be regular.
//!
//! # Starting below full rank
//!
//! When the initial design has too few rows for a non-singular `M`
//! (`n0·t < p`, or degenerate poses), the state starts with a small ridge
//! `M = XᵀX + δ·diag(r_j)`, `δ = 10⁻⁸`, `r_j = ‖X_pool[:, j]‖²/n_pool` the
//! mean information of column `j` per pool pose (a relative size far below
//! any eigenvalue a full-rank design has, yet enough to factor; per column,
//! so that a unit change of one column scales its ridge with it and changes
//! no decision). The ridge is dropped as soon as the design is non-singular
//! without it (tried after every add step), so every reported value of a
//! finished design is the ridge-free `ln det XᵀX`; trace rows taken while the
//! ridge was on carry `ridge: true`.

use crate::blocks::Blocks;
use crate::criterion::{DCriterion, OiCriterion, Prior};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

pub mod camera;
pub mod contact;
mod exchange;
pub mod moves;
mod random;
pub mod refine;
pub mod swap;
pub mod tour;
pub mod turns;

pub use exchange::{Selection, detmax, eae, fedorov, multistart, polish};
pub use random::{
    RandomSearch, SAMPLE_CAP, design_rng, oi_from_ln_oid, random_design, random_search,
};
pub use refine::{RefineSettings, Refinement, refine};

/// The selection algorithms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Algorithm {
    /// The paper's exchange-add-exchange (§IV).
    Eae,
    /// Fedorov exchange from a random `N`-pose design.
    Fedorov,
    /// DETMAX (Mitchell 1974) as the paper's §II describes it.
    Detmax,
    /// Best of many random designs (§V-C).
    Random,
}

crate::choice!(Algorithm { Eae => "eae", Fedorov => "fedorov", Detmax => "detmax", Random => "random" });

/// The criterion a selection maximises.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum CriterionKind {
    /// `ln OI_D = ln det M`, priced by O(p²) updates ([`DCriterion`]).
    #[default]
    Det,
    /// The paper's eigenvalue OI, eq. (1), recomputed ([`OiCriterion`]).
    Oi,
}

crate::choice!(CriterionKind { Det => "det", Oi => "oi" });

/// [`multistart`] with the criterion `kind`.
pub fn select(
    pool: &Blocks,
    kind: CriterionKind,
    algorithm: Algorithm,
    s: &Settings,
) -> Result<Selection> {
    match kind {
        CriterionKind::Det => multistart(pool, DCriterion::new, algorithm, s),
        CriterionKind::Oi => multistart(pool, OiCriterion::new, algorithm, s),
    }
}

/// Rounds of iterated local search ([`Settings::ils`]) that `select` runs
/// when none are asked for: 12 on the paper's PUMA pool (15,625 poses,
/// `t = 3`), fewer as a round's work grows (each round prices exchanges
/// over the whole pool, `O(n_pool·t³)`), and none where fewer than two
/// would fit (from about 9·10⁴ point poses, and on full-pose pools of
/// 15,625): there the modified-Fedorov climb that precedes the rounds costs
/// seconds (`ur5:pose`: 3.2 s with one round against 0.28 s without, for
/// +0.12 in ln det). Measured on this project's 2-core machine: 12 rounds
/// keep the PUMA selection under a second.
#[must_use]
pub fn default_ils_rounds(n_pool: usize, t: usize) -> usize {
    const BUDGET: usize = 12 * 15_625 * 27;
    let work = n_pool.max(1).saturating_mul(t.max(1).pow(3));
    // Below two rounds the climb that precedes them is most of the cost
    // and the gain is small: none.
    match BUDGET / work {
        0 | 1 => 0,
        r => r.min(12),
    }
}

/// Settings of a selection run: build with [`Settings::builder`] (validated
/// without a pool) or take [`Settings::default`]; the algorithms check them
/// against their pool with [`Settings::validate_for`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct Settings {
    /// Poses in the final design, `N` (default 30).
    pub n: usize,
    /// Initial random poses of EAE, `n0` (default 12), fixed poses included.
    pub initial: usize,
    /// Independent random starts; the best design is kept (default 1).
    pub starts: usize,
    /// Random designs drawn by [`Algorithm::Random`] (default 5,000).
    pub designs: usize,
    /// Follow the best start by a Fedorov polish (default false).
    pub polish: bool,
    /// Rounds of iterated local search after each start's algorithm
    /// (default 0: the algorithm alone, as the paper runs it). With `k > 0`
    /// each start climbs to a local optimum of single exchanges (modified
    /// Fedorov), then `k` times exchanges [`kick`](Self::kick) random design
    /// poses, climbs again and keeps the better design: this is what gets
    /// past the local optima where EAE and Fedorov stop (see docs/bound.md's
    /// "Selection quality").
    pub ils: usize,
    /// Design poses exchanged at random per round of [`ils`](Self::ils)
    /// (default 3).
    pub kick: usize,
    /// Seed of every random choice (default 1).
    pub seed: u64,
    /// Pool positions that every design contains and no step removes.
    pub fixed: Vec<usize>,
    /// Largest number of exchange (or excursion) iterations per phase
    /// (default 1,000).
    pub max_iter: usize,
    /// Information already measured, `M0` (default none): the search then
    /// maximises `ln det(M0 + XᵀX)` and every reported `ln OI_D` includes
    /// `M0`. Not serialised (a report names its source instead).
    #[serde(skip)]
    pub prior: Option<Prior>,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            n: 30,
            initial: 12,
            starts: 1,
            designs: 5000,
            polish: false,
            ils: 0,
            kick: 3,
            seed: 1,
            fixed: Vec::new(),
            max_iter: 1000,
            prior: None,
        }
    }
}

crate::settings::settings_builder! {
    /// Validated construction of [`Settings`] (the checks that need no pool).
    SettingsBuilder for Settings, error Error {
        /// Poses in the final design, `N` (default 30; `initial` must not
        /// exceed it).
        n: usize,
        /// Initial random poses of EAE, `1..=N` (default 12).
        initial: usize,
        /// Independent random starts (default 1).
        starts: usize,
        /// Random designs of [`Algorithm::Random`] (default 5,000).
        designs: usize,
        /// A Fedorov polish of the best start (default false).
        polish: bool,
        /// Rounds of iterated local search per start (default 0).
        ils: usize,
        /// Poses exchanged per round of iterated local search (default 3).
        kick: usize,
        /// Seed of every random choice (default 1).
        seed: u64,
        /// Pool positions every design contains (default none).
        fixed: Vec<usize>,
        /// Most exchange iterations per phase (default 1,000).
        max_iter: usize,
        /// Information already measured, `M0` (default none).
        prior: Option<Prior>,
    }
}

impl Settings {
    /// Checks the fields that need no pool: at least one start, design and
    /// iteration, a kick with iterated local search, `initial` in `1..=N`,
    /// fixed poses unique and no more of them than `N`.
    pub fn validate(&self) -> Result<()> {
        crate::io::design::check_unique(&self.fixed)?;
        if self.fixed.len() > self.n {
            return Err(Error::Invalid(format!(
                "{} fixed poses do not fit in a design of N = {}",
                self.fixed.len(),
                self.n
            )));
        }
        if self.starts == 0 || self.designs == 0 || self.max_iter == 0 {
            return Err(Error::Invalid(
                "starts, designs and max_iter must be at least 1".into(),
            ));
        }
        if self.ils > 0 && self.kick == 0 {
            return Err(Error::Invalid(
                "kick must be at least 1 when ils rounds are asked for".into(),
            ));
        }
        if self.initial == 0 || self.initial > self.n {
            return Err(Error::Invalid(format!(
                "the initial design size must be in 1..=N, got {}",
                self.initial
            )));
        }
        Ok(())
    }

    /// Checks the settings ([`Settings::validate`]) and then against a pool:
    /// `N` within the pool, `N·t ≥ p`, fixed poses in the pool.
    pub fn validate_for(&self, pool: &Blocks) -> Result<()> {
        let (n_pool, t, p) = (pool.n_poses(), pool.t(), pool.p());
        if n_pool == 0 {
            return Err(Error::Invalid("the pose pool is empty".into()));
        }
        if self.n > n_pool {
            return Err(Error::Invalid(format!(
                "N = {} is larger than the pool ({n_pool} poses)",
                self.n
            )));
        }
        if let Some(pr) = &self.prior
            && pr.p() != p
        {
            return Err(Error::Invalid(format!(
                "the prior information is for {} unknowns, the pool has {p}",
                pr.p()
            )));
        }
        // With a prior, fewer new rows than unknowns may do: the state
        // refuses a design that is singular even with M0.
        if self.n * t < p && self.prior.is_none() {
            return Err(Error::Invalid(format!(
                "N = {} poses give {} measurement rows, fewer than the {p} unknowns: every design would be singular (need N >= {})",
                self.n,
                self.n * t,
                p.div_ceil(t)
            )));
        }
        if let Some(&f) = self.fixed.iter().find(|&&f| f >= n_pool) {
            return Err(Error::PoseNotInPool {
                index: f,
                reason: format!("pool position {f} >= pool size {n_pool}"),
            });
        }
        self.validate()
    }
}

/// Kind of a step in a trace.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StepKind {
    /// The initial design.
    Init,
    /// A pose exchanged for another (EAE exchange step, Fedorov).
    Exchange,
    /// A pose added.
    Add,
    /// A pose removed.
    Remove,
    /// The ridge of a rank-deficient start dropped.
    DropRidge,
}

/// One row of a trace (the paper's Fig. 4–6): the state after a step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TraceRow {
    /// Step number, 0 for the initial design.
    pub step: usize,
    /// What the step did.
    pub kind: StepKind,
    /// Pool position of the pose added, if any.
    pub added: Option<usize>,
    /// Pool position of the pose removed, if any.
    pub removed: Option<usize>,
    /// Design size after the step.
    pub size: usize,
    /// `ln OI_D = ln det M` after the step (ridge included while `ridge`).
    pub ln_oid: f64,
    /// The paper's OI, eq. (1), after the step.
    pub oi: f64,
    /// Whether the ridge of a rank-deficient start was still on.
    pub ridge: bool,
}
