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
