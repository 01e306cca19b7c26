//! Bad input across every command, table-driven: each case must exit with
//! its status (2 for a usage error found by the argument parser, 1 for every
//! other error), print a message containing the expected words (naming the
//! input and, for files, the place), never panic, and never print what the
//! case says it must not (a `--force` hint for a directory, a 301-digit
//! number).
//!
//! Every case is refused before any expensive step (pools of at most
//! 3⁶ = 729 poses), so the whole table runs in seconds.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One bad input.
struct Case {
    /// Arguments; `@` is replaced by the scratch directory.
    args: &'static [&'static str],
    /// Expected exit status.
    status: i32,
    /// Words the message must contain.
    needs: &'static [&'static str],
    /// Words the message must not contain.
    lacks: &'static [&'static str],
    /// An address-space limit in KiB (`ulimit -v`), 0 for none.
    ulimit_v: u64,
    /// Environment variables set for the run.
    env: &'static [(&'static str, &'static str)],
}

const fn case(args: &'static [&'static str], status: i32, needs: &'static [&'static str]) -> Case {
    Case {
        args,
        status,
        needs,
        lacks: &[],
        ulimit_v: 0,
        env: &[],
    }
}

const fn case_lacking(
    args: &'static [&'static str],
    status: i32,
    needs: &'static [&'static str],
    lacks: &'static [&'static str],
) -> Case {
    Case {
        args,
        status,
        needs,
        lacks,
        ulimit_v: 0,
        env: &[],
    }
}

/// A case run under an address-space limit (`ulimit -v`, KiB) and with
/// environment variables.
const fn case_limited(
    args: &'static [&'static str],
    ulimit_v: u64,
    env: &'static [(&'static str, &'static str)],
    needs: &'static [&'static str],
) -> Case {
    Case {
        args,
        status: 1,
        needs,
        lacks: &[],
        ulimit_v,
        env,
    }
}

const BOX_INVERTED: &str = r#"{"kind":"box","min":[1,1,1],"max":[0,0,0]}"#;
const CONE_ZERO_AXIS: &str =
    r#"{"kind":"cone","apex":[0,0,0],"axis":[0,0,0],"half_angle":0.1,"max_range":40}"#;
const CONE_NEGATIVE: &str =
    r#"{"kind":"cone","apex":[0,0,0],"axis":[0,0,1],"half_angle":-0.1,"max_range":40}"#;
const BOX_FAR: &str = r#"{"kind":"box","min":[100,100,100],"max":[101,101,101]}"#;
const BOX_OK: &str = r#"{"kind":"box","min":[-30,-30,-30],"max":[30,30,30]}"#;

const TIAGO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/figaroh/tiago.urdf");
const UR5: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/ur5.urdf");
const TIAGO_ARM: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/figaroh/tiago.urdf#tip=arm_tool_link"
);
/// The issue's address-space limit: 2,000,000 KiB (2.05 GB).
const ULIMIT_2G: u64 = 2_000_000;
const UR10_POSE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/figaroh/ur10_robot.urdf:pose"
);
const UR10_CSV: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/figaroh/ur10_full_pose.csv"
);

