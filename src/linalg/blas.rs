//! The system BLAS (OpenBLAS, linked for Clarabel's PSD cones), kept on one
//! thread.
//!
//! Clarabel's BLAS calls are small (`p(p+1)/2`-sized cone blocks, p ≈ 30),
//! where OpenBLAS's worker threads cost more than they give: an idle worker
//! spins in `sched_yield` and took 38 % of the Clarabel bound's profile on
//! this 2-core machine (with `OPENBLAS_NUM_THREADS=1` the bound used 42 %
//! less CPU). OpenBLAS reads that variable when the library loads, before
//! `main`, so the library sets the thread count itself before the first
//! solve.

use std::os::raw::c_int;
use std::sync::Once;

unsafe extern "C" {
    /// OpenBLAS's run-time thread count (exported by libopenblas).
    fn openblas_set_num_threads(n: c_int);
}

/// Sets OpenBLAS to one thread, once per process.
pub(crate) fn single_threaded() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // SAFETY: a plain setter of OpenBLAS's global thread count, called
        // once, before any BLAS call of this crate's solvers.
        unsafe { openblas_set_num_threads(1) }
    });
}
