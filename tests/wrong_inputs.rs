//! Issue 40's wrong inputs, each refused with a message naming the input,
//! the place and the cause (or, for a closed pipe, never a panic):
//! positions and lengths in the wrong unit, frames files read strictly,
//! conflicting options, stale temporaries of a killed write, fits that
//! made another robot.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const UR10_POSE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/figaroh/ur10_robot.urdf:pose"
);
const UR10_CSV: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/figaroh/ur10_full_pose.csv"
);
const PANDA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/mukca/panda.urdf");
const PANDA_CSV: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/mukca/panda_2.csv");

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_activecal"))
}

/// Runs the binary in `dir`.
fn run_in(dir: &Path, args: &[&str]) -> Output {
    bin().current_dir(dir).args(args).output().expect("runs")
}

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("activecal-wrong-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Asserts exit status `status`, no panic, every one of `needs` in the
/// first line of stderr, and that first line under 200 characters (without
/// the repository's path, which the test's fixtures' names carry).
fn refused(out: &Output, status: i32, needs: &[&str], what: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(status), "{what}: {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
    let first = err.lines().next().unwrap_or("");
    let shown = first.replace(env!("CARGO_MANIFEST_DIR"), "");
    for n in needs {
        assert!(first.contains(n), "{what}: '{first}' lacks '{n}'");
    }
    assert!(
        shown.chars().count() < 200,
        "{what}: first line too long: {first}"
    );
}

/// A pipe whose reading end is already closed: writing to it fails with
/// EPIPE, every time, whatever the timing.
fn closed_pipe() -> Stdio {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    Stdio::from(writer)
}

/// A closed stderr (the issue's `fk --q 1e308,… 2>&1 | true`) ends with the
/// error's status, not a panic (101); a closed stdout ends with a plain
/// error on stderr; both closed, still no panic; progress lines to a closed
/// stderr are dropped and the command succeeds.
#[test]
fn closed_pipes_never_panic() {
    let out = bin()
        .args(["fk", "--q", "1e308,0,0,0,0,0"])
        .stderr(closed_pipe())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "fk with stderr closed");
    let out = bin().arg("robots").stdout(closed_pipe()).output().unwrap();
    refused(
        &out,
        1,
        &["cannot write the output to stdout", "Broken pipe"],
        "robots | closed",
    );
    let out = bin()
        .arg("robots")
        .stdout(closed_pipe())
        .stderr(closed_pipe())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "both closed");
    let out = bin()
        .args(["select", "--levels", "3", "--progress", "--json"])
        .stderr(closed_pipe())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "progress to a closed stderr");
    assert!(out.stdout.starts_with(b"{"), "the design is still printed");
    // An error with stdout closed: the message still reaches stderr.
    let out = bin()
        .args(["fk", "--q", "1e308,0,0,0,0,0"])
        .stdout(closed_pipe())
        .output()
        .unwrap();
    refused(&out, 1, &["1e308"], "fk with stdout closed");
}

/// The UR10's full-pose data (metres) read as millimetres: refused before
/// the fit as positions that barely move, with the hint to drop the unit;
/// nothing written.
#[test]
fn metres_read_as_millimetres_are_refused() {
    let d = scratch("mm");
    let out = run_in(
        &d,
        &[
            "calibrate",
            "--robot",
            UR10_POSE,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
            "--length-unit",
            "mm",
            "--out",
            "c.yaml",
        ],
    );
    refused(
        &out,
        1,
        &[
            "ur10_full_pose.csv",
            "the measured positions move",
            "look like metres",
        ],
        "UR10 in mm",
    );
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("hint: the lengths look like metres: drop --length-unit mm")
    );
    assert!(!d.join("c.yaml").exists());
    // `evaluate` reads positions the same way.
    let out = run_in(
        &d,
        &[
            "evaluate",
            "--robot",
            UR10_POSE,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
            "--length-unit",
            "mm",
        ],
    );
    refused(&out, 1, &["look like metres"], "evaluate UR10 in mm");
    let _ = std::fs::remove_dir_all(&d);
}

