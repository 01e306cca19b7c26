//! Issue 49, item 5: no option is accepted and ignored. Each option given
//! with a sensor it does not act on is refused before any work, naming the
//! option and the sensor (`src/cli/acts_on.rs`; its unit tests go through
//! every option of clap's definitions). These are the cases found accepted
//! and ignored, through the binary.

use crate::common;

/// `calibrate --observations` on the camera example (`tests/camera_cli.rs`).
const CAMERA: [&str; 11] = crate::common::CAMERA_EXAMPLE;

/// `select --camera-info` for the UR5's camera (`docs/cameras.md`).
const CAMERA_SELECT: [&str; 14] = [
    "select",
    "--robot",
    "fixtures/ur5.urdf",
    "--camera-info",
    "fixtures/camera/camera_info.yaml",
    "--target",
    "fixtures/camera/board.yaml",
    "--mounting",
    "eye-to-hand",
    "--camera-pose=1.2,0.6,0.9,-2.0985,0,2.0779",
    "--target-pose=-0.0853,0.0568,0.02,3.1416,0,0.03",
    "--n",
    "20",
    "--count=2000",
];

fn with<'a>(base: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
    base.iter().chain(extra).copied().collect()
}

#[test]
fn a_cameras_pixels_refuse_the_options_of_a_point_fit() {
    let d = common::scratch_dir("options", "camera_fit");
    let report = d.join("report");
    let report = report.to_str().unwrap();
    for (extra, why) in [
        (&["--loss", "huber"][..], "the camera fit is least squares"),
        (&["--holdout", "0.2"], "held-out"),
        (
            &["--fix", "d_shoulder_lift_joint"],
            "it acts on point measurements",
        ),
        (&["--report", report], "report"),
        (&["--compliance"], "point measurements"),
        (&["--weights", "fixed"], "no orientations"),
    ] {
        let out = common::run(&with(&CAMERA, extra));
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{extra:?}: {err}");
        let named = format!(
            "{}: not used with --observations (a camera's pixels)",
            extra[0]
        );
        assert!(err.contains(&named), "{extra:?}: '{err}' lacks '{named}'");
        assert!(err.contains(why), "{extra:?}: '{err}' lacks '{why}'");
        // Before any work: nothing printed, no report directory.
        assert!(out.stdout.is_empty(), "{extra:?}");
    }
    assert!(!d.join("report").exists());
}

#[test]
fn a_camera_design_refuses_the_options_of_a_pool() {
    for extra in [
        &["--algorithm", "fedorov"][..],
        &[
            "--visibility",
            r#"{"kind":"box","min":[-9,-9,-9],"max":[9,9,9]}"#,
        ],
        &["--orientation-noise", "0.01"],
        &["--marker", "tool0@0,0,0.1"],
        &["--criterion", "oi"],
        &["--margin", "5"],
    ] {
        let named = format!("{}: not used with --camera-info", extra[0]);
        common::fails_with(&with(&CAMERA_SELECT, extra), &named);
    }
}