/// The table. Files named here are made by [`scratch`]: `d.json` a valid
/// 3-level PUMA design, `m.json` its measurements, and broken variants.
const CASES: &[Case] = &[
    // ---- usage errors: clap, exit status 2 --------------------------------
    case(
        &["frobnicate"],
        2,
        &["unrecognized subcommand 'frobnicate'"],
    ),
    case(
        &["select", "--bogus"],
        2,
        &["unexpected argument '--bogus'"],
    ),
    case(
        &["select", "--algorithm", "nope"],
        2,
        &["'nope'", "eae, fedorov, detmax, random"],
    ),
    case(&["select", "--criterion", "x"], 2, &["'x'", "det, oi"]),
    case(&["select", "--levels", "abc"], 2, &["'abc'", "--levels"]),
    case(&["select", "--n", "-3"], 2, &["'-3'", "--n"]),
    case(
        &["select", "--seed", "-1"],
        2,
        &["--seed", "the seed must be a non-negative integer", "'-1'"],
    ),
    case(
        &["select", "--seed=-1"],
        2,
        &["--seed", "the seed must be a non-negative integer", "'-1'"],
    ),
    case(
        &["calibrate", "--design", "d.json", "--seed", "x"],
        2,
        &["the seed must be a non-negative integer", "'x'"],
    ),
    case(
        &["reproduce", "--seed", "1.5"],
        2,
        &["the seed must be a non-negative integer"],
    ),
    case(&["select", "--gap-solver", "newton"], 2, &["--gap"]),
    case(&["select", "--params", "bogus"], 2, &["nominal, real"]),
    case(&["fk"], 2, &["--q"]),
    case(
        &["score", "--poses", "1", "--design", "d.json"],
        2,
        &["--poses", "cannot be used with", "--design"],
    ),
    case(&["gap"], 2, &["--design"]),
    case(&["calibrate"], 2, &["--design"]),
    case(
        &[
            "calibrate",
            "--design",
            "d.json",
            "--measurements",
            "m.json",
        ],
        2,
        &["cannot be used with"],
    ),
    case(&["bound", "--solver", "simplex"], 2, &["clarabel, newton"]),
    case(&["robots", "--out", "x.toml"], 2, &["--export"]),
    case(&["pool", "--levels", "3.5"], 2, &["'3.5'", "--levels"]),
    case(&["reproduce", "--trials", "-1"], 2, &["'-1'", "--trials"]),
    // ---- select -------------------------------------------------------------
    case(
        &["select", "--levels", "1"],
        1,
        &["at least 2 levels per joint, got 1"],
    ),
    case(
        &["select", "--levels", "3", "--n", "5"],
        1,
        &["N = 5", "fewer than the 27 unknowns", "need N >= 9"],
    ),
    case(
        &["select", "--levels", "3", "--n", "1000"],
        1,
        &["N = 1000", "larger than the pool (729 poses)"],
    ),
    case(
        &["select", "--levels", "3", "--starts", "0"],
        1,
        &["starts", "at least 1"],
    ),
    case(
        &["select", "--levels", "3", "--initial", "40", "--n", "30"],
        1,
        &["--initial 40", "1..=N", "--n 30"],
    ),
    case(
        &["select", "--levels", "3", "--initial", "0"],
        1,
        &["--initial 0"],
    ),
    case(
        &["select", "--levels", "3", "--fixed", "1,1"],
        1,
        &["pose 1 appears more than once"],
    ),
    case(
        &["select", "--levels", "3", "--fixed", "99999"],
        1,
        &["pose 99999 is not in the pool", "729 poses"],
    ),
    case(
        &["select", "--levels", "3", "--fixed", "a,b"],
        1,
        &["--fixed: cannot parse 'a'"],
    ),
    case(
        &["select", "--robot", "nosuch"],
        1,
        &["unknown robot 'nosuch'", "puma560, ur5, stanford"],
    ),
    case(&["select", "--robot", "missing.toml"], 1, &["missing.toml"]),
    case(
        &["select", "--levels", "3", "--visibility", BOX_INVERTED],
        1,
        &["--visibility", "inverted on x"],
    ),
    case(
        &["select", "--levels", "3", "--visibility", CONE_ZERO_AXIS],
        1,
        &["--visibility", "cone axis is zero"],
    ),
    case(
        &["select", "--levels", "3", "--visibility", CONE_NEGATIVE],
        1,
        &["--visibility", "half-angle -0.1"],
    ),
    case(
        &["select", "--levels", "3", "--visibility", "nope"],
        1,
        &["--visibility", "line 1 column"],
    ),
    case(
        &["select", "--levels", "3", "--visibility", BOX_FAR],
        1,
        &["removed every pose"],
    ),
    case_lacking(
        &["select", "--levels", "3", "--out", "@"],
        1,
        &["--out", "is a directory", "give a file name"],
        &["--force"],
    ),
    case(
        &["select", "--levels", "3", "--out", "no/such/dir/x.json"],
        1,
        &["--out", "no/such/dir", "does not exist"],
    ),
    case(
        &["select", "--levels", "3", "--out", "d.json"],
        1,
        &["--out d.json", "exists; pass --force"],
    ),
    case(
        &["select", "--levels", "20"],
        1,
        &["would need", "of memory", "ACTIVECAL_MAX_MEMORY"],
    ),
    // Memory limits from every source: the address-space limit names
    // itself; a random search's memory no longer grows with --designs.
    case_limited(
        &[
            "select",
            "--levels",
            "12",
            "--algorithm",
            "random",
            "--designs",
            "100000000",
        ],
        ULIMIT_2G,
        &[],
        &[
            "a pool of 2985984 poses",
            "would need 4.0 GB",
            "ulimit -v of 2.0 GB less",
        ],
    ),
    case_limited(
        &["select", "--levels", "6", "--algorithm", "random"],
        ULIMIT_2G,
        &[("ACTIVECAL_MAX_MEMORY", "10M")],
        &[
            "would need 63.1 MB",
            "above the limit of 10.5 MB (ACTIVECAL_MAX_MEMORY=10M)",
        ],
    ),
    // The bound's Newton system grows with N²: refused with its figure
    // (at N = 50,000 it was a 20 GB allocation and a panic).
    case_limited(
        &["bound", "--levels", "3", "--n", "700"],
        0,
        &[("ACTIVECAL_MAX_MEMORY", "2M")],
        &[
            "the Newton solver's 700×700 system",
            "would need 3.9 MB",
            "(ACTIVECAL_MAX_MEMORY=2M)",
        ],
    ),
    case_lacking(
        &["select", "--robot", "big.toml"],
        1,
        &[
            "big.toml",
            "line 18",
            "frame '0'",
            "a = 1e300",
            "out of range",
        ],
        &["00000000000"],
    ),
    case(
        &["select", "--robot", "empty.toml", "--levels", "3"],
        1,
        &["empty.toml", "frame '2'", "q3", "empty range [0.5, 0.5]"],
    ),
    // ---- fk and pool --------------------------------------------------------
    case(
        &["fk", "--q", "0,0,0"],
        1,
        &["expected 6 joint angles, got 3"],
    ),
    // The wrong joint count names the joints expected, in order.
    case(
        &["fk", "--robot", UR5, "--q", "0,0,0"],
        1,
        &[
            "expected 6 joint angles, got 3",
            "shoulder_pan_joint, shoulder_lift_joint, elbow_joint, wrist_1_joint",
        ],
    ),
    // An unknown --fix name: the closest valid name, then all of them.
    case(
        &[
            "--tip",
            "wrist_3_link",
            "calibrate",
            "--robot",
            UR10_POSE,
            "--measurements",
            UR10_CSV,
            "--fix",
            "gamma_elbow_jiont",
        ],
        1,
        &[
            "fixed parameter 'gamma_elbow_jiont'",
            "hint: --fix NAME",
            "did you mean gamma_elbow_joint?",
            "the valid names are gamma_base, ",
        ],
    ),
    case(&["fk", "--q", "0,0,0,0,0,x"], 1, &["--q: cannot parse 'x'"]),
    case(
        &["fk", "--q", "0,0,0,0,0,NaN"],
        1,
        &["q6 is not a finite number"],
    ),
    case(
        &["fk", "--robot", TIAGO, "--q", "0"],
        1,
        &["tiago.urdf", "tree", "--tip", "candidate tips"],
    ),
    case(
        &["fk", "--robot", TIAGO, "--tip", "nolink", "--q", "0"],
        1,
        &["tip link 'nolink' is not in the URDF"],
    ),
    case(
        &["fk", "--robot", UR5, "--lock", "nojoint=1", "--q", "0"],
        1,
        &[
            "locked joint 'nojoint'",
            "no joint 'nojoint'",
            "hint: --lock NAME=VALUE",
        ],
    ),
    case(
        &[
            "fk",
            "--robot",
            UR5,
            "--lock",
            "shoulder_pan_joint",
            "--q",
            "0",
        ],
        1,
        &["--lock shoulder_pan_joint", "expected JOINT=VALUE"],
    ),
    case(
        &["fk", "--robot", "loop.urdf", "--q", "0"],
        1,
        &["loop.urdf", "loop (j1 → j2 → j3 → j1)"],
    ),
    case(
        &[
            "fk",
            "--robot",
            TIAGO_ARM,
            "--tip",
            "arm_7_link",
            "--q",
            "0",
        ],
        1,
        &[
            "--tip arm_7_link conflicts with the robot",
            "#tip=arm_tool_link",
            "give the chain once",
        ],
    ),
    case(
        &[
            "select",
            "--robot",
            TIAGO_ARM,
            "--lock",
            "torso_lift_joint=0.1",
        ],
        1,
        &[
            "--lock torso_lift_joint=0.1 conflicts",
            "#tip=arm_tool_link",
        ],
    ),
    case(
        &["fk", "--robot", "nojoint.toml", "--q", "0"],
        1,
        &["nojoint.toml", "this robot has no joints"],
    ),
    case(
        &["pool", "--levels", "3", "--digits", "0,0,0"],
        1,
        &["digits [0, 0, 0]", "need 6 digits"],
    ),
    case(&["pool", "--levels", "100"], 1, &["100^6", "too large"]),
    // ---- score ---------------------------------------------------------------
    case(&["score", "--levels", "3"], 1, &["--poses", "--design"]),
    case(
        &["score", "--levels", "3", "--poses", "1,1"],
        1,
        &["pose 1 appears more than once"],
    ),
    case(
        &["score", "--levels", "3", "--poses", "99999"],
        1,
        &["pose 99999 is not in the pool"],
    ),
    case(
        &["score", "--design", "nofile.json"],
        1,
        &["nofile.json", "No such file"],
    ),
    case(
        &["score", "--design", "trunc.json"],
        1,
        &["trunc.json", "line 2 column"],
    ),
    case(
        &["score", "--design", "dup.json"],
        1,
        &["dup.json", "pose 1 appears more than once"],
    ),
    case(
        &["score", "--design", "norobot.json"],
        1,
        &["unknown robot 'nosuch'"],
    ),
    case(
        &["score", "--robot", "ur5", "--design", "d.json"],
        1,
        &["--robot ur5 conflicts with d.json", "'puma560'"],
    ),
    case(
        &["score", "--levels", "4", "--design", "d.json"],
        1,
        &["--levels 4 conflicts with d.json", "3-level lattice"],
    ),
    case(
        &["score", "--visibility", BOX_OK, "--design", "d.json"],
        1,
        &["--visibility conflicts with d.json", "no filter"],
    ),
    // ---- bound and gap -------------------------------------------------------
    case(
        &["bound", "--levels", "3", "--n", "5"],
        1,
        &["N = 5", "need N ≥ 9"],
    ),
    case(
        &["bound", "--levels", "3", "--n", "1000"],
        1,
        &["N = 1000", "only 729"],
    ),
    case(
        &["bound", "--levels", "3", "--gap-tol", "-1"],
        1,
        &["gap_tol = -1", "> 0"],
    ),
    case(
        &["bound", "--levels", "3", "--max-rounds", "0"],
        1,
        &["max_rounds = 0"],
    ),
    case(
        &["gap", "--design", "trunc.json"],
        1,
        &["trunc.json", "line 2 column"],
    ),
    case(
        &["gap", "--design", "d.json", "--gap-tol", "0"],
        1,
        &["gap_tol = 0"],
    ),
    // ---- calibrate -----------------------------------------------------------
    case(
        &["calibrate", "--design", "d.json", "--noise", "-1"],
        1,
        &["--noise -1", ">= 0"],
    ),
    case(
        &["calibrate", "--design", "d.json", "--noise", "nan"],
        1,
        &["--noise NaN"],
    ),
    case(
        &["calibrate", "--design", "d.json", "--trials", "0"],
        1,
        &["trials = 0"],
    ),
    case(
        &["calibrate", "--design", "d.json", "--validation", "0"],
        1,
        &["--validation 0", "at least 1 held-out pose"],
    ),
    case(
        &["calibrate", "--design", "d.json", "--validation", "100000"],
        1,
        &["validation_poses = 100000", "more validation poses"],
    ),
    case(
        &["calibrate", "--design", "d.json", "--max-iterations", "0"],
        1,
        &["max_iterations = 0"],
    ),
    case(
        &["calibrate", "--design", "d.json", "--out", "d.json"],
        1,
        &["--out d.json", "is an input of this command"],
    ),
    // A calibrated robot is written as .urdf, .yaml or .toml: anything
    // else is refused before any work, naming the three.
    case(
        &["calibrate", "--design", "d.json", "--out", "cal.json"],
        1,
        &["cal.json", ".urdf", ".yaml", ".toml"],
    ),
    case(
        &["robots", "--export", "puma560", "--out", "puma.csv"],
        1,
        &["puma.csv", ".urdf", ".yaml", ".toml"],
    ),
    // A mistyped link: the nearest names.
    case(
        &["fk", "--robot", TIAGO, "--tip", "arm_tool_lnk", "--q", "0"],
        1,
        &["arm_tool_lnk", "did you mean arm_tool_link?"],
    ),
    // The frames file is a .urdf robot's: a built-in has none.
    case(
        &["calibrate", "--design", "d.json", "--out", "cal.yaml"],
        1,
        &["cal.yaml", "not imported from a URDF"],
    ),
    case(
        &[
            "fk",
            "--frames",
            "no-such-frames.yaml",
            "--q",
            "0,0,0,0,0,0",
        ],
        1,
        &["--frames no-such-frames.yaml", "no such file"],
    ),
    case(
        &[
            "calibrate",
            "--design",
            "d.json",
            "--out",
            "x.toml",
            "--save-measurements",
            "x.toml",
        ],
        1,
        &["--out and --save-measurements name the same file x.toml"],
    ),
    case_lacking(
        &["calibrate", "--design", "d.json", "--out", "@"],
        1,
        &["--out", "is a directory"],
        &["--force"],
    ),
    case(
        &["calibrate", "--robot", "ur5", "--design", "d.json"],
        1,
        &["d.json", "the design is for robot 'puma560', not 'ur5'"],
    ),
    case(
        &["calibrate", "--design", "badvis.json"],
        1,
        &["visibility filter", "inverted on x"],
    ),
    case(
        &["calibrate", "--measurements", "m.json", "--noise", "0"],
        1,
        &["--noise 0: the sensor's stated σ, tested against the residuals"],
    ),
    case(
        &[
            "calibrate",
            "--measurements",
            "m.json",
            "--validation",
            "10",
        ],
        2,
        &["cannot be used with '--validation <VALIDATION>'"],
    ),
    case(
        &["calibrate", "--measurements", "m.json", "--seed", "3"],
        1,
        &["--seed 3", "only draws the --holdout splits"],
    ),
    case(
        &["calibrate", "--measurements", "m4.json"],
        1,
        &[
            "m4.json",
            "point 7",
            "expected 3 coordinates [x, y, z], got 4",
        ],
    ),
    case(
        &["calibrate", "--measurements", "mshort.json"],
        1,
        &["mshort.json", "29 measured points"],
    ),
    case(
        &["calibrate", "--measurements", "mq5.json"],
        1,
        &["mq5.json", "pose 0", "expected 6 joint angles, got 5"],
    ),
    case(
        &["calibrate", "--measurements", "mrobot.json"],
        1,
        &["mrobot.json", "robot 'ur5', not 'puma560'"],
    ),
    case(
        &["calibrate", "--measurements", "mextra.json"],
        1,
        &["mextra.json", "unknown field `extra`"],
    ),
    case(
        &["calibrate", "--measurements", "mnan.json"],
        1,
        &["mnan.json", "line 1 column"],
    ),
    case(
        &["calibrate", "--measurements", "d.json"],
        1,
        &["d.json", "unknown field"],
    ),
    // ---- reproduce, bench, robots ---------------------------------------------
    case(
        &["reproduce", "--levels", "3", "--trials", "0", "--out", "r"],
        1,
        &["trials", "at least 1"],
    ),
    case(
        &["reproduce", "--levels", "3", "--noise", "nan", "--out", "r"],
        1,
        &["noise", "NaN"],
    ),
    case(
        &[
            "reproduce",
            "--levels",
            "3",
            "--initial",
            "40",
            "--out",
            "r",
        ],
        1,
        &["1..=N, got 40"],
    ),
    case(
        &["reproduce", "--out", "d.json"],
        1,
        &["--out d.json", "not a directory"],
    ),
    case(&["bench", "--reps", "0"], 1, &["--reps 0"]),
    case(
        &["robots", "--export", "nosuch"],
        1,
        &["unknown robot 'nosuch'"],
    ),
    case_lacking(
        &["robots", "--export", "puma560", "--out", "@"],
        1,
        &["is a directory"],
        &["--force"],
    ),
    case(
        &["robots", "--export", "puma560", "--out", "d.json"],
        1,
        &["--out d.json", "exists; pass --force"],
    ),
    // Compliance (issue #31): a URDF with inertials, a payload of three
    // coordinates, options that need --compliance.
    case(
        &[
            "calibrate",
            "--robot",
            "ur5",
            "--measurements",
            UR10_CSV,
            "--compliance",
        ],
        1,
        &["--compliance needs a URDF robot", "'ur5'"],
    ),
    case(
        &[
            "calibrate",
            "--robot",
            UR10_POSE,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
            "--compliance",
            "--payload",
            "-1",
        ],
        2,
        &["--payload", "must be finite and >= 0"],
    ),
    case(
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
            "nowhere.urdf",
        ],
        1,
        &["--inertia nowhere.urdf"],
    ),
    case(
        &[
            "calibrate",
            "--robot",
            UR10_POSE,
            "--tip",
            "wrist_3_link",
            "--measurements",
            UR10_CSV,
            "--compare-compliance",
        ],
        2,
        &["--holdout"],
    ),
];

