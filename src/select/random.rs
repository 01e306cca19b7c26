//! Random design search (paper §V-C): `R` random `N`-pose designs, the best
//! one by `ln OI_D`, and the whole distribution (the paper's Fig. 2).

use crate::blocks::Blocks;
use crate::criterion::Prior;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

/// Outcome of a random search.
#[derive(Clone, Debug, Serialize)]
pub struct RandomSearch {
    /// Pool positions of the best design (fixed poses first).
    pub best: Vec<usize>,
    /// `ln OI_D` of the best design.
    pub best_ln_oid: f64,
    /// `ln OI_D` of every design, in design order (`-inf` for a singular one).
    pub ln_oid: Vec<f64>,
    /// The paper's OI, eq. (1), of every design (0 for a singular one).
    pub oi: Vec<f64>,
}

/// The RNG of design `k` of a search seeded with `seed`: one ChaCha stream
/// per design, so the designs do not depend on the number of threads.
#[must_use]
pub fn design_rng(seed: u64, k: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(k);
    rng
}

/// `n − fixed.len()` distinct pool positions drawn uniformly from `allowed`
/// (pool positions that are not fixed), appended to `fixed`.
pub fn random_design(
    rng: &mut ChaCha8Rng,
    allowed: &[usize],
    fixed: &[usize],
    n: usize,
) -> Vec<usize> {
    let mut d = fixed.to_vec();
    let k = n - fixed.len();
    d.extend(
        rand::seq::index::sample(rng, allowed.len(), k)
            .into_iter()
            .map(|i| allowed[i]),
    );
    d
}

/// `ln det(XᵀX)` of a design by Cholesky of its equilibrated form, or
/// `None` when it is singular by the rank rule every command shares
/// ([`crate::linalg::rank`]: condition number of the equilibrated `XᵀX` at
/// least [`MAX_CONDITION`](crate::linalg::rank::MAX_CONDITION)), so a unit
/// change of a column changes no verdict.
#[must_use]
pub fn ln_det_direct(pool: &Blocks, poses: &[usize]) -> Option<f64> {
    use crate::linalg::rank::{MAX_CONDITION, ln_det_regular};
    ln_det_regular(pool.information(poses).as_ref(), MAX_CONDITION)
}

/// `ln det(M0 + XᵀX)` of a design on top of a prior (`ln det XᵀX`
/// without one), or `None` when it is not positive definite.
#[must_use]
pub fn ln_det_with_prior(pool: &Blocks, prior: Option<&Prior>, poses: &[usize]) -> Option<f64> {
    match prior {
        None => ln_det_direct(pool, poses),
        Some(pr) => {
            let m = pool.information(poses) + pr.matrix();
            crate::linalg::chol::ln_det_spd(m.as_ref())
        }
    }
}

/// The paper's OI, eq. (1), from `ln OI_D` of a full-rank design with `p`
/// unknowns: `OI = exp(ln OI_D / (2p)) / p`, since `OI_D = ((OI·L)^L)²`.
#[must_use]
pub fn oi_from_ln_oid(ln_oid: f64, p: usize) -> f64 {
    if ln_oid.is_finite() {
        (ln_oid / (2.0 * p as f64)).exp() / p as f64
    } else {
        0.0
    }
}

/// Draws `designs` random `n`-pose designs (each containing `fixed`, the
/// rest from `allowed`) in parallel and keeps the best. Deterministic for a
/// seed whatever the thread count; ties go to the lowest design number.
#[must_use]
pub fn random_search(
    pool: &Blocks,
    allowed: &[usize],
    fixed: &[usize],
    n: usize,
    designs: usize,
    seed: u64,
) -> RandomSearch {
    random_search_with_prior(pool, None, allowed, fixed, n, designs, seed)
}

/// [`random_search`] with the designs ranked by `ln det(M0 + XᵀX)`
/// ([`ln_det_with_prior`]).
#[must_use]
pub fn random_search_with_prior(
    pool: &Blocks,
    prior: Option<&Prior>,
    allowed: &[usize],
    fixed: &[usize],
    n: usize,
    designs: usize,
    seed: u64,
) -> RandomSearch {
    let p = pool.p();
    // Only the values are kept (8 bytes a design); the best design is drawn
    // again from its own seed, so no design list is held in memory.
    let ln_oid: Vec<f64> = (0..designs)
        .into_par_iter()
        .map(|k| {
            let d = random_design(&mut design_rng(seed, k as u64), allowed, fixed, n);
            ln_det_with_prior(pool, prior, &d).unwrap_or(f64::NEG_INFINITY)
        })
        .collect();
    let mut best = 0;
    for (k, &v) in ln_oid.iter().enumerate() {
        if v > ln_oid[best] {
            best = k;
        }
    }
    RandomSearch {
        best: random_design(&mut design_rng(seed, best as u64), allowed, fixed, n),
        best_ln_oid: ln_oid[best],
        oi: ln_oid.iter().map(|&v| oi_from_ln_oid(v, p)).collect(),
        ln_oid,
    }
}
