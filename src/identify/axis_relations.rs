//! Calibration that keeps closed-form inverse kinematics: the unknowns
//! restricted to those that leave the nominal model's axis relations as
//! they are (parallel, perpendicular and intersecting consecutive joint
//! axes, and three consecutive axes meeting in one point, as a spherical
//! wrist's do), so that the UR family's solver, IKFast and Pieper-type
//! solvers still apply to the calibrated model.
//!
//! In a chain's frames (DH `Rz(θ) Tz(d) Tx(a) Rx(α)`, Hayati `Rz(θ) Tx(a)
//! Rx(α) Ry(β)`) the frame of joint `k` maps joint `k`'s axis onto joint
//! `k + 1`'s, and each relation is carried by one parameter of it:
//!
//! * the angle between the axes by its twist α (and a Hayati frame's β):
//!   held when the axes are nominally parallel or perpendicular;
//! * the distance between the axis lines by its length `a`: held when the
//!   axes nominally intersect (both joints revolute: a prismatic joint's
//!   axis is a direction, not a line);
//! * where three consecutive revolute axes `k`, `k + 1`, `k + 2` meet in one
//!   point, the two meeting points lie `d` apart along axis `k + 1`: frame
//!   `k + 1`'s `d` is held as well.
//!
//! Holding a parameter at its nominal value is the linear constraint
//! `δp = 0` on its column of the identification Jacobian; the others
//! (joint offsets `γ`, the offsets `d` along an axis, lengths between
//! parallel or skew axes, the measurement frame and the tool) are fitted.
//! A fixed frame between two joints (a chain whose URDF keeps a fixed joint
//! there) carries the relation with the joint frame before it: all of its
//! parameters are held with that frame's α, β and `a`.

use crate::model::{Convention, JointKind, ParamId, Robot, Symbol};
use serde::Serialize;

/// Angle (radians) and distance (metres, relative to the chain's length)
/// below which a nominal relation holds: the rounding of a URDF's decimals
/// (1e-9) is far below it, a designed offset of 0.1 mm far above.
const EXACT: f64 = 1e-9;

/// A nominal relation between consecutive joint axes that the restricted
/// fit keeps, and the parameters it holds for it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HeldRelation {
    /// The first joint (URDF name, or the frame's label).
    pub from: String,
    /// The next joint.
    pub to: String,
    /// The relation: `parallel`, `perpendicular`, `intersecting`,
    /// `perpendicular and intersecting`, `coaxial`, or `three axes meeting
    /// in one point` (`from`, the joint between, and `to`).
    pub relation: String,
    /// The parameters held at their nominal values for it (names as in the
    /// estimate), unknowns of the robot only.
    pub held: Vec<String>,
}

/// What the nominal parameters of joint frame `f` say of the axes of its
/// joint and the next: (parallel, perpendicular, intersecting).
fn relation_of(robot: &Robot, f: usize, length: f64) -> (bool, bool, bool) {
    let row = robot.nominal.rows[f];
    let alpha = row[Symbol::Alpha.column()];
    let a = row[Symbol::A.column()];
    let (sin, cos) = alpha.sin_cos();
    match robot.frames[f].convention {
        Convention::Dh => (
            sin.abs() < EXACT,
            cos.abs() < EXACT,
            a.abs() < EXACT * length,
        ),
        Convention::Hayati => {
            let beta = row[Symbol::Beta.column()];
            let parallel = sin.abs() < EXACT && beta.sin().abs() < EXACT;
            (parallel, false, parallel && a.abs() < EXACT * length)
        }
    }
}

/// The relation's name for the report.
fn relation_name(parallel: bool, perpendicular: bool, meet: bool) -> Option<&'static str> {
    match (parallel, perpendicular, meet) {
        (true, _, true) => Some("coaxial"),
        (true, _, false) => Some("parallel"),
        (_, true, true) => Some("perpendicular and intersecting"),
        (_, true, false) => Some("perpendicular"),
        (_, _, true) => Some("intersecting"),
        _ => None,
    }
}

/// The name of driven frame `f`'s joint (the URDF's, else the frame label).
fn joint_name(robot: &Robot, f: usize) -> String {
    robot
        .param_name(ParamId {
            frame: f,
            symbol: Symbol::Gamma,
        })
        .trim_start_matches("gamma_")
        .to_string()
}

/// The relations of `robot`'s nominal model that a fit restricted by
/// [`held_unknowns`] keeps, each with the unknowns it holds.
#[must_use]
pub fn held_relations(robot: &Robot) -> Vec<HeldRelation> {
    let driven: Vec<usize> = (0..robot.frames.len())
        .filter(|&f| robot.frames[f].joint.is_some())
        .collect();
    let length = crate::units::reach(robot).max(1e-3);
    let is_unknown = |id: &ParamId| robot.unknowns.contains(id);
    let name = |frame: usize, symbol: Symbol| ParamId { frame, symbol };
    let revolute = |f: usize| robot.frames[f].joint_kind == JointKind::Revolute;
    let mut out = Vec::new();
    let mut meets = vec![false; driven.len()];
    for (k, w) in driven.windows(2).enumerate() {
        let (f, next) = (w[0], w[1]);
        let (parallel, perpendicular, meet) = relation_of(robot, f, length);
        let meet = meet && revolute(f) && revolute(next) && next == f + 1;
        meets[k] = meet;
        let Some(relation) = relation_name(parallel, perpendicular, meet) else {
            continue;
        };
        let mut ids = Vec::new();
        if parallel || perpendicular {
            ids.push(name(f, Symbol::Alpha));
            ids.push(name(f, Symbol::Beta));
        }
        if meet {
            ids.push(name(f, Symbol::A));
        }
        // Fixed frames between the two joints carry the relation too.
        for between in f + 1..next {
            ids.extend(Symbol::ALL.into_iter().map(|s| name(between, s)));
        }
        push_relation(robot, &mut out, (f, next), relation, &ids, &is_unknown);
    }
    // Three consecutive axes meeting in one point: frame k+1's d is 0.
    for k in 0..driven.len().saturating_sub(2) {
        let mid = driven[k + 1];
        let d = robot.nominal.rows[mid][Symbol::D.column()];
        let dh = robot.frames[mid].convention == Convention::Dh;
        if meets[k] && meets[k + 1] && dh && d.abs() < EXACT * length {
            let ids = [name(mid, Symbol::D)];
            push_relation(
                robot,
                &mut out,
                (driven[k], driven[k + 2]),
                "three axes meeting in one point",
                &ids,
                &is_unknown,
            );
        }
    }
    out
}

