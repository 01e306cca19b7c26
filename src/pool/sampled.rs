//! Sampled pools: uniform random and low-discrepancy (Sobol) configurations
//! inside the joint limits, each pose computable from its id alone so that a
//! pool is the same whatever the number of threads that builds it. A
//! revolute joint that turns all the way round is drawn on one turn from its
//! lower limit (`[lo, lo + 2π)`, [`super::turn`]): each angle once.
//!
//! * [`Uniform`]: sample `k` is the values `k·dof .. (k+1)·dof` of one
//!   ChaCha8 stream seeded with the pool's seed (each value a uniform `f64`
//!   in `[0, 1)` from one 64-bit draw, mapped onto `[lo, hi]`): exactly the
//!   first `count·dof` draws of that stream, in order.
//! * [`Sobol`]: point `k` of the Sobol sequence in `dof` dimensions with the
//!   direction numbers of Joe and Kuo (2008, `new-joe-kuo-6.21201`, the
//!   table SciPy and most libraries ship) for up to [`SOBOL_MAX_DIM`]
//!   joints, in Gray-code order (the order of Antonov–Saleev generation, and
//!   SciPy's), 32 bits per coordinate. With a seed, each dimension is
//!   scrambled by a random linear matrix (a unit lower-triangular binary
//!   matrix applied to its direction numbers, Matoušek 1998) and a random
//!   digital shift, both drawn from ChaCha8: the first `2^m` points stay a
//!   `(t, m, s)`-net, so every joint's range is still stratified exactly.

use crate::error::{Error, Result};
use crate::model::Robot;
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Most samples a sampled pool may have (ids are 32-bit Sobol indices).
pub const MAX_SAMPLES: usize = 1 << 32;

/// The intervals a robot's joints are sampled from: its joint limits,
/// checked (finite, `lo ≤ hi`), one turn of a joint that turns all the way
/// round ([`super::turn::sampling_range`]).
pub(crate) fn checked_limits(robot: &Robot) -> Result<Vec<[f64; 2]>> {
    let revolute = super::turn::revolute_joints(robot);
    for (j, &[lo, hi]) in robot.limits.iter().enumerate() {
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(Error::InvalidLimits {
                joint: j + 1,
                lo,
                hi,
            });
        }
    }
    Ok(robot
        .limits
        .iter()
        .zip(&revolute)
        .map(|(&l, &r)| super::turn::sampling_range(r, l))
        .collect())
}

/// `lo·(1−u) + hi·u`: exact at both ends (with `u < 1`, a full turn's top,
/// which is its bottom again, is reached only by rounding).
fn lerp([lo, hi]: [f64; 2], u: f64) -> f64 {
    lo * (1.0 - u) + hi * u
}

fn check_count(count: usize) -> Result<()> {
    if count == 0 || count > MAX_SAMPLES {
        return Err(Error::Invalid(format!(
            "a sampled pool needs 1 to {MAX_SAMPLES} samples, got {count}"
        )));
    }
    Ok(())
}

/// Uniform random configurations inside the joint limits (see the module
/// docs for the exact stream).
#[derive(Clone, Debug)]
pub struct Uniform {
    limits: Vec<[f64; 2]>,
    count: usize,
    seed: u64,
}

impl Uniform {
    /// `count` samples for `robot`, seeded with `seed`.
    pub fn new(robot: &Robot, count: usize, seed: u64) -> Result<Self> {
        check_count(count)?;
        Ok(Self {
            limits: checked_limits(robot)?,
            count,
            seed,
        })
    }

    /// Number of samples.
    #[must_use]
    pub fn size(&self) -> usize {
        self.count
    }

    /// Joint values of sample `k`, written into `q`.
    pub fn q_into(&self, k: usize, q: &mut [f64]) {
        let dof = self.limits.len();
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        // One 64-bit draw (two 32-bit words) per value.
        rng.set_word_pos(2 * (k as u128) * dof as u128);
        for (v, &lim) in q.iter_mut().zip(&self.limits) {
            *v = lerp(lim, rng.random::<f64>());
        }
    }
}

/// Most dimensions (joints) of [`Sobol`].
pub const SOBOL_MAX_DIM: usize = 21;

/// Joe–Kuo `new-joe-kuo-6.21201`, dimensions 2..=21: `(s, a, m_1..m_s)`,
/// the degree of the primitive polynomial, its inner coefficients as bits,
/// and the initial direction integers. Dimension 1 is the van der Corput
/// sequence (all `m_i = 1`).
const JOE_KUO: [(u32, u32, &[u32]); SOBOL_MAX_DIM - 1] = [
    (1, 0, &[1]),
    (2, 1, &[1, 3]),
    (3, 1, &[1, 3, 1]),
    (3, 2, &[1, 1, 1]),
    (4, 1, &[1, 1, 3, 3]),
    (4, 4, &[1, 3, 5, 13]),
    (5, 2, &[1, 1, 5, 5, 17]),
    (5, 4, &[1, 1, 5, 5, 5]),
    (5, 7, &[1, 1, 7, 11, 19]),
    (5, 11, &[1, 1, 5, 1, 1]),
    (5, 13, &[1, 1, 1, 3, 11]),
    (5, 14, &[1, 3, 5, 5, 31]),
    (6, 1, &[1, 3, 3, 9, 7, 49]),
    (6, 13, &[1, 1, 1, 15, 21, 21]),
    (6, 16, &[1, 3, 1, 13, 27, 49]),
    (6, 19, &[1, 1, 1, 15, 7, 5]),
    (6, 22, &[1, 3, 1, 15, 13, 25]),
    (6, 25, &[1, 1, 5, 5, 19, 61]),
    (7, 1, &[1, 3, 7, 11, 23, 15, 103]),
    (7, 4, &[1, 3, 7, 13, 13, 15, 69]),
];

