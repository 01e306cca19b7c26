//! Resource limits and output safety from the command line: every case is
//! refused before the expensive step, with exit status 1, a message naming
//! the input and what would be accepted, and no file left behind.

use crate::common;

use common::{fails_with, run};
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

fn scratch(name: &str) -> PathBuf {
    common::scratch_dir("safety", name)
}

#[test]
fn oversized_pools_are_refused_with_the_figure_before_allocating() {
    // 20^6 = 64 million poses: an 86 GB Jacobian and workspace. Refused at
    // once (a try would take minutes or meet the OOM killer).
    let t0 = Instant::now();
    fails_with(
        &["select", "--levels", "20", "--n", "30"],
        "would need 86.5 GB of memory",
    );
    assert!(
        t0.elapsed() < Duration::from_secs(20),
        "refused late: {:?}",
        t0.elapsed()
    );
    // The budget can be set; a malformed one is named.
    let out = Command::new(env!("CARGO_BIN_EXE_activecal"))
        .args(["bound", "--levels", "4", "--n", "30"])
        .env("ACTIVECAL_MAX_MEMORY", "1M")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("above the limit of 1.0 MB (ACTIVECAL_MAX_MEMORY=1M)"),
        "{err}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_activecal"))
        .args(["bound", "--levels", "3", "--n", "30"])
        .env("ACTIVECAL_MAX_MEMORY", "lots")
        .output()
        .unwrap();
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("ACTIVECAL_MAX_MEMORY=lots: expected a size")
    );
}

#[test]
fn outputs_are_checked_before_any_work() {
    let d = scratch("outputs");
    let ds = d.to_str().unwrap();
    let missing = d.join("no/such/dir/design.json");
    // A missing directory, a directory, before the search starts.
    let t0 = Instant::now();
    fails_with(
        &[
            "select",
            "--levels",
            "3",
            "--n",
            "15",
            "--out",
            missing.to_str().unwrap(),
        ],
        "does not exist",
    );
    assert!(t0.elapsed() < Duration::from_secs(10));
    fails_with(
        &["select", "--levels", "3", "--n", "15", "--out", ds],
        "is a directory",
    );
    // One file for two outputs, even with --force.
    let f = d.join("x.json");
    let fs = f.to_str().unwrap();
    let design = d.join("design.json");
    let out = run(&[
        "select",
        "--levels",
        "3",
        "--n",
        "15",
        "--out",
        design.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    fails_with(
        &[
            "calibrate",
            "--design",
            design.to_str().unwrap(),
            "--out",
            fs,
            "--save-measurements",
            fs,
            "--force",
        ],
        "name the same file",
    );
    // An output that is an input.
    fails_with(
        &[
            "calibrate",
            "--design",
            design.to_str().unwrap(),
            "--save-measurements",
            design.to_str().unwrap(),
            "--force",
        ],
        "is an input of this command",
    );
    assert!(!f.exists(), "nothing written on refusal");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn reproduce_checks_everything_first_and_swaps_its_directory_in_whole() {
    let d = scratch("reproduce");
    let out = d.join("report");
    let os = out.to_str().unwrap();
    // Bad settings: refused at once, and no directory is made.
    for (args, want) in [
        (vec!["--trials", "0"], "trials"),
        (vec!["--noise", "NaN"], "noise"),
    ] {
        let mut a = vec![
            "reproduce",
            "--out",
            os,
            "--levels",
            "3",
            "--n",
            "15",
            "--initial",
            "10",
        ];
        a.extend(args);
        let t0 = Instant::now();
        fails_with(&a, want);
        assert!(t0.elapsed() < Duration::from_secs(10), "{a:?} refused late");
        assert!(!out.exists(), "{a:?} made the output directory");
    }
    // An old report is replaced whole with --force: no old file remains.
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("stale.txt"), "old").unwrap();
    fails_with(&["reproduce", "--out", os, "--levels", "3"], "--force");
    let args = [
        "reproduce",
        "--out",
        os,
        "--force",
        "--levels",
        "3",
        "--n",
        "15",
        "--initial",
        "10",
        "--designs",
        "50",
        "--starts",
        "1",
        "--trials",
        "3",
        "--skip-oi",
    ];
    let r = run(&args);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(out.join("report.json").exists());
    assert!(
        !out.join("stale.txt").exists(),
        "the old directory was not replaced whole"
    );
    // No staging directory is left beside it.
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
    std::fs::remove_dir_all(&d).unwrap();
}
