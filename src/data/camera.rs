//! A camera's observations ([`CameraObservations`]): per pose its joint
//! values and the pixel of every target point it saw.

/// The observations of a camera, by pose.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraObservations {
    /// The file, for messages.
    pub origin: String,
    /// Each pose's id, in the order poses first appear.
    pub pose_ids: Vec<i64>,
    /// Each pose's joint values (radians, metres).
    pub qs: Vec<Vec<f64>>,
    /// Each pose's pixel of every target point (target order), `None`
    /// where the point was not seen.
    pub seen: Vec<Vec<Option<[f64; 2]>>>,
}

impl CameraObservations {
    /// The measured values in the camera sensor's layout
    /// ([`crate::measure::camera`]: `u, v, seen` per target point), pose
    /// after pose.
    #[must_use]
    pub fn values(&self) -> Vec<f64> {
        self.seen
            .iter()
            .flat_map(|s| crate::measure::camera::CameraSensor::value_of(s))
            .collect()
    }

    /// The number of points seen over all poses.
    #[must_use]
    pub fn n_seen(&self) -> usize {
        self.seen.iter().flatten().filter(|s| s.is_some()).count()
    }
}
