//! Contact designs on the common criterion and exchange: the configurations
//! of a socket pool ([`SocketPool`], its Jacobian as [`Blocks`]) chosen
//! D-optimally by [`multistart`] with [`DCriterion`] (the known distances'
//! information `CᵀC` as the prior every design adds to), then exchanged for
//! a predicted error `tr(M⁻¹W)` by the Fedorov [`polish`] with the linear
//! criterion [`ICriterion`]; and the whole design for sockets at given
//! positions ([`socket_design`]).

use crate::blocks::Blocks;
use crate::criterion::{DCriterion, ICriterion};
use crate::error::Result;
use crate::identify::contact::select::{SocketPool, consistency_moment};
use crate::select::{Algorithm, Settings, default_ils_rounds, multistart, polish};
use nalgebra::DMatrix;
use serde::Serialize;

pub mod socket_design;

/// How a contact design searches: the seed of its random starts and kicks
/// and its rounds of iterated local search. Deterministic for a seed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct ContactSearch {
    /// Seed of every random choice of the exchange (default 1).
    pub seed: u64,
    /// Rounds of iterated local search after the exchange-add-exchange
    /// climb ([`Settings::ils`]); `None` (the default) takes
    /// [`default_ils_rounds`] of the pool.
    pub ils: Option<usize>,
}

impl Default for ContactSearch {
    fn default() -> Self {
        Self { seed: 1, ils: None }
    }
}

/// The common selection's settings for `n` configurations of `pool` with
/// the search `s`: one start, the pool's known distances as the prior.
fn settings(pool: &SocketPool, n: usize, s: &ContactSearch) -> Result<Settings> {
    let n_pool = pool.blocks.n_poses();
    Settings::builder()
        .n(n)
        .initial(n.min(Settings::default().initial))
        .seed(s.seed)
        .ils(
            s.ils
                .unwrap_or_else(|| default_ils_rounds(n_pool, pool.blocks.t())),
        )
        .prior(pool.prior())
        .build()
}

/// `n` configurations of the pool with the largest `ln det M`
/// (`M = CᵀC + XᵀX`): exchange-add-exchange from a random start, then
/// iterated local search ([`ContactSearch`]), by the common exchange with
/// [`DCriterion`]. Errors when `n` exceeds the pool or every design is
/// singular.
pub fn select_d_optimal(pool: &SocketPool, n: usize, s: &ContactSearch) -> Result<Vec<usize>> {
    let settings = settings(pool, n, s)?;
    Ok(multistart(&pool.blocks, DCriterion::new, Algorithm::Eae, &settings)?.poses)
}

/// `design` improved by Fedorov exchanges that lower `tr(M⁻¹ W)` for the
/// moment `w` (the I-optimal criterion of [`predicted_error`], as
/// [`ICriterion`]) until no exchange lowers it.
///
/// [`predicted_error`]: crate::identify::contact::select::predicted_error
pub fn refine_for(
    pool: &SocketPool,
    design: &[usize],
    w: &DMatrix<f64>,
    s: &ContactSearch,
) -> Result<Vec<usize>> {
    let settings = settings(pool, design.len(), s)?;
    let start = start_selection(&pool.blocks, design, &settings);
    Ok(polish(&pool.blocks, &mut ICriterion::new(w), start, &settings)?.poses)
}

/// [`refine_for`] with the pool's [`consistency_moment`].
pub fn refine_for_consistency(
    pool: &SocketPool,
    design: &[usize],
    s: &ContactSearch,
) -> Result<Vec<usize>> {
    refine_for(pool, design, &consistency_moment(pool), s)
}

/// `design` as a finished selection (the D criterion's record of it), for
/// [`polish`] to continue from.
fn start_selection(x: &Blocks, design: &[usize], s: &Settings) -> crate::select::Selection {
    let ln_oid =
        crate::criterion::design_ln_det(x, s.prior.as_ref(), design).unwrap_or(f64::NEG_INFINITY);
    crate::select::Selection {
        poses: design.to_vec(),
        ln_oid,
        oi: crate::select::oi_from_ln_oid(ln_oid, x.p()),
        trace: Vec::new(),
        algorithm: Algorithm::Fedorov,
        criterion: "D".into(),
        score: ln_oid,
        start: 0,
        start_ln_oid: vec![ln_oid],
        start_score: vec![ln_oid],
    }
}
