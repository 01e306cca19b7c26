//! Chains from URDF trees: `base`, `tip` and `lock` on FIGAROH's TIAGo and
//! UR10 (trees with a mobile base, head, hand, camera mounts) and on small
//! hand-made trees; each imported chain reproduces a direct evaluation of the
//! URDF from the base link to the tip, and each bad choice is refused with a
//! message naming what is wrong and what to do.

use activecal::io::urdf::{self, MAX_CHAIN_JOINTS, UrdfOptions};
use activecal::kinematics::pose;
use activecal::model::Robot;
use nalgebra::Isometry3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use crate::common;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

fn opts(base: Option<&str>, tip: Option<&str>, lock: &[(&str, f64)]) -> UrdfOptions {
    UrdfOptions {
        base: base.map(str::to_string),
        tip: tip.map(str::to_string),
        lock: lock.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
        ..UrdfOptions::default()
    }
}

/// Direct URDF kinematics from `base` to `tip`, independent of the importer:
/// `Π origin_k · motion_k(q_k)`, with each moving joint's value taken from
/// `q` by name.
fn urdf_fk(path: &Path, base: &str, tip: &str, q: &HashMap<String, f64>) -> Isometry3<f64> {
    urdf_fk_of(&urdf_rs::read_file(path).unwrap(), base, tip, q)
}

/// [`urdf_fk`] of a parsed URDF.
fn urdf_fk_of(
    u: &urdf_rs::Robot,
    base: &str,
    tip: &str,
    q: &HashMap<String, f64>,
) -> Isometry3<f64> {
    common::urdf_fk(u, base, tip, q)
}

/// The imported robot's driven frames carry the URDF joint names (sanitised;
/// these have no characters to sanitise) in joint order.
fn joint_names(r: &Robot) -> Vec<String> {
    let mut v = vec![String::new(); r.dof()];
    for f in &r.frames {
        if let Some(j) = f.joint {
            v[j] = f.label.clone();
        }
    }
    v
}

/// Imported FK equals direct FK at a few configurations inside the limits.
/// The import converts axis lines to DH/Hayati frames in closed form
/// (normalisations, atan2; a near-parallel pair's parameters are up to
/// 1/sin 10° ≈ 5.8 times as sensitive as the axes) and composes ~20
/// transforms of up to 1.5 m (TIAGo): rounding of 2e-16 · 1.5 m amplified
/// ~100-fold is ~3e-14 m; 1.7e-15 is the largest seen. 1e-12 m (the
/// tolerance of the Pinocchio cross-checks) bounds it with margin, while any
/// wrong frame or joint moves the tip by millimetres. (Before the common
/// normal's direction came from the axes, TIAGo's arm was off by 1.7e-12 m.)
fn assert_matches_urdf(r: &Robot, path: &Path, base: &str, tip: &str, extra: &[(&str, f64)]) {
    let names = joint_names(r);
    for k in 0..7 {
        let q: Vec<f64> = r
            .limits
            .iter()
            .enumerate()
            .map(|(j, &[lo, hi])| lo + (hi - lo) * (0.13 + 0.11 * ((k * 3 + j * 5) % 7) as f64))
            .collect();
        let mut by_name: HashMap<String, f64> =
            names.iter().cloned().zip(q.iter().copied()).collect();
        for (n, v) in extra {
            by_name.insert(n.to_string(), *v);
        }
        let want = urdf_fk(path, base, tip, &by_name);
        let (rot, p) = pose(r, &r.nominal, &q);
        let dp = (p - want.translation.vector).norm();
        let dr = (rot - want.rotation.to_rotation_matrix().into_inner())
            .abs()
            .max();
        assert!(dp < 1e-12 && dr < 1e-12, "{}: {dp:e} m, {dr:e}", r.name);
    }
}

fn err(path: &Path, o: &UrdfOptions) -> String {
    urdf::load(path, o).unwrap_err().to_string()
}

