//! `--pool lattice|random|sobol|file:PATH` on the command line: every
//! command that builds a pool, filter statistics in the reports, design files
//! that need no pool file, the memory budget, and clear errors.

use crate::common;

use common::{fails_with, json_of, run};
use std::path::PathBuf;
use std::process::Command;

const UR10: &str = "fixtures/figaroh/ur10_robot.urdf:pose";
const UR10_CSV: &str = "fixtures/figaroh/ur10_full_pose.csv";

fn scratch(name: &str) -> PathBuf {
    common::scratch_dir("cli-pools", name)
}

#[test]
fn sampled_pools_are_recorded_and_reproducible() {
    let args = [
        "select",
        "--pool",
        "random",
        "--count",
        "1500",
        "--pool-seed",
        "4",
        "--n",
        "30",
        "--json",
    ];
    let a = json_of(&args);
    let b = json_of(&args);
    assert_eq!(a["poses"], b["poses"]);
    assert_eq!(a["pool"]["source"]["random"]["count"], 1500);
    assert_eq!(a["pool"]["source"]["random"]["seed"], 4);
    assert_eq!(a["pool_stats"]["candidates"], 1500);
    assert_eq!(a["pool_stats"]["kept"], 1500);
    assert_eq!(a["pool_size"], 1500);
    // Every id is a sample number.
    assert!(
        a["poses"]
            .as_array()
            .unwrap()
            .iter()
            .all(|p| p.as_u64().unwrap() < 1500)
    );
    // Sobol with a visibility filter: the report says what it removed.
    let half = r#"{"kind":"box","min":[-100,-100,-100],"max":[100,100,0.5]}"#;
    let v = json_of(&[
        "bound",
        "--pool",
        "sobol",
        "--count",
        "1024",
        "--pool-seed",
        "2",
        "--n",
        "30",
        "--visibility",
        half,
        "--solver",
        "newton",
        "--json",
    ]);
    let st = &v["pool_stats"];
    let f = &st["filters"][0];
    assert_eq!(f["filter"], "visibility");
    assert_eq!(f["seen"], 1024);
    let removed = f["removed"].as_u64().unwrap();
    assert!(removed > 0 && removed < 1024, "{st}");
    assert_eq!(st["kept"].as_u64().unwrap(), 1024 - removed);
    assert_eq!(v["pool_size"].as_u64().unwrap(), 1024 - removed);
    let text = String::from_utf8_lossy(
        &run(&[
            "bound",
            "--pool",
            "sobol",
            "--count",
            "1024",
            "--n",
            "30",
            "--visibility",
            half,
            "--solver",
            "newton",
        ])
        .stdout,
    )
    .into_owned();
    assert!(text.contains("visibility filter removed"), "{text}");
}

#[test]
fn a_file_sourced_design_scores_gaps_and_calibrates_without_its_file() {
    let d = scratch("file-design");
    let csv = d.join("poses.csv");
    std::fs::copy(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(UR10_CSV),
        &csv,
    )
    .unwrap();
    let design = d.join("design.json");
    let (csv_s, design_s) = (csv.to_str().unwrap(), design.to_str().unwrap());
    let pool = format!("file:{csv_s}");
    let sel = json_of(&[
        "select",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        &pool,
        "--n",
        "8",
        "--out",
        design_s,
        "--json",
    ]);
    assert_eq!(sel["pool_size"], 23);
    let notes = sel["pool_stats"]["notes"].to_string();
    assert!(notes.contains("x1") && notes.contains("phiz1"), "{notes}");
    let stored: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&design).unwrap()).unwrap();
    assert_eq!(stored["pool"]["source"]["file"]["path"], csv_s);
    assert_eq!(stored["pool_qs"].as_array().unwrap().len(), 23);
    // The original file is gone: the design carries what it needs.
    std::fs::remove_file(&csv).unwrap();
    let score = json_of(&["score", "--design", design_s, "--json"]);
    let gap = json_of(&["gap", "--design", design_s, "--solver", "newton", "--json"]);
    let ln = sel["ln_oid"].as_f64().unwrap();
    // Both recompute ln det of the same 8 poses' Jacobians (the stored joint
    // values are the file's, bit for bit): only summation order differs.
    for v in [&score["ln_oid"], &gap["ln_oid"]] {
        assert!(
            (v.as_f64().unwrap() - ln).abs() < 1e-9 * ln.abs(),
            "{v} vs {ln}"
        );
    }
    let eff = gap["d_efficiency"].as_f64().unwrap();
    assert!(eff > 0.0 && eff <= 1.0, "{eff}");
    let cal = json_of(&[
        "calibrate",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--design",
        design_s,
        "--validation",
        "10",
        "--json",
    ]);
    assert_eq!(cal["poses"], 8);
    assert_eq!(cal["pool_size"], 23);
    // Without stored configurations the file is needed, and its absence is named.
    let mut bare = stored.clone();
    bare.as_object_mut().unwrap().remove("pool_qs");
    let bare_path = d.join("bare.json");
    std::fs::write(&bare_path, bare.to_string()).unwrap();
    fails_with(
        &["gap", "--design", bare_path.to_str().unwrap()],
        "poses.csv",
    );
}

#[test]
fn pool_options_and_files_fail_clearly() {
    fails_with(&["select", "--pool", "grid"], "unknown pool 'grid'");
    fails_with(
        &["select", "--pool", "random", "--levels", "3"],
        "--levels: applies to --pool lattice only",
    );
    fails_with(
        &["bound", "--levels", "3", "--count", "10"],
        "--count: applies to --pool random or sobol only",
    );
    fails_with(&["select", "--pool", "sobol", "--count", "0"], "needs 1 to");
    let d = scratch("bad-files");
    let bad = d.join("bad.csv");
    std::fs::write(&bad, "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n0,0,0,0,7,0\n").unwrap();
    let pool = format!("file:{}", bad.display());
    fails_with(
        &["select", "--pool", &pool, "--n", "2"],
        "line 3, column 'q5'",
    );
    let missing = d.join("missing.csv");
    std::fs::write(&missing, "q1,q2,q3,q4,q5\n0,0,0,0,0\n").unwrap();
    let pool = format!("file:{}", missing.display());
    fails_with(
        &["score", "--pool", &pool, "--poses", "0"],
        "no column for joint 6",
    );
    // The memory budget covers every source, before anything is allocated.
    let out = Command::new(env!("CARGO_BIN_EXE_activecal"))
        .args(["select", "--pool", "random", "--count", "5000", "--n", "30"])
        .env("ACTIVECAL_MAX_MEMORY", "1M")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("a pool of 5000 poses") && err.contains("1.0 MB"),
        "{err}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_activecal"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "select",
            "--robot",
            UR10,
            "--tip",
            "wrist_3_link",
            "--pool",
            &format!("file:{UR10_CSV}"),
            "--n",
            "8",
        ])
        .env("ACTIVECAL_MAX_MEMORY", "1K")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("above the limit"), "{err}");
}
