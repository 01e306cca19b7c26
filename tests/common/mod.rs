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
