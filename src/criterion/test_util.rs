//! Random test data shared by the module's unit tests.

use crate::blocks::Blocks;
use faer::Mat;

/// A deterministic uniform draw in [−1, 1) (64-bit LCG), independent of the
/// rand crate's streams.
pub(crate) fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// A pool of `n` random `t × p` blocks.
pub(crate) fn random_pool(n: usize, t: usize, p: usize, seed: u64) -> Blocks {
    let mut s = seed;
    Blocks::new(Mat::from_fn(n * t, p, |_, _| lcg(&mut s)), t)
}
