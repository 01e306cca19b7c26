//! Helpers shared by the command-line tests: run the `activecal` binary from
//! the package root, parse its JSON, check its failures.

#![allow(dead_code)] // each test crate uses its own subset

use serde_json::Value;
use std::process::{Command, Output};

/// Runs `activecal` with `args` from the package root (so that relative
/// paths like `fixtures/ur5.urdf` resolve).
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_activecal"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("runs")
}

/// Runs `activecal`, asserts success, and parses its one JSON object.
pub fn json_of(args: &[&str]) -> Value {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

/// Fails with exit code 1 (our error) or 2 (clap's usage error), a message
/// containing `needle`, and no panic: never success, never a signal.
pub fn fails_with(args: &[&str], needle: &str) {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        matches!(out.status.code(), Some(1 | 2)),
        "{args:?}: status {:?}",
        out.status
    );
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    assert!(err.contains(needle), "{args:?}: '{err}' lacks '{needle}'");
}

/// One exchange-add-exchange start with the default settings (30 poses,
/// seed 1, D-criterion): the design the per-robot tests run on.
pub fn eae_design(x: &activecal::blocks::Blocks) -> activecal::select::Selection {
    use activecal::criterion::DCriterion;
    use activecal::select::{Settings, design_rng, eae};
    eae(
        x,
        &mut DCriterion::new(),
        &Settings::default(),
        &mut design_rng(1, 0),
    )
    .unwrap_or_else(|e| panic!("EAE: {e}"))
}

/// Direct URDF kinematics from `base` to `tip` of a parsed URDF,
/// independent of activecal's importer: `Π origin_k · motion_k(q_k)`, each
/// moving joint's value taken from `q` by name.
pub fn urdf_fk(
    u: &urdf_rs::Robot,
    base: &str,
    tip: &str,
    q: &std::collections::HashMap<String, f64>,
) -> nalgebra::Isometry3<f64> {
    use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
    let by_child: std::collections::HashMap<&str, &urdf_rs::Joint> = u
        .joints
        .iter()
        .map(|j| (j.child.link.as_str(), j))
        .collect();
    let mut chain = Vec::new();
    let mut at = tip;
    while at != base {
        let j = by_child[at];
        chain.push(j);
        at = &j.parent.link;
    }
    chain.reverse();
    let mut t = Isometry3::identity();
    for j in chain {
        let [x, y, z] = j.origin.xyz.0;
        let [r, p, yw] = j.origin.rpy.0;
        t *= Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yw)
                * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), p)
                * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), r),
        );
        let axis = Unit::new_normalize(Vector3::from(j.axis.xyz.0));
        use urdf_rs::JointType as T;
        match j.joint_type {
            T::Revolute | T::Continuous => {
                t *= UnitQuaternion::from_axis_angle(&axis, q[&j.name]);
            }
            T::Prismatic => t *= Translation3::from(axis.into_inner() * q[&j.name]),
            _ => {}
        }
    }
    t
}

/// A fresh, empty directory for one test of one suite (unique per process,
/// so concurrent test runs do not share files).
pub fn scratch_dir(suite: &str, name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("activecal-{suite}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `calibrate --observations` on the camera example (UR5 eye-to-hand,
/// `docs/cameras.md`), without the rough placements: the start is computed.
pub const CAMERA_EXAMPLE: [&str; 11] = [
    "calibrate",
    "--robot",
    "fixtures/ur5.urdf",
    "--observations",
    "fixtures/camera/ur5_eye_to_hand.csv",
    "--camera-info",
    "fixtures/camera/camera_info.yaml",
    "--target",
    "fixtures/camera/board.yaml",
    "--mounting",
    "eye-to-hand",
];
