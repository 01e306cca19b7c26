//! The house's rules, checked from outside: a robot is one value, resolved
//! once from the command line, and every input file is read from disk once
//! per process (counted through the loaders' one reading function,
//! `io::read::read_text`, which the binary lists on stderr when
//! `ACTIVECAL_DEBUG_READS` is set).

use crate::common;

use std::process::Command;

/// Runs `activecal` with read counting on; returns (success, stderr).
fn counted(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_activecal"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("ACTIVECAL_DEBUG_READS", "1")
        .args(args)
        .output()
        .expect("runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The `read N× PATH` lines of a run's stderr.
fn reads(stderr: &str) -> Vec<(usize, String)> {
    stderr
        .lines()
        .filter_map(|l| l.strip_prefix("read "))
        .filter_map(|l| l.split_once("× "))
        .map(|(n, p)| (n.parse().expect("a count"), p.to_string()))
        .collect()
}

/// Asserts the run succeeded, read every file in `expected` (by file name)
/// and read no file more than once.
fn reads_once(args: &[&str], expected: &[&str]) {
    let (ok, err) = counted(args);
    assert!(ok, "{args:?}: {err}");
    let r = reads(&err);
    for (n, p) in &r {
        assert_eq!(*n, 1, "{args:?}: {p} read {n} times");
    }
    for e in expected {
        assert!(
            r.iter().any(|(_, p)| p.ends_with(e)),
            "{args:?}: {e} not among the reads {r:?}"
        );
    }
}

/// Select with self-collision (the URDF feeds the chain, the collision
/// model and the joint speeds), then score, gap and calibrate the design it
/// wrote: the URDF is read once in each process.
#[test]
fn a_urdf_is_read_once_per_process() {
    let dir = common::scratch_dir("house", "reads");
    let design = dir.join("d.json");
    let d = design.to_str().unwrap();
    let urdf = "fixtures/example-robot-data/panda.urdf";
    reads_once(
        &[
            "select",
            "--robot",
            urdf,
            "--tip",
            "panda_hand_tcp",
            "--pool",
            "random",
            "--count",
            "200",
            "--self-collision",
            "--srdf",
            "fixtures/example-robot-data/panda.srdf",
            "--package-dir",
            "fixtures/example-robot-data",
            "--n",
            "12",
            "--ils",
            "0",
            "--out",
            d,
        ],
        &["panda.urdf"],
    );
    reads_once(
        &["score", "--design", d, "--json"],
        &["panda.urdf", "d.json"],
    );
    reads_once(&["gap", "--design", d, "--json"], &["panda.urdf", "d.json"]);
    reads_once(
        &[
            "calibrate",
            "--robot",
            urdf,
            "--tip",
            "panda_hand_tcp",
            "--design",
            d,
            "--validation",
            "50",
            "--json",
        ],
        &["panda.urdf", "d.json"],
    );
    // The measured-data path: URDF, measurements, once each.
    reads_once(
        &[
            "calibrate",
            "--robot",
            "fixtures/figaroh/ur10_robot.urdf:pose",
            "--tip",
            "wrist_3_link",
            "--measurements",
            "fixtures/figaroh/ur10_full_pose.csv",
            "--json",
        ],
        &["ur10_robot.urdf", "ur10_full_pose.csv"],
    );
}

/// The design file records the chain as its own structured field (not in
/// the robot's name), and a design of old, whose robot name carries the
/// chain as a `#…` fragment, still loads.
#[test]
fn designs_record_the_chain_as_fields_and_old_names_still_load() {
    let dir = common::scratch_dir("house", "chain");
    let design = dir.join("d.json");
    let d = design.to_str().unwrap();
    let urdf = "fixtures/example-robot-data/panda.urdf";
    let (ok, err) = counted(&[
        "select",
        "--robot",
        urdf,
        "--tip",
        "panda_hand_tcp",
        "--pool",
        "random",
        "--count",
        "200",
        "--n",
        "12",
        "--ils",
        "0",
        "--out",
        d,
    ]);
    assert!(ok, "{err}");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&design).unwrap()).unwrap();
    assert_eq!(v["robot"], urdf);
    assert_eq!(v["chain"]["tip"], "panda_hand_tcp");
    let new_score = common::json_of(&["score", "--design", d, "--json"]);
    // The same design as a file of old: the chain in the robot's name.
    v["robot"] = format!("{urdf}#tip=panda_hand_tcp").into();
    v.as_object_mut().unwrap().remove("chain");
    let old = dir.join("old.json");
    std::fs::write(&old, v.to_string()).unwrap();
    let old_score = common::json_of(&["score", "--design", old.to_str().unwrap(), "--json"]);
    assert_eq!(new_score["ln_oid"], old_score["ln_oid"]);
    assert!(new_score["ln_oid"].is_number(), "{new_score}");
    // A chain option on a command without --robot is refused, not dropped.
    common::fails_with(
        &["gap", "--design", d, "--tip", "panda_link8"],
        "--tip panda_link8",
    );
    // A chain option that contradicts the chain a --robot names is refused.
    common::fails_with(
        &[
            "fk",
            "--robot",
            &format!("{urdf}#tip=panda_hand_tcp"),
            "--tip",
            "panda_link8",
            "--q",
            "0,0,0,-1,0,1,0",
        ],
        "names its chain already",
    );
}

/// Every named choice a command line offers (`names::Choice`) is named as
/// it is serialised in reports and design files, so that a value read
/// back from JSON and one typed on the command line agree.
#[test]
fn choices_are_named_as_they_are_serialised() {
    use activecal::names::Choice;
    fn check<T: Choice + serde::Serialize + std::fmt::Display>() {
        for v in T::ALL {
            let json = serde_json::to_string(v).unwrap();
            assert_eq!(json, format!("\"{}\"", v.name()));
            assert_eq!(v.to_string(), v.name());
            assert!(T::from_name(v.name()).is_some_and(|w| w.name() == v.name()));
        }
        assert!(T::from_name("no-such-choice").is_none());
    }
    check::<activecal::model::ParamSet>();
    check::<activecal::select::Algorithm>();
    check::<activecal::select::CriterionKind>();
    check::<activecal::bound::RelaxationSolver>();
}

/// The library names an input by what it is; the command line adds the
/// option that gives it. Without a tip, the TIAGo's tree is refused by the
/// library in its own words and the binary adds `--tip`; a missing locked
/// joint gets `--lock`.
#[test]
fn library_errors_name_the_input_and_the_binary_names_the_option() {
    let (ok, err) = counted(&["fk", "--robot", "fixtures/figaroh/tiago.urdf", "--q", "0"]);
    assert!(!ok);
    assert!(
        err.contains("the chain's tip") && !err.starts_with("error: --tip"),
        "{err}"
    );
    assert!(
        err.contains("hint: --tip LINK names the chain's tip"),
        "{err}"
    );
    let (ok, err) = counted(&[
        "fk",
        "--robot",
        "fixtures/figaroh/tiago.urdf",
        "--tip",
        "arm_tool_link",
        "--lock",
        "no_such_joint=0",
        "--q",
        "0",
    ]);
    assert!(!ok);
    assert!(err.contains("locked joint 'no_such_joint'"), "{err}");
    assert!(err.contains("hint: --lock NAME=VALUE"), "{err}");
}
