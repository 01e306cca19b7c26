//! The command line: documented outputs and clear errors (non-zero exit, no
//! panic) on bad input.

mod common;

use common::{fails_with, json_of, run};

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

#[test]
fn select_writes_a_design_that_score_reads_and_never_overwrites() {
    let dir = std::env::temp_dir().join(format!("activecal-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("design.json");
    let p = path.to_str().unwrap();
    let v = json_of(&[
        "select", "--levels", "4", "--n", "30", "--seed", "3", "--out", p, "--json",
    ]);
    assert_eq!(v["poses"].as_array().unwrap().len(), 30);
    assert!(v["trace"].as_array().unwrap().len() > 18);
    let s = json_of(&["score", "--design", p, "--json"]);
    // Tolerance: select reports the updated ln det, score recomputes it by SVD;
    // both are within ~1e-10 relative for this well-conditioned design.
    let (a, b) = (v["ln_oid"].as_f64().unwrap(), s["ln_oid"].as_f64().unwrap());
    assert!((a - b).abs() < 1e-8 * a.abs(), "{a} vs {b}");
    assert_eq!(s["rank"], 27);
    fails_with(
        &["select", "--levels", "4", "--out", p],
        "exists; pass --force",
    );
    let again = json_of(&[
        "select", "--levels", "4", "--seed", "3", "--out", p, "--force", "--json",
    ]);
    assert_eq!(again["poses"], v["poses"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn select_errors_are_clear() {
    fails_with(
        &["select", "--levels", "3", "--n", "1000"],
        "larger than the pool",
    );
    fails_with(
        &["select", "--levels", "3", "--n", "5"],
        "fewer than the 27 unknowns",
    );
    fails_with(
        &["select", "--levels", "3", "--fixed", "729"],
        "not in the pool",
    );
    fails_with(
        &["select", "--levels", "3", "--fixed", "4,4"],
        "more than once",
    );
    fails_with(
        &["select", "--levels", "3", "--algorithm", "magic"],
        "unknown algorithm",
    );
    fails_with(
        &["select", "--levels", "3", "--criterion", "magic"],
        "unknown criterion",
    );
    // A box far from the robot leaves nothing.
    let far = r#"{"kind":"box","min":[100,100,100],"max":[200,200,200]}"#;
    fails_with(
        &["select", "--levels", "3", "--visibility", far],
        "removed every pose",
    );
    // A pose the sensor cannot see cannot be fixed: find one outside a half-space box.
    let half = r#"{"kind":"box","min":[-100,-100,-100],"max":[100,100,0.5]}"#;
    let all = json_of(&[
        "select",
        "--levels",
        "3",
        "--n",
        "12",
        "--visibility",
        half,
        "--json",
    ]);
    assert!(all["poses"].as_array().unwrap().len() == 12);
    let mut hidden = None;
    for i in 0..729 {
        let out = run(&[
            "select",
            "--levels",
            "3",
            "--n",
            "12",
            "--visibility",
            half,
            "--fixed",
            &i.to_string(),
        ]);
        if !out.status.success() {
            hidden = Some(i);
            assert!(String::from_utf8_lossy(&out.stderr).contains("visibility filter"));
            break;
        }
    }
    assert!(hidden.is_some(), "the half-space box should hide some pose");
}

#[test]
fn score_reports_singular_designs() {
    let v = json_of(&["score", "--poses", "1,2,3", "--json"]);
    assert_eq!(v["singular"], true);
    assert!(v["rank"].as_u64().unwrap() < 27);
    fails_with(&["score", "--poses", "1,1,2"], "more than once");
    fails_with(&["score", "--poses", "1,99999"], "not in the pool");
}
