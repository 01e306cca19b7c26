//! Register hygiene after faer/gemm kernels.

/// Clears the upper halves of the vector registers (`vzeroupper`) after a
/// faer/gemm kernel. Some of gemm's x86 AVX-512 micro-kernels return with
/// dirty upper register state; until it is cleared every later SSE
/// instruction of this thread pays a transition penalty (measured: the add
/// scan slowed 10×, `ln` 7×). Cheap; a no-op without AVX.
#[inline]
pub(crate) fn clear_upper_simd_state() {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx")]
        fn zeroupper() {
            core::arch::x86_64::_mm256_zeroupper();
        }
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: AVX support was just checked.
            unsafe { zeroupper() }
        }
    }
}
