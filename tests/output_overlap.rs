//! No output over an input or another output (issue 49, item 6), and the
//! two related rows: a length in millimetres given to `select` as metres,
//! and a target or camera pool too large for memory. Every refusal comes
//! before any work, with exit status 1, a message naming the option and
//! the path (or the figure), and every input byte-identical afterwards,
//! `--force` or not.

use crate::common;

use common::run;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    common::scratch_dir("overlap", name)
}

/// Runs `args`; asserts exit status 1, no panic, and a message holding
/// every one of `needles`; returns the message.
fn refused(args: &[&str], needles: &[&str]) -> String {
    refused_with_env(args, &[], needles)
}

/// As [`refused`], with environment variables set for the run.
fn refused_with_env(args: &[&str], env: &[(&str, &str)], needles: &[&str]) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_activecal"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .envs(env.iter().copied())
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: '{err}' lacks '{n}'");
    }
    err
}

/// A file's bytes, to compare after a refused run.
fn bytes(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// A pool file of the PUMA 560 (64 Sobol poses) at `path`.
fn pool_file(path: &Path) {
    let out = run(&[
        "pool",
        "--pool",
        "sobol",
        "--count",
        "64",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The camera options of the example files, for `select` and `calibrate`
/// (with the `--target` each test gives).
const CAMERA: [&str; 8] = [
    "--robot",
    "fixtures/ur5.urdf",
    "--camera-info",
    "fixtures/camera/camera_info.yaml",
    "--mounting",
    "eye-to-hand",
    "--camera-pose=1.2,0.6,0.9,-2.0985,0,2.0779",
    "--target-pose=-0.0853,0.0568,0.02,3.1416,0,0.03",
];

/// `--out` naming a file the same run reads is refused even with
/// `--force`, for every kind of input: `--pool file:`, `--existing`,
/// `--frames`, `--robot`, the camera's `--target`, and `pool` and `robots
/// --export` too; the input is byte-identical afterwards.
#[test]
fn an_output_over_an_input_is_refused_even_with_force() {
    let d = scratch("input");
    let poses = d.join("poses.csv");
    pool_file(&poses);
    let frames = d.join("frames.yaml");
    std::fs::write(&frames, "# a frames file\n").unwrap();
    let urdf = d.join("ur5.urdf");
    std::fs::copy("fixtures/ur5.urdf", &urdf).unwrap();
    let target = d.join("target.yaml");
    std::fs::copy("fixtures/camera/board.yaml", &target).unwrap();
    let (p, f, u, t) = (
        poses.to_str().unwrap(),
        frames.to_str().unwrap(),
        urdf.to_str().unwrap(),
        target.to_str().unwrap(),
    );
    let pool_spec = format!("file:{p}");
    // The same file by another spelling is the same file.
    let dotted = d.join(".").join("poses.csv");
    let dp = dotted.to_str().unwrap();
    let mut camera = vec!["calibrate"];
    camera.extend(CAMERA);
    camera.extend([
        "--observations",
        "fixtures/camera/ur5_eye_to_hand.csv",
        "--target",
        t,
        "--out",
        t,
        "--force",
    ]);
    // Each run, the input it would overwrite, and the option that gave it.
    let cases: Vec<(Vec<&str>, &Path, &str)> = vec![
        (
            vec!["select", "--pool", &pool_spec, "--out", dp, "--force"],
            &poses,
            "--pool file:",
        ),
        (
            vec![
                "select",
                "--levels",
                "3",
                "--existing",
                p,
                "--out",
                p,
                "--force",
            ],
            &poses,
            "--existing",
        ),
        (
            vec!["select", "--robot", u, "--frames", f, "--out", f, "--force"],
            &frames,
            "--frames",
        ),
        (
            vec!["select", "--robot", u, "--out", u, "--force"],
            &urdf,
            "--robot",
        ),
        (camera, &target, "--target"),
        (
            vec!["pool", "--pool", &pool_spec, "--out", p, "--force"],
            &poses,
            "--pool file:",
        ),
        (
            vec!["robots", "--export", u, "--out", u, "--force"],
            &urdf,
            "--export",
        ),
    ];
    for (args, input, option) in cases {
        let before = bytes(input);
        let shown = args[args.iter().rposition(|a| *a == "--out").unwrap() + 1];
        let named = format!("({option} {})", input.display());
        refused(
            &args,
            &["--out", shown, "is an input of this command", &named],
        );
        assert_eq!(bytes(input), before, "{args:?} changed {}", input.display());
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// Two outputs naming one file (by any spelling), a `--report` directory
/// naming or holding an `--out` file, or holding an input, are refused
/// before any work: nothing is written, and the input is byte-identical.
#[test]
fn two_outputs_naming_one_file_are_refused_before_work() {
    let d = scratch("outputs");
    let poses = d.join("poses.csv");
    pool_file(&poses);
    let before = bytes(&poses);
    let pool_spec = format!("file:{}", poses.display());
    let e = d.join("e.json");
    let e_dotted = d.join(".").join("e.json");
    let report = d.join("report");
    let inside = report.join("x.json");
    let (es, eds, rs, is, ds) = (
        e.to_str().unwrap(),
        e_dotted.to_str().unwrap(),
        report.to_str().unwrap(),
        inside.to_str().unwrap(),
        d.to_str().unwrap(),
    );
    let select = ["select", "--pool", pool_spec.as_str(), "--n", "20"];
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["--out", es, "--out", eds, "--force"],
            vec!["--out and --out name the same file", eds],
        ),
        (
            vec!["--out", es, "--report", es, "--force"],
            vec!["--out and --report name the same file", es],
        ),
        (
            vec!["--out", is, "--report", rs, "--force"],
            vec!["--out", is, "is inside the --report directory", rs],
        ),
        (
            vec!["--report", ds, "--force"],
            vec![
                "--report",
                ds,
                "holds an input of this command (--pool file:",
            ],
        ),
    ];
    for (more, needles) in cases {
        let mut args = select.to_vec();
        args.extend(more);
        refused(&args, &needles);
        assert!(!e.exists() && !report.exists(), "{args:?} wrote an output");
        assert_eq!(bytes(&poses), before, "{args:?} changed the input");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// `select --point-distance A,B=50` (millimetres given as metres) is
/// refused with `calibrate`'s own message, and so is a `--marker` offset
/// in millimetres; the robot and an existing `--out` are byte-identical
/// afterwards.
#[test]
fn select_refuses_lengths_in_millimetres_as_calibrate_does() {
    let d = scratch("scale");
    let out = d.join("design.json");
    std::fs::write(&out, "old design\n").unwrap();
    let o = out.to_str().unwrap();
    let urdf = "fixtures/mukca/panda.urdf";
    let robot_before = bytes(Path::new(urdf));
    let distance = "high/0,high/1=50";
    let select = refused(
        &[
            "select",
            "--robot",
            urdf,
            "--tip",
            "ball_link",
            "--point",
            "high/0=0.5,0,0.3",
            "--point",
            "high/1=0.55,0,0.3",
            "--point-distance",
            distance,
            "--out",
            o,
            "--force",
        ],
        &[
            "--point-distance",
            distance,
            "the robot's reach",
            "millimetres",
        ],
    );
    let calibrate = refused(
        &[
            "calibrate",
            "--robot",
            urdf,
            "--tip",
            "ball_link",
            "--measurements",
            "fixtures/mukca/panda_2.csv",
            "--point-distance",
            distance,
        ],
        &["--point-distance", distance],
    );
    let first = |s: &str| s.lines().next().unwrap_or_default().to_string();
    assert_eq!(first(&select), first(&calibrate), "not the same message");
    // A marker 50 m and 100 m off the tip: millimetres.
    let marker = "tool0@50,0,100";
    let ur5 = "fixtures/example-robot-data/ur5_robot.urdf";
    let ur5_before = bytes(Path::new(ur5));
    let select = refused(
        &[
            "select", "--robot", ur5, "--tip", "tool0", "--marker", marker, "--pool", "sobol",
            "--count", "256", "--out", o, "--force",
        ],
        &[marker, "beyond the robot's reach", "millimetres"],
    );
    let calibrate = refused(
        &[
            "calibrate",
            "--robot",
            ur5,
            "--tip",
            "tool0",
            "--marker",
            marker,
            "--measurements",
            "fixtures/ur5_real.json",
        ],
        &[marker],
    );
    assert_eq!(first(&select), first(&calibrate), "not the same message");
    assert_eq!(bytes(&out), b"old design\n", "--out was written");
    assert_eq!(bytes(Path::new(urdf)), robot_before);
    assert_eq!(bytes(Path::new(ur5)), ur5_before);
    std::fs::remove_dir_all(&d).unwrap();
}

/// A target of 10¹² points and a camera pool whose pixel Jacobian exceeds
/// the memory budget are refused with the figure, naming the input,
/// instead of aborting; the target file is byte-identical afterwards.
#[test]
fn huge_targets_and_camera_pools_are_refused_with_the_figure() {
    let d = scratch("huge");
    let target = d.join("huge.yaml");
    let text = "checkerboard: {rows: 1000000, cols: 1000000, square: 0.025}\n";
    std::fs::write(&target, text).unwrap();
    let t = target.to_str().unwrap();
    let out = d.join("design.csv");
    let o = out.to_str().unwrap();
    let mut args = vec!["select", "--n", "12"];
    args.extend(CAMERA);
    args.extend(["--target", t, "--out", o, "--force"]);
    refused(
        &args,
        &["--target", t, "1000000 × 1000000 inner corners", "56.0 TB"],
    );
    assert_eq!(bytes(&target), text.as_bytes());
    assert!(!out.exists());
    // The pixel Jacobian of 20,000 candidates against a 20 MB budget.
    let mut args = vec!["select", "--n", "12"];
    args.extend(CAMERA);
    args.extend([
        "--target",
        "fixtures/camera/board.yaml",
        "--count",
        "20000",
        "--out",
        o,
    ]);
    refused_with_env(
        &args,
        &[("ACTIVECAL_MAX_MEMORY", "20M")],
        &[
            "--count 20000",
            "the pixel Jacobian",
            "would need",
            "ACTIVECAL_MAX_MEMORY=20M",
        ],
    );
    assert!(!out.exists());
    std::fs::remove_dir_all(&d).unwrap();
}
