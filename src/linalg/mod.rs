//! The one home of dense kernels: every module that factors, inverts or
//! updates a matrix uses these, and none keeps a copy.
//!
//! - [`chol`]: Cholesky of `p×p` SPD matrices, `ln det`, inverse;
//! - [`small`]: `t×t` block kernels of the rank-t updates (eqs. (17)–(22));
//! - [`gram`]: `M ± XᵀX` on `p×p` slices, `AᵀA` and products;
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
pub mod qr;
pub mod rank;
pub mod simd;
pub mod small;
