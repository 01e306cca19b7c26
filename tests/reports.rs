//! `calibrate --report` and `select --report`: every figure is written as a
//! PNG that decodes, at its documented size, beside its SVG; report.md and
//! report.json are there; an existing directory is refused without --force.

use crate::common;

use common::{fails_with, run, scratch_dir};
use std::path::Path;

const UR10: &str = "fixtures/figaroh/ur10_robot.urdf:pose";
const UR10_CSV: &str = "fixtures/figaroh/ur10_full_pose.csv";

/// Decodes `dir/stem.png` and returns its size; asserts the SVG beside it.
fn png_size(dir: &Path, stem: &str) -> (u32, u32) {
    let path = dir.join(format!("{stem}.png"));
    let file = std::fs::File::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap_or_else(|e| panic!("{} does not decode: {e}", path.display()));
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("one frame");
    // Not blank: a figure has more than the white background.
    assert!(
        buf[..info.buffer_size()].iter().any(|&b| b < 200),
        "{} is blank",
        path.display()
    );
    let svg = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).expect("svg");
    assert!(svg.contains("<svg"), "{stem}.svg is not SVG");
    (info.width, info.height)
}

fn ok(args: &[&str]) {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn calibrate_report_on_the_ur10_writes_every_figure() {
    let d = scratch_dir("reports", "ur10").join("rep");
    let dir = d.to_str().unwrap();
    let args = [
        "--tip",
        "wrist_3_link",
        "calibrate",
        "--robot",
        UR10,
        "--measurements",
        UR10_CSV,
        "--holdout",
        "0.25",
        "--report",
        dir,
    ];
    ok(&args);
    for (stem, size) in [
        ("position_errors_sorted", (900, 560)),
        ("position_errors_histogram", (1200, 560)),
        ("orientation_errors_sorted", (900, 560)),
        ("orientation_errors_histogram", (1200, 560)),
        ("holdout_splits", (900, 560)),
        ("parameter_changes", (1100, 950)),
        ("correlation", (1100, 950)),
    ] {
        assert_eq!(png_size(&d, stem), size, "{stem}");
    }
    let md = std::fs::read_to_string(d.join("report.md")).unwrap();
    assert!(md.contains("mm") && md.contains("position_errors_sorted.png"));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("report.json")).unwrap()).unwrap();
    assert_eq!(v["status"], "converged");
    // The directory now holds a report: refused without --force, replaced with it.
    fails_with(&args, "--force");
    let mut forced = args.to_vec();
    forced.push("--force");
    ok(&forced);
}

#[test]
fn select_report_draws_the_curve_the_limits_and_the_tour() {
    let d = scratch_dir("reports", "select").join("rep");
    let dir = d.to_str().unwrap();
    ok(&[
        "--tip",
        "panda_hand_tcp",
        "select",
        "--robot",
        "fixtures/example-robot-data/panda.urdf:pose",
        "--pool",
        "sobol",
        "--count",
        "256",
        "--n",
        "12",
        "--starts",
        "1",
        "--report",
        dir,
        "--noise",
        "0.001",
    ]);
    assert_eq!(png_size(&d, "how_many_poses"), (1200, 560));
    // 120 px of frame and 70 a joint.
    assert_eq!(png_size(&d, "joints_vs_limits"), (1000, 120 + 70 * 7));
    // A URDF robot's poses are ordered by default: the tour is drawn.
    assert_eq!(png_size(&d, "tour"), (900, 560));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("report.json")).unwrap()).unwrap();
    let curve = &v["how_many_poses"];
    // p = 34 unknowns, 6 rows a pose: from 6 poses to 18, and the N asked.
    assert_eq!(curve["n_min"], 6);
    let pts = curve["points"].as_array().unwrap();
    let ns: Vec<u64> = pts.iter().map(|p| p["n"].as_u64().unwrap()).collect();
    assert_eq!(ns.first(), Some(&6));
    assert_eq!(ns.last(), Some(&18));
    assert!(ns.contains(&12));
    for p in pts {
        let e = p["d_efficiency"].as_f64().unwrap();
        assert!(e > 0.0 && e <= 1.0 + 1e-9, "{p}");
        let (rms, p95) = (
            p["predicted"]["position_rms_mm"].as_f64().unwrap(),
            p["predicted"]["position_p95_mm"].as_f64().unwrap(),
        );
        assert!(rms > 0.0 && p95 > 0.0, "{p}");
    }
    // Designs of different sizes are chosen independently (a larger one need
    // not contain a smaller one), so only the ends are compared: 18 poses
    // carry three times the rows of 6.
    let first = pts[0]["predicted"]["position_rms_mm"].as_f64().unwrap();
    let last = pts[pts.len() - 1]["predicted"]["position_rms_mm"]
        .as_f64()
        .unwrap();
    assert!(last < first, "{first} -> {last}");
    // Every size from 6 to 18 (step 1), and the curve's recommendation by
    // its rule: the knee, recomputed here from the points.
    assert_eq!(curve["step"], 1);
    let rms = |k: usize| pts[k]["predicted"]["position_rms_mm"].as_f64().unwrap();
    let knee = (0..pts.len()).find_map(|i| {
        let want = ns[i] + (ns[i] * 10).div_ceil(100).max(1);
        let j = (i + 1..pts.len()).find(|&j| ns[j] >= want)?;
        (1.0 - rms(j) / rms(i) < 0.05).then_some(ns[i])
    });
    let rec = &curve["recommended"];
    match knee {
        Some(n) => assert_eq!(
            (rec["rule"].as_str(), rec["n"].as_u64()),
            (Some("knee"), Some(n))
        ),
        None => assert_eq!(
            (rec["rule"].as_str(), rec["n"].as_u64()),
            (Some("no_knee"), Some(18))
        ),
    }
    // A target between two sizes' predictions: the smaller size reaching it.
    let target = 0.5 * (rms(3) + rms(4));
    let want = ns[(0..pts.len()).find(|&k| rms(k) <= target).unwrap()];
    let d2 = scratch_dir("reports", "select-target").join("rep");
    let out = run(&[
        "--tip",
        "panda_hand_tcp",
        "select",
        "--robot",
        "fixtures/example-robot-data/panda.urdf:pose",
        "--pool",
        "sobol",
        "--count",
        "256",
        "--n",
        "12",
        "--starts",
        "1",
        "--report",
        d2.to_str().unwrap(),
        "--noise",
        "0.001",
        "--target-error",
        &target.to_string(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(&format!(
            "how many poses: N = {want} recommended, the fewest predicted to reach {target} mm"
        )),
        "{text}"
    );
    let v2: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d2.join("report.json")).unwrap()).unwrap();
    assert_eq!(v2["how_many_poses"]["recommended"]["rule"], "target");
    assert_eq!(
        v2["how_many_poses"]["recommended"]["n"].as_u64(),
        Some(want)
    );
    // Without --report there is no curve to read a target from.
    fails_with(
        &[
            "select",
            "--robot",
            "puma560",
            "--levels",
            "3",
            "--target-error",
            "1",
        ],
        "--report",
    );
}