#[test]
fn tiago_arm_chains_by_base_tip_and_lock() {
    let path = fixture("figaroh/tiago.urdf");
    // A tree: without a tip, the error lists the candidates and says how.
    let e = err(&path, &UrdfOptions::default());
    assert!(
        e.contains("the chain's tip") && e.contains("candidate tips"),
        "{e}"
    );
    // Root to the arm tool: the torso's prismatic lift and seven arm joints.
    let r = urdf::load(&path, &opts(None, Some("arm_tool_link"), &[])).unwrap();
    let mut want: Vec<String> = vec!["torso_lift_joint".into()];
    want.extend((1..=7).map(|k| format!("arm_{k}_joint")));
    assert_eq!(joint_names(&r), want);
    assert_matches_urdf(&r, &path, "base_footprint", "arm_tool_link", &[]);
    // From the torso: seven joints, the lift no longer in the chain.
    let r = urdf::load(
        &path,
        &opts(Some("torso_lift_link"), Some("arm_tool_link"), &[]),
    )
    .unwrap();
    assert_eq!(joint_names(&r), want[1..].to_vec());
    assert_matches_urdf(&r, &path, "torso_lift_link", "arm_tool_link", &[]);
    // The lift locked at 0.12 m: a fixed frame at that height.
    let lock = [("torso_lift_joint", 0.12)];
    let r = urdf::load(&path, &opts(None, Some("arm_tool_link"), &lock)).unwrap();
    assert_eq!(joint_names(&r), want[1..].to_vec());
    assert_matches_urdf(&r, &path, "base_footprint", "arm_tool_link", &lock);
}

#[test]
fn ur10_on_its_support_chains_from_any_base() {
    let path = fixture("figaroh/ur10_robot.urdf");
    let arm: Vec<String> = [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    ]
    .map(String::from)
    .to_vec();
    for base in [None, Some("base_link")] {
        let r = urdf::load(&path, &opts(base, Some("wrist_3_link"), &[])).unwrap();
        assert_eq!(joint_names(&r), arm);
        assert_matches_urdf(&r, &path, base.unwrap_or("world"), "wrist_3_link", &[]);
    }
}

/// Four revolute joints about a metre from the root, the first two axes
/// perpendicular with a common normal of 0.1 µm, the next two 20 nm apart.
const SHORT_NORMALS: &str = r#"<?xml version="1.0"?>
<robot name="short_normals">
  <link name="l0"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="l0"/><child link="l1"/>
    <origin xyz="0.3 0.2 0.9" rpy="0.1 -0.2 0.3"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="1e-7 0.4 0.7" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.5 0.1 -2e-8" rpy="0 1.5707963267948966 0.2"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/>
    <origin xyz="0.05 0.6 0.3" rpy="-1.5707963267948966 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="tool" type="fixed"><parent link="l4"/><child link="tip"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.4 0.5 0.6"/></joint>
</robot>
"#;

/// Largest position (m) and rotation-entry deviation of the import of `text`
/// from the direct URDF evaluation, over 50 configurations in [−3, 3].
fn import_deviation(text: &str) -> (f64, f64) {
    let r = urdf::parse(text, "t.urdf", &UrdfOptions::default()).unwrap();
    let u = urdf_rs::read_from_string(text).unwrap();
    let names = joint_names(&r);
    let (mut dp, mut dr) = (0.0f64, 0.0f64);
    for k in 0..50 {
        let q: Vec<f64> = (0..r.dof())
            .map(|j| 3.0 * (0.37 * (k * r.dof() + j) as f64 + 0.1).sin())
            .collect();
        let by_name = names.iter().cloned().zip(q.iter().copied()).collect();
        let want = urdf_fk_of(&u, "l0", "tip", &by_name);
        let (rot, p) = pose(&r, &r.nominal, &q);
        dp = dp.max((p - want.translation.vector).norm());
        dr = dr.max(
            (rot - want.rotation.to_rotation_matrix().into_inner())
                .abs()
                .max(),
        );
    }
    (dp, dr)
}

/// A DH frame's x axis is the common normal's direction. Taken from the
/// difference of the normal's two feet (coordinates of ~1 m, rounded to
/// ~1e-16 m) it would be off by 1e-16 / 1e-7 = 1e-9 rad for a 0.1 µm normal,
/// and every later axis with it (9.5e-10 m and 6.2e-10 were seen); taken
/// from the cross product of the two axes it is exact to rounding, and the
/// import reproduces the URDF to ~1e-15.
#[test]
fn a_short_common_normal_loses_no_precision() {
    let r = urdf::parse(SHORT_NORMALS, "t.urdf", &UrdfOptions::default()).unwrap();
    // The normal of 0.1 µm is a DH frame's a, not rounded away.
    let a = r.nominal.rows[1][2];
    assert!((a - 1e-7).abs() < 1e-12, "a = {a:e}");
    let (dp, dr) = import_deviation(SHORT_NORMALS);
    assert!(dp < 1e-13 && dr < 1e-13, "{dp:e} m, {dr:e}");
}

