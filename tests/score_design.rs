//! `score --design` scores a design on its own pool: a pool filter given
//! beside it (margin, clearance, collision) is refused, never ignored.

use crate::common;

use common::{fails_with, run, scratch_dir};

#[test]
fn pool_filters_beside_a_design_are_refused_naming_the_option() {
    let d = scratch_dir("score_design", "filters").join("d.json");
    let p = d.to_str().unwrap();
    let out = run(&[
        "select", "--levels", "3", "--n", "10", "--starts", "1", "--out", p,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for extra in [
        &["--margin", "3"][..],
        &["--clearance", "0.01"],
        &["--floor", "-0.5"],
        &["--obstacle", "box:1,1,1,0.1,0.1,0.1"],
    ] {
        let mut args = vec!["score", "--design", p];
        args.extend_from_slice(extra);
        fails_with(&args, &format!("{} given with", extra[0]));
    }
    // Alone, the design scores.
    assert!(run(&["score", "--design", p]).status.success());
}

/// `score --orientation-noise` scores a full-pose design weighted as
/// `select --orientation-noise` chose it (issue #39, item 4): the same
/// ln OI_D as select reports for its design (to 1e-9, the rounding of a
/// log-determinant of O(100) recomputed from the written joint values),
/// and a different one without the weight (1 m/rad, the robot's own scale,
/// so the test fails if the option is ignored); on a point sensor it is
/// refused, naming the option.
#[test]
fn orientation_noise_scores_as_select_weighs() {
    let d = scratch_dir("score_design", "orientation").join("d.json");
    let p = d.to_str().unwrap();
    let weigh = ["--noise", "0.0001", "--orientation-noise", "0.0005"];
    let mut sel = vec![
        "select",
        "--robot",
        "puma560:pose",
        "--levels",
        "3",
        "--n",
        "30",
        "--starts",
        "1",
        "--json",
        "--out",
        p,
    ];
    sel.extend_from_slice(&weigh);
    let chosen = common::json_of(&sel)["ln_oid"].as_f64().unwrap();
    let mut sc = vec!["score", "--design", p, "--json"];
    sc.extend_from_slice(&weigh);
    let scored = common::json_of(&sc)["ln_oid"].as_f64().unwrap();
    assert!((scored - chosen).abs() < 1e-9, "{scored} vs {chosen}");
    let plain = common::json_of(&["score", "--design", p, "--json"])["ln_oid"]
        .as_f64()
        .unwrap();
    assert!((plain - chosen).abs() > 1.0, "{plain} vs {chosen}");
    let q = d.with_file_name("point.json");
    let q = q.to_str().unwrap();
    let out = run(&[
        "select", "--levels", "3", "--n", "10", "--starts", "1", "--out", q,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    fails_with(
        &["score", "--design", q, "--orientation-noise", "0.001"],
        "--orientation-noise: robot",
    );
}
