use super::*;

/// Origins with every component non-zero, turned less than
/// [`FOREIGN_TURN_RAD`] from identity.
fn origins(prefix: &str) -> Vec<(String, Isometry3<f64>)> {
    UR_KEYS
        .iter()
        .enumerate()
        .map(|(k, (_, j))| {
            let s = k as f64 + 1.0;
            (
                format!("{prefix}{j}"),
                iso(
                    [0.1 * s, -0.02 * s, 1e-11 * s],
                    [0.01 * s, -0.03 / s, 0.2 - 0.05 * s],
                ),
            )
        })
        .collect()
}

fn max_diff(a: &[(String, Isometry3<f64>)], b: &[(String, Isometry3<f64>)]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|((na, ta), (nb, tb))| {
            assert_eq!(na, nb);
            (ta.to_homogeneous() - tb.to_homogeneous()).abs().max()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_ur_file_reads_back_to_the_origins_it_was_written_from() {
    let o = origins("");
    let text = ur_kinematics("ur5", &o).unwrap();
    let back = parse(&text, "k.yaml").unwrap();
    assert_eq!(back.layout, Layout::UrKinematics);
    // Shortest round-trip decimals: only the rpy conversion's rounding.
    assert!(max_diff(&o, &back.origins) < 1e-15);
    let hash = back.hash.unwrap();
    assert!(hash.starts_with("activecal_") && hash.len() == 26, "{hash}");
    // A different value, a different hash.
    let mut o2 = o.clone();
    o2[3].1.translation.vector.x += 1e-9;
    let back2 = parse(&ur_kinematics("ur5", &o2).unwrap(), "k.yaml").unwrap();
    assert_ne!(back2.hash.unwrap(), hash);
}

#[test]
fn numbers_are_never_written_in_exponent_form() {
    // PyYAML reads `1e-11` (no dot) as a string: xacro would fail on it.
    let text = ur_kinematics("ur5", &origins("")).unwrap();
    let values: Vec<&str> = text
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .filter_map(|l| l.split_once(':').map(|(_, v)| v.trim()))
        .filter(|v| v.parse::<f64>().is_ok())
        .collect();
    assert_eq!(values.len(), 36, "{text}");
    assert!(values.iter().all(|v| !v.contains(['e', 'E'])), "{text}");
    assert!(text.contains("z: 0.00000000001\n"), "{text}");
}

#[test]
fn universal_robots_own_file_reads() {
    // The layout of ur_description's config/ur5/default_kinematics.yaml:
    // integers, an unquoted hash.
    let text = "kinematics:\n  shoulder:\n    x: 0\n    y: 0\n    z: 0.089159\n    roll: 0\n    pitch: 0\n    yaw: 0\n  upper_arm:\n    x: 0\n    y: 0\n    z: 0\n    roll: 1.570796327\n    pitch: 0\n    yaw: 0\n  forearm:\n    x: -0.425\n    y: 0\n    z: 0\n    roll: 0\n    pitch: 0\n    yaw: 0\n  wrist_1:\n    x: -0.39225\n    y: 0\n    z: 0.10915\n    roll: 0\n    pitch: 0\n    yaw: 0\n  wrist_2:\n    x: 0\n    y: -0.09465\n    z: -1.941303950897609e-11\n    roll: 1.570796327\n    pitch: 0\n    yaw: 0\n  wrist_3:\n    x: 0\n    y: 0.0823\n    z: -1.688001216681175e-11\n    roll: 1.570796326589793\n    pitch: 3.141592653589793\n    yaw: 3.141592653589793\n  hash: calib_209549117540498681\n";
    let f = parse(text, "default_kinematics.yaml").unwrap();
    assert_eq!(f.hash.as_deref(), Some("calib_209549117540498681"));
    assert_eq!(f.origins[0].0, "shoulder_pan_joint");
    assert_eq!(f.origins[0].1.translation.vector.z, 0.089159);
    assert_eq!(f.origins[4].1.translation.vector.z, -1.941303950897609e-11);
    let r = f.origins[1].1.rotation.euler_angles();
    assert!((r.0 - 1.570796327).abs() < 1e-15);
}

#[test]
fn a_per_joint_file_reads_back_to_its_origins() {
    let o = origins("arm_");
    let text = joint_origins("r", &o);
    let back = parse(&text, "o.yaml").unwrap();
    assert_eq!(back.layout, Layout::JointOrigins);
    // The file lists joints by name; compare in that order.
    let mut sorted = o.clone();
    sorted.sort_by(|a, b| a.0.cmp(&b.0));
    assert!(max_diff(&sorted, &back.origins) < 1e-15);
}

#[test]
fn a_prefixed_ur_chain_is_written_under_its_keys_and_read_back_onto_it() {
    let o = origins("left_");
    let text = ur_kinematics("r", &o).unwrap();
    let f = parse(&text, "k.yaml").unwrap();
    // Applied to a URDF whose joints carry the prefix.
    let mut urdf = String::from("<robot name=\"r\">\n");
    for (n, _) in &o {
        urdf += &format!(
            "  <joint name=\"{n}\" type=\"revolute\">\n    <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/>\n  </joint>\n"
        );
    }
    urdf += "</robot>\n";
    let edited = with_file(&urdf, "r.urdf", &f).unwrap();
    let back = urdf_origins(&edited, "r.urdf").unwrap();
    assert!(max_diff(&o, &back) < 1e-15);
}

#[test]
fn a_chain_that_is_not_a_ur_is_refused_naming_the_joint() {
    let mut o = origins("");
    o.remove(2);
    let e = ur_kinematics("r", &o).unwrap_err().to_string();
    assert!(
        e.contains("elbow_joint") && e.contains("per-joint origins"),
        "{e}"
    );
    let mut o = origins("");
    o.push(("rail_joint".into(), Isometry3::identity()));
    let e = ur_kinematics("r", &o).unwrap_err().to_string();
    assert!(e.contains("rail_joint"), "{e}");
}

#[test]
fn a_file_for_another_description_is_refused() {
    // fixtures/ur5.urdf follows ROS-Industrial (shoulder_lift_joint turned
    // a quarter turn about y); Universal Robots' file turns it about x.
    let urdf =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/ur5.urdf")).unwrap();
    let mut o: Vec<(String, Isometry3<f64>)> = urdf_origins(&urdf, "ur5.urdf")
        .unwrap()
        .into_iter()
        .filter(|(n, _)| UR_KEYS.iter().any(|(_, j)| j == n))
        .collect();
    // Its own origins apply; a quarter turn about x on shoulder_lift does not.
    let own = parse(&ur_kinematics("ur5", &o).unwrap(), "k.yaml").unwrap();
    assert!(with_file(&urdf, "ur5.urdf", &own).is_ok());
    o[1].1 = iso([0.0; 3], [std::f64::consts::FRAC_PI_2, 0.0, 0.0]);
    let other = parse(&ur_kinematics("ur5", &o).unwrap(), "k.yaml").unwrap();
    let e = with_file(&urdf, "ur5.urdf", &other)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("shoulder_lift_joint")
            && e.contains("k.yaml")
            && e.contains("another description"),
        "{e}"
    );
}

#[test]
fn bad_files_name_the_file_and_what_is_wrong() {
    for (text, want) in [
        ("", "no joint origins"),
        ("kinematics:\n  shoulder: {x: 0}\n", "Universal Robots"),
        ("j1: {xyz: [0, 0], rpy: [0, 0, 0]}\n", "per-joint origins"),
        ("j1: {xyz: [0, 0, .nan], rpy: [0, 0, 0]}\n", "finite"),
        ("- 1\n- 2\n", "kinematics file"),
    ] {
        let e = parse(text, "bad.yaml").unwrap_err().to_string();
        assert!(e.contains("bad.yaml") && e.contains(want), "{text:?}: {e}");
    }
    let f = parse("nope_joint: {xyz: [0, 0, 0], rpy: [0, 0, 0]}\n", "o.yaml").unwrap();
    let e = with_file("<robot name=\"r\"/>", "r.urdf", &f)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("nope_joint") && e.contains("o.yaml") && e.contains("r.urdf"),
        "{e}"
    );
}

#[test]
fn joint_offsets_follow_the_named_unit_and_sign() {
    let j = [
        ("j1".to_string(), 0.01, true),
        ("rail".to_string(), 0.002, false),
    ];
    let add = joint_offsets("r", &j, OffsetConvention::default());
    assert!(
        add.contains("unit: rad\nsign: add\noffsets:\n  j1: 0.01\n  rail: 0.002\n"),
        "{add}"
    );
    let sub = joint_offsets(
        "r",
        &j,
        OffsetConvention {
            degrees: true,
            subtract: true,
        },
    );
    let deg = format!("{}", -0.01f64.to_degrees());
    // Prismatic offsets stay in metres.
    assert!(
        sub.contains(&format!(
            "unit: deg\nsign: subtract\noffsets:\n  j1: {deg}\n  rail: -0.002\n"
        )),
        "{sub}"
    );
    assert!(sub.contains("q = q_encoder - offset"), "{sub}");
}