/// Only links' names and joints are read: a `<texture/>` without a file name
/// (iCub's and Romeo's URDFs in example-robot-data have them), which
/// `urdf_rs` alone refuses, and visual, collision, inertial, Gazebo and
/// transmission elements leave the chain as it is without them.
#[test]
fn appearance_elements_are_not_read() {
    let decorated = SHORT_NORMALS
        .replace(
            r#"<link name="l1"/>"#,
            r#"<link name="l1"><inertial><mass value="1.5"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><mesh filename="package://x/l1.dae" scale="1 1 1"/></geometry>
      <material name="LightGrey"><texture /></material></visual>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>"#,
        )
        .replace(
            "</robot>",
            r#"<material name="LightGrey"><color rgba="0.6 0.6 0.6 1"/><texture /></material>
  <gazebo reference="l1"><material>Gazebo/Grey</material></gazebo>
  <transmission name="t1"><type>transmission_interface/SimpleTransmission</type>
    <joint name="j1"><hardwareInterface>EffortJointInterface</hardwareInterface></joint></transmission>
</robot>"#,
        );
    let e = urdf_rs::read_from_string(&decorated)
        .unwrap_err()
        .to_string();
    assert!(e.contains("filename"), "{e}");
    let o = UrdfOptions::default();
    let bare = urdf::parse(SHORT_NORMALS, "t.urdf", &o).unwrap();
    let r = urdf::parse(&decorated, "t.urdf", &o).unwrap();
    assert_eq!(joint_names(&r), joint_names(&bare));
    assert_eq!(r.nominal, bare.nominal);
    assert_eq!(r.limits, bare.limits);
    // Not XML, or not a robot: still refused.
    for (text, want) in [
        ("<robot name=\"x\"><joint", "not a valid URDF"),
        (
            "<sdf version=\"1.6\"/>",
            "the root element is <sdf>, not <robot>",
        ),
    ] {
        let e = urdf::parse(text, "t.urdf", &o).unwrap_err().to_string();
        assert!(e.contains(want), "want '{want}' in: {e}");
    }
}

#[test]
fn bad_chains_are_refused_with_what_to_do() {
    let tiago = fixture("figaroh/tiago.urdf");
    for (o, want) in [
        (
            opts(Some("nowhere"), None, &[]),
            "the base link 'nowhere' is not in the URDF",
        ),
        (
            opts(None, Some("nowhere"), &[]),
            "the tip link 'nowhere' is not in the URDF",
        ),
        (
            opts(Some("arm_3_link"), Some("head_2_link"), &[]),
            "the tip link 'head_2_link' is not below the base link 'arm_3_link'",
        ),
        (
            opts(None, Some("arm_tool_link"), &[("head_1_joint", 0.0)]),
            "locked joint 'head_1_joint': the joint is not on the chain",
        ),
        (
            opts(None, Some("arm_tool_link"), &[("no_such_joint", 0.0)]),
            "there is no joint 'no_such_joint'",
        ),
        (
            opts(None, Some("arm_tool_link"), &[("arm_tool_joint", 0.0)]),
            "the joint is fixed already",
        ),
    ] {
        let e = err(&tiago, &o);
        assert!(e.contains(want), "want '{want}' in: {e}");
    }
}

fn joint(name: &str, kind: &str, parent: &str, child: &str, limits: (f64, f64)) -> String {
    format!(
        r#"<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/><origin xyz="0.1 0.2 0.3" rpy="0.3 0.2 0.1"/><axis xyz="0 0 1"/><limit lower="{}" upper="{}" effort="0" velocity="0"/></joint>"#,
        limits.0, limits.1
    )
}

fn parse_err(text: &str, o: &UrdfOptions) -> String {
    urdf::parse(text, "t.urdf", o).unwrap_err().to_string()
}

