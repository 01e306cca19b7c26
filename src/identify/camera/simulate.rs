//! Simulated camera observations: the pixels a true robot and true
//! placements give, with Gaussian pixel noise, keeping the points the
//! camera sees (in front of it, inside the image with a margin) and the
//! poses that see at least [`MIN_POINTS_PER_POSE`] of them.

use crate::data::CameraObservations;
use crate::identify::simulate::fill_standard_normal;
use crate::kinematics::Evaluator;
use crate::measure::Sensor;
use crate::measure::camera::CameraSensor;
use crate::measure::camera::MIN_POINTS_PER_POSE;
use crate::model::{ParamTable, Robot};
use rand::Rng;

/// Observations of `table` (the true robot) with `sensor` at own unknowns
/// `own` (the true placements) at configurations `qs`, each pixel
/// coordinate with N(0, σ²) noise (`sigma_px` pixels): points predicted
/// inside the image at least `margin` pixels from its border are seen
/// (unless the noise carries one out of the image). Poses that
/// see fewer than 4 points are left out; pose ids are the indices into
/// `qs`.
#[allow(clippy::too_many_arguments)]
pub fn simulate_observations<R: Rng + ?Sized>(
    robot: &Robot,
    table: &ParamTable,
    sensor: &CameraSensor,
    own: &[f64],
    qs: &[Vec<f64>],
    sigma_px: f64,
    margin: f64,
    rng: &mut R,
) -> CameraObservations {
    let mut ev = Evaluator::new(robot, table);
    let mut pred = vec![0.0; sensor.value_len()];
    let mut noise = vec![0.0; 2 * sensor.points().len()];
    let mut obs = CameraObservations {
        origin: "simulated".into(),
        pose_ids: Vec::new(),
        qs: Vec::new(),
        seen: Vec::new(),
    };
    for (i, q) in qs.iter().enumerate() {
        sensor.predict(&ev.end_frame(q), own, &mut pred);
        fill_standard_normal(rng, &mut noise);
        let seen: Vec<Option<[f64; 2]>> = pred
            .chunks_exact(3)
            .zip(noise.chunks_exact(2))
            .map(|(p, n)| {
                let px = [p[0], p[1]];
                let noisy = [px[0] + sigma_px * n[0], px[1] + sigma_px * n[1]];
                (p[2] != 0.0
                    && sensor.intrinsics().inside(px, margin)
                    && sensor.intrinsics().inside(noisy, 0.0))
                .then_some(noisy)
            })
            .collect();
        if seen.iter().flatten().count() >= MIN_POINTS_PER_POSE {
            obs.pose_ids.push(i as i64);
            obs.qs.push(q.clone());
            obs.seen.push(seen);
        }
    }
    obs
}
