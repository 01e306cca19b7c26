//! A model's errors on measured data, in the units an engineer reads:
//! position errors in millimetres (the norm of each measured point's error
//! vector) and orientation errors in degrees (the angle of `R̂ Rᵀ`), per
//! sample and summarised (RMS and maximum over samples), with no fitting.
//!
//! A sample is one measured point: a pose of a point or full-pose sensor,
//! one marker of one pose for a `K`-marker sensor (whose RMS is also given
//! per marker). The sensor's weighted residual rows are unweighted here, so
//! that `orientation_scale` never mixes metres and radians in a figure.

use super::Result;
use crate::data::Measurements;
use crate::kinematics::Evaluator;
use crate::measure::{RowKind, sensor_for};
use crate::model::{ParamTable, Robot};
use serde::Serialize;

/// One pose's errors.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SampleResidual {
    /// 0-based pose number in the measurement set.
    pub pose: usize,
    /// Position error norm of each measured point (one per marker), mm.
    pub position_mm: Vec<f64>,
    /// Orientation error, degrees, for sensors that measure it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_deg: Option<f64>,
}

/// A model's errors on a measurement set.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ModelErrors {
    /// RMS over samples (measured points) of the position error norm, mm.
    pub position_rms_mm: f64,
    /// Largest position error norm, mm.
    pub position_max_mm: f64,
    /// RMS position error of each marker, mm (one entry for one point).
    pub position_rms_mm_per_marker: Vec<f64>,
    /// RMS orientation error angle over poses, degrees (full poses only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_rms_deg: Option<f64>,
    /// Largest orientation error angle, degrees (full poses only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation_max_deg: Option<f64>,
    /// Every pose's errors, in measurement order.
    pub per_sample: Vec<SampleResidual>,
}

/// The errors of `robot` with parameters `table` on `meas` (checked against
/// the robot first).
pub fn residuals(robot: &Robot, table: &ParamTable, meas: &Measurements) -> Result<ModelErrors> {
    meas.check(robot)?;
    let sensor = sensor_for(robot);
    let (t, vl) = (sensor.rows(), sensor.value_len());
    let kinds = sensor.row_kinds().to_vec();
    let weights = sensor.weights().to_vec();
    let own = table.marker_values();
    let mut ev = Evaluator::new(robot, table);
    let (mut pred, mut y, mut r) = (vec![0.0; vl], vec![0.0; vl], vec![0.0; t]);
    let k = meas.markers();
    let mut per_sample = Vec::with_capacity(meas.len());
    for (i, q) in meas.qs().iter().enumerate() {
        sensor.predict(&ev.end_frame(q), &own, &mut pred);
        sensor.encode(&meas.observation(i), &mut y);
        sensor.residual(&pred, &y, &mut r);
        let (mut pos, mut ori) = (Vec::with_capacity(k), Vec::new());
        // Rows come in triples of one kind: a point, or a rotation vector.
        for ((rows, kind), w) in r.chunks(3).zip(kinds.chunks(3)).zip(weights.chunks(3)) {
            let norm = rows
                .iter()
                .zip(w)
                .map(|(v, w)| (v / w).powi(2))
                .sum::<f64>()
                .sqrt();
            match kind[0] {
                RowKind::Position => pos.push(1e3 * norm),
                RowKind::Orientation => ori.push(norm.to_degrees()),
                // A camera's pixels have figures of their own
                // (`identify::camera`); no robot's own sensor has them.
                RowKind::Pixel => {}
            }
        }
        per_sample.push(SampleResidual {
            pose: i,
            position_mm: pos,
            orientation_deg: ori.first().copied(),
        });
    }
    let rms = |v: &mut dyn Iterator<Item = f64>| {
        let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x * x, n + 1));
        (s / n.max(1) as f64).sqrt()
    };
    let max = |v: &mut dyn Iterator<Item = f64>| v.fold(0.0, f64::max);
    let pos = || {
        per_sample
            .iter()
            .flat_map(|s| s.position_mm.iter().copied())
    };
    let ori = || per_sample.iter().filter_map(|s| s.orientation_deg);
    let has_ori = per_sample.iter().any(|s| s.orientation_deg.is_some());
    Ok(ModelErrors {
        position_rms_mm: rms(&mut pos()),
        position_max_mm: max(&mut pos()),
        position_rms_mm_per_marker: (0..k)
            .map(|m| rms(&mut per_sample.iter().map(|s| s.position_mm[m])))
            .collect(),
        orientation_rms_deg: has_ori.then(|| rms(&mut ori())),
        orientation_max_deg: has_ori.then(|| max(&mut ori())),
        per_sample,
    })
}

