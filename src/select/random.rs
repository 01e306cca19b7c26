//! Random design search (paper §V-C): `R` random `N`-pose designs, the best
//! one by `ln OI_D`, and their distribution (the paper's Fig. 2) from a
//! sample of fixed size: memory does not grow with `R`.

use crate::blocks::Blocks;
use crate::criterion::Prior;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

/// Most designs whose values a random search keeps for the distribution
/// (16 bytes each: 2 MiB). Up to this many designs every one is kept; above
/// it every `stride`-th ([`RandomSearch::stride`]).
pub const SAMPLE_CAP: usize = 1 << 17;

/// Designs evaluated in parallel between two sequential passes that update
/// the best design and the sample (one 128 KiB buffer of values).
const BATCH: usize = 1 << 14;

/// Outcome of a random search.
#[derive(Clone, Debug, Serialize)]
pub struct RandomSearch {
    /// Pool positions of the best design (fixed poses first).
    pub best: Vec<usize>,
    /// `ln OI_D` of the best design.
    pub best_ln_oid: f64,
    /// Number of the best design (the lowest on ties).
    pub best_design: usize,
    /// Designs drawn.
    pub designs: usize,
    /// The kept designs are numbers `0, stride, 2·stride, …`: every design
    /// up to [`SAMPLE_CAP`] of them, else a systematic sample of at most
    /// that many. The designs are independent draws, so the sample has the
    /// distribution of all of them.
    pub stride: usize,
    /// `ln OI_D` of every kept design, in design order (`-inf` for a
    /// singular one).
    pub ln_oid: Vec<f64>,
    /// The paper's OI, eq. (1), of every kept design (0 for a singular one).
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
/// With a prior `M0`, the designs are ranked by `ln det(M0 + XᵀX)`
/// ([`crate::criterion::design_ln_det`]).
#[must_use]
pub fn random_search(
    pool: &Blocks,
    prior: Option<&Prior>,
    allowed: &[usize],
    fixed: &[usize],
    n: usize,
    designs: usize,
    seed: u64,
) -> RandomSearch {
    sampled_search(pool, prior, allowed, fixed, n, designs, seed, SAMPLE_CAP)
}

/// The search, keeping at most `cap` designs' values. Designs are evaluated
/// in parallel batches; the best one is then drawn again from its own seed,
/// so no design list is held in memory.
#[allow(clippy::too_many_arguments)]
fn sampled_search(
    pool: &Blocks,
    prior: Option<&Prior>,
    allowed: &[usize],
    fixed: &[usize],
    n: usize,
    designs: usize,
    seed: u64,
    cap: usize,
) -> RandomSearch {
    let stride = designs.div_ceil(cap.max(1)).max(1);
    let mut ln_oid = Vec::with_capacity(designs.div_ceil(stride));
    let (mut best, mut best_ln_oid) = (0, f64::NEG_INFINITY);
    let mut batch = vec![0.0; BATCH.min(designs)];
    for start in (0..designs).step_by(BATCH) {
        let values = &mut batch[..BATCH.min(designs - start)];
        values.par_iter_mut().enumerate().for_each(|(i, v)| {
            let k = (start + i) as u64;
            let d = random_design(&mut design_rng(seed, k), allowed, fixed, n);
            *v = crate::criterion::design_ln_det(pool, prior, &d).unwrap_or(f64::NEG_INFINITY);
        });
        for (i, &v) in values.iter().enumerate() {
            let k = start + i;
            if v > best_ln_oid || k == 0 {
                (best, best_ln_oid) = (k, v);
            }
            if k % stride == 0 {
                ln_oid.push(v);
            }
        }
    }
    let p = pool.p();
    RandomSearch {
        best: random_design(&mut design_rng(seed, best as u64), allowed, fixed, n),
        best_ln_oid,
        best_design: best,
        designs,
        stride,
        oi: ln_oid.iter().map(|&v| oi_from_ln_oid(v, p)).collect(),
        ln_oid,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3-level PUMA pool (729 poses).
    fn pool() -> Blocks {
        let robot = crate::model::Robot::puma560();
        let pool = crate::pool::PoolSpec::lattice(3)
            .build(&robot, &robot.nominal)
            .unwrap();
        pool.jacobian(&robot, &robot.nominal)
    }

    #[test]
    fn the_sample_is_bounded_and_the_best_is_that_of_every_design() {
        let x = pool();
        let all: Vec<usize> = (0..x.n_poses()).collect();
        let full = sampled_search(&x, None, &all, &[], 30, 1000, 5, usize::MAX);
        assert_eq!((full.stride, full.ln_oid.len()), (1, 1000));
        // A cap of 64 keeps every 16th design (1000 / 64 rounded up) ...
        let s = sampled_search(&x, None, &all, &[], 30, 1000, 5, 64);
        assert_eq!((s.stride, s.ln_oid.len()), (16, 63));
        for (j, &v) in s.ln_oid.iter().enumerate() {
            assert_eq!(
                v.to_bits(),
                full.ln_oid[j * 16].to_bits(),
                "design {}",
                j * 16
            );
        }
        // ... and finds the same best design among all of them.
        let max = full
            .ln_oid
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(s.best_ln_oid, max);
        assert_eq!(full.ln_oid[s.best_design], max);
        assert_eq!(
            (s.best.clone(), s.best_design),
            (full.best, full.best_design)
        );
        assert_eq!(
            crate::criterion::design_ln_det(&x, None, &s.best),
            Some(max)
        );
        assert_eq!(s.oi.len(), s.ln_oid.len());
    }
}