#[test]
fn a_report_path_that_is_a_file_is_refused_before_any_work() {
    let d = scratch_dir("reports", "file");
    let f = d.join("taken");
    std::fs::write(&f, "x").unwrap();
    fails_with(
        &[
            "select",
            "--levels",
            "3",
            "--n",
            "10",
            "--report",
            f.to_str().unwrap(),
        ],
        "not a directory",
    );
}

/// Whether the PNG `dir/stem.png` has a pixel of colour `rgb` (the
/// figures are RGB, 8 bits a channel).
fn has_colour(dir: &Path, stem: &str, rgb: [u8; 3]) -> bool {
    let file = std::fs::File::open(dir.join(format!("{stem}.png"))).unwrap();
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "{stem}");
    buf[..info.buffer_size()].chunks(3).any(|p| p == rgb)
}

/// `calibrate --report` on a contact file draws each placement's
/// consistency and each distance's error (nominal, calibrated and, with
/// held-out placements, held out: the held-out bars' green is there only
/// then) and each row's distance to its point's mean (a second, held-out
/// panel with held-out placements); report.md lists them.
#[test]
fn calibrate_report_on_contacts_draws_placements_distances_and_rows() {
    const HELD_GREEN: [u8; 3] = [40, 150, 70];
    let mut args = vec![
        "calibrate",
        "--robot",
        "fixtures/mukca/panda.urdf",
        "--tip",
        "ball_link",
        "--measurements",
        "fixtures/mukca/panda_2.csv",
    ];
    let placements = [
        "back_left",
        "back_right",
        "front_center",
        "front_left",
        "front_right",
        "high",
        "mid-high",
        "mid_left",
        "mid_right",
    ];
    let d: Vec<String> = placements
        .iter()
        .flat_map(|p| ["--point-distance".to_string(), format!("{p}/0,{p}/1=0.05")])
        .collect();
    args.extend(d.iter().map(String::as_str));
    let root = scratch_dir("reports", "contacts");
    let (held, plain) = (root.join("held"), root.join("plain"));
    let mut with_held = args.clone();
    with_held.extend([
        "--train-on",
        "front_left",
        "--report",
        held.to_str().unwrap(),
    ]);
    ok(&with_held);
    assert_eq!(png_size(&held, "consistency_by_placement"), (1300, 620));
    assert_eq!(png_size(&held, "row_distances"), (1300, 980));
    assert!(has_colour(&held, "consistency_by_placement", HELD_GREEN));
    let md = std::fs::read_to_string(held.join("report.md")).unwrap();
    assert!(
        md.contains("consistency_by_placement.png") && md.contains("row_distances.png"),
        "{md}"
    );
    assert!(md.contains("(mm"), "{md}");
    let mut without = args.clone();
    without.extend(["--report", plain.to_str().unwrap()]);
    ok(&without);
    assert_eq!(png_size(&plain, "consistency_by_placement"), (1300, 620));
    assert_eq!(png_size(&plain, "row_distances"), (1300, 560));
    assert!(!has_colour(&plain, "consistency_by_placement", HELD_GREEN));
    let _ = std::fs::remove_dir_all(root);
}
