//! The height sensor's Jacobian row against central differences of its
//! prediction, through the kinematics (not through `motion_rows`).

use super::*;
use crate::kinematics::Evaluator;
use crate::measure::JacobianEvaluator;
use crate::model::Robot;

/// Column `c` of the row is `∂p_z/∂θ_c`: compared with
/// `(p_z(θ + h e_c) − p_z(θ − h e_c)) / 2h` at h = 1e-6 (m or rad). The
/// central difference's truncation error is `h²/6 |∂³p_z|`, under 1e-12 for
/// a chain of metre scale, and its rounding `ε |p_z| / h` ≈ 2e-10: 1e-8
/// leaves a margin above both.
#[test]
fn row_is_the_derivative_of_the_height() {
    let robot = Robot::ur5().with_measurement(KIND).unwrap();
    assert_eq!(robot.rows_per_pose(), 1);
    let table = robot.nominal.clone();
    let mut jev = JacobianEvaluator::new(&robot, &table);
    let q = [0.3, -1.1, 0.8, -0.4, 1.2, 0.5];
    let mut row = vec![0.0; robot.n_params()];
    jev.eval(&q, &mut row);
    let h = 1e-6;
    for (c, &id) in robot.unknowns.iter().enumerate() {
        let z = |d: f64| {
            let mut t = table.clone();
            t.set(id, table.get(id) + d);
            Evaluator::new(&robot, &t).end_frame(&q).position.z
        };
        let fd = (z(h) - z(-h)) / (2.0 * h);
        assert!(
            (row[c] - fd).abs() < 1e-8,
            "{}: row {} vs central difference {fd}",
            robot.param_name(id),
            row[c]
        );
    }
}

/// One row per pose sees the end point's height only: the base's `x`, `y`
/// and its turn about `z` move no height, so the robot keeps at least three
/// unknowns fewer than the point sensor's `4R + 3` (the UR5's 27), and the
/// set it keeps passes the identifiability check. (The UR5 loses five: a
/// translation along a direction that stays horizontal at every
/// configuration — along the common normal of the vertical first joint,
/// along the horizontal axes of joints 2–4 — moves no height either.)
#[test]
fn height_keeps_at_least_three_unknowns_fewer_than_a_point() {
    let point = Robot::ur5();
    let height = point.with_measurement(KIND).unwrap();
    assert_eq!(point.n_unknowns(), 27);
    let dropped: Vec<String> = point
        .unknowns
        .iter()
        .filter(|u| !height.unknowns.contains(u))
        .map(|&u| point.param_name(u))
        .collect();
    eprintln!("height drops {dropped:?}");
    assert!(height.unknowns.iter().all(|u| point.unknowns.contains(u)));
    assert!(dropped.len() >= 3, "{dropped:?}");
    height.check_identifiable().unwrap();
}
