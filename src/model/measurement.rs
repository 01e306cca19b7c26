//! What is measured at each pose: a point, a full pose, or several markers.

use serde::{Deserialize, Serialize};

/// What is measured at each pose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MeasurementKind {
    /// The position of the end point: 3 rows per pose.
    Point,
    /// The position and orientation of the end frame: 6 rows per pose,
    /// position first, then the orientation (an angular velocity: the rows of
    /// a rotation parameter about unit axis `u` are `u`, those of a
    /// translation parameter are 0).
    Pose,
    /// `K ≥ 1` markers fixed to the last frame, each measured as a point:
    /// `3K` rows per pose. Marker `k` sits at `p + R o_k` with its own offset
    /// `o_k` ([`ParamTable::markers`](super::ParamTable::markers)), three unknowns per marker after the
    /// robot's.
    Markers(usize),
}

impl MeasurementKind {
    /// Rows of the identification Jacobian per pose.
    #[must_use]
    pub fn rows(self) -> usize {
        match self {
            MeasurementKind::Point => 3,
            MeasurementKind::Pose => 6,
            MeasurementKind::Markers(k) => 3 * k,
        }
    }

    /// `point`, `pose` or `markers`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MeasurementKind::Point => "point",
            MeasurementKind::Pose => "pose",
            MeasurementKind::Markers(_) => "markers",
        }
    }

    /// Markers per pose: `K` for [`MeasurementKind::Markers`], else 0
    /// (the end point itself is measured, with no offset unknowns).
    #[must_use]
    pub fn markers(self) -> usize {
        match self {
            MeasurementKind::Markers(k) => k,
            _ => 0,
        }
    }
}