fn activecal(dir: &Path, args: &[&str]) -> std::process::Output {
    limited(dir, args, 0, &[])
}

/// Runs the binary under `ulimit -v ulimit_v` (KiB; 0: no limit) with `env`.
fn limited(dir: &Path, args: &[&str], ulimit_v: u64, env: &[(&str, &str)]) -> std::process::Output {
    let bin = env!("CARGO_BIN_EXE_activecal");
    let mut cmd = if ulimit_v > 0 {
        let mut c = Command::new("sh");
        c.arg("-c")
            .arg(format!("ulimit -v {ulimit_v} && exec \"$0\" \"$@\""))
            .arg(bin);
        c
    } else {
        Command::new(bin)
    };
    cmd.current_dir(dir)
        .args(args)
        .envs(env.iter().copied())
        .output()
        .expect("runs")
}

/// A scratch directory with the files the table names.
fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("activecal-bad-inputs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let ok = |args: &[&str]| {
        let out = activecal(&dir, args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    };
    ok(&["select", "--levels", "3", "--n", "30", "--out", "d.json"]);
    ok(&[
        "calibrate",
        "--design",
        "d.json",
        "--validation",
        "10",
        "--save-measurements",
        "m.json",
    ]);
    let w = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
    w(
        "trunc.json",
        "{\"robot\":\"puma560\",\"levels\":3,\"poses\":[0,1\n",
    );
    w(
        "dup.json",
        r#"{"robot":"puma560","levels":3,"poses":[0,1,1]}"#,
    );
    w(
        "norobot.json",
        r#"{"robot":"nosuch","levels":3,"poses":[0,1]}"#,
    );
    let mut design: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("d.json")).unwrap()).unwrap();
    design["pool"]["filters"] =
        serde_json::from_str(&format!(r#"[{{"visibility":{BOX_INVERTED}}}]"#)).unwrap();
    w("badvis.json", &design.to_string());
    // Measurement files: one broken thing each.
    let m: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("m.json")).unwrap()).unwrap();
    let variant = |name: &str, edit: &dyn Fn(&mut Value)| {
        let mut v = m.clone();
        edit(&mut v);
        w(name, &v.to_string());
    };
    variant("m4.json", &|v| {
        v["points"][7].as_array_mut().unwrap().push(1.0.into());
    });
    variant("mshort.json", &|v| {
        v["points"].as_array_mut().unwrap().pop();
    });
    variant("mq5.json", &|v| {
        for q in v["qs"].as_array_mut().unwrap() {
            q.as_array_mut().unwrap().pop();
        }
    });
    variant("mrobot.json", &|v| v["robot"] = "ur5".into());
    variant("mextra.json", &|v| v["extra"] = 1.into());
    let nan = m
        .to_string()
        .replacen(&m["points"][3][1].to_string(), "NaN", 1);
    w("mnan.json", &nan);
    // Robot descriptions: the PUMA with a 1e300 length, with an empty joint
    // range; a URDF whose joints form a loop.
    let puma = String::from_utf8(ok(&["robots", "--export", "puma560"]).stdout).unwrap();
    let edit_line = |from: &str, to: &str| {
        assert!(puma.contains(from), "{from}");
        puma.replacen(from, to, 1)
    };
    w(
        "big.toml",
        &edit_line(
            "real = [0.0, -1.5707963267948966, 0.0, 0.6858, 10.0]",
            "real = [0.0, -1.5707963267948966, 1e300, 0.6858, 10.0]",
        ),
    );
    w(
        "empty.toml",
        &edit_line(
            "limits = [-2.321287905152458, 2.321287905152458]",
            "limits = [0.5, 0.5]",
        ),
    );
    // A description whose only frame is fixed: no joints.
    w(
        "nojoint.toml",
        "name = \"nojoint\"\nmeasurement = \"point\"\nunknowns = \"auto\"\n\n[[frame]]\nlabel = \"a\"\n\
         convention = \"hayati\"\njoint = \"fixed\"\nreal = [0.0, 0.0, 1.0, 0.0, 0.0]\n\
         nominal = [0.0, 0.0, 1.0, 0.0, 0.0]\n",
    );
    let j = r#"<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>"#;
    w(
        "loop.urdf",
        &format!(
            r#"<robot name="loop"><link name="a"/><link name="b"/><link name="c"/>
<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>{j}</joint>
<joint name="j2" type="revolute"><parent link="b"/><child link="c"/>{j}</joint>
<joint name="j3" type="revolute"><parent link="c"/><child link="a"/>{j}</joint></robot>"#
        ),
    );
    dir
}