/// Bits per Sobol coordinate.
const BITS: usize = 32;

/// The 32 direction numbers `v_1..v_32` of Sobol dimension `d` (0-based),
/// as 32-bit fractions (`v_i = m_i · 2^(32−i)`).
fn direction_numbers(d: usize) -> [u32; BITS] {
    let mut v = [0u32; BITS];
    if d == 0 {
        for (i, vi) in v.iter_mut().enumerate() {
            *vi = 1 << (BITS - 1 - i);
        }
        return v;
    }
    let (s, a, m) = JOE_KUO[d - 1];
    let s = s as usize;
    for i in 0..s.min(BITS) {
        v[i] = m[i] << (BITS - 1 - i);
    }
    // v_i = a_1 v_{i−1} ⊕ … ⊕ a_{s−1} v_{i−s+1} ⊕ v_{i−s} ⊕ (v_{i−s} >> s).
    for i in s..BITS {
        let mut x = v[i - s] ^ (v[i - s] >> s);
        for k in 1..s {
            if (a >> (s - 1 - k)) & 1 == 1 {
                x ^= v[i - k];
            }
        }
        v[i] = x;
    }
    v
}

/// Linear matrix scramble of one dimension's direction numbers: `v ← L v`
/// with `L` unit lower triangular over GF(2), its strictly lower bits drawn
/// from `rng`. Digit `r` (bit `31 − r`, the most significant first) of
/// `L v` is the parity of row `r` of `L` and `v`, and row `r` touches only
/// digits `0..=r`, so the first `m` digits of every point depend on the
/// first `m` digits alone and the net property survives.
fn scramble(v: &mut [u32; BITS], rng: &mut ChaCha8Rng) {
    let rows: Vec<u32> = (0..BITS)
        .map(|r| {
            let diag = 1u32 << (BITS - 1 - r);
            // The bits more significant than the diagonal one.
            let above = !(diag | (diag - 1));
            (rng.next_u32() & above) | diag
        })
        .collect();
    for x in v.iter_mut() {
        let mut y = 0u32;
        for (r, &row) in rows.iter().enumerate() {
            if (row & *x).count_ones() % 2 == 1 {
                y |= 1 << (BITS - 1 - r);
            }
        }
        *x = y;
    }
}

/// A Sobol sequence in the joint box (see the module docs).
#[derive(Clone, Debug)]
pub struct Sobol {
    limits: Vec<[f64; 2]>,
    count: usize,
    /// Direction numbers per dimension (scrambled when seeded).
    v: Vec<[u32; BITS]>,
    /// Digital shift per dimension (0 unscrambled).
    shift: Vec<u32>,
}

impl Sobol {
    /// `count` points for `robot`; scrambled (linear matrix scramble and
    /// digital shift) when `seed` is given.
    pub fn new(robot: &Robot, count: usize, seed: Option<u64>) -> Result<Self> {
        let limits = checked_limits(robot)?;
        let mut s = Self::unit_cube(limits.len(), count, seed)?;
        s.limits = limits;
        Ok(s)
    }

    /// `count` points in `[0, 1]^dim` (the limits of every dimension `[0,
    /// 1]`); scrambled when `seed` is given.
    pub fn unit_cube(dim: usize, count: usize, seed: Option<u64>) -> Result<Self> {
        check_count(count)?;
        if dim > SOBOL_MAX_DIM {
            return Err(Error::Invalid(format!(
                "a Sobol pool supports up to {SOBOL_MAX_DIM} joints, the robot has {dim}"
            )));
        }
        let mut v: Vec<[u32; BITS]> = (0..dim).map(direction_numbers).collect();
        let mut shift = vec![0u32; dim];
        if let Some(seed) = seed {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            for (vd, sd) in v.iter_mut().zip(shift.iter_mut()) {
                scramble(vd, &mut rng);
                *sd = rng.next_u32();
            }
        }
        Ok(Self {
            limits: vec![[0.0, 1.0]; dim],
            count,
            v,
            shift,
        })
    }

    /// Number of points.
    #[must_use]
    pub fn size(&self) -> usize {
        self.count
    }

    /// The point `k` in `[0, 1)^dof` (32-bit coordinates).
    #[must_use]
    pub fn unit_point(&self, k: usize) -> Vec<u32> {
        let gray = (k ^ (k >> 1)) as u64;
        self.v
            .iter()
            .zip(&self.shift)
            .map(|(vd, &s)| {
                let mut x = s;
                for (i, &vi) in vd.iter().enumerate() {
                    if (gray >> i) & 1 == 1 {
                        x ^= vi;
                    }
                }
                x
            })
            .collect()
    }

    /// Joint values of point `k`, written into `q`.
    pub fn q_into(&self, k: usize, q: &mut [f64]) {
        let u = self.unit_point(k);
        for ((v, &lim), &x) in q.iter_mut().zip(&self.limits).zip(&u) {
            *v = lerp(lim, f64::from(x) / 4_294_967_296.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_numbers_follow_the_recurrence() {
        // Dimension 2 (s = 1, x + 1): v_i = v_{i−1} ⊕ v_{i−1}>>1 gives the
        // points 0, 1/2, 3/4, 1/4, ... in Gray-code order.
        let v = direction_numbers(1);
        assert_eq!(v[0], 1 << 31);
        assert_eq!(v[1], 3 << 30);
        assert_eq!(v[2], 5 << 29);
    }
}
