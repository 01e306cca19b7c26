//! `reproduce` on a reduced setting: the report and figures exist, the
//! Markdown tables parse, the numbers equal those of the underlying commands
//! run separately, and they equal the golden report committed before the
//! restructuring of the module tree (`tests/golden/reproduce_levels3.json`).

use crate::common;

use serde_json::Value;
use std::process::Command;

use common::json_of as run_json;

/// Compares `report` with the golden report `gold`, leaf by leaf over the
/// golden keys (a report may gain keys; it may not lose or change one).
///
/// - Wall-clock times (`seconds`) are skipped.
/// - Strings compare case-insensitively (a status's spelling may change, not
///   its value).
/// - Selections, random designs, identification and Monte-Carlo are
///   deterministic for a seed: every number agrees to 1e-9 relative (with an
///   absolute floor of 1e-15 for entries that are zero up to rounding).
/// - The relaxation bound is a solver's point inside its certified gap:
///   `ln_bound`, `ln_primal` and `log10_bound` may move by the sum of the two
///   reports' certificate gaps (and `log10` by that over ln 10); a design's
///   D-efficiency `exp((ln OI_D − ln bound)/p)` moves by that sum over p,
///   relative.
fn compare_golden(gold: &Value, report: &Value, path: &str, bound_tol: f64, p: f64) {
    match gold {
        Value::Object(m) => {
            for (k, g) in m {
                if k == "seconds" {
                    continue;
                }
                let r = report
                    .get(k)
                    .unwrap_or_else(|| panic!("{path}.{k}: missing from the report"));
                compare_golden(g, r, &format!("{path}.{k}"), bound_tol, p);
            }
        }
        Value::Array(a) => {
            let b = report
                .as_array()
                .unwrap_or_else(|| panic!("{path}: not an array"));
            assert_eq!(a.len(), b.len(), "{path}: length");
            for (i, (g, r)) in a.iter().zip(b).enumerate() {
                compare_golden(g, r, &format!("{path}[{i}]"), bound_tol, p);
            }
        }
        Value::Number(g) => {
            let g = g.as_f64().unwrap();
            let r = report
                .as_f64()
                .unwrap_or_else(|| panic!("{path}: {report} is not a number"));
            let leaf = path.rsplit('.').next().unwrap();
            let tol = if path.starts_with(".bound") && leaf.starts_with("ln_") {
                bound_tol
            } else if path.starts_with(".bound") && leaf == "log10_bound" {
                bound_tol / std::f64::consts::LN_10
            } else if leaf == "d_efficiency" {
                g.abs() * bound_tol / p
            } else if path.starts_with(".bound") && leaf == "certificate_gap" {
                bound_tol
            } else if path.starts_with(".bound") && leaf == "support_size" {
                f64::INFINITY // which poses carry weight 1e-9 is the solver's choice
            } else {
                1e-9 * g.abs().max(r.abs()) + 1e-15
            };
            assert!(
                (g - r).abs() <= tol,
                "{path}: golden {g}, now {r} (tolerance {tol:e})"
            );
        }
        Value::String(g) => {
            let r = report
                .as_str()
                .unwrap_or_else(|| panic!("{path}: not a string"));
            assert!(g.eq_ignore_ascii_case(r), "{path}: golden {g}, now {r}");
        }
        other => assert_eq!(other, report, "{path}"),
    }
}

