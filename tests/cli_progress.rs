//! Progress goes to stderr only, and never pollutes `--json` output: with
//! `--progress` (stderr is a pipe here, so progress comes as plain lines)
//! the long stages of `bound`, `select` and `calibrate` report on stderr
//! while stdout stays one JSON object equal to the run without progress;
//! without `--progress`, `--json` runs print no progress at all.

use crate::common;
use common::run;
use serde_json::Value;

fn progress_lines(stderr: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(stderr)
        .lines()
        .filter(|l| l.starts_with("progress: "))
        .map(str::to_string)
        .collect()
}

/// Runs `args` with and without `--progress`; returns the progress lines of
/// the first run after checking that both stdouts are the same JSON (the
/// `seconds` fields aside) and that the quiet run printed no progress.
fn check(args: &[&str]) -> Vec<String> {
    let quiet = run(args);
    assert!(
        quiet.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&quiet.stderr)
    );
    assert!(
        progress_lines(&quiet.stderr).is_empty(),
        "{args:?} without --progress printed progress"
    );
    let mut with: Vec<&str> = args.to_vec();
    with.push("--progress");
    let loud = run(&with);
    assert!(loud.status.success());
    let strip = |v: &mut Value| {
        fn walk(v: &mut Value) {
            match v {
                Value::Object(m) => {
                    m.retain(|k, _| !k.contains("seconds"));
                    m.values_mut().for_each(walk);
                }
                Value::Array(a) => a.iter_mut().for_each(walk),
                _ => {}
            }
        }
        walk(v);
    };
    let mut a: Value = serde_json::from_slice(&quiet.stdout).expect("JSON without --progress");
    let mut b: Value =
        serde_json::from_slice(&loud.stdout).expect("stdout stays JSON with --progress");
    strip(&mut a);
    strip(&mut b);
    assert_eq!(a, b, "{args:?}: --progress changed the results");
    progress_lines(&loud.stderr)
}

#[test]
fn bound_reports_its_rounds_on_stderr_only() {
    let lines = check(&["bound", "--levels", "3", "--n", "30", "--json"]);
    for task in ["jacobian", "bound: first-order rounds", "newton steps"] {
        assert!(
            lines
                .iter()
                .any(|l| l.starts_with(&format!("progress: {task}")) && l.ends_with("started")),
            "no start of {task}: {lines:#?}"
        );
        assert!(
            lines
                .iter()
                .any(|l| l.starts_with(&format!("progress: {task}")) && l.contains("done in")),
            "no end of {task}: {lines:#?}"
        );
    }
    // The pool's Jacobian counts every one of the 3^6 lattice poses.
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("progress: jacobian 729/729 done in")),
        "{lines:#?}"
    );
}

#[test]
fn multistart_and_monte_carlo_count_their_units() {
    let lines = check(&[
        "select", "--levels", "3", "--n", "30", "--starts", "5", "--json",
    ]);
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("progress: select (eae starts) 5/5 done in")),
        "{lines:#?}"
    );
    let dir = std::env::temp_dir().join(format!("activecal-progress-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let design = dir.join("d.json");
    let d = design.to_str().unwrap();
    let out = run(&[
        "select", "--levels", "3", "--n", "30", "--out", d, "--force",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines = check(&["calibrate", "--design", d, "--trials", "7", "--json"]);
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("progress: monte-carlo trials 7/7 done in")),
        "{lines:#?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
