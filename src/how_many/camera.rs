//! "How many poses" for a camera: the curve on a camera design's visible
//! pool ([`crate::select::camera`]), its errors those of the moving one's
//! origin in the fixed one's frame
//! ([`crate::identify::camera::predict::probe_jacobians`]), its noise in
//! pixels.

use super::{
    CurveSettings, ErrorRows, HowManyError, NoiseUnit, PoseCountCurve, fewest_poses,
    pose_count_curve_on,
};
use crate::identify::camera::predict::probe_jacobians;
use crate::measure::RowKind;
use crate::select::camera::CameraDesign;

impl CameraDesign {
    /// The rows a camera design's errors are predicted from: the
    /// derivative of the moving one's origin in the fixed one's frame
    /// ([`crate::identify::camera::predict::probe_jacobians`]) at
    /// `configurations` generic configurations of seed `seed`.
    #[must_use]
    pub fn error_rows(&self, configurations: usize, seed: u64) -> ErrorRows {
        let mut theta = self.robot.unknown_values(&self.robot.nominal);
        theta.extend_from_slice(&self.own);
        let qs = crate::observability::generic_configurations(&self.robot, configurations, seed);
        ErrorRows {
            eval: probe_jacobians(&self.robot, &self.sensor, &theta, &qs),
            kinds: vec![RowKind::Position; 3],
            orientation_weight: 1.0,
            point_rows: 3,
        }
    }

    /// "How many poses" for this camera's visible pool: for each size, the
    /// best design, its D-efficiency against the certified bound and the
    /// true error it predicts for pixel noise `settings.noise` (px) at
    /// `settings.configurations` generic configurations (seed
    /// `settings.seed`), from `⌈p / 6⌉` poses (a pose's pixel information
    /// has rank 6, [`Self::rank_per_pose`]). The curve's point at this
    /// design's size predicts what [`Self::predicted_error_per_px`] does
    /// (same configurations by default: 1,000, seed 0).
    pub fn how_many(
        &self,
        settings: &CurveSettings,
    ) -> std::result::Result<PoseCountCurve, HowManyError> {
        let rows = self.error_rows(settings.configurations, settings.seed);
        let n_min = fewest_poses(&self.blocks, settings);
        pose_count_curve_on(
            &self.blocks,
            &self.pool,
            settings,
            &rows,
            n_min,
            NoiseUnit::Pixels,
        )
    }
}
