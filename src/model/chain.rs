//! The chain's frames: each frame's parameterisation (DH or Hayati) and
//! the joint, if any, that drives it.

use serde::{Deserialize, Serialize};

/// Parameterization of one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Convention {
    /// Denavit–Hartenberg: `Rz(q+γ) Tz(d) Tx(a) Rx(α)`; has no β.
    Dh,
    /// Hayati: `Rz(q+γ) Tx(a) Rx(α) Ry(β)`, for nearly parallel consecutive axes.
    Hayati,
}

/// How a joint drives its frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Rotation about the frame's base z axis: `Rz(q + γ)`; `q` in radians.
    #[default]
    Revolute,
    /// Translation along the frame's base z axis: `Tz(q + d)`; `q` in metres.
    Prismatic,
}

/// One frame of the chain.
#[derive(Clone, Debug, Serialize)]
pub struct Frame {
    /// Frame label used in parameter names (`a`, `0`, `1`, …).
    pub label: String,
    /// DH or Hayati.
    pub convention: Convention,
    /// Index (0-based) of the joint that drives this frame, or `None` if fixed.
    pub joint: Option<usize>,
    /// Revolute or prismatic; only meaningful when `joint` is `Some`
    /// (fixed frames keep the default, revolute).
    pub joint_kind: JointKind,
}

impl Frame {
    /// A fixed frame (no joint).
    #[must_use]
    pub fn fixed(label: &str, convention: Convention) -> Frame {
        Frame {
            label: label.to_string(),
            convention,
            joint: None,
            joint_kind: JointKind::Revolute,
        }
    }

    /// A frame driven by joint `joint` (0-based) of the given kind.
    #[must_use]
    pub fn driven(label: &str, convention: Convention, joint: usize, kind: JointKind) -> Frame {
        Frame {
            label: label.to_string(),
            convention,
            joint: Some(joint),
            joint_kind: kind,
        }
    }

    /// Whether this frame is driven by a prismatic joint.
    #[must_use]
    pub fn is_prismatic(&self) -> bool {
        self.joint.is_some() && self.joint_kind == JointKind::Prismatic
    }
}