fn panda_contacts(dir: &Path, extra: &[&str]) -> Output {
    let mut a = vec![
        "calibrate",
        "--robot",
        PANDA,
        "--tip",
        "ball_link",
        "--measurements",
    ];
    a.extend(extra);
    run_in(dir, &a)
}

/// A socket distance in millimetres given as metres (and 1e12) is refused
/// before the fit, naming the distance and suggesting the unit; a distance
/// far shorter than the nominal one too.
#[test]
fn known_distances_in_the_wrong_unit_are_refused() {
    let d = scratch("dist");
    for (value, needs) in [
        (
            "50",
            &[
                "--point-distance",
                "front_left/0,front_left/1=50",
                "reach",
                "looks like millimetres",
            ][..],
        ),
        ("1e12", &["--point-distance", "=1e12", "reach"][..]),
        (
            "0.0001",
            &["--point-distance", "=0.0001", "shorter than"][..],
        ),
    ] {
        let dist = format!("front_left/0,front_left/1={value}");
        let out = panda_contacts(
            &d,
            &[PANDA_CSV, "--point-distance", &dist, "--out", "mm.yaml"],
        );
        refused(&out, 1, needs, &dist);
        assert!(!d.join("mm.yaml").exists(), "{dist}: written");
    }
    // `evaluate` reads them the same way.
    let out = run_in(
        &d,
        &[
            "evaluate",
            "--robot",
            PANDA,
            "--tip",
            "ball_link",
            "--measurements",
            PANDA_CSV,
            "--point-distance",
            "front_left/0,front_left/1=50",
        ],
    );
    refused(
        &out,
        1,
        &["--point-distance", "looks like millimetres"],
        "evaluate =50",
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A known plane 1e12 m away is refused before the fit, naming the plane.
#[test]
fn a_plane_beyond_reach_is_refused() {
    let d = scratch("plane");
    // MUKCa's contacts, the first ten rows' configurations also touching a
    // plane `table`.
    let text = std::fs::read_to_string(PANDA_CSV).unwrap();
    let mut lines = text.lines();
    let mut csv = format!("{},plane\n", lines.next().unwrap());
    let rows: Vec<&str> = lines.collect();
    for r in &rows {
        csv += &format!("{r},\n");
    }
    for r in &rows[..10] {
        let (q, _) = r.rsplit_once(',').unwrap();
        csv += &format!("{q},,table\n");
    }
    std::fs::write(d.join("planes.csv"), csv).unwrap();
    let out = panda_contacts(
        &d,
        &[
            "planes.csv",
            "--point-distance",
            "front_left/0,front_left/1=0.05",
            "--plane",
            "table=0,0,1,1e12",
        ],
    );
    refused(
        &out,
        1,
        &["--plane", "plane table", "1e12", "cannot touch it"],
        "plane at 1e12",
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A distance within reach but four times the sockets' (0.2 m for 50 mm):
/// the fit converges by stretching the arm; it exits 3 naming the joint it
/// moved, and writes nothing.
#[test]
fn a_fit_that_makes_another_robot_exits_3_and_writes_nothing() {
    let d = scratch("stretch");
    let out = panda_contacts(
        &d,
        &[
            PANDA_CSV,
            "--point-distance",
            "front_left/0,front_left/1=0.2",
            "--out",
            "x.yaml",
        ],
    );
    refused(
        &out,
        3,
        &[
            "the fit moved the origin of joint",
            "% of its link",
            "x.yaml not written",
        ],
        "stretched",
    );
    assert!(!d.join("x.yaml").exists());
    let _ = std::fs::remove_dir_all(&d);
}

/// The plausibility rule on a table: a PUMA link stretched by 0.5 m, or a
/// tool 100 m long, is not a calibration; the nominal model is.
#[test]
fn implausible_tables_are_named() {
    use activecal::identify::plausible::implausible;
    let robot = activecal::model::Robot::builtin("puma560").unwrap();
    assert_eq!(implausible(&robot, &robot.nominal), None);
    let mut t = robot.nominal.clone();
    let k = robot
        .frames
        .iter()
        .position(|f| f.joint == Some(2))
        .unwrap();
    t.rows[k][2] += 0.5;
    let why = implausible(&robot, &t).expect("stretched");
    assert!(
        why.contains("moved the origin") && why.contains("500.0 mm"),
        "{why}"
    );
    let mut t = robot.nominal.clone();
    let last = t.rows.len() - 1;
    t.rows[last][3] += 100.0;
    let why = implausible(&robot, &t).expect("long tool");
    assert!(why.contains("reach"), "{why}");
}

/// `--holdout-by` with `--train-on` (or `--holdout`): a usage error, not one
/// silently dropped; and every other pair that was silently ignored.
#[test]
fn conflicting_options_are_refused() {
    let d = scratch("conflict");
    for extra in [
        &["--holdout-by", "placement", "--train-on", "front_left"][..],
        &["--holdout", "0.2", "--train-on", "front_left"][..],
        &["--holdout", "0.2", "--holdout-by", "placement"][..],
    ] {
        let mut a = vec![
            PANDA_CSV,
            "--point-distance",
            "front_left/0,front_left/1=0.05",
        ];
        a.extend(extra);
        let out = panda_contacts(&d, &a);
        refused(&out, 2, &["cannot be used with"], &format!("{extra:?}"));
    }
    // Options of one kind of data, or one algorithm, given with another:
    // each was silently ignored.
    let out = run_in(
        &d,
        &["select", "--levels", "3", "--n", "30", "--out", "d.json"],
    );
    assert!(out.status.success());
    let cases: [(&[&str], i32, &[&str]); 9] = [
        (
            &["calibrate", "--design", "d.json", "--loss", "huber"],
            2,
            &["'--loss <LOSS>'", "cannot be used with"],
        ),
        (
            &["calibrate", "--design", "d.json", "--fix", "a_1"],
            2,
            &["'--fix <FIX>'"],
        ),
        (
            &["calibrate", "--design", "d.json", "--holdout", "0.2"],
            2,
            &["'--holdout <F>'"],
        ),
        (
            &["calibrate", "--design", "d.json", "--compliance"],
            2,
            &["'--compliance'"],
        ),
        (
            &["robots", "--robot", "puma560", "--out", "x.toml"],
            2,
            &["'--out <OUT>'", "cannot be used with"],
        ),
        (
            &[
                "select",
                "--levels",
                "3",
                "--algorithm",
                "fedorov",
                "--designs",
                "10",
            ],
            1,
            &["--designs 10", "--algorithm fedorov draws none"],
        ),
        (
            &[
                "select",
                "--levels",
                "3",
                "--algorithm",
                "random",
                "--initial",
                "5",
            ],
            1,
            &["--initial 5", "--algorithm random does not use it"],
        ),
        (
            &["select", "--levels", "3", "--home", "0,0,0,0,0,0"],
            1,
            &["--home", "--order time"],
        ),
        (
            &[
                "calibrate",
                "--robot",
                PANDA,
                "--tip",
                "ball_link",
                "--measurements",
                PANDA_CSV,
                "--point-distance",
                "front_left/0,front_left/1=0.05",
                "--fix",
                "d_panda_joint1",
            ],
            1,
            &["--fix: not used with --measurements of contacts"],
        ),
    ];
    for (args, status, needs) in cases {
        refused(&run_in(&d, args), status, needs, &format!("{args:?}"));
    }
    assert!(!d.join("x.toml").exists());
    let _ = std::fs::remove_dir_all(&d);
}

/// Temporaries of a killed write (`.NAME.tmp-PID-N` whose process is gone)
/// are removed by the next write to the target; a running process's are
/// kept.
#[test]
fn a_killed_writes_temporaries_are_removed_by_the_next_write() {
    let d = scratch("stale");
    // Above Linux's largest pid_max (2^22): never a running process.
    let dead = d.join(".d.json.tmp-4194305-0");
    let live = d.join(format!(".d.json.tmp-{}-0", std::process::id()));
    std::fs::write(&dead, "half").unwrap();
    std::fs::write(&live, "half").unwrap();
    let out = run_in(
        &d,
        &["select", "--levels", "3", "--n", "30", "--out", "d.json"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(d.join("d.json").exists());
    if Path::new("/proc/self").exists() {
        assert!(!dead.exists(), "the stale temporary is still there");
    }
    assert!(live.exists(), "a running process's temporary was removed");
    let _ = std::fs::remove_dir_all(&d);
}

/// `calibrate --out cal.yaml --out cal.urdf` on the UR10's data in `dir`;
/// the frames file's text.
fn ur10_frames(dir: &Path) -> String {
    let out = run_in(
        dir,
        &[
            "calibrate",
            "--robot",
            UR10_POSE,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
            "--out",
            "cal.yaml",
            "--out",
            "cal.urdf",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read_to_string(dir.join("cal.yaml")).unwrap()
}

/// `text` with the block under top-level `key` removed.
fn without_block(text: &str, key: &str) -> String {
    let mut out = Vec::new();
    let mut skipping = false;
    for l in text.lines() {
        if l.starts_with(&format!("{key}:")) {
            skipping = true;
            continue;
        }
        if skipping && (l.starts_with(' ') || l.starts_with('-')) {
            continue;
        }
        skipping = false;
        out.push(l);
    }
    out.join("\n") + "\n"
}

/// `text` with the measurement frame's quaternion replaced by `numbers`.
fn with_quaternion(text: &str, numbers: &[&str]) -> String {
    let i = text.find("measurement_frame:").unwrap();
    let j = i + text[i..].find("  quaternion:\n").unwrap();
    let k = j + text[j..].find("  sigma_xyz_mm:").unwrap();
    let q: String = numbers.iter().map(|x| format!("  - {x}\n")).collect();
    format!("{}  quaternion:\n{q}{}", &text[..j], &text[k..])
}

/// Frames files are read strictly: each broken variant of a written file
/// is refused naming the file, the key path and (where there is one) the
/// line; the file as written still evaluates.
#[test]
fn frames_files_are_read_strictly() {
    let d = scratch("frames");
    let text = ur10_frames(&d);
    let evaluate = |frames: &str| {
        run_in(
            &d,
            &[
                "evaluate",
                "--robot",
                "cal.urdf:pose",
                "--frames",
                frames,
                "--measurements",
                UR10_CSV,
                "--json",
            ],
        )
    };
    let out = evaluate("cal.yaml");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r2 = std::f64::consts::FRAC_1_SQRT_2.to_string();
    let cases: Vec<(&str, String, Vec<&str>)> = vec![
        (
            "empty.yaml",
            String::new(),
            vec!["empty.yaml", "the file is empty"],
        ),
        (
            "nomf.yaml",
            without_block(&text, "measurement_frame"),
            vec!["nomf.yaml", "measurement_frame: missing"],
        ),
        (
            "notool.yaml",
            without_block(&text, "tool"),
            vec!["notool.yaml", "tool: missing"],
        ),
        (
            "nochain.yaml",
            without_block(&text, "chain"),
            vec!["chain: missing"],
        ),
        (
            "turned.yaml",
            with_quaternion(&text, &[&r2, &r2, "0.0", "0.0"]),
            vec![
                "turned.yaml",
                "measurement_frame.quaternion (line",
                "measurement_frame.rpy (line",
                "must agree",
            ],
        ),
        (
            "doubled.yaml",
            with_quaternion(&text, &["2.0", "0.0", "0.0", "0.0"]),
            vec!["measurement_frame.quaternion (line", "norm 2.000, not 1"],
        ),
        (
            "word.yaml",
            with_quaternion(&text, &["1.0", "abc", "0.0", "0.0"]),
            vec![
                "word.yaml: measurement_frame.quaternion (line 35, column 5): invalid floating point",
            ],
        ),
        (
            "cut.yaml",
            with_quaternion(&text, &["1.0"]),
            vec![
                "measurement_frame.quaternion (line",
                "1 numbers, expected 4",
            ],
        ),
        (
            "chainjoint.yaml",
            text.replacen("  - elbow_joint\n", "  - elbow_jiont\n", 1),
            vec![
                "chain.joints[2] (line 13)",
                "'elbow_jiont' is not a joint of the chain",
                "elbow_joint",
            ],
        ),
        (
            "joint.yaml",
            text.replacen("  elbow_joint:\n", "  elbow_jiont:\n", 1),
            vec!["joints (line", "'elbow_jiont' is not a joint"],
        ),
        (
            "parent.yaml",
            text.replacen("  parent: wrist_3_link\n", "  parent: wrist_2_link\n", 1),
            vec![
                "tool.parent (line",
                "'wrist_2_link' is not the tip link 'wrist_3_link'",
            ],
        ),
    ];
    for (name, body, needs) in &cases {
        std::fs::write(d.join(name), body).unwrap();
        refused(&evaluate(name), 1, needs, name);
    }
    // The calibration's locked joints are the default lock.
    let locked = text.replacen(
        "  - wrist_3_joint\n  locked: {}",
        "  locked:\n    wrist_3_joint: 0.0",
        1,
    );
    assert_ne!(locked, text);
    std::fs::write(d.join("locked.yaml"), locked).unwrap();
    let out = evaluate("locked.yaml");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        v["chain"].as_array().map(Vec::len),
        Some(5),
        "{}",
        v["chain"]
    );
    // A joint locked now that the calibration drove.
    let out = run_in(
        &d,
        &[
            "evaluate",
            "--robot",
            "cal.urdf:pose",
            "--frames",
            "cal.yaml",
            "--lock",
            "wrist_3_joint=0",
            "--measurements",
            UR10_CSV,
        ],
    );
    refused(
        &out,
        1,
        &[
            "cal.yaml: chain.joints (line 11)",
            "the file's chain drives wrist_3_joint, which this one holds",
        ],
        "locked joint",
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// A Panda's frames file given to the UR10 names the frames file (and the
/// robot it was written for), not the URDF.
#[test]
fn another_robots_frames_file_is_named() {
    let d = scratch("other");
    let out = panda_contacts(
        &d,
        &[
            PANDA_CSV,
            "--point-distance",
            "front_left/0,front_left/1=0.05",
            "--out",
            "panda.yaml",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run_in(
        &d,
        &[
            "evaluate",
            "--robot",
            UR10_POSE,
            "--frames",
            "panda.yaml",
            "--measurements",
            UR10_CSV,
        ],
    );
    refused(
        &out,
        1,
        &[
            "error: panda.yaml: chain.base (line 8): 'panda_link0' is not a link of",
            "written for panda.urdf",
        ],
        "panda frames on the UR10",
    );
    let out = run_in(
        &d,
        &[
            "evaluate",
            "--robot",
            UR10_POSE,
            "--base",
            "world",
            "--tip",
            "wrist_3_link",
            "--frames",
            "panda.yaml",
            "--measurements",
            UR10_CSV,
        ],
    );
    refused(
        &out,
        1,
        &["error: panda.yaml: chain.joints[0] (line", "'panda_joint1'"],
        "panda joints",
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Measured data: the UR10's measurement frame held at its nominal height
/// (`--fix d_base`, the tracker is 64 mm off) bends the arm to fit (elbow
/// and wrist 1 moved by 0.2 m): exit 3 naming the joint, nothing written.
#[test]
fn a_measured_fit_that_bends_the_arm_exits_3() {
    let d = scratch("bent");
    let out = run_in(
        &d,
        &[
            "calibrate",
            "--robot",
            UR10_POSE,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
            "--fix",
            "d_base",
            "--out",
            "bent.yaml",
            "--json",
        ],
    );
    refused(
        &out,
        3,
        &[
            "the fit moved the origin of joint 'elbow_joint'",
            "bent.yaml was not written",
        ],
        "--fix d_base",
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("the report");
    assert_eq!(v["exit_status"], 3);
    assert!(!d.join("bent.yaml").exists());
    let _ = std::fs::remove_dir_all(&d);
}

/// Runs the binary in `dir` under `ulimit -v` (KiB).
fn limited_in(dir: &Path, kib: u64, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_activecal"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("runs")
}

/// The issue's unclear messages, each now saying what is wrong on a first
/// line under 200 characters: a CSV given as a design file; a 1e300 URDF
/// origin; one joint value typed wrong among radians (no "degrees" hint);
/// a memory refusal under `ulimit -v`; and `pool`, which builds no
/// Jacobian, is no longer refused for one.
#[test]
fn unclear_messages_say_what_is_wrong() {
    let d = scratch("messages");
    let out = run_in(
        &d,
        &["select", "--levels", "3", "--n", "30", "--out", "d.csv"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run_in(&d, &["score", "--design", "d.csv"]);
    refused(
        &out,
        1,
        &[
            "d.csv",
            "a .csv design holds only joint values",
            ".json or .yaml",
        ],
        "csv design",
    );
    // One value of a CSV of radians typed as 100.
    let csv = std::fs::read_to_string(d.join("d.csv")).unwrap();
    let mut lines: Vec<String> = csv.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[5].split(',').map(str::to_string).collect();
    cells[1] = "100".into();
    lines[5] = cells.join(",");
    std::fs::write(d.join("typo.csv"), lines.join("\n") + "\n").unwrap();
    let out = run_in(&d, &["pool", "--pool", "file:typo.csv"]);
    refused(
        &out,
        1,
        &["typo.csv", "line 6", "100"],
        "one value typed wrong",
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !err.contains("degrees"),
        "one wrong value is not a column of degrees: {err}"
    );
    // A URDF origin of 1e300 m.
    let urdf =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/ur5.urdf")).unwrap();
    let from = r#"<origin xyz="0.0 0.0 0.089159""#;
    assert!(urdf.contains(from), "the fixture's shoulder origin");
    std::fs::write(
        d.join("far.urdf"),
        urdf.replacen(from, r#"<origin xyz="1e300 0.0 0.089159""#, 1),
    )
    .unwrap();
    let out = run_in(&d, &["pool", "--robot", "far.urdf", "--levels", "2"]);
    refused(
        &out,
        1,
        &[
            "far.urdf",
            "origin xyz=\"1e300 0 0.089159\" is out of range",
        ],
        "1e300 origin",
    );
    // Memory: the refusal's first line is short; `pool` counts no Jacobian.
    let out = limited_in(
        &d,
        2_000_000,
        &[
            "select",
            "--levels",
            "12",
            "--algorithm",
            "random",
            "--designs",
            "100000000",
        ],
    );
    refused(
        &out,
        1,
        &[
            "a pool of 2985984 poses",
            "would need 4.0 GB",
            "ulimit -v of 2.0 GB",
        ],
        "memory",
    );
    let out = limited_in(&d, 2_000_000, &["pool", "--levels", "12", "--json"]);
    assert!(
        out.status.success(),
        "pool --levels 12: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// More of the issue's messages: identical contact rows name the point and
/// its lines; an `--inertia` file without `<inertial>` says so; three
/// full poses for 30 unknowns say that first.
#[test]
fn repeated_rows_masses_and_too_few_poses_are_named() {
    let d = scratch("more");
    let text = std::fs::read_to_string(PANDA_CSV).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let (q, _) = lines.next().unwrap().rsplit_once(',').unwrap();
    let mut csv = format!("{header}\n");
    for p in ["a/0", "a/0", "a/0", "a/1", "a/1", "a/1"] {
        csv += &format!("{q},{p}\n");
    }
    std::fs::write(d.join("same.csv"), csv).unwrap();
    let out = panda_contacts(&d, &["same.csv", "--point-distance", "a/0,a/1=0.05"]);
    refused(
        &out,
        1,
        &[
            "same.csv",
            "point 'a/0' has 3 rows (line 2, 3, 4) but 1 different configuration",
        ],
        "identical rows",
    );
    let ur5 = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/ur5.urdf");
    let out = run_in(
        &d,
        &[
            "calibrate",
            "--robot",
            UR10_POSE,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
            "--compliance",
            "--inertia",
            ur5,
        ],
    );
    refused(
        &out,
        1,
        &["ur5.urdf", "no link has an <inertial> element"],
        "no inertials",
    );
    let all = std::fs::read_to_string(UR10_CSV).unwrap();
    let head: Vec<&str> = all.lines().take(4).collect();
    std::fs::write(d.join("three.csv"), head.join("\n") + "\n").unwrap();
    let out = run_in(
        &d,
        &[
            "calibrate",
            "--robot",
            UR10_POSE,
            "--tip",
            "wrist_3_link",
            "--measurements",
            "three.csv",
        ],
    );
    refused(
        &out,
        3,
        &[
            "3 poses give 18 measurement rows for 30 unknowns: too few",
            "at least 5 poses",
        ],
        "three poses",
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// No abort under a memory limit: the linear-algebra backend allocates
/// twice the L3 cache on every thread that multiplies matrices, outside any
/// budget; with enough threads under `ulimit -v 2000000` that allocation
/// failed and the process aborted (exit 134). The thread count is now
/// capped so the buffers fit in a quarter of the budget. The test asks
/// for enough threads to exceed the limit on this machine's L3 (at most
/// 64).
#[test]
fn no_abort_under_a_memory_limit_whatever_the_threads() {
    let d = scratch("threads");
    let buffer = activecal::resources::backend_buffer_bytes();
    let over = usize::try_from(2_048_000_000 / buffer.max(1)).unwrap_or(64) + 2;
    for threads in [1, 4, over.min(64)] {
        let out = Command::new("sh")
            .arg("-c")
            .arg("ulimit -v 2000000 && exec \"$0\" \"$@\"")
            .arg(env!("CARGO_BIN_EXE_activecal"))
            .args(["select", "--levels", "4", "--json"])
            .env("RAYON_NUM_THREADS", threads.to_string())
            .current_dir(&d)
            .output()
            .expect("runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{threads} threads: {err}");
        assert!(
            !err.contains("memory allocation"),
            "{threads} threads: {err}"
        );
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// A frame coordinate no estimated unknown moves is said to be fixed, never
/// given σ 0 (issue #39, item 7). On FIGAROH's UR10 full poses the
/// measurement frame absorbs the first joint's whole origin: in the frames
/// file every σ is either positive or null, each null coordinate is listed
/// under its block's `fixed`, and the text names them "fixed".
#[test]
fn fixed_coordinates_have_no_sigma_zero() {
    let d = scratch("fixed_sigma");
    let text = ur10_frames(&d);
    let mut nulls = 0;
    let mut in_sigma = false;
    for l in text.lines() {
        let t = l.trim();
        if t.starts_with("sigma_") {
            in_sigma = true;
            if let Some(v) = t.split_once(':').map(|(_, v)| v.trim())
                && !v.is_empty()
            {
                in_sigma = false;
                nulls += usize::from(v == "null");
                assert!(v == "null" || v.parse::<f64>().unwrap() > 0.0, "{l}");
            }
            continue;
        }
        if in_sigma && let Some(v) = t.strip_prefix("- ") {
            nulls += usize::from(v == "null");
            assert!(v == "null" || v.parse::<f64>().unwrap() > 0.0, "{l}");
            continue;
        }
        in_sigma = false;
    }
    let listed = text.matches("\n    - offset").count();
    assert!(nulls > 0, "no coordinate fixed in\n{text}");
    assert!(
        text.contains("fixed:") && listed >= 1,
        "the fixed offset is not listed:\n{text}"
    );
    let out = run_in(
        &d,
        &[
            "calibrate",
            "--robot",
            UR10_POSE,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
        ],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("fixed (held at the file's value")
            && stdout.contains("shoulder_pan_joint x y z"),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(&d);
}
