//! A natural logarithm over slices that the compiler vectorises: the
//! add-gain scan takes one `ln` per candidate (eq. (20)), and the scalar
//! libm call, which no compiler vectorises, was most of its cost.
//!
//! The algorithm is fdlibm's `__ieee754_log` (Sun Microsystems, 1993; the
//! one in musl and FreeBSD's libm): `x = 2^k·(1+f)` with
//! `√2/2 ≤ 1+f < √2`, `s = f/(2+f)`, and
//! `ln(1+f) = f − s·(f − R(s²))` with a degree-14 minimax polynomial `R`
//! (error below 2^-58.45), so the result is within 1 ulp of the exact
//! logarithm. It is written without branches (selects only), with the
//! exponent read and written through the bits, so that a loop over a slice
//! becomes SIMD code. Only positive normal finite inputs take this path;
//! zero, negative, subnormal, infinite and NaN inputs get `f64::ln`.

/// `ln 2` split as fdlibm does: `LN2_HI` has its low 32 bits zero, so
/// `k·LN2_HI` is exact for every exponent `k`.
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
/// The rest of `ln 2` below [`LN2_HI`].
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// fdlibm's minimax coefficients of `R(z) = Lg1·z + … + Lg7·z⁷`, as
/// e_log.c gives them in hexadecimal.
const LG: [f64; 7] = [
    f64::from_bits(0x3fe5_5555_5555_5593), // 6.666666666666735130e-01
    f64::from_bits(0x3fd9_9999_9997_fa04), // 3.999999999940941908e-01
    f64::from_bits(0x3fd2_4924_9422_9359), // 2.857142874366239149e-01
    f64::from_bits(0x3fcc_71c5_1d8e_78af), // 2.222219843214978396e-01
    f64::from_bits(0x3fc7_4664_96cb_03de), // 1.818357216161805012e-01
    f64::from_bits(0x3fc3_9a09_d078_c69f), // 1.531383769920937332e-01
    f64::from_bits(0x3fc2_f112_df3e_5244), // 1.479819860511658591e-01
];

/// `1.mantissa` at the high word 0x6147a: from here e_log.c's first form.
const FORM_LO: f64 = f64::from_bits(0x3ff6_147a_0000_0000);
/// `1.mantissa` just above the high word 0x6b851: the first form's end.
const FORM_HI: f64 = f64::from_bits(0x3ff6_b852_0000_0000);
/// Mask of an `f64`'s 52 mantissa bits.
const MANTISSA: u64 = (1 << 52) - 1;
/// `2^52` as bits: `from_bits(EXP_MAGIC | e) − 2^52 = e` exactly for
/// `e < 2^52`, an integer-to-float conversion that needs no SIMD convert
/// instruction (SSE2 has none for 64-bit integers).
const EXP_MAGIC: u64 = 0x4330_0000_0000_0000;

/// `ln x` for a positive normal finite `x` (undefined otherwise: the
/// callers select on [`is_fast_domain`]). Branch-free; within 1 ulp.
#[inline(always)]
fn ln_normal(x: f64) -> f64 {
    let bits = x.to_bits();
    let hx = bits & MANTISSA;
    // fdlibm: normalise the mantissa to [√2/2, √2): `i` is 2^52 when the
    // mantissa is at least √2 (its high word at least 0x6a09e, the
    // threshold 0x95f64 = 0x100000 − 0x6a09c from e_log.c).
    let i = (hx + (0x95f64 << 32)) & (1 << 52);
    let m = f64::from_bits(hx | (i ^ 0x3ff0_0000_0000_0000));
    // k = biased exponent − 1023 + (1 if the mantissa was halved).
    let e = (bits >> 52) + (i >> 52);
    let k = f64::from_bits(EXP_MAGIC | e) - (f64::from_bits(EXP_MAGIC) + 1023.0);
    let f = m - 1.0;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG[1] + w * (LG[3] + w * LG[5]));
    let t2 = z * (LG[0] + w * (LG[2] + w * (LG[4] + w * LG[6])));
    let r = t2 + t1;
    // e_log.c's two final forms, chosen on the mantissa's high word `hw`
    // as there (0x6147a ≤ hw ≤ 0x6b851: f in about [0.38, 0.42]); compared
    // as the doubles `1.mantissa`, exactly the same test, because SSE2 has
    // no 64-bit integer comparison.
    let mant = f64::from_bits(hx | 0x3ff0_0000_0000_0000);
    let hfsq = 0.5 * f * f;
    let a = k * LN2_HI - ((hfsq - (s * (hfsq + r) + k * LN2_LO)) - f);
    let b = k * LN2_HI - ((s * (f - r) - k * LN2_LO) - f);
    if (FORM_LO..FORM_HI).contains(&mant) {
        a
    } else {
        b
    }
}

/// Whether `x` is in the fast path's domain: positive, normal and finite.
///
/// `false` for every `x` survives the mutation sample (issue #30) as
/// equivalent in value: every block then takes `f64::ln`, which the fast
/// path matches within 1 ulp; it costs time only.
#[inline(always)]
fn is_fast_domain(x: f64) -> bool {
    (f64::MIN_POSITIVE..f64::INFINITY).contains(&x)
}

/// Lanes handled per block: the domain check and the logarithm run over a
/// block at a time, so both loops vectorise.
const BLOCK: usize = 64;

