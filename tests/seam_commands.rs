//! Issue #50 item 2 through the command line: the registered height sensor
//! (`src/measure/height/`, one registration line) is named by its key after
//! a robot (`ur5:height`) or in a robot file (`measurement = "height"`), and
//! every command selects, bounds, scores, fits and reports it; its measured
//! files hold the column it reads (`z1`), checked as every measured file is.
//! The binary never names the sensor: it finds it in the registry.

use crate::common;
use crate::seam_sensor::{assert_recovered_as_predicted, height_rms};

use activecal::identify::{simulate, trial_rng};
use activecal::measure::height;
use activecal::model::Robot;
use activecal::pool::Pool;
use common::{fails_with, json_of};
use serde_json::Value;
use std::path::{Path, PathBuf};

const ROBOT: &str = "ur5:height";

fn scratch(name: &str) -> PathBuf {
    common::scratch_dir("seam-commands", name)
}

fn num(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("no number '{key}' in {v}"))
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// `ur5:height` loads as the library's height robot: the same sensor and
/// unknowns as `Robot::with_measurement(height::KIND)`.
#[test]
fn the_key_after_a_robot_names_the_registered_sensor() {
    let loaded = activecal::io::load_robot(ROBOT).unwrap();
    let lib = Robot::ur5().with_measurement(height::KIND).unwrap();
    assert_eq!(loaded.measurement, height::KIND);
    assert_eq!(loaded.unknowns, lib.unknowns);
    assert_eq!(loaded.name, ROBOT);
}

