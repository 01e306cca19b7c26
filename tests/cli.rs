//! The command line: documented outputs and clear errors (non-zero exit, no
//! panic) on bad input.

use crate::common;

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
        "possible values: nominal, real",
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
        "possible values: eae, fedorov, detmax, random",
    );
    fails_with(
        &["select", "--levels", "3", "--criterion", "magic"],
        "possible values: det, oi",
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

/// `calibrate --design` draws its validation poses from the design's own
/// pool, with the visibility filter `select` applied (it used to rebuild
/// the unfiltered lattice, so poses the sensor cannot see were validated).
#[test]
fn calibrate_uses_the_design_pool_with_its_visibility_filter() {
    let dir = std::env::temp_dir().join(format!("activecal-calvis-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let design = dir.join("vis.json");
    let d = design.to_str().unwrap();
    let half = r#"{"kind":"box","min":[-100,-100,-100],"max":[100,100,0.5]}"#;
    let sel = json_of(&[
        "select",
        "--levels",
        "3",
        "--visibility",
        half,
        "--out",
        d,
        "--json",
    ]);
    let pool_size = sel["pool_size"].as_u64().unwrap() as usize;
    assert!(pool_size < 729, "the box should hide some poses");
    assert_eq!(sel["pool"]["filters"][0]["visibility"]["kind"], "box");
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&design).unwrap()).unwrap();
    assert_eq!(file["pool"], sel["pool"]);
    assert_eq!(file["q"].as_array().unwrap().len(), 30);
    // Every pose outside the design but in the filtered pool validates.
    let free = pool_size - 30;
    let v = json_of(&[
        "calibrate",
        "--design",
        d,
        "--validation",
        &free.to_string(),
        "--json",
    ]);
    assert_eq!(v["pool_size"].as_u64().unwrap() as usize, pool_size);
    assert_eq!(v["validation_poses"].as_u64().unwrap() as usize, free);
    assert_eq!(v["pool"], sel["pool"]);
    assert_eq!(v["chain"].as_array().unwrap().len(), 6);
    // One more is more than the sensor sees (the unfiltered lattice has 699).
    fails_with(
        &[
            "calibrate",
            "--design",
            d,
            "--validation",
            &(free + 1).to_string(),
        ],
        "more validation poses than pool poses",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A design file of the old format (lattice indices only) still loads in
/// `score`, `gap` and `calibrate`, with the lattice's joint values.
#[test]
fn old_design_files_still_load() {
    let old = "fixtures/designs/puma560_levels3_v0.json";
    let ids: Vec<&str> = vec![
        "0", "13", "26", "40", "53", "67", "80", "94", "107", "121", "134", "148", "161", "175",
        "188", "202", "215", "229", "242", "256", "269", "283", "296", "310", "323", "337", "350",
        "364", "377", "391",
    ];
    let s = json_of(&["score", "--design", old, "--json"]);
    let by_ids = json_of(&[
        "score",
        "--levels",
        "3",
        "--poses",
        &ids.join(","),
        "--json",
    ]);
    assert_eq!(s["poses"].as_array().unwrap().len(), 30);
    assert_eq!(s["ln_oid"], by_ids["ln_oid"]);
    assert_eq!(s["levels"], 3);
    let g = json_of(&[
        "gap",
        "--design",
        old,
        "--first-order",
        "--gap-tol",
        "1e-3",
        "--json",
    ]);
    assert_eq!(g["poses"], s["poses"]);
    assert_eq!(g["bound"]["status"], "certified");
    // This old 30-pose design does not determine every unknown
    // (RankDeficient): the report is printed, and the exit status is
    // calibrate's own for a fit that did not converge, as JSON says.
    let out = run(&["calibrate", "--design", old, "--validation", "50", "--json"]);
    let c: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(c["poses"], 30);
    assert_eq!(c["pool_size"], 729);
    assert_eq!(
        out.status.code(),
        c["exit_status"].as_i64().map(|v| v as i32)
    );
    assert_eq!(c["status"] == "converged", out.status.code() == Some(0));
}

/// A design's stored joint values are what `score` uses: a pose moved off
/// the lattice changes the score, and `gap` (which needs the pool's poses)
/// says which pose is not in the pool.
#[test]
fn stored_joint_values_are_scored() {
    let dir = std::env::temp_dir().join(format!("activecal-qdesign-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("d.json");
    let p = path.to_str().unwrap();
    json_of(&[
        "select", "--levels", "3", "--seed", "2", "--out", p, "--json",
    ]);
    let before = json_of(&["score", "--design", p, "--json"]);
    let mut file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    file["q"][0][1] = serde_json::json!(0.123);
    std::fs::write(&path, file.to_string()).unwrap();
    let after = json_of(&["score", "--design", p, "--json"]);
    assert_ne!(before["ln_oid"], after["ln_oid"]);
    fails_with(
        &["gap", "--design", p, "--first-order"],
        "other joint values",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The bound's status is spelled the same (serde, lowercase) in every report.
#[test]
fn bound_status_is_lowercase_everywhere() {
    let b = json_of(&[
        "bound",
        "--levels",
        "3",
        "--n",
        "15",
        "--first-order",
        "--gap-tol",
        "1e-3",
        "--json",
    ]);
    assert_eq!(b["status"], "certified");
    let s = json_of(&[
        "select",
        "--levels",
        "3",
        "--n",
        "15",
        "--gap",
        "--gap-solver",
        "newton",
        "--json",
    ]);
    assert_eq!(s["bound_status"], "certified");
}

/// A tracker 3 m away and turned 100°: the nominal line first says what
/// the robot's own geometry is off by (the nominal geometry in the best
/// rigid placement of the measurement frame, millimetres), then the
/// as-given figure (metres off); `--json` keeps `nominal_residuals` as
/// given and adds `nominal_placed_position_rms_mm`.
#[test]
fn a_far_tracker_s_nominal_line_leads_with_the_best_rigid_placement() {
    let dir = std::env::temp_dir().join(format!("activecal-far-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (design, near, far) = (
        dir.join("d.json"),
        dir.join("near.json"),
        dir.join("far.json"),
    );
    let robot = [
        "--robot",
        "fixtures/example-robot-data/ur5_robot.urdf",
        "--tip",
        "tool0",
        "--marker",
        "tool0@0.03,-0.02,0.1",
    ];
    // The command first, then the robot, then the command's options.
    fn with<'a>(robot: &[&'a str], cmd: &[&'a str]) -> Vec<&'a str> {
        cmd[..1]
            .iter()
            .chain(robot)
            .chain(&cmd[1..])
            .copied()
            .collect()
    }
    let sel = [
        "select",
        "--pool",
        "sobol",
        "--count",
        "256",
        "--n",
        "30",
        "--out",
        design.to_str().unwrap(),
    ];
    assert!(run(&with(&robot, &sel)).status.success());
    let sim = [
        "calibrate",
        "--design",
        design.to_str().unwrap(),
        "--noise",
        "5e-5",
        "--validation",
        "100",
        "--save-measurements",
        near.to_str().unwrap(),
    ];
    assert!(run(&with(&robot, &sim)).status.success());
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&near).unwrap()).unwrap();
    // 100° about z, then 3 m away.
    let (c, s) = (100f64.to_radians().cos(), 100f64.to_radians().sin());
    for p in m["points"].as_array_mut().unwrap() {
        let v: Vec<f64> = p
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        *p = serde_json::json!([
            c * v[0] - s * v[1] + 2.0,
            s * v[0] + c * v[1] - 2.2,
            v[2] + 0.3
        ]);
    }
    std::fs::write(&far, m.to_string()).unwrap();
    let cal = ["calibrate", "--measurements", far.to_str().unwrap()];
    let v = json_of(&with(&robot, &[&cal[..], &["--json"]].concat()));
    let placed = v["nominal_placed_position_rms_mm"].as_f64().unwrap();
    let given = v["nominal_residuals"]["position_rms_mm"].as_f64().unwrap();
    // The simulated robot is a few mm off its URDF (12.8 mm RMS at the
    // tour's poses); as given, the points are metres away.
    assert!(placed > 1.0 && placed < 30.0, "{placed}");
    assert!(given > 1000.0, "{given}");
    let out = run(&with(&robot, &cal));
    let text = String::from_utf8_lossy(&out.stdout);
    let first = text
        .find("nominal geometry, best rigid placement of the measurement frame: position RMS")
        .unwrap_or_else(|| panic!("{text}"));
    let second = text
        .find("nominal as given (the measurement frame at the base): position RMS")
        .unwrap_or_else(|| panic!("{text}"));
    assert!(first < second, "{text}");
    // Data near the nominal model keep the one nominal line.
    let out = run(&with(
        &robot,
        &["calibrate", "--measurements", near.to_str().unwrap()],
    ));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("\nnominal: position RMS") && !text.contains("best rigid placement"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Hints name what the user gave: a URDF on the command line gets `--tip`,
/// a description file its `tip = "…"` key (and the error no longer tells a
/// command-line user about descriptions); a missing package mesh names
/// the directory `--package-dir` should point to.
#[test]
fn hints_name_the_option_the_user_actually_used() {
    let stderr = |args: &[&str]| {
        let out = run(args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let e = stderr(&[
        "select",
        "--robot",
        "fixtures/figaroh/tiago.urdf",
        "--n",
        "10",
    ]);
    assert!(e.contains("hint: --tip LINK names the chain's tip"), "{e}");
    assert!(!e.contains("description"), "{e}");
    let dir = std::env::temp_dir().join(format!("activecal-hints-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toml = dir.join("setup.toml");
    let urdf = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/figaroh/tiago.urdf");
    std::fs::write(&toml, format!("urdf = {:?}\n", urdf.to_str().unwrap())).unwrap();
    let e = stderr(&["robots", "--robot", toml.to_str().unwrap()]);
    assert!(
        e.contains("hint: tip = \"LINK\" in the description names the chain's tip"),
        "{e}"
    );
    assert!(!e.contains("--tip"), "{e}");
    let e = stderr(&[
        "select",
        "--robot",
        "fixtures/figaroh/tiago.urdf",
        "--tip",
        "arm_tool_link",
        "--self-collision",
        "--pool",
        "sobol",
        "--count",
        "64",
        "--n",
        "10",
    ]);
    assert!(
        e.contains("hint: --package-dir DIR names a package directory (repeatable): the directory that holds tiago_description/ (or tiago_description itself)"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `calibrate --design … --save-measurements m.csv` writes the CSV a
/// tracker exports (joint columns, `x1,y1,z1`, a quaternion for full
/// poses), and calibrating from it gives what the JSON file gives.
#[test]
fn simulated_measurements_saved_as_csv_calibrate_as_the_json_does() {
    let dir = std::env::temp_dir().join(format!("activecal-savecsv-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let p = |n: &str| dir.join(n).to_str().unwrap().to_string();
    for (robot, head) in [
        ("ur5:pose", "q1,q2,q3,q4,q5,q6,x1,y1,z1,qw1,qx1,qy1,qz1"),
        ("fixtures/ur5.urdf", ""),
    ] {
        let d = p("d.json");
        let _ = std::fs::remove_file(&d);
        let sel = run(&[
            "select", "--robot", robot, "--levels", "3", "--n", "20", "--out", &d,
        ]);
        assert!(
            sel.status.success(),
            "{}",
            String::from_utf8_lossy(&sel.stderr)
        );
        for m in ["m.csv", "m.json"] {
            let _ = std::fs::remove_file(p(m));
            let args = [
                "calibrate",
                "--robot",
                robot,
                "--design",
                &d,
                "--noise",
                "1e-4",
                "--validation",
                "10",
                "--save-measurements",
                &p(m),
            ];
            assert!(run(&args).status.success(), "{args:?}");
        }
        let csv = std::fs::read_to_string(p("m.csv")).unwrap();
        assert!(csv.starts_with(head), "{csv}");
        assert_eq!(csv.lines().count(), 21);
        let fit = |m: &str| {
            json_of(&[
                "calibrate",
                "--robot",
                robot,
                "--measurements",
                &p(m),
                "--json",
            ])
        };
        let (a, b) = (fit("m.csv"), fit("m.json"));
        let est = |v: &serde_json::Value| -> Vec<f64> {
            v["estimate"]
                .as_object()
                .unwrap()
                .values()
                .map(|x| x.as_f64().unwrap())
                .collect()
        };
        let (ea, eb) = (est(&a), est(&b));
        assert_eq!(ea.len(), eb.len());
        for (x, y) in ea.iter().zip(&eb) {
            assert!((x - y).abs() < 1e-9, "{robot}: {x} vs {y}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