#[test]
fn every_bad_input_gets_its_status_and_a_clear_message() {
    assert!(CASES.len() >= 60, "{} cases", CASES.len());
    let dir = scratch();
    let d = dir.to_str().unwrap();
    let mut failures = Vec::new();
    for c in CASES {
        let args: Vec<String> = c.args.iter().map(|a| a.replace('@', d)).collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = limited(&dir, &args, c.ulimit_v, c.env);
        let err = String::from_utf8_lossy(&out.stderr);
        let mut wrong = Vec::new();
        if out.status.code() != Some(c.status) {
            wrong.push(format!(
                "status {:?}, expected {}",
                out.status.code(),
                c.status
            ));
        }
        if err.contains("panicked") {
            wrong.push("panicked".into());
        }
        for n in c.needs {
            if !err.contains(n) {
                wrong.push(format!("lacks '{n}'"));
            }
        }
        for l in c.lacks {
            if err.contains(l) {
                wrong.push(format!("contains '{l}'"));
            }
        }
        if !wrong.is_empty() {
            failures.push(format!(
                "{:?}: {}\n    {}",
                c.args,
                wrong.join("; "),
                err.trim()
            ));
        }
    }
    // Nothing was written where an output was refused.
    for f in ["x.toml", "r"] {
        assert!(!dir.join(f).exists(), "{f} was created");
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        CASES.len(),
        failures.join("\n")
    );
}
