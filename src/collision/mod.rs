//! Self-collision and obstacles: the pool filter that removes the poses a
//! real arm cannot take.
//!
//! A [`CollisionModel`] is read from a URDF's `<collision>` elements (boxes,
//! cylinders, spheres, capsules and STL meshes, the meshes found through
//! `package://` or a path relative to the URDF, [`stl`]) on every link of
//! the tree — gripper fingers and other links outside the measured chain
//! included, at joint value 0 (locked joints at their lock value). Placements
//! come from the URDF's own joint origins and axes (`tree`). Meshes are
//! triangle surfaces, as Coal (hpp-fcl) treats them for Pinocchio, so the two
//! agree on what touches; the queries are `parry3d`'s (the nalgebra authors'
//! collision library), after a bounding-sphere test per pair.
//!
//! Pairs checked: every two geometries on different rigid bodies (links
//! joined by fixed joints are one body) that are not adjacent (bodies joined
//! by one joint touch by design) and not listed in an SRDF's
//! `disable_collisions` ([`srdf`]). Obstacles — boxes and a floor plane in
//! the frame of the chain's base link — are checked against every geometry
//! not on the base's rigid body.
//!
//! The filter ([`CollisionFilter`]) stores only its [`CollisionSpec`] (paths
//! and numbers; a design file keeps it) and loads the model once per
//! process, on first use or in [`CollisionFilter::load`], which pool
//! building calls before any candidate is checked.

mod always;
mod build;
mod closest;
pub mod mesh;
mod mesh_tree;
mod model;
mod moves;
pub(crate) mod shapes;
mod sight;
mod spec;
pub mod srdf;
pub mod stl;
pub(crate) mod tree;

pub use closest::Closest;
pub use model::{CollisionModel, ContactPair};
pub use moves::MoveCheck;
pub use spec::{AlwaysTouching, CollisionSpec, Obstacle, TouchingPair};

use serde::{Deserialize, Serialize};
use std::sync::{Arc, OnceLock};

/// The pool filter: a [`CollisionSpec`] and its model, loaded once.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct CollisionFilter {
    /// What is checked.
    #[serde(flatten)]
    pub spec: CollisionSpec,
    #[serde(skip)]
    model: Arc<OnceLock<Result<Arc<CollisionModel>, String>>>,
}

impl CollisionFilter {
    /// A filter for `spec` (nothing loaded yet).
    #[must_use]
    pub fn new(spec: CollisionSpec) -> Self {
        Self {
            spec,
            model: Arc::default(),
        }
    }

    /// The loaded model (loading it on first call), or the load error.
    pub fn load(&self) -> Result<Arc<CollisionModel>, String> {
        self.model
            .get_or_init(|| CollisionModel::load(&self.spec).map(Arc::new))
            .clone()
    }

    /// As [`CollisionFilter::load`], taking the URDF's text from `source`
    /// (a file's path and the text a robot was imported from) when the spec
    /// holds none and names the same file: the file is not read again.
    pub fn load_sharing(
        &self,
        source: Option<(&str, &str)>,
    ) -> Result<Arc<CollisionModel>, String> {
        self.model
            .get_or_init(|| {
                let shared = source.filter(|(path, _)| *path == self.spec.urdf);
                match (&self.spec.text, shared) {
                    (None, Some((_, text))) => CollisionModel::load(&CollisionSpec {
                        text: Some(text.into()),
                        ..self.spec.clone()
                    }),
                    _ => CollisionModel::load(&self.spec),
                }
                .map(Arc::new)
            })
            .clone()
    }

    /// Whether `q` is free; `false` when the model cannot be loaded (pool
    /// building loads it first and reports the error).
    #[must_use]
    pub fn keeps(&self, q: &[f64]) -> bool {
        self.load().is_ok_and(|m| m.contact_key(q).is_none())
    }

    /// The contact that removes `q` ([`CollisionModel::contact_key`]), or
    /// `None` when it is free or the model cannot be loaded.
    #[must_use]
    pub fn contact_key(&self, q: &[f64]) -> Option<usize> {
        self.load().ok().and_then(|m| m.contact_key(q))
    }

    /// `self-collision`, `obstacles`, or `collision` (both).
    #[must_use]
    pub fn kind(&self) -> &'static str {
        let obstacles = !self.spec.obstacles.is_empty() || self.spec.floor.is_some();
        match (self.spec.self_collision, obstacles) {
            (true, false) => "self-collision",
            (false, true) => "obstacles",
            _ => "collision",
        }
    }
}
