//! A rigid placement as the fixtures and the Python bridge store it.

use serde::{Deserialize, Serialize};

/// A placement: rotation (row-major; its columns are the frame's axes) and
/// position.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    /// Rotation, row-major.
    pub rotation: [[f64; 3]; 3],
    /// Position (metres).
    pub position: [f64; 3],
}