#[test]
fn grippers_loops_and_long_chains_are_never_taken_silently() {
    let arm = [
        joint("j1", "revolute", "a", "b", (-1.0, 1.0)),
        joint("j2", "revolute", "b", "c", (-1.0, 1.0)),
        joint("j3", "revolute", "c", "d", (-1.0, 1.0)),
    ]
    .concat();
    // A single leaf whose last joint is a short prismatic jaw.
    let jaw = joint("finger_joint", "prismatic", "d", "e", (0.0, 0.04));
    let text = format!("<robot name=\"t\">{arm}{jaw}</robot>");
    let e = parse_err(&text, &UrdfOptions::default());
    assert!(
        e.contains("'finger_joint' looks like a gripper's") && e.contains("the chain's tip 'd'"),
        "{e}"
    );
    // Named explicitly, or the jaw locked, the chain is taken.
    urdf::parse(&text, "t.urdf", &opts(None, Some("e"), &[])).unwrap();
    let r = urdf::parse(
        &text,
        "t.urdf",
        &opts(None, None, &[("finger_joint", 0.02)]),
    )
    .unwrap();
    assert_eq!(r.dof(), 3);
    // A prismatic end joint of the same stroke under a neutral name is still
    // a jaw (short stroke).
    let text2 = format!(
        "<robot name=\"t\">{arm}{}</robot>",
        joint("slide", "prismatic", "d", "e", (0.0, 0.04))
    );
    assert!(parse_err(&text2, &UrdfOptions::default()).contains("short prismatic joint"));
    // A loop beside the tree: the message names its joints.
    let looped = format!(
        "<robot name=\"t\">{arm}{}{}</robot>",
        joint("k1", "revolute", "x", "y", (-1.0, 1.0)),
        joint("k2", "revolute", "y", "x", (-1.0, 1.0))
    );
    let e = parse_err(&looped, &UrdfOptions::default());
    assert!(
        e.contains("the joints form a loop") && e.contains("k1") && e.contains("k2"),
        "{e}"
    );
    // A chain longer than the cap: refused with the count and the ends.
    let n = MAX_CHAIN_JOINTS + 1;
    let long: String = (0..n)
        .map(|k| {
            joint(
                &format!("q{k}"),
                "revolute",
                &format!("l{k}"),
                &format!("l{}", k + 1),
                (-1.0, 1.0),
            )
        })
        .collect();
    let e = parse_err(
        &format!("<robot name=\"t\">{long}</robot>"),
        &UrdfOptions::default(),
    );
    assert!(
        e.contains(&format!("has {n} moving joints ('q0' … 'q{}')", n - 1)),
        "{e}"
    );
}

#[test]
fn descriptions_choose_the_chain_too() {
    let urdf_path = fixture("figaroh/tiago.urdf");
    let text = format!(
        "urdf = {:?}\nbase = \"base_footprint\"\ntip = \"arm_tool_link\"\n\n[lock]\ntorso_lift_joint = 0.12\n",
        urdf_path.to_str().unwrap()
    );
    let r = activecal::io::robot_toml::parse(&text, "tiago.toml", None).unwrap();
    let direct = urdf::load(
        &urdf_path,
        &opts(
            Some("base_footprint"),
            Some("arm_tool_link"),
            &[("torso_lift_joint", 0.12)],
        ),
    )
    .unwrap();
    assert_eq!(r.nominal, direct.nominal);
    assert_eq!(joint_names(&r), joint_names(&direct));
    // The keys belong to URDF imports only; the message points at the line.
    let e = activecal::io::robot_toml::parse("base = \"x\"\n", "a.toml", None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("a.toml: line 1") && e.contains("`base` is only for"),
        "{e}"
    );
}

#[test]
fn the_command_line_chooses_the_chain_and_records_it() {
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_activecal"))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(args)
            .output()
            .unwrap()
    };
    let tiago = "fixtures/figaroh/tiago.urdf";
    let out = run(&[
        "fk",
        "--robot",
        tiago,
        "--tip",
        "arm_tool_link",
        "--lock",
        "torso_lift_joint=0.1",
        "--q",
        "0,0,0,0,0,0,0",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let chain: Vec<String> = (1..=7).map(|k| format!("arm_{k}_joint")).collect();
    assert_eq!(v["chain"], serde_json::json!(chain));
    // The name records the chain, so a design file loads the same one.
    let name = v["robot"].as_str().unwrap();
    assert_eq!(
        name,
        format!("{tiago}#tip=arm_tool_link;lock=torso_lift_joint:0.1")
    );
    let again = run(&["fk", "--robot", name, "--q", "0,0,0,0,0,0,0", "--json"]);
    let w: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
    assert_eq!(w["position"], v["position"]);
    for (args, want) in [
        (
            vec![
                "fk",
                "--robot",
                "puma560",
                "--tip",
                "x",
                "--q",
                "0,0,0,0,0,0",
            ],
            "not of a built-in robot",
        ),
        (
            vec![
                "fk",
                "--robot",
                tiago,
                "--tip",
                "arm_tool_link",
                "--lock",
                "torso",
                "--q",
                "0",
            ],
            "expected JOINT=VALUE",
        ),
        (vec!["fk", "--robot", tiago, "--q", "0"], "candidate tips"),
    ] {
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: want '{want}' in {err}");
    }
}
