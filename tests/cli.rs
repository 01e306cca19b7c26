//! The command line: documented outputs and clear errors (non-zero exit, no
//! panic) on bad input.

use serde_json::Value;
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_activecal"))
        .args(args)
        .output()
        .expect("runs")
}

fn json_of(args: &[&str]) -> Value {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

/// Fails with exit code 1, a message containing `needle`, and no panic.
fn fails_with(args: &[&str], needle: &str) {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    // 1: our error; 2: clap's usage error. Never success, never a signal.
    assert!(
        matches!(out.status.code(), Some(1 | 2)),
        "{args:?}: status {:?}",
        out.status
    );
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    assert!(err.contains(needle), "{args:?}: '{err}' lacks '{needle}'");
}

#[test]
fn pool_reports_paper_index() {
    let v = json_of(&[
        "pool",
        "--robot",
        "puma560",
        "--levels",
        "5",
        "--digits",
        "0,3,0,4,1,2",
        "--json",
    ]);
    assert_eq!(v["size"], 15625);
    assert_eq!(v["index"], 1982);
    assert_eq!(v["q"].as_array().unwrap().len(), 6);
}

#[test]
fn fk_accepts_negative_angles_both_ways() {
    let a = json_of(&[
        "fk",
        "--robot",
        "puma560",
        "--q",
        "-250,-110,-133,0,0,0",
        "--deg",
        "--json",
    ]);
    let b = json_of(&[
        "fk",
        "--robot",
        "puma560",
        "--q=-250,-110,-133,0,0,0",
        "--deg",
        "--json",
    ]);
    assert_eq!(a["position"], b["position"]);
    assert_eq!(a["position"].as_array().unwrap().len(), 3);
}

#[test]
fn fk_jacobian_has_3_rows_of_27() {
    let v = json_of(&[
        "fk",
        "--q",
        "0.1,0.2,0.3,0.4,0.5,0.6",
        "--params",
        "real",
        "--jacobian",
        "--json",
    ]);
    let j = v["jacobian"].as_array().unwrap();
    assert_eq!(j.len(), 3);
    assert!(j.iter().all(|r| r.as_array().unwrap().len() == 27));
    assert_eq!(v["parameter_names"][0], "gamma_a");
}

#[test]
fn robots_lists_puma() {
    let v = json_of(&["robots", "--json"]);
    assert_eq!(v["robots"][0]["name"], "puma560");
    assert_eq!(v["robots"][0]["unknowns"].as_array().unwrap().len(), 27);
}

#[test]
fn bad_input_is_a_clear_error() {
    fails_with(
        &["fk", "--robot", "nosuchbot", "--q", "0,0,0,0,0,0"],
        "unknown robot 'nosuchbot'",
    );
    fails_with(&["fk", "--q", "0,0,0"], "expected 6 joint angles, got 3");
    fails_with(&["fk", "--q", "0,NaN,0,0,0,0"], "q2 is not a finite number");
    fails_with(&["fk", "--q", "0,inf,0,0,0,0"], "q2 is not a finite number");
    fails_with(&["fk", "--q", "0,x,0,0,0,0"], "cannot parse 'x'");
    fails_with(
        &["fk", "--q", "0,0,0,0,0,0", "--params", "guess"],
        "unknown parameter set",
    );
    fails_with(&["pool", "--levels", "1"], "at least 2 levels");
    fails_with(
        &["pool", "--levels", "5", "--digits", "0,5,0,0,0,0"],
        "invalid lattice digits",
    );
    fails_with(
        &["pool", "--levels", "5", "--digits", "0,1"],
        "invalid lattice digits",
    );
}
