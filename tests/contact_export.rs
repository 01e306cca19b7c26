//! `calibrate --out` for a contact fit (issue 29): the written URDF, read
//! back by `urdf_rs`, composed with the written frames file's measurement
//! frame and `point` (the ball centre on the tip link), gives the fitted
//! model's tool point of every row; the frames file carries the fitted
//! points; `evaluate --frames` on the written files gives the fit's
//! in-sample consistency; outputs are refused without `--force` and in a
//! format that has no place for the contact setup.

use crate::common;
use activecal::data::NamedDistance;
use activecal::identify::contact::{ContactSettings, fit_contacts, resolve_distances, tool_points};
use activecal::io::contacts::read_contacts;
use activecal::io::load_robot;
use common::{fails_with, json_of};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::path::Path;

const URDF: &str = "fixtures/mukca/panda.urdf";
const DATA: &str = "fixtures/mukca/panda_2.csv";
const PLACEMENTS: [&str; 3] = ["back_left", "front_left", "mid_right"];

/// Three placements of `panda_2` (six sockets) as a contact file of their
/// own: a fit of 185 rows.
fn subset(dir: &Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(DATA).unwrap();
    let mut lines = text.lines();
    let mut out = lines.next().unwrap().to_string() + "\n";
    for l in lines.filter(|l| PLACEMENTS.iter().any(|p| l.contains(&format!(",{p}/")))) {
        out += l;
        out += "\n";
    }
    let path = dir.join("three.csv");
    std::fs::write(&path, out).unwrap();
    path
}

fn distance_args() -> Vec<String> {
    PLACEMENTS
        .iter()
        .flat_map(|p| ["--point-distance".to_string(), format!("{p}/0,{p}/1=0.05")])
        .collect()
}

/// A frames-file frame (`xyz`, `rpy` as in URDF) as an isometry.
fn frame(v: &serde_json::Value) -> Isometry3<f64> {
    let n = |k: &str, i: usize| v[k][i].as_f64().unwrap();
    Isometry3::from_parts(
        Translation3::new(n("xyz", 0), n("xyz", 1), n("xyz", 2)),
        UnitQuaternion::from_euler_angles(n("rpy", 0), n("rpy", 1), n("rpy", 2)),
    )
}

fn xyz(v: &serde_json::Value) -> Vector3<f64> {
    Vector3::from_fn(|i, _| v["xyz"][i].as_f64().unwrap())
}

