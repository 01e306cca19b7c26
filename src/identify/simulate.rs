//! Simulated measurements: `y_i = p(θ_real, q_i) + ε_i`, `ε_i ~ N(0, σ² I₃)`,
//! and for a full-pose robot `R_i = exp([η_i]×) R(θ_real, q_i)`,
//! `η_i ~ N(0, (σ/w)² I₃)`, `w` = [`Robot::orientation_scale`].
//!
//! Normal deviates come from Box–Muller on the crate's ChaCha generator, not
//! from `rand_distr`: the `rand_distr` in the registry (0.5) is built on
//! `rand` 0.9's traits and does not accept a `rand` 0.10 generator, and two
//! lines of Box–Muller are not worth a second `rand` in the build.

use super::Result;
use crate::data::Measurements;
use crate::kinematics::Evaluator;
use crate::measure::sensor_for;
use crate::model::{ParamTable, Robot};
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The generator of trial `trial` under `seed`: ChaCha8 seeded from `seed`,
/// on stream `trial`. Trials are independent and each is reproducible on its
/// own, whatever the order or the thread they run on.
#[must_use]
pub fn trial_rng(seed: u64, trial: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(trial);
    rng
}

/// Fills `out` with independent N(0, 1) deviates (Box–Muller, both outputs used).
pub(crate) fn fill_standard_normal<R: Rng + ?Sized>(rng: &mut R, out: &mut [f64]) {
    for pair in out.chunks_mut(2) {
        // u1 in (0, 1] so that ln u1 is finite.
        let u1 = 1.0 - rng.random::<f64>();
        let u2 = rng.random::<f64>();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        pair[0] = r * c;
        if pair.len() > 1 {
            pair[1] = r * s;
        }
    }
}

/// Measurements of `table` (normally `robot.real`) at the joint vectors `qs`,
/// with independent N(0, σ²) noise on every coordinate (σ = `sigma`, metres),
/// and for a full-pose robot orientations turned by independent N(0, (σ/w)²)
/// rotation vectors (radians, `w` = [`Robot::orientation_scale`]).
///
/// Draws: 3 normals per pose for points (x, y, z), 6 for full poses (x, y,
/// z, then the rotation vector), in pose order.
///
/// Errors on a joint vector that does not fit the robot or a `sigma` that is
/// negative or not finite.
pub fn simulate<R: Rng + ?Sized>(
    robot: &Robot,
    table: &ParamTable,
    qs: &[Vec<f64>],
    sigma: f64,
    rng: &mut R,
) -> Result<Measurements> {
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(super::IdentifyError::Setting {
            name: "sigma",
            value: sigma.to_string(),
            reason: "the noise standard deviation must be finite and >= 0",
        });
    }
    // The sensor's prediction, moved along its manifold by σ z_r / w_r per
    // row r (w_r its weight: position rows 1, orientation rows w).
    let sensor = sensor_for(robot);
    let t = sensor.rows();
    let mut noise = vec![0.0; t * qs.len()];
    fill_standard_normal(rng, &mut noise);
    let mut ev = Evaluator::new(robot, table);
    let own = table.marker_values();
    let mut value = vec![0.0; sensor.value_len()];
    let mut delta = vec![0.0; t];
    let mut points = Vec::with_capacity(qs.len());
    let mut orientations = Vec::new();
    for (i, q) in qs.iter().enumerate() {
        robot
            .check_q(q)
            .map_err(|source| crate::data::DataError::Pose { pose: i, source })?;
        sensor.predict(&ev.end_frame(q), &own, &mut value);
        let z = &noise[t * i..t * (i + 1)];
        for ((d, z), w) in delta.iter_mut().zip(z).zip(sensor.weights()) {
            *d = sigma * z / w;
        }
        sensor.retract(&mut value, &delta);
        let obs = sensor.decode(&value);
        points.extend(obs.points);
        orientations.extend(obs.orientation);
    }
    Ok(
        Measurements::with_orientations(robot, qs.to_vec(), points, orientations)?
            .of_robot(&robot.name),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_have_unit_moments() {
        let mut rng = trial_rng(1, 0);
        let mut z = vec![0.0; 200_001];
        fill_standard_normal(&mut rng, &mut z);
        let n = z.len() as f64;
        let mean = z.iter().sum::<f64>() / n;
        let var = z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        let kurt = z.iter().map(|v| (v - mean).powi(4)).sum::<f64>() / n / (var * var);
        // Standard errors: mean 1/√n ≈ 0.0022, variance √(2/n) ≈ 0.0032,
        // kurtosis √(24/n) ≈ 0.011; the bounds are 5 standard errors.
        assert!(mean.abs() < 0.011, "mean {mean}");
        assert!((var - 1.0).abs() < 0.016, "variance {var}");
        assert!((kurt - 3.0).abs() < 0.055, "kurtosis {kurt}");
    }

    #[test]
    fn streams_differ_and_repeat() {
        let draw = |seed, trial| {
            let mut rng = trial_rng(seed, trial);
            (0..4).map(|_| rng.random::<u64>()).collect::<Vec<_>>()
        };
        assert_eq!(draw(7, 3), draw(7, 3));
        assert_ne!(draw(7, 3)[0], draw(7, 3)[1]);
        let x: u64 = trial_rng(7, 3).random();
        let y: u64 = trial_rng(7, 4).random();
        let z: u64 = trial_rng(8, 3).random();
        assert!(x != y && x != z);
    }
}