/// `--pool file:` gives a camera design its candidates (the rows of a
/// design written before: all 20 chosen, in the file's row numbers);
/// `--pool lattice`, `--count` with a file and a unit without one are
/// refused.
#[test]
fn a_camera_design_takes_its_candidates_from_a_pool_file() {
    let d = common::scratch_dir("options", "camera_pool");
    let first = d.join("first.csv");
    let first = first.to_str().unwrap();
    let base = &CAMERA_SELECT[..CAMERA_SELECT.len() - 1];
    let v = common::json_of(&with(&CAMERA_SELECT, &["--out", first, "--json"]));
    assert_eq!(v["candidates"], 2000, "{v}");
    let file = format!("file:{first}");
    let v = common::json_of(&with(base, &["--pool", &file, "--json"]));
    assert_eq!(v["candidates"], 20, "{v}");
    let mut chosen: Vec<u64> = v["chosen_candidates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_u64().unwrap())
        .collect();
    chosen.sort_unstable();
    assert_eq!(chosen, (0..20).collect::<Vec<u64>>());
    common::fails_with(
        &with(base, &["--pool", "lattice"]),
        "--pool lattice: a camera design",
    );
    common::fails_with(
        &with(base, &["--pool", &file, "--count", "5"]),
        "--count: not used with --pool file:",
    );
    common::fails_with(
        &with(base, &["--angle-unit", "deg"]),
        "--angle-unit: the unit of a --pool file:'s joint values",
    );
}

/// With `--point` the sockets decide: every camera option is refused, no
/// longer dropped.
#[test]
fn sockets_refuse_the_camera_options() {
    let args = with(&CAMERA_SELECT, &["--point", "a=0.4,0.1,0.3"]);
    let out = common::run(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    for flag in [
        "--camera-info",
        "--target",
        "--mounting",
        "--camera-pose",
        "--target-pose",
    ] {
        let named = format!("{flag}: not used with --point (configurations touching sockets)");
        assert!(err.contains(&named), "'{err}' lacks '{named}'");
    }
}

/// The UR10 full-pose file of FIGAROH (`fixtures/figaroh`) written again:
/// without its orientation columns, and with each orientation the identity.
fn ur10_files(d: &std::path::Path) -> (String, String) {
    let text = std::fs::read_to_string("fixtures/figaroh/ur10_full_pose.csv").unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let phi: Vec<usize> = (0..header.len())
        .filter(|&i| header[i].starts_with("phi"))
        .collect();
    assert_eq!(phi.len(), 3);
    let (mut points, mut identity) = (String::new(), text.lines().next().unwrap().to_string());
    identity.push('\n');
    for (k, line) in text.lines().enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        let kept: Vec<&str> = (0..cells.len())
            .filter(|i| !phi.contains(i))
            .map(|i| cells[i])
            .collect();
        points += &(kept.join(",") + "\n");
        if k > 0 {
            let zeroed: Vec<&str> = (0..cells.len())
                .map(|i| if phi.contains(&i) { "0" } else { cells[i] })
                .collect();
            identity += &(zeroed.join(",") + "\n");
        }
    }
    let (p, i) = (d.join("points.csv"), d.join("identity.csv"));
    std::fs::write(&p, points).unwrap();
    std::fs::write(&i, identity).unwrap();
    (p.display().to_string(), i.display().to_string())
}

const UR10: [&str; 5] = [
    "calibrate",
    "--robot",
    "fixtures/figaroh/ur10_robot.urdf",
    "--tip",
    "wrist_3_link",
];

#[test]
fn points_refuse_the_weights_of_orientations() {
    let d = common::scratch_dir("options", "points");
    let (points, _) = ur10_files(&d);
    for extra in [&["--weights", "fixed"][..], &["--orientation-scale", "0.5"]] {
        let mut args = with(&UR10, &["--measurements", &points]);
        args.extend(extra);
        let named = format!(
            "{}: not used with --measurements of points (a file without orientations)",
            extra[0]
        );
        common::fails_with(&args, &named);
    }
    // The same file fits without them.
    let v = common::json_of(&with(&UR10, &["--measurements", &points, "--json"]));
    assert_eq!(v["exit_status"], 0, "{v}");
}

/// Orientations that are the identity at every pose while the joints turn
/// the wrist are no measurement: refused (they converged, with an
/// orientation σ of tens of degrees), for a point robot and a full-pose one.
#[test]
fn orientations_that_never_change_are_refused() {
    let d = common::scratch_dir("options", "identity");
    let (_, identity) = ur10_files(&d);
    for robot in [
        "fixtures/figaroh/ur10_robot.urdf",
        "fixtures/figaroh/ur10_robot.urdf:pose",
    ] {
        let mut args = UR10.to_vec();
        args[2] = robot;
        args.extend(["--measurements", &identity]);
        common::fails_with(
            &args,
            "the orientation is the identity at every one of the 23 poses",
        );
    }
    // The file's own orientations still calibrate.
    let mut args = UR10.to_vec();
    args.extend([
        "--measurements",
        "fixtures/figaroh/ur10_full_pose.csv",
        "--json",
    ]);
    assert_eq!(common::json_of(&args)["exit_status"], 0);
}