/// Rows of the Markdown table that follows `heading`, as cells.
fn table_after(md: &str, heading: &str) -> Vec<Vec<String>> {
    let start = md.find(heading).unwrap_or_else(|| panic!("no '{heading}'"));
    md[start..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

#[test]
fn reduced_reproduce_matches_the_underlying_commands() {
    let dir = std::env::temp_dir().join(format!("activecal-repro-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let d = dir.to_str().unwrap();
    let common = [
        "--levels",
        "3",
        "--n",
        "15",
        "--initial",
        "10",
        "--seed",
        "5",
    ];
    let mut args = vec![
        "reproduce",
        "--out",
        d,
        "--designs",
        "200",
        "--starts",
        "2",
        "--trials",
        "10",
    ];
    args.extend(common);
    let out = Command::new(env!("CARGO_BIN_EXE_activecal"))
        .args(&args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "fig2_random_designs",
        "fig3_initial_poses",
        "fig4_log10_oid",
        "fig4a_selected_poses",
        "fig5_oi",
        "fig6_inverse_oid",
    ] {
        for ext in ["png", "svg"] {
            let meta = std::fs::metadata(dir.join(format!("{f}.{ext}"))).unwrap();
            assert!(meta.len() > 1000, "{f}.{ext} is too small");
        }
    }
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();

    // Same seeds, same results as before the restructuring.
    let gold: Value = serde_json::from_str(include_str!("golden/reproduce_levels3.json")).unwrap();
    let gap = |v: &Value| {
        v["bound"]["certificate_gap"].as_f64().unwrap()
            + v["bound"]["newton"]["certificate_gap"].as_f64().unwrap()
    };
    let p = report["settings"]["p"].as_f64().unwrap();
    compare_golden(&gold, &report, "", gap(&gold) + gap(&report), p);

    // The summary table parses and agrees with report.json.
    let summary = table_after(&md, "## Summary");
    assert!(summary.len() >= 6);
    for row in &summary {
        assert_eq!(row.len(), 3, "{row:?}");
    }
    let eae_row = summary
        .iter()
        .find(|r| r[0] == "EAE design, log10 OI_D")
        .unwrap();
    let eae_md: f64 = eae_row[2].parse().unwrap();
    let eae_json = report["eae"]["log10_oid"].as_f64().unwrap();
    assert!((eae_md - eae_json).abs() < 1e-4);
    for (t, cols) in [
        ("## Table III", 6),
        ("## Table IV", 6),
        ("## Designs and their", 3),
        ("## Monte-Carlo", 8),
    ] {
        let rows = table_after(&md, t);
        assert!(!rows.is_empty(), "{t}");
        assert!(rows.iter().all(|r| r.len() == cols), "{t}: {rows:?}");
    }
    assert_eq!(table_after(&md, "## Table III").len(), 7);

    // The same numbers from the underlying commands.
    // The paper's EAE: no iterated local search, one start (select's
    // defaults add both).
    let mut base = vec!["select", "--algorithm", "eae", "--ils", "0", "--json"];
    base.extend(common);
    let mut sel = base.clone();
    sel.extend(["--starts", "1"]);
    let s = run_json(&sel);
    assert_eq!(s["log10_oid"].as_f64().unwrap(), eae_json);
    assert_eq!(s["poses"], report["eae"]["poses"]);
    let mut ms = base.clone();
    ms.extend(["--starts", "2", "--polish"]);
    let m = run_json(&ms);
    assert_eq!(m["log10_oid"], report["multistart"]["log10_oid"]);
    let b = run_json(&["bound", "--levels", "3", "--n", "15", "--json"]);
    // Both are certified to a gap of 1e-6 in ln det; they may stop at
    // different points inside it.
    let (b1, b2) = (
        b["log10_bound"].as_f64().unwrap(),
        report["bound"]["log10_bound"].as_f64().unwrap(),
    );
    assert!((b1 - b2).abs() < 1e-6, "{b1} vs {b2}");
    // The Newton cross-check in the report, and `bound --solver newton`.
    let nb = &report["bound"]["newton"];
    assert_eq!(nb["status"], "certified");
    let b3 = nb["log10_bound"].as_f64().unwrap();
    assert!((b3 - b2).abs() < 1e-6, "{b3} vs {b2}");
    let bn = run_json(&[
        "bound", "--levels", "3", "--n", "15", "--solver", "newton", "--json",
    ]);
    assert_eq!(bn["solver"]["solver"], "newton");
    assert_eq!(bn["log10_bound"], nb["log10_bound"]);
    let mut rnd = sel.clone();
    rnd[2] = "random";
    // --initial sets EAE's start: refused with another algorithm.
    let k = rnd.iter().position(|a| *a == "--initial").unwrap();
    rnd.drain(k..k + 2);
    rnd.extend(["--designs", "200"]);
    let r = run_json(&rnd);
    // Same design; its ln det is computed by two Cholesky paths (the search's
    // and the state's), equal to rounding: 1e-12 relative.
    let (r1, r2) = (
        r["log10_oid"].as_f64().unwrap(),
        report["random"]["best_log10_oid"].as_f64().unwrap(),
    );
    assert!((r1 - r2).abs() < 1e-12 * r2.abs(), "{r1} vs {r2}");
    assert_eq!(r["poses"], report["random"]["best_poses"]);
    // The bound is above every design.
    for d in report["designs"].as_array().unwrap() {
        assert!(d["log10_oid"].as_f64().unwrap() <= b1 + 1e-9);
        assert!(d["d_efficiency"].as_f64().unwrap() <= 1.0 + 1e-9);
    }
    // Refuses to overwrite without --force.
    let again = Command::new(env!("CARGO_BIN_EXE_activecal"))
        .args(&args)
        .output()
        .unwrap();
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
    std::fs::remove_dir_all(&dir).unwrap();
}
