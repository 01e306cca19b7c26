//! `robots --robot X` describes one robot (a URDF chain with --tip
//! included): its chain, joints with limits and parameters.

use crate::common;

use common::{fails_with, json_of, run};

#[test]
fn a_urdf_robot_is_described_with_its_chain_joints_and_limits() {
    let v = json_of(&[
        "--tip",
        "wrist_3_link",
        "robots",
        "--robot",
        "fixtures/figaroh/ur10_robot.urdf",
        "--json",
    ]);
    let r = &v["robots"][0];
    assert_eq!(v["robots"].as_array().unwrap().len(), 1);
    assert_eq!(r["dof"], 6);
    assert_eq!(r["joint_names"][0], "shoulder_pan_joint");
    // The URDF's elbow limits, ±π, in degrees.
    let elbow = r["limits_deg"][2].as_array().unwrap();
    assert!((elbow[1].as_f64().unwrap() - 180.0).abs() < 1e-9);
    assert!(!r["unknowns"].as_array().unwrap().is_empty());
    let out = run(&[
        "--tip",
        "wrist_3_link",
        "robots",
        "--robot",
        "fixtures/figaroh/ur10_robot.urdf",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("chain: shoulder_pan_joint -> "), "{text}");
    assert!(
        text.contains("elbow_joint") && text.contains("deg"),
        "{text}"
    );
}

#[test]
fn a_tree_without_a_tip_names_the_candidates() {
    fails_with(
        &["robots", "--robot", "fixtures/figaroh/tiago.urdf"],
        "--tip",
    );
}