impl ModelErrors {
    /// One line: `position RMS 2.41 mm (max 5.10 mm)[, orientation RMS …]`.
    #[must_use]
    pub fn summary(&self) -> String {
        let mut s = format!(
            "position RMS {:.3} mm (max {:.3} mm)",
            self.position_rms_mm, self.position_max_mm
        );
        if self.position_rms_mm_per_marker.len() > 1 {
            let v: Vec<String> = self
                .position_rms_mm_per_marker
                .iter()
                .map(|x| format!("{x:.3}"))
                .collect();
            s += &format!(", per marker {} mm", v.join(" / "));
        }
        if let (Some(r), Some(m)) = (self.orientation_rms_deg, self.orientation_max_deg) {
            s += &format!("; orientation RMS {r:.4}° (max {m:.4}°)");
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::simulate;
    use rand::SeedableRng;

    /// A model evaluated on its own noiseless predictions has zero error;
    /// moving one point by 3 mm along x shows exactly 3 mm on that sample;
    /// turning one orientation by 0.5° shows 0.5° (independent of the
    /// orientation scale's weighting).
    #[test]
    fn errors_are_in_millimetres_and_degrees() {
        let mut robot = Robot::builtin("ur5:pose").unwrap();
        robot.orientation_scale = 0.3;
        let qs: Vec<Vec<f64>> = (0..5).map(|i| vec![0.1 * i as f64; 6]).collect();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let m = simulate(&robot, &robot.nominal, &qs, 0.0, &mut rng).unwrap();
        let r = residuals(&robot, &robot.nominal, &m).unwrap();
        assert!(r.position_max_mm < 1e-9 && r.orientation_max_deg.unwrap() < 1e-9);
        let mut pts = m.points().to_vec();
        pts[2][0] += 0.003;
        let mut rots = m.orientations().to_vec();
        let turn =
            nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::y_axis(), 0.5f64.to_radians());
        rots[4] = crate::data::rows(&(turn.matrix() * crate::data::matrix(&rots[4])));
        let moved = Measurements::with_orientations(&robot, qs.clone(), pts, rots).unwrap();
        let r = residuals(&robot, &robot.nominal, &moved).unwrap();
        assert!(
            (r.per_sample[2].position_mm[0] - 3.0).abs() < 1e-9,
            "{:?}",
            r.per_sample[2]
        );
        assert!((r.position_max_mm - 3.0).abs() < 1e-9);
        assert!((r.position_rms_mm - (9.0f64 / 5.0).sqrt()).abs() < 1e-9);
        assert!((r.orientation_max_deg.unwrap() - 0.5).abs() < 1e-9);
    }
}

/// Checks that the measured points are within reach of `robot`'s nominal
/// model ([`crate::units::check_positions_in_reach`]): each point against
/// the nominal end frame's position at its pose. `length` is the unit the
/// file was read in (for the hint); `file` names it.
pub fn check_in_reach(
    robot: &Robot,
    meas: &Measurements,
    file: &str,
    length: crate::units::LengthUnit,
) -> Result<()> {
    let k = meas.markers().max(1);
    if meas.qs().iter().any(|q| q.len() != robot.dof()) || meas.points().len() != k * meas.len() {
        // The shape is the residuals' check to report, naming the pose.
        return Ok(());
    }
    let mut ev = Evaluator::new(robot, &robot.nominal);
    let predicted: Vec<[f64; 3]> = meas
        .qs()
        .iter()
        .flat_map(|q| {
            let p: [f64; 3] = ev.end_frame(q).position.into();
            std::iter::repeat_n(p, k)
        })
        .collect();
    crate::units::check_positions_in_reach(robot, file, length, meas.points(), &predicted)?;
    Ok(())
}
