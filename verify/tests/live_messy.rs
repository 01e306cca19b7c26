//! Messy captures against a known true robot (issue #49; feature `live`,
//! the project venv and `target/debug/activecal`): Pinocchio plays the real
//! robot and the tracker (`verify/python/truth.py`, as the truth gate of
//! `live_truth.rs`: every joint origin off by 0.5–2 mm and 0.05–0.3°, a
//! tracker 2.6 m away turned 95°), and the capture goes wrong the way real
//! ones do:
//!
//! * **no tool point given**: the measured point is 12 cm off the last
//!   axis (four directions about it) and `calibrate` is told only the tip
//!   link. Asserted on four arms: noise-free data recover the truth to
//!   [`EXACT_MM`]; with 0.05 mm of noise (one direction per arm, [`DRAWS`]
//!   draws) the true error's RMS is within [`RATIO`] of what `select`
//!   predicts for the design with the tool point known;
//! * **two tracker glitches** of 3–5 mm in 30 poses: both left out in at
//!   least 95 % of the draws, and the true error within [`RATIO`] of the
//!   clean data's fit; on clean data, poses are flagged in no more draws
//!   than the test's rate allows ([`false_alarm_bound`]);
//! * **the stated noise 3× too small**: the warning is printed and the
//!   calibrated model's own predicted error (at σ̂) is within [`RATIO`] of
//!   its true error.

use super::live_truth::{activecal, compare, root, truth_py};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Noise-free data recover the truth to this, mm (as the truth gate).
const EXACT_MM: f64 = 1e-6;
/// True error against prediction (as the truth gate).
const RATIO: f64 = 1.3;
/// Tracker noise per axis, metres.
const NOISE: f64 = 5e-5;
/// Noise draws per noisy case.
const DRAWS: usize = 10;
/// Poses of a design.
const N: usize = 30;

/// An arm of `fixtures/example-robot-data` and its tip link.
struct Arm {
    name: &'static str,
    urdf: &'static str,
    tip: &'static str,
}

const ARMS: &[Arm] = &[
    Arm {
        name: "ur5",
        urdf: "ur5_robot.urdf",
        tip: "tool0",
    },
    Arm {
        name: "ur10",
        urdf: "ur10_robot.urdf",
        tip: "tool0",
    },
    Arm {
        name: "kinova",
        urdf: "kinova.urdf",
        tip: "j2s6s200_end_effector",
    },
    Arm {
        name: "panda",
        urdf: "panda.urdf",
        tip: "panda_hand_tcp",
    },
];

/// Tool points 12 cm off the tip link's z (the last joint's axis on these
/// arms) in four directions about it, 3 cm along it (metres).
const DIRECTIONS: [[f64; 3]; 4] = [
    [0.12, 0.0, 0.03],
    [0.0, 0.12, 0.03],
    [-0.12, 0.0, 0.03],
    [0.0, -0.12, 0.03],
];

fn urdf(a: &Arm) -> PathBuf {
    root().join("fixtures/example-robot-data").join(a.urdf)
}

fn marker_arg(a: &Arm, m: [f64; 3]) -> String {
    format!("{}@{},{},{}", a.tip, m[0], m[1], m[2])
}

/// A true robot with the tool at `marker` (its true point 2 mm off), a
/// random pool of the nominal robot with the marker known, and the 30 poses
/// `select` chooses from it (`design.csv`): `select`'s predicted true RMS
/// (mm) for 0.05 mm of noise.
fn setup(dir: &Path, a: &Arm, marker: [f64; 3], seed: u64) -> f64 {
    setup_n(dir, a, marker, seed, N)
}

