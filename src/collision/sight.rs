//! Line of sight: whether segments (rays from a camera's centre to the
//! points of its target) cross the robot's collision geometry or an
//! obstacle at a configuration.

use super::CollisionModel;
use parry3d_f64::na::{Isometry3, Point3};
use parry3d_f64::query::Ray;

impl CollisionModel {
    /// The rigid body of the chain's tip link (the link a camera or a
    /// target on the flange rides on, and every link fixed to it).
    fn tip_body(&self) -> usize {
        self.drives
            .last()
            .map_or(self.tree.body[self.tree.root], |&j| j + 1)
    }

    /// For each of `points` (the chain's base-link frame, metres) whether
    /// the segment from `eye` to it, stopped `stop` metres short of the
    /// point, crosses a collision geometry of the robot at configuration
    /// `q` (or an obstacle of the spec): `true` when blocked. A geometry
    /// on the tip's rigid body is not checked when `skip_tip` is set (what
    /// a camera or target on the flange is fixed to). A segment that starts
    /// inside a primitive shape is blocked; a mesh is a surface (as Coal
    /// treats it), crossed or not.
    #[must_use]
    pub fn blocked_rays(
        &self,
        q: &[f64],
        eye: &Point3<f64>,
        points: &[Point3<f64>],
        stop: f64,
        skip_tip: bool,
    ) -> Vec<bool> {
        let links = self.link_placements(q);
        let base = links[self.base];
        let tip = self.tip_body();
        let shapes: Vec<(Isometry3<f64>, usize)> = self
            .geoms
            .iter()
            .enumerate()
            .filter(|(_, g)| !(skip_tip && self.tree.body[g.link] == tip))
            .map(|(k, g)| (links[g.link] * g.origin, k))
            .collect();
        let from = base * eye;
        points
            .iter()
            .map(|p| {
                let to = base * p;
                let d = to - from;
                let len = d.norm();
                if len <= stop {
                    return false;
                }
                let ray = Ray::new(from, d / len);
                let reach = len - stop;
                let by_geometry = shapes.iter().any(|(pose, k)| {
                    let g = &self.geoms[*k];
                    segment_near(&from, &ray, reach, &(pose * g.center), g.radius)
                        && g.shape.cast_ray(pose, &ray, reach, true).is_some()
                });
                by_geometry
                    || self
                        .obstacles
                        .iter()
                        .any(|(_, pose, s)| s.cast_ray(pose, &ray, reach, true).is_some())
            })
            .collect()
    }
}

/// Whether the segment `from + t·dir`, `0 ≤ t ≤ reach`, passes within
/// `radius` of `centre` (a bounding-sphere test before the exact cast).
fn segment_near(
    from: &Point3<f64>,
    ray: &Ray,
    reach: f64,
    centre: &Point3<f64>,
    radius: f64,
) -> bool {
    let t = (centre - from).dot(&ray.dir).clamp(0.0, reach);
    (from + ray.dir * t - centre).norm() <= radius
}