/// `x ← ln x` for every element, within 1 ulp of the exact logarithm (and
/// exactly `f64::ln` outside the positive normal range: `−∞` at zero, NaN
/// below it). Vectorised over blocks whose elements are all in the fast
/// domain; a block with any other element takes `f64::ln` throughout.
///
/// On x86-64 the loop is compiled three times, for AVX-512, AVX2 and the
/// SSE2 baseline, and the widest the CPU has runs. Every variant gives the
/// same bits: the code has no fused multiply-adds (Rust never contracts
/// `a * b + c`), only wider registers.
pub fn ln_in_place(xs: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    {
        // Mutation sample (issue #30): emptying `wide512` survives on a CPU
        // without AVX-512 (the sample's), where it never runs; the same
        // tests kill it on one that has it.
        #[target_feature(enable = "avx512f")]
        fn wide512(xs: &mut [f64]) {
            ln_blocks(xs);
        }
        #[target_feature(enable = "avx2")]
        fn wide256(xs: &mut [f64]) {
            ln_blocks(xs);
        }
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: AVX-512F support was just checked.
            return unsafe { wide512(xs) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: AVX2 support was just checked.
            return unsafe { wide256(xs) };
        }
    }
    ln_blocks(xs);
}

/// [`ln_in_place`]'s loop, inlined into each of its target-feature
/// variants.
#[inline(always)]
fn ln_blocks(xs: &mut [f64]) {
    for block in xs.chunks_mut(BLOCK) {
        if block.iter().all(|&x| is_fast_domain(x)) {
            for x in block.iter_mut() {
                *x = ln_normal(*x);
            }
        } else {
            for x in block.iter_mut() {
                *x = x.ln();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::test_rng::lcg;

    /// Distance in units in the last place between two finite positive
    /// doubles of the same sign (their bit patterns are ordered).
    fn ulps(a: f64, b: f64) -> u64 {
        (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs()
    }

    fn check(xs: &[f64]) {
        let mut ys = xs.to_vec();
        ln_in_place(&mut ys);
        for (&x, &y) in xs.iter().zip(&ys) {
            let r = x.ln();
            if r == 0.0 {
                assert_eq!(y, 0.0, "ln({x:e})");
                continue;
            }
            // Both are within 1 ulp of the exact value (fdlibm's bound for
            // this one, glibc's < 1 ulp for `f64::ln`), and both are
            // faithful, so they differ by at most 1 ulp where the sign
            // agrees; a wrong coefficient or exponent is off by far more.
            assert_eq!(y.is_sign_negative(), r.is_sign_negative(), "ln({x:e})");
            assert!(ulps(y, r) <= 1, "ln({x:e}) = {y:e}, f64::ln {r:e}");
        }
    }

    #[test]
    fn agrees_with_libm_within_one_ulp_over_the_whole_normal_range() {
        let mut seed = 7;
        // Log-uniform over every binade of the normal range.
        let xs: Vec<f64> = (0..200_000)
            .map(|_| (lcg(&mut seed) * 708.0).exp())
            .filter(|x| is_fast_domain(*x))
            .collect();
        check(&xs);
    }

    #[test]
    fn agrees_near_one_near_the_mantissa_thresholds_and_at_powers_of_two() {
        let mut xs = Vec::new();
        for k in -1022..=1023 {
            let p = 2f64.powi(k);
            xs.extend([p, p * 1.5, p * std::f64::consts::SQRT_2, p * 0.999_999]);
        }
        // Around 1 (where ln is small and cancellation would show) and
        // around each switch between e_log.c's two forms.
        for i in 1..20_000 {
            let d = i as f64 * 1e-9;
            xs.extend([1.0 + d, 1.0 - d, 1.0 + d * 1e6, 1.0 - d * 1e4]);
        }
        for hw in [0x6147a_u64, 0x6147b, 0x6b850, 0x6b851, 0x6a09e, 0x6a09f] {
            for lo in [0u64, 1, 0xffff_ffff] {
                let b = 0x3ff0_0000_0000_0000 | (hw << 32) | lo;
                xs.extend([f64::from_bits(b), f64::from_bits(b) * 1024.0]);
            }
        }
        check(&xs);
        // Exactly zero at one, exact multiples of ln 2 at powers of two.
        let mut one = [1.0, 2.0, 0.5];
        ln_in_place(&mut one);
        assert_eq!(one, [0.0, std::f64::consts::LN_2, -std::f64::consts::LN_2]);
    }

    #[test]
    fn the_cpu_specific_variant_gives_the_baseline_bits() {
        let mut seed = 11;
        let xs: Vec<f64> = (0..10_000)
            .map(|_| (lcg(&mut seed) * 700.0).exp())
            .collect();
        let (mut a, mut b) = (xs.clone(), xs);
        ln_in_place(&mut a);
        ln_blocks(&mut b);
        assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
    }

    #[test]
    fn inputs_outside_the_normal_range_get_libm_values() {
        let special = [
            0.0,
            -0.0,
            -1.0,
            f64::INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE / 4.0,
            5e-324,
        ];
        // A special value anywhere in a block sends the whole block to
        // `f64::ln`: the normal values around it must still be right.
        for (pos, &sv) in special.iter().enumerate() {
            let mut xs: Vec<f64> = (1..=100).map(|i| i as f64 * 0.37).collect();
            xs[pos * 9] = sv;
            let want: Vec<f64> = xs.iter().map(|x| x.ln()).collect();
            ln_in_place(&mut xs);
            for (y, w) in xs.iter().zip(&want) {
                assert!(y == w || (y.is_nan() && w.is_nan()), "{y} vs {w}");
            }
        }
    }
}
