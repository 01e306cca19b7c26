//! Gravity torques of a robot's chain joints from the masses and centres of
//! mass of the links they carry: `τ(q) = ∂V/∂q` with `V = −Σ_k m_k g·c_k(q)`
//! (Pinocchio's `computeGeneralizedGravity`: the torque a motor applies to
//! hold the arm still).
//!
//! The model is the whole link tree of a URDF, not only the chain: a chain
//! joint carries every link below it, links off the chain (a gripper, a
//! head on a torso) included. Joints that are not driven sit at a fixed
//! value (a locked joint at its value, every other at 0). For a revolute
//! joint with unit axis `z` through `o` (world frame), carrying mass `M`
//! with first moment `S = Σ m_k c_k`, `τ = −g·(z × (S − M o))`; for a
//! prismatic one `τ = −M g·z`. Both come from one pass down the tree
//! (placements) and one pass up (subtree masses and moments): no dynamics
//! library is needed for the static case. Pure data and arithmetic:
//! [`crate::io::inertia`] builds it from a URDF.

use super::JointKind;
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use std::collections::HashMap;

/// Standard gravity, m/s² (Pinocchio's default `model.gravity`, −z of the
/// URDF's root).
pub const STANDARD_GRAVITY: f64 = 9.81;

/// One joint of the link tree.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeJoint {
    /// The URDF joint's name.
    pub name: String,
    /// Parent link index.
    pub parent: usize,
    /// Child link index.
    pub child: usize,
    /// Parent link frame → joint frame.
    pub origin: Isometry3<f64>,
    /// Unit axis in the joint frame.
    pub axis: Vector3<f64>,
    /// Revolute or prismatic; `None` for a fixed joint (or any other type,
    /// held at its zero).
    pub kind: Option<JointKind>,
}

/// The mass of one link: kilograms, and its centre in the link's frame
/// (metres).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LinkMass {
    /// Mass, kg.
    pub mass: f64,
    /// Centre of mass in the link frame, m.
    pub com: Vector3<f64>,
}

/// The link tree with its masses, the chain's driven joints and the values
/// every other joint is held at.
#[derive(Clone, Debug, PartialEq)]
pub struct GravityModel {
    links: Vec<String>,
    root: usize,
    /// Joints from the root down: a parent link is placed before its child.
    joints: Vec<TreeJoint>,
    /// Value of each joint of `joints` when not driven.
    held: Vec<f64>,
    /// Per link.
    masses: Vec<LinkMass>,
    /// For each driven chain joint (configuration order), its index in `joints`.
    driven: Vec<usize>,
    /// Gravity in the root frame, m/s².
    gravity: Vector3<f64>,
}

/// Why a gravity model could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GravityError {
    /// The links do not form one tree.
    #[error("{0}")]
    Tree(String),
    /// A driven joint is not in the tree.
    #[error("the chain joint '{0}' is not a joint of the URDF's tree")]
    MissingJoint(String),
    /// A mass is negative or not finite.
    #[error(
        "link '{link}': mass {mass} kg (must be finite and >= 0) or a centre of mass that is not finite"
    )]
    BadMass {
        /// The link.
        link: String,
        /// Its mass.
        mass: f64,
    },
}

