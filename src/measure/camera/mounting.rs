//! Where a camera and its target are: [`Mounting`].

/// Where the camera and the target are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mounting {
    /// A fixed camera (placement in the base) sees a target on the end
    /// frame.
    EyeToHand,
    /// A camera on the end frame sees a fixed target (placement in the
    /// base).
    EyeInHand,
}

crate::choice!(Mounting { EyeToHand => "eye-to-hand", EyeInHand => "eye-in-hand" });

impl Mounting {
    /// `eye-to-hand` or `eye-in-hand` ([`crate::names::Choice::name`]).
    #[must_use]
    pub fn name(self) -> &'static str {
        crate::names::Choice::name(self)
    }

    /// What the camera's placement is relative to: `base` or `end frame`.
    #[must_use]
    pub fn camera_parent(self) -> &'static str {
        match self {
            Mounting::EyeToHand => "base",
            Mounting::EyeInHand => "end frame",
        }
    }

    /// What the target's placement is relative to.
    #[must_use]
    pub fn target_parent(self) -> &'static str {
        match self {
            Mounting::EyeToHand => "end frame",
            Mounting::EyeInHand => "base",
        }
    }
}
