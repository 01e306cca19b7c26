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
        let skip: Vec<usize> = if skip_tip {
            vec![self.tip_body()]
        } else {
            Vec::new()
        };
        self.cast(&links, &links[self.base], &skip, eye, points, stop)
    }

    /// [`Self::blocked_rays`] for a camera on the robot's own link `link`
    /// (a head camera): `eye` and `points` are in that link's frame, and
    /// neither its rigid body (the camera is fixed to it) nor the tip's
    /// (the target's carrier) is checked. `None` when the model has no
    /// link of that name.
    #[must_use]
    pub fn blocked_rays_from_link(
        &self,
        q: &[f64],
        link: &str,
        eye: &Point3<f64>,
        points: &[Point3<f64>],
        stop: f64,
    ) -> Option<Vec<bool>> {
        let at = *self.tree.index.get(link)?;
        let links = self.link_placements(q);
        let skip = [self.tip_body(), self.tree.body[at]];
        Some(self.cast(&links, &links[at], &skip, eye, points, stop))
    }

    /// Whether the model has a link of this name.
    #[must_use]
    pub fn has_link(&self, link: &str) -> bool {
        self.tree.index.contains_key(link)
    }

    /// The rays of [`Self::blocked_rays`] from `eye` to `points`, both in
    /// the frame placed at `frame` (root frame), against the geometries at
    /// the link placements `links` except those on the rigid bodies
    /// `skip`, and the obstacles.
    fn cast(
        &self,
        links: &[Isometry3<f64>],
        frame: &Isometry3<f64>,
        skip: &[usize],
        eye: &Point3<f64>,
        points: &[Point3<f64>],
        stop: f64,
    ) -> Vec<bool> {
        let shapes: Vec<(Isometry3<f64>, usize)> = self
            .geoms
            .iter()
            .enumerate()
            .filter(|(_, g)| !skip.contains(&self.tree.body[g.link]))
            .map(|(k, g)| (links[g.link] * g.origin, k))
            .collect();
        let from = frame * eye;
        points
            .iter()
            .map(|p| {
                let to = frame * p;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::CollisionSpec;

    /// base –j1 (revolute about z)→ arm, a 0.1 m box centred 0.5 m out
    /// along the arm's x; –j2 (revolute)→ tip, carrying a 0.2 m box at its
    /// origin (the carrier of a target).
    fn model() -> CollisionModel {
        let text = r#"<robot name="t">
<link name="base"/>
<link name="arm"><collision><origin xyz="0.5 0 0"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
<link name="tip"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="arm"/><child link="tip"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#;
        CollisionModel::load(&CollisionSpec {
            urdf: "t.urdf".into(),
            text: Some(text.into()),
            joints: vec!["j1".into(), "j2".into()],
            base: Some("base".into()),
            ..CollisionSpec::default()
        })
        .unwrap()
    }

    /// A ray along x from the base's origin crosses the arm's box (at x
    /// 0.45–0.55) when j1 = 0 and misses it when j1 turns the arm by 90°;
    /// a ray ending on the box's face (x = 0.45) is blocked only without
    /// the stop; the tip's own box (around x = 1) blocks only when it is
    /// not skipped; a ray starting inside a box is blocked.
    #[test]
    fn rays_are_blocked_by_the_geometry_between() {
        let m = model();
        let eye = Point3::origin();
        let far = Point3::new(2.0, 0.0, 0.0);
        let side = Point3::new(0.0, 2.0, 0.0);
        assert_eq!(
            m.blocked_rays(&[0.0, 0.0], &eye, &[far, side], 1e-3, true),
            [true, false]
        );
        // Turned by 90°: the arm's box now lies on the y axis.
        assert_eq!(
            m.blocked_rays(
                &[std::f64::consts::FRAC_PI_2, 0.0],
                &eye,
                &[far, side],
                1e-3,
                true
            ),
            [false, true]
        );
        // Ending on the face at x = 0.45: stopped 1 mm short it is free;
        // without the stop the face is reached.
        let face = Point3::new(0.45, 0.0, 0.0);
        assert_eq!(
            m.blocked_rays(
                &[1.0, 0.0],
                &eye,
                &[Point3::new(0.45 * 1f64.cos(), 0.45 * 1f64.sin(), 0.0)],
                1e-3,
                true
            ),
            [false]
        );
        assert_eq!(
            m.blocked_rays(&[0.0, 0.0], &eye, &[face], 1e-3, true),
            [false]
        );
        assert_eq!(
            m.blocked_rays(&[0.0, 0.0], &eye, &[face], 0.0, true),
            [true]
        );
        // The tip's box (x 0.9–1.1 at j1 = 0): a ray from above to a point
        // past it, with the arm's box out of the way (z = 0.3 above it).
        let (hi, past) = (Point3::new(1.0, 0.0, 0.5), Point3::new(1.0, 0.0, -0.5));
        assert_eq!(
            m.blocked_rays(&[0.0, 0.0], &hi, &[past], 1e-3, true),
            [false]
        );
        assert_eq!(
            m.blocked_rays(&[0.0, 0.0], &hi, &[past], 1e-3, false),
            [true]
        );
        // Rays from the tip's own frame (a camera on the tip's link): the
        // arm's box, 0.5 m behind the tip along the arm, is at the tip's
        // (-0.5, 0, 0) when j2 = 0 and at (0, 0.5, 0) when j2 turns the
        // tip by 90° (whatever j1 is); the tip's own box is not checked.
        let (back, left) = (Point3::new(-2.0, 0.0, 0.0), Point3::new(0.0, 2.0, 0.0));
        for j1 in [0.0, 1.0] {
            assert_eq!(
                m.blocked_rays_from_link(&[j1, 0.0], "tip", &eye, &[back, left], 1e-3),
                Some(vec![true, false])
            );
            assert_eq!(
                m.blocked_rays_from_link(
                    &[j1, std::f64::consts::FRAC_PI_2],
                    "tip",
                    &eye,
                    &[back, left],
                    1e-3
                ),
                Some(vec![false, true])
            );
        }
        assert!(
            m.blocked_rays_from_link(&[0.0, 0.0], "head", &eye, &[far], 1e-3)
                .is_none()
        );
        // From inside the arm's box outwards, away from everything.
        let inside = Point3::new(0.5, 0.0, 0.0);
        assert_eq!(
            m.blocked_rays(
                &[0.0, 0.0],
                &inside,
                &[Point3::new(0.5, 0.0, 3.0)],
                1e-3,
                true
            ),
            [true]
        );
    }
}