impl GravityModel {
    /// A model from the tree's links (by name), its joints (any order),
    /// each link's mass (missing links weigh nothing), the driven chain
    /// joints by name in configuration order and the values of held joints
    /// by name (others at 0). Gravity is `−9.81 m/s²` along the root's z.
    pub fn new(
        links: Vec<String>,
        joints: Vec<TreeJoint>,
        masses: &HashMap<String, LinkMass>,
        driven: &[String],
        held: &HashMap<String, f64>,
    ) -> Result<GravityModel, GravityError> {
        let (root, joints) = order(&links, joints)?;
        let mut m = vec![LinkMass::default(); links.len()];
        for (i, l) in links.iter().enumerate() {
            if let Some(x) = masses.get(l) {
                if !(x.mass.is_finite() && x.mass >= 0.0 && x.com.iter().all(|v| v.is_finite())) {
                    return Err(GravityError::BadMass {
                        link: l.clone(),
                        mass: x.mass,
                    });
                }
                m[i] = *x;
            }
        }
        let driven = driven
            .iter()
            .map(|n| {
                joints
                    .iter()
                    .position(|j| &j.name == n && j.kind.is_some())
                    .ok_or_else(|| GravityError::MissingJoint(n.clone()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let held = joints
            .iter()
            .map(|j| held.get(&j.name).copied().unwrap_or(0.0))
            .collect();
        Ok(GravityModel {
            links,
            root,
            joints,
            held,
            masses: m,
            driven,
            gravity: Vector3::new(0.0, 0.0, -STANDARD_GRAVITY),
        })
    }

    /// Number of driven joints (the length of a configuration).
    #[must_use]
    pub fn dof(&self) -> usize {
        self.driven.len()
    }

    /// The names of the driven joints, in configuration order.
    #[must_use]
    pub fn driven_names(&self) -> Vec<&str> {
        self.driven
            .iter()
            .map(|&k| self.joints[k].name.as_str())
            .collect()
    }

    /// Adds a point mass `mass` (kg) at `at` (m, in the link's frame) to
    /// the link `link`; `false` if there is no such link.
    pub fn add_point_mass(&mut self, link: &str, mass: f64, at: Vector3<f64>) -> bool {
        let Some(i) = self.links.iter().position(|l| l == link) else {
            return false;
        };
        let m = &mut self.masses[i];
        let total = m.mass + mass;
        if total > 0.0 {
            m.com = (m.com * m.mass + at * mass) / total;
        }
        m.mass = total;
        true
    }

    /// The mass each driven joint carries (kg): every link below it.
    #[must_use]
    pub fn carried_mass(&self) -> Vec<f64> {
        let mut below = self.masses.iter().map(|m| m.mass).collect::<Vec<_>>();
        for j in self.joints.iter().rev() {
            below[j.parent] += below[j.child];
        }
        self.driven
            .iter()
            .map(|&k| below[self.joints[k].child])
            .collect()
    }

    /// Gravity torques (N·m for a revolute joint, N for a prismatic one) of
    /// the driven joints at configuration `q` (radians, metres), written into
    /// `out`.
    pub fn torques(&self, q: &[f64], out: &mut [f64]) {
        debug_assert_eq!(q.len(), self.driven.len());
        debug_assert_eq!(out.len(), self.driven.len());
        let mut values = self.held.clone();
        for (&k, &v) in self.driven.iter().zip(q) {
            values[k] = v;
        }
        let n = self.links.len();
        let mut place = vec![Isometry3::identity(); n];
        let mut joint_frames = Vec::with_capacity(self.joints.len());
        place[self.root] = Isometry3::identity();
        for (j, &v) in self.joints.iter().zip(&values) {
            let frame = place[j.parent] * j.origin;
            joint_frames.push(frame);
            place[j.child] = frame * motion(j, v);
        }
        // Subtree masses and first moments, from the leaves up.
        let mut mass: Vec<f64> = self.masses.iter().map(|m| m.mass).collect();
        let mut moment: Vec<Vector3<f64>> = (0..n)
            .map(|i| place[i].transform_point(&self.masses[i].com.into()).coords * mass[i])
            .collect();
        for j in self.joints.iter().rev() {
            mass[j.parent] += mass[j.child];
            let s = moment[j.child];
            moment[j.parent] += s;
        }
        for (o, &k) in out.iter_mut().zip(&self.driven) {
            let j = &self.joints[k];
            let f = &joint_frames[k];
            let z = f.rotation * j.axis;
            let (m, s) = (mass[j.child], moment[j.child]);
            *o = match j.kind {
                Some(JointKind::Revolute) => {
                    -self.gravity.dot(&z.cross(&(s - f.translation.vector * m)))
                }
                Some(JointKind::Prismatic) => -m * self.gravity.dot(&z),
                None => 0.0,
            };
        }
    }

    /// [`GravityModel::torques`] as a new vector.
    #[must_use]
    pub fn torques_at(&self, q: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.driven.len()];
        self.torques(q, &mut out);
        out
    }

    /// Potential energy `V(q) = −Σ m_k g·c_k` (J), for checks.
    #[must_use]
    pub fn potential(&self, q: &[f64]) -> f64 {
        let mut values = self.held.clone();
        for (&k, &v) in self.driven.iter().zip(q) {
            values[k] = v;
        }
        let mut place = vec![Isometry3::identity(); self.links.len()];
        for (j, &v) in self.joints.iter().zip(&values) {
            place[j.child] = place[j.parent] * j.origin * motion(j, v);
        }
        place
            .iter()
            .zip(&self.masses)
            .map(|(p, m)| -m.mass * self.gravity.dot(&p.transform_point(&m.com.into()).coords))
            .sum()
    }
}

fn motion(j: &TreeJoint, v: f64) -> Isometry3<f64> {
    match j.kind {
        Some(JointKind::Revolute) => Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&Unit::new_normalize(j.axis), v),
        ),
        Some(JointKind::Prismatic) => Isometry3::from_parts(
            Translation3::from(j.axis.normalize() * v),
            UnitQuaternion::identity(),
        ),
        None => Isometry3::identity(),
    }
}

/// The root link and the joints from the root down; errors name a link
/// with two parents, several roots or a loop.
fn order(
    links: &[String],
    joints: Vec<TreeJoint>,
) -> Result<(usize, Vec<TreeJoint>), GravityError> {
    let n = links.len();
    let mut parent_of: Vec<Option<usize>> = vec![None; n];
    for (k, j) in joints.iter().enumerate() {
        if j.parent >= n || j.child >= n {
            return Err(GravityError::Tree(format!(
                "joint '{}' names a link that is not in the tree",
                j.name
            )));
        }
        if let Some(o) = parent_of[j.child] {
            return Err(GravityError::Tree(format!(
                "link '{}' is the child of two joints ('{}' and '{}')",
                links[j.child], joints[o].name, j.name
            )));
        }
        parent_of[j.child] = Some(k);
    }
    let roots: Vec<usize> = (0..n).filter(|&l| parent_of[l].is_none()).collect();
    if roots.len() != 1 {
        return Err(GravityError::Tree(format!(
            "the links form {} trees, not one",
            roots.len()
        )));
    }
    let mut out = Vec::with_capacity(joints.len());
    let mut frontier = vec![roots[0]];
    while let Some(l) = frontier.pop() {
        for j in joints.iter().filter(|j| j.parent == l) {
            out.push(j.clone());
            frontier.push(j.child);
        }
    }
    if out.len() != joints.len() {
        return Err(GravityError::Tree("the joints form a loop".into()));
    }
    Ok((roots[0], out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joint(name: &str, parent: usize, child: usize, xyz: [f64; 3], axis: [f64; 3]) -> TreeJoint {
        TreeJoint {
            name: name.into(),
            parent,
            child,
            origin: Isometry3::from_parts(
                Translation3::new(xyz[0], xyz[1], xyz[2]),
                UnitQuaternion::from_euler_angles(0.3, -0.2, 0.1),
            ),
            axis: Vector3::from(axis).normalize(),
            kind: Some(JointKind::Revolute),
        }
    }

    /// A 3-joint arm with a branch (a "gripper" off link 2) and a prismatic joint.
    fn model() -> GravityModel {
        let links: Vec<String> = ["base", "l1", "l2", "l3", "grip"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let mut j3 = joint("j3", 2, 3, [0.0, 0.3, 0.1], [0.0, 0.0, 1.0]);
        j3.kind = Some(JointKind::Prismatic);
        let mut g = joint("g", 2, 4, [0.1, 0.0, 0.05], [1.0, 0.0, 0.0]);
        g.kind = None;
        let joints = vec![
            g,
            TreeJoint {
                origin: Isometry3::translation(0.0, 0.0, 0.3),
                ..joint("j1", 0, 1, [0.0; 3], [0.0, 0.0, 1.0])
            },
            j3,
            joint("j2", 1, 2, [0.1, 0.0, 0.2], [0.0, 1.0, 0.2]),
        ];
        let masses: HashMap<String, LinkMass> = [
            ("l1", 2.0, [0.0, 0.05, 0.1]),
            ("l2", 1.5, [0.2, 0.0, 0.0]),
            ("l3", 0.7, [0.0, 0.1, 0.0]),
            ("grip", 0.4, [0.03, 0.0, 0.02]),
        ]
        .into_iter()
        .map(|(l, m, c)| {
            (
                l.to_string(),
                LinkMass {
                    mass: m,
                    com: Vector3::from(c),
                },
            )
        })
        .collect();
        let driven: Vec<String> = ["j1", "j2", "j3"].iter().map(|s| s.to_string()).collect();
        GravityModel::new(links, joints, &masses, &driven, &HashMap::new()).unwrap()
    }

    #[test]
    fn torques_are_the_gradient_of_the_potential() {
        let m = model();
        for k in 0..20 {
            let q: Vec<f64> = (0..3)
                .map(|j| ((k * 5 + j * 3) as f64 * 0.7).sin())
                .collect();
            let tau = m.torques_at(&q);
            for j in 0..3 {
                let h = 1e-6;
                let (mut a, mut b) = (q.clone(), q.clone());
                a[j] += h;
                b[j] -= h;
                let fd = (m.potential(&a) - m.potential(&b)) / (2.0 * h);
                // Central differences of a smooth O(10 J) function: error
                // O(h²·V''') ≈ 1e-11 plus rounding 1e-16·10/1e-6 = 1e-9.
                assert!((fd - tau[j]).abs() < 1e-7, "joint {j}: {fd} vs {}", tau[j]);
            }
            // The first joint is vertical: gravity never turns it.
            assert!(tau[0].abs() < 1e-12);
        }
    }

    #[test]
    fn a_payload_adds_its_torque_and_the_carried_mass() {
        let mut m = model();
        let before = m.carried_mass();
        assert!((before[0] - 4.6).abs() < 1e-12);
        assert!((before[1] - 2.6).abs() < 1e-12);
        let q = [0.3, 0.8, 0.05];
        let t0 = m.torques_at(&q);
        assert!(m.add_point_mass("l3", 1.0, Vector3::new(0.0, 0.2, 0.0)));
        assert!(!m.add_point_mass("nowhere", 1.0, Vector3::zeros()));
        let t1 = m.torques_at(&q);
        assert!((m.carried_mass()[2] - 1.7).abs() < 1e-12);
        assert!((t1[1] - t0[1]).abs() > 1e-3);
    }
}
