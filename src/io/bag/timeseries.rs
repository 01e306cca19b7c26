//! The time series a bag gives: joint values and a measured position (and
//! orientation), each sorted by its header stamp.

/// Joint values over time, in the robot's joint order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointSeries {
    /// Header stamps (s), increasing.
    pub t: Vec<f64>,
    /// The joint values at each stamp (radians, metres).
    pub q: Vec<Vec<f64>>,
}

/// A measured position (and orientation) over time, in the sensor's frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeasSeries {
    /// Header stamps (s), increasing.
    pub t: Vec<f64>,
    /// The positions (metres).
    pub p: Vec<[f64; 3]>,
    /// The orientations `[w, x, y, z]` (empty for points).
    pub r: Vec<[f64; 4]>,
}
