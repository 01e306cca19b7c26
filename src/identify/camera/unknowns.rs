//! The robot's unknowns a camera can identify beside its two placements.
//!
//! A camera sees the whole end frame (four or more target points off a
//! line), but through two unknown placements: the fixed one (the camera's
//! in eye-to-hand, the target's in eye-in-hand) absorbs every rigid motion
//! of the base, the moving one every rigid motion of the end frame. The
//! robot's unknowns are therefore chosen as for a full pose, with these 12
//! rigid motions taken first: a candidate is kept when its column (end
//! point velocity and end frame angular velocity, [`Motion`]) is
//! independent of the rigid motions' and of the candidates kept before it
//! (the greedy Gram–Schmidt walk of [`Robot::choose_unknowns`], with its
//! tolerance, on [generic configurations](generic_configurations)). For a
//! generic chain of `R` revolute and `P` prismatic joints that leaves
//! `4R + 2P + 6 − 12` robot unknowns: 18 for a 6R arm, 22 for a 7R one.

use crate::error::Result;
use crate::kinematics::{Evaluator, Motion};
use crate::model::{MeasurementKind, ParamId, Robot};
use crate::observability::{INDEPENDENCE_TOL, generic_configurations};
use nalgebra::Vector3;

/// The seed of the configurations the choice is made on.
const SEED: u64 = 0x5eed_ca3e_0041;

/// A copy of `robot` measured through a camera: a point sensor without
/// markers (the camera sensor is the fit's own, [`super::fit_camera`]) and
/// its unknowns chosen as in the module documentation, its current
/// unknowns preferred.
pub fn camera_robot(robot: &Robot) -> Result<Robot> {
    let mut r = robot.clone();
    // Builds a kind, decides nothing: the camera's rows come from its own
    // sensor; the robot's unknowns are chosen for a point's.
    r.measurement = MeasurementKind::Point;
    r.real.markers.clear();
    r.nominal.markers.clear();
    let mut order: Vec<ParamId> = Vec::new();
    for &u in robot.unknowns.iter().chain(&r.candidate_unknowns()) {
        if !order.contains(&u) && u.symbol != crate::model::Symbol::C {
            order.push(u);
        }
    }
    let mut all = order.clone();
    all.sort();
    let mut probe = r.clone();
    probe.unknowns = all.clone();
    let qs = generic_configurations(&probe, (2 * all.len()).max(40), SEED);
    let mut ev = Evaluator::new(&probe, &probe.nominal);
    let mut motions = vec![Motion::default(); all.len()];
    let mut cols: Vec<Vec<f64>> = vec![Vec::with_capacity(6 * qs.len()); all.len() + 12];
    for q in &qs {
        let end = ev.motions(q, &mut motions);
        let mut push = |c: usize, m: &Motion| {
            cols[c].extend(m.lin.iter().chain(m.ang.iter()));
        };
        for (c, m) in motions.iter().enumerate() {
            push(c, m);
        }
        for i in 0..3 {
            let e = Vector3::ith(i, 1.0);
            let re = end.rotation * e;
            let rigid = [
                Motion {
                    lin: e,
                    ang: Vector3::zeros(),
                },
                Motion {
                    lin: e.cross(&end.position),
                    ang: e,
                },
                Motion {
                    lin: re,
                    ang: Vector3::zeros(),
                },
                Motion {
                    lin: Vector3::zeros(),
                    ang: re,
                },
            ];
            for (k, m) in rigid.iter().enumerate() {
                push(all.len() + 3 * k + i, m);
            }
        }
    }
    let mut basis: Vec<Vec<f64>> = Vec::new();
    // The placements' rigid motions first (independent of each other).
    for col in &cols[all.len()..] {
        let _ = independent(col, &mut basis);
    }
    let mut kept: Vec<ParamId> = order
        .into_iter()
        .filter(|u| {
            let k = all.binary_search(u).expect("all holds every candidate");
            independent(&cols[k], &mut basis)
        })
        .collect();
    kept.sort();
    r.unknowns = kept;
    r.validate()?;
    Ok(r)
}

/// Whether `col` (normalised) keeps a part above [`INDEPENDENCE_TOL`]
/// orthogonal to `basis` (two passes of modified Gram–Schmidt); if so, that
/// part joins the basis.
fn independent(col: &[f64], basis: &mut Vec<Vec<f64>>) -> bool {
    let n = col.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(n > 1e-12) {
        return false;
    }
    let mut v: Vec<f64> = col.iter().map(|x| x / n).collect();
    for _ in 0..2 {
        for b in basis.iter() {
            let d: f64 = b.iter().zip(&v).map(|(x, y)| x * y).sum();
            v.iter_mut().zip(b).for_each(|(y, x)| *y -= d * x);
        }
    }
    let r = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if r > INDEPENDENCE_TOL {
        v.iter_mut().for_each(|x| *x /= r);
        basis.push(v);
        true
    } else {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 6R arm (the built-in UR5) keeps `4·6 + 6 − 12 = 18` unknowns: a
    /// full pose's 30 less the 12 the placements take.
    #[test]
    fn a_six_joint_arm_keeps_eighteen() {
        let r = camera_robot(&Robot::ur5()).unwrap();
        assert_eq!(r.n_unknowns(), 18, "{:?}", r.parameter_names());
        assert_eq!(r.n_params(), 18);
    }
}
