//! The region a sensor sees: a pose is measurable when its end point lies
//! inside (a box or a viewing cone in the measurement frame).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A simple sensor-visibility region in the measurement frame: a pose is
/// visible when its end point (at nominal parameters) lies inside.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    /// Checks the region: every number finite; a cone with a nonzero axis, a
    /// half-angle in (0, π] and a range > 0 (an infinite range is "no
    /// limit"); a box with `min ≤ max` on every axis. The message says what
    /// is wrong and what would be accepted.
    pub fn validate(&self) -> Result<(), String> {
        match self {
            Visibility::All => Ok(()),
            Visibility::Cone {
                apex,
                axis,
                half_angle,
                max_range,
            } => {
                if !apex.iter().chain(axis).all(|x| x.is_finite()) {
                    return Err("the cone's apex and axis must be finite numbers".into());
                }
                if axis.iter().all(|&x| x == 0.0) {
                    return Err("the cone axis is zero (give a direction, e.g. [0, 0, 1])".into());
                }
                if !(half_angle.is_finite()
                    && *half_angle > 0.0
                    && *half_angle <= std::f64::consts::PI)
                {
                    return Err(format!(
                        "the cone half-angle {half_angle} must be in (0, π] radians"
                    ));
                }
                if max_range.is_nan() || *max_range <= 0.0 {
                    return Err(format!(
                        "the cone's max_range {max_range} must be > 0 metres"
                    ));
                }
                Ok(())
            }
            Visibility::Box { min, max } => {
                if !min.iter().chain(max).all(|x| x.is_finite()) {
                    return Err("every corner coordinate of the box must be finite".into());
                }
                if let Some(k) = (0..3).find(|&k| min[k] > max[k]) {
                    return Err(format!(
                        "the box is inverted on {}: min {} > max {} (need min <= max)",
                        ["x", "y", "z"][k],
                        min[k],
                        max[k]
                    ));
                }
                Ok(())
            }
        }
    }

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_regions_are_named() {
        let cone = |axis: [f64; 3], half_angle: f64, max_range: f64| Visibility::Cone {
            apex: [0.0; 3],
            axis,
            half_angle,
            max_range,
        };
        assert!(cone([0.0, 0.0, 1.0], 0.3, 10.0).validate().is_ok());
        assert!(cone([0.0, 0.0, 1.0], 0.3, f64::INFINITY).validate().is_ok());
        for (v, want) in [
            (cone([0.0; 3], 0.3, 10.0), "axis is zero"),
            (cone([0.0, 0.0, 1.0], -0.3, 10.0), "half-angle -0.3"),
            (cone([0.0, 0.0, 1.0], 4.0, 10.0), "half-angle 4"),
            (cone([0.0, 0.0, 1.0], 0.3, 0.0), "max_range 0"),
            (cone([f64::NAN, 0.0, 1.0], 0.3, 1.0), "finite"),
            (
                Visibility::Box {
                    min: [0.0, 2.0, 0.0],
                    max: [1.0, 1.0, 1.0],
                },
                "inverted on y: min 2 > max 1",
            ),
        ] {
            let e = v.validate().unwrap_err();
            assert!(e.contains(want), "want '{want}' in: {e}");
        }
    }
}