#[test]
fn the_written_urdf_and_frames_give_the_fitted_tool_points() {
    let dir = common::scratch_dir("contact_export", "tool_points");
    let csv = subset(&dir);
    let (urdf_out, yaml_out) = (dir.join("cal.urdf"), dir.join("cal.yaml"));
    let d = distance_args();
    let mut args = vec![
        "calibrate",
        "--robot",
        URDF,
        "--tip",
        "ball_link",
        "--measurements",
        csv.to_str().unwrap(),
        "--out",
        urdf_out.to_str().unwrap(),
        "--out",
        yaml_out.to_str().unwrap(),
        "--json",
        // Every row fitted, as the in-process fit and `evaluate` below
        // take them (the gross-error test leaves some rows of this subset
        // out by default).
        "--outliers",
        "keep",
    ];
    args.extend(d.iter().map(String::as_str));
    let v = json_of(&args);
    assert_eq!(v["exit_status"], 0);
    assert_eq!(v["out"].as_array().unwrap().len(), 2, "{}", v["out"]);

    // The same fit in process: the command's defaults (L2, 200 iterations,
    // geodesic acceleration), the same rows and distances.
    let robot = load_robot(&format!("{URDF}#tip=ball_link")).unwrap();
    let file = read_contacts(&csv, &robot, Default::default()).unwrap();
    let given: Vec<NamedDistance> = PLACEMENTS
        .iter()
        .map(|p| NamedDistance {
            a: format!("{p}/0"),
            b: format!("{p}/1"),
            metres: 0.05,
        })
        .collect();
    let known = resolve_distances(&file, &given, true).unwrap();
    let settings = ContactSettings::default();
    let fit = fit_contacts(&robot, &robot.nominal, &file, &known, &settings).unwrap();
    let ours = tool_points(&fit.robot, &fit.table, &fit.tool_offset, &file.qs);

    // The written files, read without activecal.
    let u = urdf_rs::read_file(&urdf_out).unwrap();
    let frames: serde_json::Value =
        serde_saphyr::from_str(&std::fs::read_to_string(&yaml_out).unwrap()).unwrap();
    let m = frame(&frames["measurement_frame"]);
    let marker = &frames["markers"][0];
    assert_eq!(marker["name"], "point");
    assert_eq!(marker["parent"], "ball_link");
    let ball = Point3::from(xyz(marker));
    let names: Vec<String> = serde_json::from_value(frames["chain"]["joints"].clone()).unwrap();
    let mut worst = 0.0f64;
    for (q, want) in file.qs.iter().zip(&ours) {
        let qm: HashMap<String, f64> = names.iter().cloned().zip(q.iter().copied()).collect();
        let got = m * common::urdf_fk(&u, "panda_link0", "ball_link", &qm) * ball;
        worst = worst.max((got.coords - want).norm());
    }
    // Two chains of ~10 products of metre-size transforms, and the written
    // numbers are shortest round-trip decimals: rounding is ~1e-15 m; 1e-9 m
    // (the bar of `tests/frames.rs`) is far below any modelling error (the
    // tool offset alone is 1.3 mm, a joint origin's change 0.1–1 mm).
    assert!(worst <= 1e-9, "largest difference {worst:e} m");
    // The check can fail: the point is not the tip link's origin (the
    // fitted tool offset, 1.3 mm here), so a file without it is off by more.
    assert!(ball.coords.norm() > 1e-4, "{ball}");

    // The fitted points, in the measurement frame, as the fit has them.
    let points = frames["contacts"]["points"].as_array().unwrap();
    assert_eq!(points.len(), 6);
    for (p, (name, at)) in points
        .iter()
        .zip(fit.points.iter().zip(&fit.point_positions))
    {
        assert_eq!(p["name"], name.as_str());
        assert!((xyz(p) - Vector3::from(*at)).norm() <= 1e-12, "{p}");
        assert!(p["sigma_xyz_mm"][0].as_f64().unwrap() > 0.0);
    }
    assert_eq!(frames["contacts"]["distances"].as_array().unwrap().len(), 3);

    // `evaluate` mounts the written files (--frames) and judges the rows:
    // the fit's in-sample consistency (the same sums of the same points, to
    // rounding of the written decimals).
    let e = json_of(&[
        "evaluate",
        "--robot",
        urdf_out.to_str().unwrap(),
        "--frames",
        yaml_out.to_str().unwrap(),
        "--measurements",
        csv.to_str().unwrap(),
        "--json",
    ]);
    let (pooled, in_sample) = (
        e["contacts"]["pooled_mm"].as_f64().unwrap(),
        v["in_sample"]["calibrated_mm"].as_f64().unwrap(),
    );
    assert!(
        (pooled - in_sample).abs() <= 1e-9,
        "{pooled} vs {in_sample}"
    );

    // Existing outputs are refused without --force (before the fit), and
    // replaced with it.
    fails_with(&args, "exists; pass --force");
    let mut forced = args.clone();
    forced.push("--force");
    assert_eq!(json_of(&forced)["exit_status"], 0);
    let _ = std::fs::remove_dir_all(dir);
}

/// A description has no place for the tool offset and the points: `.toml`
/// is refused before the fit, naming what to write instead.
#[test]
fn a_contact_calibration_is_not_written_as_a_description() {
    let dir = common::scratch_dir("contact_export", "toml");
    let out = dir.join("cal.toml");
    fails_with(
        &[
            "calibrate",
            "--robot",
            URDF,
            "--tip",
            "ball_link",
            "--measurements",
            DATA,
            "--point-distance",
            "front_left/0,front_left/1=0.05",
            "--out",
            out.to_str().unwrap(),
        ],
        "a .toml description has no place for them",
    );
    assert!(!out.exists());
    let _ = std::fs::remove_dir_all(dir);
}
