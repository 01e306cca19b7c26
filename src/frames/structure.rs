//! What a calibrated model does to the relations between consecutive joint
//! axes that closed-form inverse kinematics rely on (the UR family's
//! solver, IKFast, ik-geo assume parallel, intersecting or perpendicular
//! axes where the design has them).

use super::CalibratedFrames;
use nalgebra::{Isometry3, Vector3};
use serde::Serialize;

/// Angle (radians) and distance (metres, relative to the chain's length)
/// below which a nominal relation holds: rounding of a URDF's decimals
/// (1e-9) is far below, a designed offset of 0.1 mm far above.
const EXACT: f64 = 1e-9;

/// How two consecutive joint axes relate.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct AxisRelation {
    /// The first joint.
    pub from: String,
    /// The next joint.
    pub to: String,
    /// The nominal relation: `parallel`, `coaxial`, `intersecting`,
    /// `perpendicular and intersecting`, `perpendicular` or `skew`.
    pub nominal: String,
    /// Angle between the axes (degrees, 0–90), nominal and calibrated.
    pub angle_deg: [f64; 2],
    /// Distance between the axis lines (mm), nominal and calibrated.
    pub distance_mm: [f64; 2],
    /// Whether the calibrated model keeps the nominal relation exactly.
    pub kept: bool,
}

/// The axis lines (point, unit direction) of the joints at `q = 0`.
fn lines(origins: &[Isometry3<f64>], axes: &[Vector3<f64>]) -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let mut at = Isometry3::identity();
    origins
        .iter()
        .zip(axes)
        .map(|(o, a)| {
            at *= o;
            (at.translation.vector, at.rotation * a)
        })
        .collect()
}

/// Angle (0–π/2) and distance between two lines.
fn relation(a: &(Vector3<f64>, Vector3<f64>), b: &(Vector3<f64>, Vector3<f64>)) -> (f64, f64) {
    let c = a.1.cross(&b.1);
    let angle = c.norm().atan2(a.1.dot(&b.1).abs());
    let w = b.0 - a.0;
    let dist = if c.norm() > 1e-12 {
        w.dot(&c).abs() / c.norm()
    } else {
        (w - a.1 * w.dot(&a.1)).norm()
    };
    (angle, dist)
}

fn name(angle: f64, dist: f64, length: f64) -> &'static str {
    let parallel = angle < EXACT;
    let perpendicular = (std::f64::consts::FRAC_PI_2 - angle).abs() < EXACT;
    let meet = dist < EXACT * length;
    match (parallel, perpendicular, meet) {
        (true, _, true) => "coaxial",
        (true, _, false) => "parallel",
        (_, true, true) => "perpendicular and intersecting",
        (_, true, false) => "perpendicular",
        (_, _, true) => "intersecting",
        _ => "skew",
    }
}

/// The relation of each pair of consecutive driven joints, nominal and
/// calibrated, at `q = 0`; `before[k]` is the fixed transform before joint
/// `k`'s origin ([`super::chain::UrdfFrames::before`]).
#[must_use]
pub fn relations(f: &CalibratedFrames, before: &[Isometry3<f64>]) -> Vec<AxisRelation> {
    let chain = |cal: bool| -> Vec<Isometry3<f64>> {
        f.joints
            .iter()
            .zip(before)
            .map(|(j, b)| b * if cal { j.calibrated } else { j.nominal })
            .collect()
    };
    let axes: Vec<Vector3<f64>> = f.joints.iter().map(|j| j.axis).collect();
    let (nom, cal) = (lines(&chain(false), &axes), lines(&chain(true), &axes));
    let length: f64 = chain(false)
        .iter()
        .map(|o| o.translation.vector.norm())
        .sum::<f64>()
        .max(1e-3);
    (1..f.joints.len())
        .map(|k| {
            let (an, dn) = relation(&nom[k - 1], &nom[k]);
            let (ac, mut dc) = relation(&cal[k - 1], &cal[k]);
            let nominal = name(an, dn, length);
            if matches!(nominal, "parallel" | "coaxial") {
                // Nominally parallel axes that are no longer are skew, and
                // their common normal may lie far away: the distance that
                // compares with the nominal one is the next axis's distance
                // from the first joint's origin.
                let (p, (q, u)) = (cal[k - 1].0, cal[k]);
                let w = p - q;
                dc = (w - u * w.dot(&u)).norm();
            }
            let kept = match nominal {
                "coaxial" => ac < EXACT && dc < EXACT * length,
                "parallel" => ac < EXACT,
                "perpendicular and intersecting" => {
                    (std::f64::consts::FRAC_PI_2 - ac).abs() < EXACT && dc < EXACT * length
                }
                "perpendicular" => (std::f64::consts::FRAC_PI_2 - ac).abs() < EXACT,
                "intersecting" => dc < EXACT * length,
                _ => true,
            };
            AxisRelation {
                from: f.joints[k - 1].name.clone(),
                to: f.joints[k].name.clone(),
                nominal: nominal.to_string(),
                angle_deg: [an.to_degrees(), ac.to_degrees()],
                distance_mm: [dn * 1e3, dc * 1e3],
                kept,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frames::JointOrigin;
    use crate::model::JointKind;
    use nalgebra::{Translation3, UnitQuaternion};

    fn joint(name: &str, nominal: Isometry3<f64>, calibrated: Isometry3<f64>) -> JointOrigin {
        JointOrigin {
            name: name.into(),
            kind: JointKind::Revolute,
            axis: Vector3::z(),
            nominal,
            calibrated,
        }
    }

    #[test]
    fn a_tilted_parallel_pair_is_reported_with_its_angle_and_distance() {
        let shifted =
            Isometry3::from_parts(Translation3::new(1.0, 0.0, 0.0), UnitQuaternion::identity());
        let tilted = shifted * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.01);
        let f = CalibratedFrames {
            measurement: Isometry3::identity(),
            tool: Isometry3::identity(),
            markers: Vec::new(),
            joints: vec![
                joint("a", Isometry3::identity(), Isometry3::identity()),
                joint("b", shifted, tilted),
                joint("c", shifted, shifted),
            ],
        };
        let r = relations(&f, &[Isometry3::identity(); 3]);
        // a → b: parallel 1 m apart; calibrated 0.01 rad apart, and b's
        // axis still 1 m from a's origin (the tilt is about b's origin).
        assert_eq!(r[0].nominal, "parallel");
        assert!(!r[0].kept);
        assert!((r[0].angle_deg[1] - 0.01f64.to_degrees()).abs() < 1e-12);
        assert!((r[0].distance_mm[1] - 1000.0).abs() < 1e-9);
        // b → c: c is placed from b's calibrated (tilted) frame with the
        // same origin as nominal: the pair keeps its relation.
        assert_eq!(r[1].nominal, "parallel");
        assert!(r[1].kept, "{:?}", r[1]);
    }
}
