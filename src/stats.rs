//! The distribution functions the tests of a fit need: the F distribution's
//! upper tail (the per-pose outlier test, [`crate::lsq::outliers`]) and
//! the χ² distribution's tails (σ̂ against a stated noise), from the
//! regularised incomplete beta and gamma functions (Numerical Recipes, 3rd
//! ed., §6.2 and §6.4: series and Lentz's continued fractions, accurate to
//! about 1e-13 relative over the arguments a fit produces).

/// `ln Γ(x)` for `x > 0` (Lanczos, g = 7, 9 terms; relative error ~1e-15).
#[must_use]
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 − x) = π / sin(πx).
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (k, c) in C.iter().enumerate().skip(1) {
        a += c / (x + k as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Iterations and tolerance of the series and continued fractions.
const ITERATIONS: usize = 10_000;
const EPS: f64 = 1e-15;
const TINY: f64 = 1e-300;

/// `x`, or [`TINY`] when `|x|` is below it: Lentz's guard against a zero
/// denominator.
fn nonzero(x: f64) -> f64 {
    if x.abs() < TINY { TINY } else { x }
}

/// Lentz's evaluation of the continued fraction of the incomplete beta
/// function (Numerical Recipes' `betacf`).
fn beta_fraction(a: f64, b: f64, x: f64) -> f64 {
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 / nonzero(1.0 - qab * x / qap);
    let mut h = d;
    for m in 1..ITERATIONS {
        let m = m as f64;
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        d = nonzero(d);
        c = 1.0 + aa / c;
        c = nonzero(c);
        d = 1.0 / d;
        h *= d * c;
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        d = nonzero(d);
        c = 1.0 + aa / c;
        c = nonzero(c);
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < EPS {
            break;
        }
    }
    h
}

/// The regularised incomplete beta function `I_x(a, b)` for `a, b > 0`,
/// `0 ≤ x ≤ 1`.
#[must_use]
pub fn beta_regularized(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln();
    let front = ln_front.exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        front * beta_fraction(a, b, x) / a
    } else {
        1.0 - front * beta_fraction(b, a, 1.0 - x) / b
    }
}

/// `P(F > f)` for `F ~ F(d1, d2)`: the upper tail of the F distribution
/// (`I_{d2/(d2 + d1 f)}(d2/2, d1/2)`); 1 for `f ≤ 0`.
#[must_use]
pub fn f_upper_tail(f: f64, d1: f64, d2: f64) -> f64 {
    if !(f > 0.0) {
        return 1.0;
    }
    beta_regularized(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f))
}

/// The regularised lower incomplete gamma function `P(a, x)`, `a > 0`.
#[must_use]
pub fn gamma_lower_regularized(a: f64, x: f64) -> f64 {
    gamma_regularized(a, x).0
}

/// `(P(a, x), Q(a, x) = 1 − P(a, x))`, each computed where it is accurate
/// (a tail far below 1e-16 is not lost to `1 − P`).
fn gamma_regularized(a: f64, x: f64) -> (f64, f64) {
    if x <= 0.0 {
        return (0.0, 1.0);
    }
    let ln_front = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        // The series.
        let (mut ap, mut sum) = (a, 1.0 / a);
        let mut del = sum;
        for _ in 0..ITERATIONS {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * EPS {
                break;
            }
        }
        let p = sum * ln_front.exp();
        return (p, 1.0 - p);
    }
    // The continued fraction for Q(a, x) (Lentz).
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..ITERATIONS {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        d = nonzero(d);
        c = b + an / c;
        c = nonzero(c);
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < EPS {
            break;
        }
    }
    let q = ln_front.exp() * h;
    (1.0 - q, q)
}

/// `P(X ≤ x)` for `X ~ χ²(k)`.
#[must_use]
pub fn chi2_cdf(x: f64, k: f64) -> f64 {
    gamma_lower_regularized(0.5 * k, 0.5 * x)
}

/// `P(X ≥ x)` for `X ~ χ²(k)`, accurate far into the tail.
#[must_use]
pub fn chi2_upper_tail(x: f64, k: f64) -> f64 {
    gamma_regularized(0.5 * k, 0.5 * x).1
}

#[cfg(test)]
mod tests {
    use super::*;

    // Reference values from printed tables (Abramowitz & Stegun, tables
    // 26.8 and 26.9; NIST/SEMATECH e-Handbook §1.3.6.7): the quantile must
    // give back its tail to the table's 4–5 digits.

    #[test]
    fn chi_square_quantiles_give_their_tails() {
        for (x, k, upper) in [
            (3.841_46, 1.0, 0.05),
            (18.307, 10.0, 0.05),
            (6.634_90, 1.0, 0.01),
            (37.566, 20.0, 0.01),
            (0.1026, 2.0, 0.95),
        ] {
            let got = chi2_upper_tail(x, k);
            assert!((got + chi2_cdf(x, k) - 1.0).abs() < 1e-14);
            assert!(
                (got - upper).abs() < 2e-5,
                "χ²({k}) at {x}: {got} not {upper}"
            );
        }
    }

    #[test]
    fn f_quantiles_give_their_tails() {
        for (f, d1, d2, upper) in [
            (4.965, 1.0, 10.0, 0.05),
            (2.758, 3.0, 60.0, 0.05),
            (4.126, 3.0, 60.0, 0.01),
            (2.421, 6.0, 30.0, 0.05),
        ] {
            let got = f_upper_tail(f, d1, d2);
            assert!(
                (got - upper).abs() < 3e-4,
                "F({d1}, {d2}) at {f}: {got} not {upper}"
            );
        }
    }

    #[test]
    fn gamma_function_at_integers_and_a_half() {
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-13);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-13);
        // The F tail and the χ² tail agree as d2 → ∞: d1 F → χ²(d1).
        let (a, b) = (f_upper_tail(2.0, 3.0, 1e7), 1.0 - chi2_cdf(6.0, 3.0));
        assert!((a - b).abs() < 1e-5, "{a} {b}");
    }
}