/// `select` (EAE on D, the 3-level lattice, certified gap), `bound`,
/// `score` and `gap` on the design all see the height sensor's one row per
/// pose and agree with each other; then `calibrate` fits heights simulated
/// from the perturbed real UR5 at the design (written as the CSV the sensor
/// reads) over `T` noise draws, and the calibrated descriptions
/// (`--out cal.toml`, read back with their `measurement = "height"`) are
/// off the real robot's heights by the RMS `select` predicted: the mean
/// square within 4 standard errors of the trials' mean (independent
/// trials: their sample deviation over √T; a false failure below 1e-4),
/// as `tests/seam_sensor.rs` asserts through the library.
#[test]
fn every_command_selects_bounds_scores_fits_and_reports_the_height_sensor() {
    let dir = scratch("all");
    let design = dir.join("design.json");
    let (n, sigma) = (48usize, 1e-4);
    let sel = json_of(&[
        "select",
        "--robot",
        ROBOT,
        "--levels",
        "3",
        "--n",
        "48",
        "--noise",
        "1e-4",
        "--gap",
        "--out",
        path_str(&design),
        "--json",
    ]);
    assert_eq!(sel["robot"], ROBOT);
    assert_eq!(sel["bound_status"], "certified");
    let poses: Vec<usize> = sel["poses"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(poses.len(), n);
    let d_eff = num(&sel, "d_efficiency");
    assert!(d_eff > 0.0 && d_eff <= 1.0 + 1e-12, "D-efficiency {d_eff}");

    // Bounded: every 48-pose design's ln OI_D is below the bound, this one's too.
    let bound = json_of(&[
        "bound", "--robot", ROBOT, "--levels", "3", "--n", "48", "--json",
    ]);
    let ln_oid = num(&sel, "ln_oid");
    let ln_bound = num(&bound, "ln_bound");
    assert!(
        ln_oid <= ln_bound + 1e-9 * ln_bound.abs(),
        "{ln_oid} > {ln_bound}"
    );

    // Scored and gapped from the design file alone: the same design.
    let robot = activecal::io::load_robot(ROBOT).unwrap();
    let score = json_of(&["score", "--design", path_str(&design), "--json"]);
    assert_eq!(score["rank"].as_u64(), Some(robot.n_params() as u64));
    let gap = json_of(&["gap", "--design", path_str(&design), "--json"]);
    assert!((num(&gap, "d_efficiency") - d_eff).abs() < 1e-9, "{gap}");

    // Fitted and reported: the real robot's heights recovered within the
    // prediction, from measured files of the sensor's column.
    let predicted_m = num(&sel["predicted"], "position_rms_mm") * 1e-3;
    let configurations = sel["predicted"]["configurations"].as_u64().unwrap() as usize;
    let pool = Pool::full(&robot, 3).unwrap();
    let qs: Vec<Vec<f64>> = poses.iter().map(|&k| pool.q(k)).collect();
    let at = activecal::how_many::random_configurations(&robot, configurations, 0);
    let trials = 40;
    let mut ms = Vec::with_capacity(trials);
    for t in 0..trials {
        let meas = simulate(&robot, &robot.real, &qs, sigma, &mut trial_rng(7, t as u64)).unwrap();
        let csv = activecal::io::measurements::to_csv(&meas, &robot);
        assert!(csv.starts_with("q1,q2,q3,q4,q5,q6,z1\n"), "{}", &csv[..40]);
        let (file, out) = (
            dir.join(format!("m{t}.csv")),
            dir.join(format!("cal{t}.toml")),
        );
        std::fs::write(&file, csv).unwrap();
        let cal = json_of(&[
            "calibrate",
            "--robot",
            ROBOT,
            "--measurements",
            path_str(&file),
            "--out",
            path_str(&out),
            "--json",
        ]);
        assert_eq!(cal["status"], "converged");
        assert_eq!(cal["robot"], ROBOT);
        assert_eq!(cal["measurement"], "height", "{}", cal["measurement"]);
        assert_eq!(cal["poses"].as_u64(), Some(n as u64));
        let fitted = activecal::io::load_robot(path_str(&out)).unwrap();
        assert_eq!(fitted.measurement, height::KIND);
        ms.push(height_rms(&robot, &fitted.nominal, &robot.real, &at).powi(2));
    }
    let before = height_rms(&robot, &robot.nominal, &robot.real, &at);
    assert_recovered_as_predicted("height via the CLI", &ms, predicted_m, before);
}

/// An unknown key is refused naming the known ones, after a robot and in a
/// robot file (with its line); a height file without its column, or with a
/// bad cell, names the file, the line and the column.
#[test]
fn unknown_keys_and_bad_height_files_are_refused_with_their_place() {
    fails_with(
        &[
            "bound",
            "--robot",
            "ur5:heigth",
            "--levels",
            "3",
            "--n",
            "30",
        ],
        "ur5:heigth: unknown measurement 'heigth' after ':' (known: pose, height)",
    );
    let dir = scratch("bad");
    let desc = dir.join("h.toml");
    let text = activecal::io::robot_toml::to_toml(&activecal::io::load_robot(ROBOT).unwrap());
    assert!(text.contains("measurement = \"height\"\n"), "{text}");
    std::fs::write(&desc, &text).unwrap();
    json_of(&[
        "bound",
        "--robot",
        path_str(&desc),
        "--levels",
        "3",
        "--n",
        "30",
        "--json",
    ]);
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text.replace("\"height\"", "\"heigth\"")).unwrap();
    let line = text
        .lines()
        .position(|l| l.starts_with("measurement"))
        .unwrap()
        + 1;
    fails_with(
        &[
            "bound",
            "--robot",
            path_str(&bad),
            "--levels",
            "3",
            "--n",
            "30",
        ],
        &format!(
            "line {line}, column 15: measurement = \"heigth\": unknown (known: point, pose, markers, height)"
        ),
    );
    let csv = dir.join("m.csv");
    std::fs::write(&csv, "q1,q2,q3,q4,q5,q6,x1,y1\n0,0,0,0,0,0,0.1,0.2\n").unwrap();
    fails_with(
        &[
            "calibrate",
            "--robot",
            ROBOT,
            "--measurements",
            path_str(&csv),
        ],
        "no measured point: expected column z1 (metres); the header has q1, q2, q3, q4, q5, q6, x1, y1",
    );
    std::fs::write(
        &csv,
        "q1,q2,q3,q4,q5,q6,z1\n0,0,0,0,0,0,0.1\n0,0,0,0,0,0,high\n",
    )
    .unwrap();
    fails_with(
        &[
            "calibrate",
            "--robot",
            ROBOT,
            "--measurements",
            path_str(&csv),
        ],
        "line 3, column 7 ('z1'): cannot read 'high'",
    );
}
