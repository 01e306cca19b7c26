//! ROS 2 bags of a simulated run against a known true robot (issue #52;
//! feature `live`, the project venv and `target/debug/activecal`).
//! Pinocchio plays the real UR5 and its tracker (`verify/python/truth.py`:
//! every joint origin off by 0.5–2 mm and 0.05–0.3°, a tracker 2.6 m away),
//! `rosbags` (a library nobody here wrote) writes the bag
//! (`verify/python/bag_truth.py`): the arm driven through `select`'s 30
//! poses with rests of 1.6–2.4 s and smooth moves, `/joint_states` at
//! 500 Hz with 2 µrad of encoder noise, the measurement with 0.05 mm of
//! noise per axis. Then `activecal extract` → `calibrate` → the calibrated
//! URDF + frames compared with the truth at 1,000 random configurations.
//!
//! * **tracker points, MCAP**: 100 Hz, the tracker's clock 3.9 s ahead and
//!   15 ms of latency, the tracker dropping out 0.8 s at pose 8 and a
//!   glitch (15 samples off by 3–5 mm) at pose 13. Asserted: 30 rests
//!   found, the gap pose and the glitch pose left out with their reasons
//!   and no other; the clock offset within [`OFFSET_TOL`] of the truth;
//!   the true error's RMS over [`DRAWS`] bags within [`RATIO`] of the
//!   calibrated model's own prediction; σ̂ within [`SIGMA_RATIO`] of the
//!   noise the extraction measured. A second extraction with the
//!   calibrated model finds the offset within 3 of its stated
//!   uncertainties.
//! * **full poses, SQLite 3**: a motion-capture `PoseStamped` at 120 Hz,
//!   1e-4 rad of orientation noise, the clock 0.8 s ahead: the offset
//!   within [`OFFSET_TOL`], the true error within [`RATIO`] of the
//!   prediction.
//! * **/tf**: the same run as a tracker → marker `TFMessage` plus a static
//!   world → tracker: `--tf world:marker` is `--tf tracker:marker` moved by
//!   the static transform the generator wrote.

use super::live_truth::{activecal, compare, root, run};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// True error against prediction (as the truth gate).
const RATIO: f64 = 1.3;
/// The clock offset against the truth, s (issue #52's acceptance: 2 ms).
const OFFSET_TOL: f64 = 0.002;
/// σ̂ against the extraction's measured noise of an averaged pose: σ̂ on
/// 57 degrees of freedom has a relative standard error of 1/√(2·57) =
/// 9 %; 1.35 is over 3 of those.
const SIGMA_RATIO: f64 = 1.35;
/// Bags (noise draws) per case.
const DRAWS: u64 = 4;

pub(super) fn ur5() -> String {
    root()
        .join("fixtures/example-robot-data/ur5_robot.urdf")
        .display()
        .to_string()
}

pub(super) fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("activecal-live-bags-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub(super) fn python(dir: &Path, script: &str, args: &[&str]) -> Value {
    let out = run(Command::new(root().join(".venv/bin/python"))
        .current_dir(dir)
        .args(["-W", "ignore"])
        .arg(root().join("verify/python").join(script))
        .args(args))
    .unwrap_or_else(|e| panic!("{e}"));
    serde_json::from_str(&out).unwrap_or_else(|e| panic!("{script} printed {out:?}: {e}"))
}

/// A true UR5 (seed `seed`, `pose` for a full pose) and the 30 poses
/// `select` chooses for it (`design.csv`).
pub(super) fn setup(d: &Path, seed: u64, pose: bool) -> String {
    let s = seed.to_string();
    let u = ur5();
    let mut make = vec!["make", "--urdf", &u, "--tip", "tool0", "--seed", &s];
    if pose {
        make.push("--pose");
    }
    make.extend(["--out", "truth.json"]);
    python(d, "truth.py", &make);
    python(
        d,
        "truth.py",
        &[
            "sensor-frames",
            "--truth",
            "truth.json",
            "--out",
            "nominal.yaml",
        ],
    );
    let robot = if pose { format!("{u}:pose") } else { u };
    activecal(
        d,
        [
            "select",
            "--robot",
            &robot,
            "--frames",
            "nominal.yaml",
            "--pool",
            "random",
            "--count",
            "2048",
            "--pool-seed",
            &s,
            "--n",
            "30",
            "--noise",
            "5e-5",
            "--seed",
            &s,
            "--out",
            "design.csv",
            "--force",
            "--json",
        ],
    )
    .unwrap();
    robot
}

