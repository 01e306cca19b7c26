//! The `--json` keys users parse stay as they were: `bound`, `gap`,
//! `select --gap` and `calibrate` (measured data and a simulated design)
//! print exactly the key paths recorded in `tests/golden/json_keys/` (from
//! the binary of 2026-11-28 that still had `BoundReport` and
//! `IdentificationReport` beside `Bound` and `Identification`). A key
//! added, renamed or dropped fails here; refresh a list on purpose only.

use crate::common;

use common::{json_of, scratch_dir};
use serde_json::Value;
use std::collections::BTreeSet;

/// Every key path of `v` (`a.b`, array items as `a[].b`).
fn paths(v: &Value, pre: &str, out: &mut BTreeSet<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = if pre.is_empty() {
                    k.clone()
                } else {
                    format!("{pre}.{k}")
                };
                out.insert(p.clone());
                paths(x, &p, out);
            }
        }
        Value::Array(a) => {
            for x in a {
                paths(x, &format!("{pre}[]"), out);
            }
        }
        _ => {}
    }
}

fn assert_keys(name: &str, v: &Value) {
    let golden = std::fs::read_to_string(format!("tests/golden/json_keys/{name}.txt")).unwrap();
    let want: BTreeSet<String> = golden.lines().map(str::to_string).collect();
    let mut got = BTreeSet::new();
    paths(v, "", &mut got);
    let missing: Vec<_> = want.difference(&got).collect();
    let extra: Vec<_> = got.difference(&want).collect();
    assert!(
        missing.is_empty() && extra.is_empty(),
        "{name}: keys missing {missing:?}, new {extra:?}"
    );
}

#[test]
fn bound_gap_and_select_keep_their_keys() {
    let d = scratch_dir("json_shape", "bound");
    let design = d.join("d.json");
    let design = design.to_str().unwrap();
    let lattice = ["--robot", "puma560", "--levels", "3"];
    let b = json_of(&[&["bound"][..], &lattice, &["--n", "30", "--json"]].concat());
    assert_keys("bound", &b);
    // The bound's summary: log10 of the bound, and no weights.
    let (ln, log10) = (
        b["ln_bound"].as_f64().unwrap(),
        b["log10_bound"].as_f64().unwrap(),
    );
    assert!((log10 - ln / std::f64::consts::LN_10).abs() <= 1e-12 * log10.abs());
    let sel = json_of(
        &[
            &["select"][..],
            &lattice,
            &[
                "--n", "30", "--order", "none", "--gap", "--out", design, "--json",
            ],
        ]
        .concat(),
    );
    assert_keys("select_gap", &sel);
    assert_keys("gap", &json_of(&["gap", "--design", design, "--json"]));
    let sim = json_of(&[
        "calibrate",
        "--design",
        design,
        "--validation",
        "50",
        "--trials",
        "3",
        "--json",
    ]);
    assert_keys("calibrate_design", &sim);
}

#[test]
fn calibrate_on_measured_data_keeps_its_keys() {
    let v = json_of(&[
        "--tip",
        "wrist_3_link",
        "calibrate",
        "--robot",
        "fixtures/figaroh/ur10_robot.urdf:pose",
        "--measurements",
        "fixtures/figaroh/ur10_full_pose.csv",
        "--json",
    ]);
    assert_keys("calibrate_measured", &v);
    // The identification's fields sit at the top level, named by unknown.
    assert_eq!(v["converged"], true);
    let est = v["estimate"].as_object().unwrap();
    assert_eq!(est.len(), v["std"].as_object().unwrap().len());
}