/// As [`setup`], `n` poses.
fn setup_n(dir: &Path, a: &Arm, marker: [f64; 3], seed: u64, n: usize) -> f64 {
    std::fs::create_dir_all(dir).unwrap();
    // `--marker=` keeps a negative first coordinate from reading as an option.
    let m = format!("--marker={},{},{}", marker[0], marker[1], marker[2]);
    let u = urdf(a).display().to_string();
    let s = seed.to_string();
    let args = [
        "make",
        "--urdf",
        &u,
        "--tip",
        a.tip,
        "--seed",
        &s,
        &m,
        "--out",
        "truth.json",
    ];
    truth_py(dir, args);
    let mk = marker_arg(a, marker);
    let count = n.to_string();
    let sel = activecal(
        dir,
        [
            "select",
            "--robot",
            &u,
            "--tip",
            a.tip,
            "--marker",
            &mk,
            "--pool",
            "random",
            "--count",
            "2048",
            "--pool-seed",
            &s,
            "--n",
            &count,
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
    .unwrap_or_else(|e| panic!("{}: {e}", a.name));
    let v: Value = serde_json::from_str(&sel).unwrap();
    v["predicted"]["position_rms_mm"].as_f64().unwrap()
}

/// Pinocchio's measurements of `design.csv` into `outs` (the k-th draw of
/// seed `seed`, noise `noise` metres).
fn measure(dir: &Path, outs: &[String], noise: f64, seed: u64) {
    let mut args: Vec<String> = ["measure", "--truth", "truth.json", "--design"]
        .map(String::from)
        .to_vec();
    args.extend(std::iter::repeat_n("design.csv".to_string(), outs.len()));
    args.extend([
        "--noise".into(),
        noise.to_string(),
        "--seed".into(),
        seed.to_string(),
    ]);
    args.push("--out".into());
    args.extend(outs.iter().cloned());
    truth_py(dir, &args);
}

/// `calibrate --tip T` (no tool point) of `meas` into `stem.urdf` and
/// `stem.yaml`, with `extra`: its `--json` report, or the error.
fn calibrate(dir: &Path, a: &Arm, meas: &str, stem: &str, extra: &[&str]) -> Result<Value, String> {
    let u = urdf(a).display().to_string();
    let (out_u, out_y) = (format!("{stem}.urdf"), format!("{stem}.yaml"));
    let mut args = vec![
        "calibrate",
        "--robot",
        &u,
        "--tip",
        a.tip,
        "--measurements",
        meas,
    ];
    args.extend(extra);
    args.extend(["--out", &out_u, "--out", &out_y, "--force", "--json"]);
    let out = activecal(dir, &args)?;
    Ok(serde_json::from_str(&out).unwrap())
}

/// The true RMS (mm) at 1,000 random configurations (seed 0) of each
/// calibration `stems` wrote (`truth.py compare`).
fn true_rms(dir: &Path, stems: &[String]) -> Vec<f64> {
    compare(dir, 0, stems)
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

fn base(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!(
        "activecal-live-messy-{name}-{}",
        std::process::id()
    ))
}

#[test]
fn tool_point_not_given_is_recovered_on_four_arms() {
    let base = base("tool");
    let mut table = Vec::new();
    for (k, a) in ARMS.iter().enumerate() {
        for (d, m) in DIRECTIONS.iter().enumerate() {
            let dir = base.join(format!("{}-{d}", a.name));
            let seed = 10 * k as u64 + d as u64;
            let predicted = setup(&dir, a, *m, seed);
            measure(&dir, &["exact.csv".into()], 0.0, seed);
            let fit = calibrate(&dir, a, "exact.csv", "exact", &[])
                .unwrap_or_else(|e| panic!("{} {m:?}, noise-free: {e}", a.name));
            let exact = true_rms(&dir, &["exact".into()])[0];
            assert!(
                exact <= EXACT_MM,
                "{} {m:?}: the noise-free fit without the tool point is {exact} mm from the truth",
                a.name
            );
            let notes = fit["notes"].to_string();
            assert!(
                notes.contains("no tool point given"),
                "{}: the report does not say the tool point was estimated: {notes}",
                a.name
            );
            // One direction per arm with noise (the k-th, so each direction
            // is seen on one arm).
            if d != k % DIRECTIONS.len() {
                table.push((a.name, d, exact, None));
                continue;
            }
            let draws: Vec<String> = (0..DRAWS).map(|j| format!("cal{j}")).collect();
            let meas: Vec<String> = draws.iter().map(|s| format!("{s}.csv")).collect();
            measure(&dir, &meas, NOISE, seed);
            for (mf, stem) in meas.iter().zip(&draws) {
                calibrate(&dir, a, mf, stem, &[])
                    .unwrap_or_else(|e| panic!("{} {m:?}, {stem}: {e}", a.name));
            }
            let truth = rms(&true_rms(&dir, &draws));
            table.push((a.name, d, exact, Some((truth, predicted))));
            assert!(
                truth <= RATIO * predicted,
                "{} {m:?}: true error {truth} mm over {DRAWS} draws, predicted {predicted} mm",
                a.name
            );
        }
    }
    for (name, d, exact, noisy) in &table {
        let n = noisy.map_or(String::new(), |(t, p)| {
            format!(
                ", noisy: true {t:.4} mm, predicted {p:.4} mm, ratio {:.2}",
                t / p
            )
        });
        eprintln!("tool not given: {name} direction {d}: noise-free {exact:.1e} mm{n}");
    }
    let _ = std::fs::remove_dir_all(&base);
}

/// The most draws of clean data in which the test may flag a pose at rate
/// `alpha` over `draws` draws: the binomial's quantile at 1 − 1e-3 (so the
/// assertion itself fails wrongly once in a thousand runs), by summing its
/// terms.
pub(super) fn false_alarm_bound(alpha: f64, draws: usize) -> usize {
    let mut cdf = 0.0;
    let mut term = (1.0 - alpha).powi(draws as i32);
    for k in 0..=draws {
        cdf += term;
        if cdf >= 1.0 - 1e-3 {
            return k;
        }
        term *= (draws - k) as f64 / (k + 1) as f64 * alpha / (1.0 - alpha);
    }
    draws
}

/// Adds glitches to rows `rows` (0-based data rows) of a measurement CSV:
/// `offsets[k]` metres to x, y, z of the k-th.
fn glitch(path: &Path, rows: &[usize], offsets: &[[f64; 3]]) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let head: Vec<&str> = lines[0].split(',').collect();
    let x = head.iter().position(|h| *h == "x1").unwrap();
    for (r, o) in rows.iter().zip(offsets) {
        let mut c: Vec<String> = lines[r + 1].split(',').map(String::from).collect();
        for (j, d) in o.iter().enumerate() {
            c[x + j] = (c[x + j].parse::<f64>().unwrap() + d).to_string();
        }
        lines[r + 1] = c.join(",");
    }
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
}

#[test]
fn two_glitches_are_left_out_and_clean_data_rarely_flagged() {
    let a = &ARMS[2];
    let dir = base("glitch");
    let marker = [0.1, 0.02, 0.05];
    setup(&dir, a, marker, 7);
    let mk = marker_arg(a, marker);
    // Clean draws: the false alarms.
    let clean_n = 100;
    let clean: Vec<String> = (0..clean_n).map(|j| format!("clean{j}")).collect();
    let files: Vec<String> = clean.iter().map(|s| format!("{s}.csv")).collect();
    measure(&dir, &files, NOISE, 7);
    let mut flagged = 0;
    for (f, s) in files.iter().zip(&clean) {
        let r = calibrate(&dir, a, f, s, &["--marker", &mk]).unwrap_or_else(|e| panic!("{s}: {e}"));
        flagged += usize::from(!r["outliers"]["left_out"].as_array().unwrap().is_empty());
    }
    let bound = false_alarm_bound(0.01, clean_n);
    eprintln!("glitches: clean data flagged in {flagged} of {clean_n} draws (bound {bound})");
    assert!(
        flagged <= bound,
        "{flagged} of {clean_n} clean draws flagged, at most {bound} expected at α 0.01"
    );
    // The first 20 clean draws again with two glitches of 3–5 mm.
    let glitched = 20;
    let mut both = 0;
    let (mut with, mut without) = (Vec::new(), Vec::new());
    for j in 0..glitched {
        let g = format!("glitch{j}");
        std::fs::copy(dir.join(&files[j]), dir.join(format!("{g}.csv"))).unwrap();
        let rows = [(3 + 7 * j) % N, (11 + 5 * j) % N];
        let rows = if rows[0] == rows[1] {
            [rows[0], (rows[1] + 1) % N]
        } else {
            rows
        };
        let size = 3e-3 + 2e-3 * (j as f64 / glitched as f64);
        glitch(
            &dir.join(format!("{g}.csv")),
            &rows,
            &[[size, 0.0, 0.0], [0.0, -0.6 * size, 0.8 * size]],
        );
        let r = calibrate(&dir, a, &format!("{g}.csv"), &g, &["--marker", &mk])
            .unwrap_or_else(|e| panic!("{g}: {e}"));
        let out: Vec<u64> = r["outliers"]["left_out"]
            .as_array()
            .unwrap()
            .iter()
            .map(|o| o["pose"].as_u64().unwrap())
            .collect();
        both += usize::from(rows.iter().all(|p| out.contains(&(*p as u64))));
        if j == 0 {
            robust_report_is_consistent(&dir, a, &g, &mk, &rows);
        }
        with.push(g);
        without.push(clean[j].clone());
    }
    let t_with = rms(&true_rms(&dir, &with));
    let t_clean = rms(&true_rms(&dir, &without));
    eprintln!(
        "glitches: both left out in {both} of {glitched}; true error {t_with:.4} mm against {t_clean:.4} mm for the clean data ({:.2}×)",
        t_with / t_clean
    );
    assert!(
        both * 100 >= 95 * glitched,
        "both glitches left out in {both} of {glitched}"
    );
    assert!(
        t_with <= RATIO * t_clean,
        "true error {t_with} mm, clean {t_clean} mm"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_stated_noise_three_times_too_small_is_caught() {
    let a = &ARMS[0];
    let dir = base("noise");
    let marker = [0.03, -0.02, 0.1];
    setup(&dir, a, marker, 3);
    let mk = marker_arg(a, marker);
    let draws: Vec<String> = (0..DRAWS).map(|j| format!("cal{j}")).collect();
    let files: Vec<String> = draws.iter().map(|s| format!("{s}.csv")).collect();
    measure(&dir, &files, 3.0 * NOISE, 3);
    let mut predicted = Vec::new();
    for (f, s) in files.iter().zip(&draws) {
        let r = calibrate(
            &dir,
            a,
            f,
            s,
            &["--marker", &mk, "--noise", &NOISE.to_string()],
        )
        .unwrap_or_else(|e| panic!("{s}: {e}"));
        let w = r["warnings"].to_string();
        assert!(
            w.contains("noisier than stated") && w.contains(activecal::names::phrase::COMPLIANCE),
            "{s}: no warning for σ 3× the stated: {w}"
        );
        predicted.push(r["predicted"]["position_rms_mm"].as_f64().unwrap());
    }
    let truth = rms(&true_rms(&dir, &draws));
    let pred = rms(&predicted);
    eprintln!(
        "stated noise 3× too small: true {truth:.4} mm, the fit's own prediction {pred:.4} mm ({:.2})",
        truth / pred
    );
    assert!(
        truth <= RATIO * pred && pred <= RATIO * truth,
        "true {truth} mm against the calibrated model's prediction {pred} mm"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `truth.py optimum`'s RMS (mm) of the point data `meas`: an independent
/// least-squares fit (Pinocchio, SciPy) over every chain joint origin, the
/// measurement frame and the tool point.
fn independent_optimum(dir: &Path, urdf: &Path, base: Option<&str>, tip: &str, meas: &str) -> f64 {
    let u = urdf.display().to_string();
    let mut args = vec![
        "optimum",
        "--urdf",
        &u,
        "--tip",
        tip,
        "--measurements",
        meas,
    ];
    if let Some(b) = base {
        args.extend(["--base", b]);
    }
    truth_py(dir, args)["rms_mm"].as_f64().unwrap()
}

/// Equal optima: the two fits' RMS agree to this fraction (the issue's
/// 0.5 %; a fit stuck elsewhere, or one unknown short, is off by more).
const SAME_OPTIMUM: f64 = 0.005;

#[test]
fn positions_without_a_tool_reach_the_independent_optimum() {
    let dir = base("optimum");
    std::fs::create_dir_all(&dir).unwrap();
    // FIGAROH's TIAGo reduced to its first marker's positions, no tool.
    let csv =
        std::fs::read_to_string(root().join("fixtures/figaroh/tiago_mocap_4markers.csv")).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..head.len())
        .filter(|&k| !["x2", "y2", "z2", "x3", "y3", "z3", "x4", "y4", "z4"].contains(&head[k]))
        .collect();
    let pick = |l: &str| -> String {
        let c: Vec<&str> = l.split(',').collect();
        keep.iter().map(|&k| c[k]).collect::<Vec<_>>().join(",")
    };
    let mut out = vec![keep.iter().map(|&k| head[k]).collect::<Vec<_>>().join(",")];
    out.extend(lines.filter(|l| !l.trim().is_empty()).map(pick));
    std::fs::write(dir.join("tiago_p1.csv"), out.join("\n") + "\n").unwrap();
    let tiago = root().join("fixtures/figaroh/tiago.urdf");
    let t = tiago.display().to_string();
    let v: Value = serde_json::from_str(
        &activecal(
            &dir,
            [
                "calibrate",
                "--robot",
                &t,
                "--base",
                "base_footprint",
                "--tip",
                "arm_7_link",
                "--measurements",
                "tiago_p1.csv",
                "--outliers",
                "keep",
                "--out",
                "tiago.urdf",
                "--out",
                "tiago.yaml",
                "--json",
            ],
        )
        .unwrap_or_else(|e| panic!("TIAGo positions without a tool: {e}")),
    )
    .unwrap();
    let ours = v["residuals"]["position_rms_mm"].as_f64().unwrap();
    let theirs = independent_optimum(
        &dir,
        &tiago,
        Some("base_footprint"),
        "arm_7_link",
        "tiago_p1.csv",
    );
    eprintln!(
        "TIAGo positions, no tool: {ours:.6} mm fitted, independent optimum {theirs:.6} mm, {} unknowns, rank {}",
        v["parameters"].as_array().unwrap().len(),
        v["rank"]
    );
    assert_eq!(v["exit_status"], 0);
    assert!(dir.join("tiago.urdf").exists());
    assert!(
        (ours - theirs).abs() <= SAME_OPTIMUM * theirs,
        "{ours} mm against {theirs} mm"
    );
    // A true Panda (7 joints), the tool 138 mm off the last axis, 48 poses
    // of positions with 0.05 mm of noise, no tool given.
    let a = &ARMS[3];
    let marker = [0.1, 0.095, 0.04];
    let pdir = dir.join("panda");
    setup_n(&pdir, a, marker, 5, 48);
    measure(&pdir, &["m.csv".into()], NOISE, 5);
    let v = calibrate(&pdir, a, "m.csv", "cal", &["--outliers", "keep"])
        .unwrap_or_else(|e| panic!("{e}"));
    let ours = v["residuals"]["position_rms_mm"].as_f64().unwrap();
    let theirs = independent_optimum(&pdir, &urdf(a), None, a.tip, "m.csv");
    eprintln!(
        "Panda, tool 138 mm off the last axis, 48 poses: {ours:.6} mm fitted, independent optimum {theirs:.6} mm"
    );
    assert_eq!(v["exit_status"], 0);
    assert!(
        (ours - theirs).abs() <= SAME_OPTIMUM * theirs,
        "{ours} mm against {theirs} mm"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A robust loss on glitched data `g`: it lists exactly the glitched `rows`
/// as down-weighted, and its one σ (the residual block's, from the weighted
/// residuals) agrees with σ̂ (both estimate the 0.05 mm noise: within 1.3×,
/// where the unweighted residuals gave 0.67 mm beside σ̂ 0.05 mm).
fn robust_report_is_consistent(dir: &Path, a: &Arm, g: &str, mk: &str, rows: &[usize]) {
    let scale = (3.0 * NOISE).to_string();
    let r = calibrate(
        dir,
        a,
        &format!("{g}.csv"),
        &format!("{g}-cauchy"),
        &["--marker", mk, "--loss", "cauchy", "--loss-scale", &scale],
    )
    .unwrap_or_else(|e| panic!("{g} with --loss cauchy: {e}"));
    let mut down: Vec<u64> = r["downweighted"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p[0].as_u64().unwrap())
        .collect();
    down.sort_unstable();
    let mut want: Vec<u64> = rows.iter().map(|&p| p as u64).collect();
    want.sort_unstable();
    assert_eq!(
        down, want,
        "--loss cauchy down-weighted {down:?}, the glitches are {want:?}"
    );
    let sigma = r["noise"]["blocks"][0]["sigma"].as_f64().unwrap();
    let hat = r["sigma_hat"].as_f64().unwrap();
    eprintln!(
        "glitches, --loss cauchy: block σ {:.4} mm, σ̂ {:.4} mm",
        sigma * 1e3,
        hat * 1e3
    );
    assert!(
        sigma <= 1.3 * hat && hat <= 1.3 * sigma,
        "block σ {sigma} m, σ̂ {hat} m"
    );
}
