//! The collision filters of a pool, from what the user chose (self-collision,
//! an SRDF's pairs, obstacles, a floor, a clearance) and the URDF chain the
//! robot was imported from: one construction, and one check of the values
//! ([`CollisionChoice::validate`]), for the command line and the Python
//! package (each checks that the files it names exist, in its own terms).

use super::UrdfChain;
use crate::collision::{AlwaysTouching, CollisionFilter, CollisionSpec, Obstacle};
use crate::pool::PoolFilter;
use crate::pool::line_of_sight::LineOfSight;

/// What the user asked the collision check to do; the defaults check nothing.
#[derive(Clone, Debug, Default)]
pub struct CollisionChoice {
    /// Check every pair of the chain's links (less the SRDF's pairs).
    pub self_collision: bool,
    /// Skip pairs of links that touch at every sampled configuration (with
    /// `self_collision`).
    pub skip_always_touching: bool,
    /// An SRDF whose `disable_collisions` pairs are not checked.
    pub srdf: Option<String>,
    /// Directories `package://` mesh paths resolve in.
    pub package_dirs: Vec<String>,
    /// Distance below which two bodies count as touching, metres.
    pub clearance: f64,
    /// Obstacles in the base frame.
    pub obstacles: Vec<Obstacle>,
    /// A floor at this height of the base frame, metres.
    pub floor: Option<f64>,
}

impl CollisionChoice {
    /// Whether anything is to be checked.
    #[must_use]
    pub fn any(&self) -> bool {
        self.self_collision || !self.obstacles.is_empty() || self.floor.is_some()
    }

    /// Refuses a floor that is not finite, a clearance that is no distance
    /// ≥ 0, a clearance with nothing to check, and an SRDF's pairs or
    /// always-touching pairs skipped without a self-collision check.
    pub fn validate(&self) -> Result<(), crate::error::SettingError> {
        use crate::error::SettingError;
        if let Some(z) = self.floor.filter(|z| !z.is_finite()) {
            return Err(SettingError::new(
                "floor",
                z,
                "not a finite height (metres)",
            ));
        }
        if !(self.clearance.is_finite() && self.clearance >= 0.0) {
            return Err(SettingError::new(
                "clearance",
                self.clearance,
                "a distance >= 0 metres",
            ));
        }
        if self.clearance > 0.0 && !self.any() {
            return Err(SettingError::because(
                "clearance",
                "applies with `self_collision`, `obstacle` or `floor`",
            ));
        }
        if self.skip_always_touching && !self.self_collision {
            return Err(SettingError::because(
                "skip_always_touching",
                "leaves pairs of links unchecked by `self_collision`, which is not given",
            ));
        }
        if self.srdf.is_some() && !self.self_collision {
            return Err(SettingError::because(
                "srdf",
                "lists pairs of links for `self_collision`, which is not given",
            ));
        }
        Ok(())
    }

    /// The pool filters of this choice for the robot of `chain`: one for
    /// self-collision, one for obstacles and the floor (each only when
    /// asked for), in that order.
    #[must_use]
    pub fn filters(&self, chain: UrdfChain) -> Vec<PoolFilter> {
        let base_spec = CollisionSpec {
            urdf: chain.file,
            text: Some(chain.text),
            joints: chain.joints,
            lock: chain.lock,
            base: Some(chain.base),
            srdf: self.srdf.clone(),
            package_dirs: self.package_dirs.clone(),
            clearance: self.clearance,
            ..CollisionSpec::default()
        };
        let mut out = Vec::new();
        if self.self_collision {
            out.push(PoolFilter::Collision(CollisionFilter::new(CollisionSpec {
                self_collision: true,
                always_touching: self.skip_always_touching.then(AlwaysTouching::default),
                ..base_spec.clone()
            })));
        }
        if !self.obstacles.is_empty() || self.floor.is_some() {
            out.push(PoolFilter::Collision(CollisionFilter::new(CollisionSpec {
                obstacles: self.obstacles.clone(),
                floor: self.floor,
                srdf: None,
                ..base_spec
            })));
        }
        out
    }

    /// The line of sight of a camera pool for the robot of `chain`
    /// ([`LineOfSight`]): rays against its collision geometry (meshes
    /// found in this choice's package directories) and this choice's
    /// obstacles and floor; for a camera on the robot's own link
    /// `camera_link` (the chain from it, [`super::urdf_branch`]), cast
    /// from that link, obstacles and the floor in the tree's root `root`.
    #[must_use]
    pub fn line_of_sight(
        &self,
        chain: UrdfChain,
        camera_link: Option<(&str, String)>,
    ) -> LineOfSight {
        let base = camera_link
            .as_ref()
            .map_or(chain.base, |(_, root)| root.clone());
        let spec = CollisionSpec {
            urdf: chain.file,
            text: Some(chain.text),
            joints: chain.joints,
            lock: chain.lock,
            base: Some(base),
            package_dirs: self.package_dirs.clone(),
            obstacles: self.obstacles.clone(),
            floor: self.floor,
            ..CollisionSpec::default()
        };
        match camera_link {
            Some((link, _)) => LineOfSight::from_link(spec, link),
            None => LineOfSight::new(spec),
        }
    }
}
