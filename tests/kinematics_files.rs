//! Kinematics files on the command line (issue #53): `--kinematics FILE`
//! and `#kinematics=` read a file's joint origins into a `.urdf` robot,
//! `calibrate --out *kinematics.yaml / *origins.yaml` write them; bad files
//! and robots the layout cannot hold are refused with the file, the joint
//! and a non-zero exit, never a panic. (xacro reading the written files is
//! `verify/tests/live_stack.rs`.)

use crate::common::{fails_with, run, scratch_dir};

const FACTORY: &str = "fixtures/xacro/ur5_factory_kinematics.yaml";
const Q: &str = "0.3,-1.2,1.1,0.4,-0.8,0.5";

/// `fk`'s printed position (metres) of `robot` (with `extra` options) at [`Q`].
fn fk(extra: &[&str]) -> [f64; 3] {
    let mut args = vec!["fk", "--q", Q, "--json"];
    args.extend(extra);
    let out = run(&args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let p = &v["position"];
    [0, 1, 2].map(|k| p[k].as_f64().unwrap())
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn a_factory_file_moves_the_model_and_the_option_and_the_fragment_agree() {
    let bare = fk(&["--robot", "fixtures/ur5.urdf"]);
    let opt = fk(&["--robot", "fixtures/ur5.urdf", "--kinematics", FACTORY]);
    let frag = format!("fixtures/ur5.urdf#kinematics={FACTORY}");
    let in_name = fk(&["--robot", &frag]);
    assert_eq!(opt, in_name);
    // The factory file moves origins by 0.1–0.9 mm: the tip by about as much.
    let d = dist(bare, opt);
    assert!(d > 1e-4 && d < 5e-3, "{d} m");
}

#[test]
fn the_written_files_read_back_to_the_calibrated_urdf() {
    let d = scratch_dir("kinematics_files", "roundtrip");
    let at = |f: &str| d.join(f).display().to_string();
    let design = at("d.json");
    let out = run(&[
        "select",
        "--robot",
        "fixtures/ur5.urdf",
        "--n",
        "30",
        "--seed",
        "2",
        "--out",
        &design,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (urdf, kin, ori) = (
        at("cal.urdf"),
        at("cal_kinematics.yaml"),
        at("cal_origins.yaml"),
    );
    let out = run(&[
        "calibrate",
        "--robot",
        "fixtures/ur5.urdf",
        "--design",
        &design,
        "--out",
        &urdf,
        "--out",
        &kin,
        "--out",
        &ori,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let cal = fk(&["--robot", &urdf]);
    for file in [&kin, &ori] {
        let back = fk(&["--robot", "fixtures/ur5.urdf", "--kinematics", file]);
        // Both hold the same shortest decimals: rounding of the rpy
        // conversion only (1e-15 of a 1 m reach).
        assert!(dist(cal, back) < 1e-12, "{file}: {} m", dist(cal, back));
    }
    // The calibration moved the model (so the comparison can fail).
    let bare = fk(&["--robot", "fixtures/ur5.urdf"]);
    assert!(dist(cal, bare) > 1e-5, "{} m", dist(cal, bare));
    let text = std::fs::read_to_string(&kin).unwrap();
    assert!(
        text.contains("Units: metres (x, y, z) and radians"),
        "{text}"
    );
}

#[test]
fn bad_files_and_robots_are_refused_naming_them() {
    let d = scratch_dir("kinematics_files", "bad");
    fails_with(
        &[
            "fk",
            "--robot",
            "fixtures/ur5.urdf",
            "--kinematics",
            "nope.yaml",
            "--q",
            Q,
        ],
        "--kinematics nope.yaml: no such file",
    );
    // Universal Robots' own UR5 file is for ur_description's joint frames,
    // not for fixtures/ur5.urdf (ROS-Industrial's).
    let ur = d.join("default_kinematics.yaml");
    std::fs::write(&ur, "kinematics:\n  shoulder: {x: 0, y: 0, z: 0.089159, roll: 0, pitch: 0, yaw: 0}\n  upper_arm: {x: 0, y: 0, z: 0, roll: 1.570796327, pitch: 0, yaw: 0}\n  forearm: {x: -0.425, y: 0, z: 0, roll: 0, pitch: 0, yaw: 0}\n  wrist_1: {x: -0.39225, y: 0, z: 0.10915, roll: 0, pitch: 0, yaw: 0}\n  wrist_2: {x: 0, y: -0.09465, z: 0, roll: 1.570796327, pitch: 0, yaw: 0}\n  wrist_3: {x: 0, y: 0.0823, z: 0, roll: 1.570796326589793, pitch: 3.141592653589793, yaw: 3.141592653589793}\n  hash: calib_209549117540498681\n").unwrap();
    let ur = ur.display().to_string();
    fails_with(
        &[
            "fk",
            "--robot",
            "fixtures/ur5.urdf",
            "--kinematics",
            &ur,
            "--q",
            Q,
        ],
        "shoulder_lift_joint': the file's origin is turned",
    );
    let bad = d.join("bad_origins.yaml");
    std::fs::write(&bad, "elbow_joint: {xyz: [0, 0], rpy: [0, 0, 0]}\n").unwrap();
    let bad = bad.display().to_string();
    fails_with(
        &[
            "fk",
            "--robot",
            "fixtures/ur5.urdf",
            "--kinematics",
            &bad,
            "--q",
            Q,
        ],
        "bad_origins.yaml",
    );
    // A built-in robot has no URDF for the file's origins.
    fails_with(
        &["fk", "--robot", "ur5", "--kinematics", FACTORY, "--q", Q],
        "not of a built-in robot",
    );
    // The Stanford arm has no UR joints: the UR layout cannot hold it.
    let design = d.join("s.json").display().to_string();
    let out = run(&[
        "select",
        "--robot",
        "fixtures/stanford.urdf",
        "--n",
        "30",
        "--out",
        &design,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let kin = d.join("s_kinematics.yaml").display().to_string();
    fails_with(
        &[
            "calibrate",
            "--robot",
            "fixtures/stanford.urdf",
            "--design",
            &design,
            "--out",
            &kin,
        ],
        "write the per-joint origins file instead",
    );
    assert!(!std::path::Path::new(&kin).exists());
}

/// The offsets of a `*joint_offsets.yaml` file, in joint order.
fn offsets_in(path: &std::path::Path) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    text.split("offsets:\n")
        .nth(1)
        .unwrap()
        .lines()
        .map(|l| l.split(':').nth(1).unwrap().trim().parse().unwrap())
        .collect()
}

#[test]
fn the_offsets_written_turn_the_files_model_into_the_calibrated_one() {
    let d = scratch_dir("kinematics_files", "offsets");
    let at = |f: &str| d.join(f).display().to_string();
    let (design, meas) = (at("d.json"), at("m.json"));
    let ok = |args: &[&str]| {
        let out = run(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    ok(&[
        "select",
        "--robot",
        "fixtures/ur5.urdf",
        "--n",
        "30",
        "--seed",
        "2",
        "--out",
        &design,
    ]);
    ok(&[
        "calibrate",
        "--robot",
        "fixtures/ur5.urdf",
        "--design",
        &design,
        "--save-measurements",
        &meas,
    ]);
    let (urdf, add, sub) = (
        at("off.urdf"),
        at("add_joint_offsets.yaml"),
        at("sub_joint_offsets.yaml"),
    );
    let fit = |extra: &[&str]| {
        let mut args = vec![
            "calibrate",
            "--robot",
            "fixtures/ur5.urdf",
            "--measurements",
            &meas,
            "--unknowns",
            "offsets",
            "--force",
        ];
        args.extend(extra);
        ok(&args);
    };
    fit(&["--out", &urdf, "--out", &add]);
    fit(&[
        "--out",
        &sub,
        "--offset-unit",
        "deg",
        "--offset-sign",
        "subtract",
    ]);
    let plus = offsets_in(std::path::Path::new(&add));
    let minus = offsets_in(std::path::Path::new(&sub));
    // The two conventions: the same offsets, negated, in degrees.
    assert_eq!(plus.len(), 6);
    for (p, m) in plus.iter().zip(&minus) {
        assert!((m + p.to_degrees()).abs() < 1e-12, "{p} rad vs {m} deg");
    }
    // Middle joints moved (the simulated robot's offsets are off).
    assert!(plus[1..5].iter().any(|v| v.abs() > 1e-4), "{plus:?}");
    // The calibrated URDF at the reading q is the file's robot at
    // q + offset ("add"): the offsets are all the URDF changed.
    let q = [0.3, -1.2, 1.1, 0.4, -0.8, 0.5];
    let shifted: Vec<String> = q
        .iter()
        .zip(&plus)
        .map(|(a, b)| (a + b).to_string())
        .collect();
    let qs: Vec<String> = q.iter().map(f64::to_string).collect();
    let fk_at = |robot: &str, q: &[String]| {
        let out = run(&["fk", "--robot", robot, "--q", &q.join(","), "--json"]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        [0, 1, 2].map(|k| v["position"][k].as_f64().unwrap())
    };
    let cal = fk_at(&urdf, &qs);
    let file = fk_at("fixtures/ur5.urdf", &shifted);
    // `{}` prints the shortest round-trip decimal: rounding only.
    assert!(dist(cal, file) < 1e-12, "{} m", dist(cal, file));
    assert!(dist(cal, fk_at("fixtures/ur5.urdf", &qs)) > 1e-5);
    // Offset options act on the fits that write offsets, not on a camera's.
    fails_with(
        &[
            "calibrate",
            "--robot",
            "fixtures/ur5.urdf",
            "--observations",
            "x.csv",
            "--offset-unit",
            "deg",
        ],
        "offset",
    );
}
