//! Random test data shared by the module's unit tests.

use crate::blocks::Blocks;
use faer::Mat;

pub(crate) use crate::linalg::test_rng::lcg;

/// A pool of `n` random `t × p` blocks.
pub(crate) fn random_pool(n: usize, t: usize, p: usize, seed: u64) -> Blocks {
    let mut s = seed;
    Blocks::new(Mat::from_fn(n * t, p, |_, _| lcg(&mut s)), t)
}