/// Adds the relation between driven frames `pair` with the unknowns among
/// `ids` (in order, each once).
fn push_relation(
    robot: &Robot,
    out: &mut Vec<HeldRelation>,
    pair: (usize, usize),
    relation: &str,
    ids: &[ParamId],
    is_unknown: &dyn Fn(&ParamId) -> bool,
) {
    let mut held: Vec<String> = Vec::new();
    for id in ids.iter().filter(|id| is_unknown(id)) {
        let n = robot.param_name(*id);
        if !held.contains(&n) {
            held.push(n);
        }
    }
    out.push(HeldRelation {
        from: joint_name(robot, pair.0),
        to: joint_name(robot, pair.1),
        relation: relation.to_string(),
        held,
    });
}

/// The names of `robot`'s unknowns a fit that keeps the nominal axis
/// relations holds at their nominal values (each once).
#[must_use]
pub fn held_unknowns(robot: &Robot) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for n in held_relations(robot).into_iter().flat_map(|r| r.held) {
        if !names.contains(&n) {
            names.push(n);
        }
    }
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(name: &str) -> Robot {
        crate::io::load_robot(&format!("{}/fixtures/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap()
    }

    #[test]
    fn a_ur5_keeps_its_perpendicular_parallel_and_intersecting_axes() {
        let r = load("ur5.urdf");
        let rel: Vec<(String, String, String)> = held_relations(&r)
            .into_iter()
            .map(|h| (h.from, h.to, h.relation))
            .collect();
        let want = [
            (
                "shoulder_pan_joint",
                "shoulder_lift_joint",
                "perpendicular and intersecting",
            ),
            ("shoulder_lift_joint", "elbow_joint", "parallel"),
            ("elbow_joint", "wrist_1_joint", "parallel"),
            (
                "wrist_1_joint",
                "wrist_2_joint",
                "perpendicular and intersecting",
            ),
            (
                "wrist_2_joint",
                "wrist_3_joint",
                "perpendicular and intersecting",
            ),
        ];
        let want: Vec<(String, String, String)> = want
            .iter()
            .map(|(a, b, c)| ((*a).into(), (*b).into(), (*c).into()))
            .collect();
        assert_eq!(rel, want);
        // The wrist's axes meet pairwise at points 94.65 mm apart along
        // wrist 2 (the UR's offset wrist): no three-axis point.
        let held = held_unknowns(&r);
        assert_eq!(
            held,
            [
                "alpha_shoulder_pan_joint",
                "a_shoulder_pan_joint",
                "alpha_shoulder_lift_joint",
                "beta_shoulder_lift_joint",
                "alpha_elbow_joint",
                "beta_elbow_joint",
                "alpha_wrist_1_joint",
                "a_wrist_1_joint",
                "alpha_wrist_2_joint",
                "a_wrist_2_joint"
            ]
        );
        // What stays free is what the UR's closed-form solver takes: joint
        // offsets, d1 a2 a3 d4 d5 d6, the base and the tool.
        assert_eq!(r.unknowns.len() - held.len(), 17);
    }

    #[test]
    fn a_panda_s_shoulder_axes_meet_in_one_point_and_its_offsets_stay_free() {
        let r = crate::io::load_robot(&format!(
            "{}/fixtures/example-robot-data/panda.urdf#tip=panda_link8",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap();
        let rel: Vec<String> = held_relations(&r)
            .iter()
            .map(|h| format!("{}-{} {}: {}", h.from, h.to, h.relation, h.held.join(" ")))
            .collect();
        let j = |k: usize| format!("panda_joint{k}");
        let want = [
            format!(
                "{}-{} perpendicular and intersecting: alpha_{} a_{}",
                j(1),
                j(2),
                j(1),
                j(1)
            ),
            format!(
                "{}-{} perpendicular and intersecting: alpha_{} a_{}",
                j(2),
                j(3),
                j(2),
                j(2)
            ),
            format!("{}-{} perpendicular: alpha_{}", j(3), j(4), j(3)),
            format!("{}-{} perpendicular: alpha_{}", j(4), j(5), j(4)),
            format!(
                "{}-{} perpendicular and intersecting: alpha_{} a_{}",
                j(5),
                j(6),
                j(5),
                j(5)
            ),
            format!("{}-{} perpendicular: alpha_{}", j(6), j(7), j(6)),
            format!(
                "{}-{} three axes meeting in one point: d_{}",
                j(1),
                j(3),
                j(2)
            ),
        ];
        assert_eq!(rel, want);
    }
}
