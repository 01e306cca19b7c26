//! One rule for identifiability on generic configurations (issue #39): the
//! unknowns of arms whose joints turn ±2π, a tool point that starts on the
//! last joint's axis, a marker given to `select`, and weights between
//! positions and orientations estimated from the data.

use super::common::{json_of, run, scratch_dir};
use activecal::io::RobotRef;
use activecal::model::Robot;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A standard normal draw (Box–Muller).
fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let (u, v): (f64, f64) = (rng.random(), rng.random());
    (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

fn load(text: &str) -> Robot {
    RobotRef::parse(text).unwrap().load().unwrap().robot
}

/// With a marker 10 cm off the flange, the UR arms (whose joints but the
/// elbow turn ±2π) and the xArm7 have the textbook count of unknowns,
/// `4R + 3` (Everett), where a sample of 5 lattice levels (the angles 0
/// and π only on a ±2π joint) chose one fewer: 26 and 30.
#[test]
fn arms_with_whole_turn_joints_keep_every_generic_unknown() {
    for (urdf, tip, want) in [
        ("ur3_robot.urdf", "tool0", 27),
        ("ur5_robot.urdf", "tool0", 27),
        ("ur10_robot.urdf", "tool0", 27),
        ("xarm7.urdf", "link7", 31),
        ("panda.urdf", "panda_link8", 31),
    ] {
        let path = format!("fixtures/example-robot-data/{urdf}");
        let marker = format!("{tip}@0.031,-0.024,0.097");
        let v = json_of(&["robots", "--robot", &path, "--marker", &marker, "--json"]);
        let r = &v["robots"][0];
        assert_eq!(r["unknowns"].as_array().unwrap().len(), want, "{urdf}");
        // As full poses: 4R + 6.
        let pose = format!("{path}:pose");
        let v = json_of(&["robots", "--robot", &pose, "--tip", tip, "--json"]);
        let dof = v["robots"][0]["dof"].as_u64().unwrap() as usize;
        assert_eq!(
            v["robots"][0]["unknowns"].as_array().unwrap().len(),
            4 * dof + 6,
            "{urdf}:pose"
        );
    }
}

/// The generic configurations of a joint whose limits are ±2π stay within
/// one turn from its lower limit, and are distinct modulo 2π.
#[test]
fn generic_configurations_cover_one_turn_of_a_whole_turn_joint() {
    let ur5 = load("fixtures/example-robot-data/ur5_robot.urdf#tip=tool0");
    let qs = activecal::observability::generic_configurations(&ur5, 200, 7);
    for (j, &[lo, hi]) in ur5.limits.iter().enumerate() {
        let v: Vec<f64> = qs.iter().map(|q| q[j]).collect();
        assert!(
            v.iter()
                .all(|&x| x >= lo && x <= hi.min(lo + std::f64::consts::TAU))
        );
        let mut turns: Vec<f64> = v
            .iter()
            .map(|x| x.rem_euclid(std::f64::consts::TAU))
            .collect();
        turns.sort_by(f64::total_cmp);
        turns.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        assert_eq!(
            turns.len(),
            200,
            "joint {j}: values that coincide modulo 2π"
        );
    }
    // Seeded: the same sample again.
    assert_eq!(
        qs,
        activecal::observability::generic_configurations(&ur5, 200, 7)
    );
}

/// Points measured by a tool 13 cm off the last joint's axis, given to a
/// UR5 whose measured point is `tool0` (on that axis) with no marker:
/// every identifiable direction is estimated (27, none fixed), and the
/// fit reaches the noise floor, `σ √(3 (3n − p) / 3n)` per point.
#[test]
fn a_tool_point_off_the_last_axis_is_estimated_from_the_data() {
    let given = load("fixtures/example-robot-data/ur5_robot.urdf#tip=tool0");
    let src = given.source.as_ref().unwrap();
    let tool = Isometry3::from_parts(
        Translation3::new(0.09, -0.07, 0.06),
        UnitQuaternion::identity(),
    );
    let truth = activecal::io::urdf::remount(&given, src.mount, src.tool * tool).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(39);
    let values: Vec<f64> = truth
        .unknown_values(&truth.nominal)
        .iter()
        .map(|v| v + 1.5e-3 * gauss(&mut rng))
        .collect();
    let table = truth.with_unknowns(&truth.nominal, &values);
    let (n, sigma) = (60, 2e-5);
    let names = activecal::units::joint_names(&given);
    let mut csv = format!("x1,y1,z1,{}\n", names.join(","));
    for q in activecal::observability::generic_configurations(&given, n, 0x39) {
        let (_, p) = activecal::kinematics::pose(&truth, &table, &q);
        let y = p + Vector3::from_fn(|_, _| sigma * gauss(&mut rng));
        let row: Vec<String> = y.iter().chain(&q).map(|v| format!("{v:.17e}")).collect();
        csv += &(row.join(",") + "\n");
    }
    let dir = scratch_dir("identifiability", "off_axis");
    let file = dir.join("points.csv");
    std::fs::write(&file, csv).unwrap();
    let v = json_of(&[
        "calibrate",
        "--robot",
        "fixtures/example-robot-data/ur5_robot.urdf",
        "--tip",
        "tool0",
        "--measurements",
        file.to_str().unwrap(),
        "--json",
    ]);
    let fixed = v["fixed"].as_array().unwrap();
    assert!(fixed.is_empty(), "fixed: {fixed:?}");
    let p = v["parameters"].as_array().unwrap().len();
    assert_eq!(p, 27);
    let floor_mm = 1e3 * sigma * (3.0 * (3 * n - p) as f64 / (3 * n) as f64).sqrt();
    let rms = v["residuals"]["position_rms_mm"].as_f64().unwrap();
    // 153 residual degrees of freedom: the RMS's spread is ~6 %; ±20 %
    // is over 3 of it, and a dropped unknown leaves millimetres.
    assert!(
        (rms / floor_mm - 1.0).abs() < 0.2,
        "fitted {rms} mm, noise floor {floor_mm} mm"
    );
    let notes = v["notes"].as_array().unwrap();
    assert!(
        notes
            .iter()
            .any(|n| n.as_str().unwrap().contains("no tool point given")),
        "{notes:?}"
    );
}

/// `--marker` on a link that is not the chain's tip, or with a frames
/// file's markers, or with a full pose, is refused naming the marker.
#[test]
fn a_marker_is_refused_where_it_cannot_be() {
    let ur5 = "fixtures/example-robot-data/ur5_robot.urdf";
    let out = run(&[
        "robots",
        "--robot",
        ur5,
        "--tip",
        "tool0",
        "--marker",
        "wrist_1_link@0.1,0,0",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("wrist_1_link@0.1,0,0") && err.contains("tip link 'tool0'"),
        "{err}"
    );
    let pose = format!("{ur5}:pose");
    let out = run(&[
        "robots",
        "--robot",
        &pose,
        "--marker",
        "tool0@0.1,0,0",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("full pose"));
    let out = run(&[
        "robots",
        "--robot",
        ur5,
        "--marker",
        "tool0@0.1,0",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("2 coordinates after '@'"));
}
