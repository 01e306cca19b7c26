//! The region a sensor sees: a pose is measurable when its end point lies
//! inside (a box or a viewing cone in the measurement frame).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A simple sensor-visibility region in the measurement frame: a pose is
/// visible when its end point (at nominal parameters) lies inside.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Visibility {
    /// Every pose is visible.
    All,
    /// A viewing cone: apex at the sensor, unit axis, half-angle (radians),
    /// optional maximum range (metres).
    Cone {
        /// Sensor position.
        apex: [f64; 3],
        /// Viewing direction (normalised on use).
        axis: [f64; 3],
        /// Half-angle in radians.
        half_angle: f64,
        /// Maximum distance from the apex.
        max_range: f64,
    },
    /// An axis-aligned box.
    Box {
        /// Lower corner.
        min: [f64; 3],
        /// Upper corner.
        max: [f64; 3],
    },
}

impl Visibility {
    /// Whether a point is visible.
    #[must_use]
    pub fn sees(&self, p: &Vector3<f64>) -> bool {
        match self {
            Visibility::All => true,
            Visibility::Cone {
                apex,
                axis,
                half_angle,
                max_range,
            } => {
                let v = p - Vector3::from(*apex);
                let ax = Vector3::from(*axis).normalize();
                let dist = v.norm();
                dist <= *max_range && (dist == 0.0 || v.dot(&ax) / dist >= half_angle.cos())
            }
            Visibility::Box { min, max } => (0..3).all(|i| p[i] >= min[i] && p[i] <= max[i]),
        }
    }
}