/// `extract` of `bag` with `extra` (the measurement's options): its report.
fn extract(d: &Path, robot: &str, frames: &str, bag: &str, out: &str, extra: &[&str]) -> Value {
    let mut args = vec!["extract", bag, "--robot", robot, "--frames", frames];
    args.extend(extra);
    args.extend(["--out", out, "--force", "--json"]);
    let text = activecal(d, &args).unwrap_or_else(|e| panic!("{e}"));
    serde_json::from_str(&text).unwrap()
}

/// `calibrate` of `meas` into `stem.urdf` and `stem.yaml`: its report.
pub(super) fn calibrate(d: &Path, robot: &str, meas: &str, stem: &str) -> Value {
    let (u, y) = (format!("{stem}.urdf"), format!("{stem}.yaml"));
    let text = activecal(
        d,
        [
            "calibrate",
            "--robot",
            robot,
            "--frames",
            "nominal.yaml",
            "--measurements",
            meas,
            "--out",
            &u,
            "--out",
            &y,
            "--force",
            "--json",
        ],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    serde_json::from_str(&text).unwrap()
}

pub(super) fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

fn offset(report: &Value) -> (f64, f64) {
    let e = &report["clock"]["estimate"];
    (
        e["seconds"].as_f64().unwrap(),
        e["uncertainty"].as_f64().unwrap(),
    )
}

#[test]
fn live_bag_tracker_points_recover_the_truth() {
    let d = dir("points");
    let robot = setup(&d, 1, false);
    let (mut predicted, mut stems) = (Vec::new(), Vec::new());
    let mut table = Vec::new();
    for k in 1..=DRAWS {
        let (bag, meas, stem) = (format!("bag{k}"), format!("meas{k}.csv"), format!("cal{k}"));
        let s = k.to_string();
        let truth = python(
            &d,
            "bag_truth.py",
            &[
                "write",
                "--truth",
                "truth.json",
                "--design",
                "design.csv",
                "--out",
                &bag,
                "--offset",
                "3.9",
                "--latency",
                "0.015",
                "--gap-pose",
                "7",
                "--glitch-pose",
                "12",
                "--seed",
                &s,
            ],
        );
        let true_offset = truth["offset"].as_f64().unwrap();
        let r = extract(
            &d,
            &robot,
            "nominal.yaml",
            &bag,
            &meas,
            &["--points", "/tracker"],
        );
        let rests = r["rests"].as_array().unwrap();
        assert_eq!(rests.len(), 30, "draw {k}: {} rests", rests.len());
        let out: Vec<(usize, &str)> = rests
            .iter()
            .enumerate()
            .filter_map(|(i, x)| x["left_out"].as_str().map(|why| (i, why)))
            .collect();
        assert_eq!(out.len(), 2, "draw {k}: left out {out:?}");
        assert!(out[0].0 == 7 && out[0].1.contains("a gap of"), "{out:?}");
        assert!(out[1].0 == 12 && out[1].1.contains("scatter"), "{out:?}");
        let (o, u) = offset(&r);
        assert!(
            (o - true_offset).abs() <= OFFSET_TOL,
            "draw {k}: offset {o} ± {u} s, true {true_offset} s"
        );
        let c = calibrate(&d, &robot, &meas, &stem);
        let sigma = c["noise"]["blocks"][0]["sigma"].as_f64().unwrap();
        let measured = r["averaged_noise"].as_f64().unwrap();
        assert!(
            sigma / measured <= SIGMA_RATIO && measured / sigma <= SIGMA_RATIO,
            "draw {k}: σ̂ {sigma} m, the extraction's averaged noise {measured} m"
        );
        predicted.push(c["predicted"]["position_rms_mm"].as_f64().unwrap());
        table.push((o - true_offset, u, sigma, measured));
        stems.push(stem);
    }
    let truth = compare(&d, 0, &stems);
    let (t, p) = (rms(&truth), rms(&predicted));
    eprintln!(
        "live_bag points: true {t:.5} mm RMS over {DRAWS} bags, predicted {p:.5} mm (ratio {:.3}); per bag (offset error s, its uncertainty s, σ̂ m, averaged noise m): {table:?}",
        t / p
    );
    assert!(t <= RATIO * p, "true {t} mm, predicted {p} mm");
    // The calibrated model predicts the moves to micrometres: its offset is
    // the truth within its uncertainty.
    let again = extract(
        &d,
        &d.join("cal1.urdf").display().to_string(),
        "cal1.yaml",
        "bag1",
        "again.csv",
        &["--points", "/tracker"],
    );
    let (o, u) = offset(&again);
    eprintln!("live_bag points: with the calibrated model, offset {o} ± {u} s (true 3.915 s)");
    assert!((o - 3.915).abs() <= 3.0 * u.max(1e-6), "{o} ± {u} s");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn live_bag_sqlite_poses_with_a_clock_offset() {
    let d = dir("poses");
    let robot = setup(&d, 2, true);
    let (mut predicted, mut stems) = (Vec::new(), Vec::new());
    for k in 1..=3u64 {
        let (bag, meas, stem) = (format!("bag{k}"), format!("meas{k}.csv"), format!("cal{k}"));
        let s = k.to_string();
        python(
            &d,
            "bag_truth.py",
            &[
                "write",
                "--truth",
                "truth.json",
                "--design",
                "design.csv",
                "--out",
                &bag,
                "--storage",
                "sqlite3",
                "--kind",
                "poses",
                "--rate",
                "120",
                "--offset",
                "0.8",
                "--seed",
                &s,
            ],
        );
        let r = extract(
            &d,
            &robot,
            "nominal.yaml",
            &bag,
            &meas,
            &["--poses", "/mocap"],
        );
        assert_eq!(r["rests"].as_array().unwrap().len(), 30);
        let (o, u) = offset(&r);
        assert!(
            (o - 0.8).abs() <= OFFSET_TOL,
            "bag {k}: offset {o} ± {u} s, true 0.8 s"
        );
        let c = calibrate(&d, &robot, &meas, &stem);
        predicted.push(c["predicted"]["position_rms_mm"].as_f64().unwrap());
        stems.push(stem);
    }
    let truth = compare(&d, 0, &stems);
    let (t, p) = (rms(&truth), rms(&predicted));
    eprintln!(
        "live_bag poses: true {t:.5} mm, predicted {p:.5} mm (ratio {:.3})",
        t / p
    );
    assert!(t <= RATIO * p, "true {t} mm, predicted {p} mm");
    let _ = std::fs::remove_dir_all(&d);
}

fn read_csv(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect()
}

#[test]
fn live_bag_tf_chains_a_static_transform() {
    let d = dir("tf");
    let robot = setup(&d, 3, true);
    python(
        &d,
        "bag_truth.py",
        &[
            "write",
            "--truth",
            "truth.json",
            "--design",
            "design.csv",
            "--out",
            "bag",
            "--kind",
            "tf",
            "--seed",
            "3",
        ],
    );
    extract(
        &d,
        &robot,
        "nominal.yaml",
        "bag",
        "t.csv",
        &["--tf", "tracker:marker"],
    );
    extract(
        &d,
        &robot,
        "nominal.yaml",
        "bag",
        "w.csv",
        &["--tf", "world:marker"],
    );
    let (t, w) = (read_csv(&d.join("t.csv")), read_csv(&d.join("w.csv")));
    assert_eq!(t.len(), 30);
    assert_eq!(t.len(), w.len());
    // The generator's static world → tracker: 0.6 rad about z, then
    // (0.5, -0.2, 1.0) m. Columns: 6 joints, x y z, qw qx qy qz.
    let (c, s) = (0.6f64.cos(), 0.6f64.sin());
    for (a, b) in t.iter().zip(&w) {
        assert_eq!(a[..6], b[..6]);
        let (x, y, z) = (a[6], a[7], a[8]);
        let want = [c * x - s * y + 0.5, s * x + c * y - 0.2, z + 1.0];
        for k in 0..3 {
            assert!((b[6 + k] - want[k]).abs() < 1e-9, "{a:?} → {b:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}
