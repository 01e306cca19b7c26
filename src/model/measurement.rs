//! What is measured at each pose: a point, a full pose, several markers,
//! or a sensor registered beside them.

use serde::{Deserialize, Serialize, Serializer};

/// A sensor registered in `crate::measure` beside the built-in ones
/// ([`MeasurementKind::Registered`]): its name and its rows per pose (the
/// sensor it names has as many, checked when it is built). Serialized as
/// its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SensorKey {
    /// The sensor's name (`height`), as reports name the measurement.
    pub name: &'static str,
    /// Rows of the identification Jacobian per pose.
    pub rows: usize,
}

impl Serialize for SensorKey {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name)
    }
}

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
    /// A sensor registered in `crate::measure` beside these (its own folder
    /// and one registration line): the library's pipelines reach it
    /// through the `Sensor` trait alone. Named by its key: `--robot
    /// ur5:KEY`, a description's `measurement = "KEY"` (both looked up in
    /// the registry by the readers), `Robot::with_measurement`; reports
    /// name it by its key alone (`"measurement": "height"`).
    #[serde(skip_deserializing, untagged)]
    Registered(SensorKey),
}

impl MeasurementKind {
    /// Rows of the identification Jacobian per pose.
    #[must_use]
    pub fn rows(self) -> usize {
        match self {
            MeasurementKind::Point => 3,
            MeasurementKind::Pose => 6,
            MeasurementKind::Markers(k) => 3 * k,
            MeasurementKind::Registered(key) => key.rows,
        }
    }

    /// `point`, `pose`, `markers` or a registered sensor's name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MeasurementKind::Point => "point",
            MeasurementKind::Pose => "pose",
            MeasurementKind::Markers(_) => "markers",
            MeasurementKind::Registered(key) => key.name,
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
