//! Joint configurations for the checks: uniform random ones within the joint
//! limits from a fixed seed, and the `2^dof` corners of the limit box.
//!
//! The generator is SplitMix64 written out here (not `rand`), so that the
//! fixtures' configurations never change with a dependency upgrade.

use activecal::model::Robot;

/// SplitMix64 (Steele, Lea & Flood 2014): a 64-bit state advanced by the
/// golden-ratio increment and mixed by two multiply-xorshift rounds.
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator from a seed.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        SplitMix64 { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform number in `[0, 1)` with 53 random bits.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// `n` configurations uniform in the joint limits box, from `seed`.
#[must_use]
pub fn random_configurations(robot: &Robot, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            robot
                .limits
                .iter()
                .map(|&[lo, hi]| lo + (hi - lo) * rng.next_f64())
                .collect()
        })
        .collect()
}

/// The `2^dof` corners of the joint limits box. Corner `k` has joint `j` at
/// its upper limit when bit `dof−1−j` of `k` is set (joint 1 most
/// significant, as in the pose lattice's indexing).
#[must_use]
pub fn lattice_corners(robot: &Robot) -> Vec<Vec<f64>> {
    let dof = robot.dof();
    assert!(dof < 32, "2^{dof} corners are too many");
    (0..1usize << dof)
        .map(|k| {
            robot
                .limits
                .iter()
                .enumerate()
                .map(|(j, &[lo, hi])| if k >> (dof - 1 - j) & 1 == 1 { hi } else { lo })
                .collect()
        })
        .collect()
}

/// `n_random` random configurations (see [`random_configurations`])
/// followed by all lattice corners (see [`lattice_corners`]).
#[must_use]
pub fn configurations(robot: &Robot, n_random: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut qs = random_configurations(robot, n_random, seed);
    qs.extend(lattice_corners(robot));
    qs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix_matches_reference_values() {
        // First outputs for seed 1234567 from the reference C implementation.
        let mut r = SplitMix64::new(1234567);
        assert_eq!(r.next_u64(), 6457827717110365317);
        assert_eq!(r.next_u64(), 3203168211198807973);
        assert_eq!(r.next_u64(), 9817491932198370423);
    }

    #[test]
    fn configurations_lie_in_limits_and_corners_are_distinct() {
        let robot = Robot::puma560();
        let qs = configurations(&robot, 500, 7);
        assert_eq!(qs.len(), 500 + 64);
        for q in &qs {
            for (v, &[lo, hi]) in q.iter().zip(&robot.limits) {
                assert!(lo <= *v && *v <= hi);
            }
        }
        let corners = lattice_corners(&robot);
        assert_eq!(
            corners[0],
            robot.limits.iter().map(|l| l[0]).collect::<Vec<_>>()
        );
        assert_eq!(
            corners[63],
            robot.limits.iter().map(|l| l[1]).collect::<Vec<_>>()
        );
        // Corner 32 = 0b100000: only joint 1 at its upper limit.
        assert_eq!(corners[32][0], robot.limits[0][1]);
        assert!(
            corners[32][1..]
                .iter()
                .zip(&robot.limits[1..])
                .all(|(v, l)| *v == l[0])
        );
        let mut sorted = corners.clone();
        sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
        sorted.dedup();
        assert_eq!(sorted.len(), 64);
    }
}
