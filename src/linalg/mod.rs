//! The one home of dense kernels: every module that factors, inverts or
//! updates a matrix uses these, and none keeps a copy.
//!
//! - [`chol`]: Cholesky of `p×p` SPD matrices, `ln det`, inverse;
//! - [`small`]: `t×t` block kernels of the rank-t updates (eqs. (17)–(22));
//! - [`gram`]: `M ± XᵀX` on `p×p` slices, `AᵀA` and products;
//! - [`log`]: a vectorised `ln` over slices (the add-gain scan's one `ln`);
//! - [`qr`]: Householder QR, least squares and `(XᵀX)⁻¹` for identification;
//! - [`eigen`]: eigenvalues and singular values;
//! - [`rank`]: the one rank and conditioning rule, on the column-scaled
//!   (equilibrated) problem, that every command decides by;
//! - [`simd`]: register hygiene after faer's kernels;
//! - [`blas`]: the system BLAS kept on one thread.
//!
//! Every kernel is sequential, so a result never depends on the thread
//! count.
// `!(x > floor)` is deliberate: it is true for NaN, which must fail too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod blas;
pub mod chol;
pub mod eigen;
pub mod gram;
pub mod log;
pub mod qr;
pub mod rank;
pub mod simd;
pub mod small;

/// Random test data for the unit tests of every layer.
#[cfg(test)]
pub(crate) mod test_rng {
    /// A deterministic uniform draw in [−1, 1) (64-bit LCG), independent of
    /// the rand crate's streams.
    pub(crate) fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}
