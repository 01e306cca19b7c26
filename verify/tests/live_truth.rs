//! The end-to-end truth gate (issue #39, item 5; feature `live`, needs the
//! project venv and `target/debug/activecal`): Pinocchio plays the real
//! robot and the tracker (`verify/python/truth.py`). For each arm of
//! `fixtures/example-robot-data`, seeded: a true robot (every moving
//! joint's `<origin>` off by 0.5–2 mm and 0.05–0.3°), a tracker 2.6 m away
//! turned 95°, a marker ~10 cm off the flange whose nominal is off by 2 mm;
//! `activecal select` chooses 30 poses of a random pool for the nominal
//! robot and marker and predicts the true error (`--report`); Pinocchio
//! measures them with 0.05 mm of noise per axis; `activecal calibrate`
//! writes URDF + frames; Pinocchio compares them with the truth at 1,000
//! random configurations. Asserted: the true RMS (over 10 noise draws at
//! the chosen design) is within 1.3× of the prediction, and noise-free
//! measurements recover the truth to 1e-6 mm.
//! Control: the noise-free fit with its last unknown held at nominal (as
//! the sampler that found 26 of 27 did) leaves more than 1e-3 mm, so the
//! gate sees a missing unknown. Also: activecal's unknowns equal the rank of Pinocchio's identification
//! Jacobian of a complete model (every joint origin, tracker, marker) at
//! random configurations. Reported: the chosen design's true error against
//! the median of random designs of the same pool (`TRUTH_RANDOM`, default
//! 20; 0 skips them).
//!
//! The prediction is `select --report`'s (report.json's
//! `how_many_poses.points[n = 30].predicted.position_rms_mm`). Its "how
//! many poses" curve costs a certified bound per design size (20–40 s per
//! arm in a debug build), so by default only the arms of [`REPORT_ARMS`]
//! and the full pose (whose `--orientation-noise` needs `--noise`, which
//! needs `--report`) run it; for every arm the figure is computed with the same library
//! function (`how_many::predicted_errors`, 1,000 configurations of seed 0)
//! on the design `select` wrote, and where the report runs, the two must
//! agree to 1e-9. `TRUTH_REPORT=all` runs the report on every arm.
//! `TRUTH_ARMS=ur5,xarm7` runs some arms only (the assertion that at least
//! 8 ran is then skipped). `verify/python/truth_run.sh ARM` runs one arm
//! from the shell.

use serde_json::Value;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

pub(super) fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

pub(super) fn bin() -> PathBuf {
    let b = root().join("target/debug/activecal");
    if b.exists() {
        b
    } else {
        root().join("target/release/activecal")
    }
}

/// An arm: a URDF of `fixtures/example-robot-data`, its tip link, full pose
/// or a point.
struct Arm {
    name: &'static str,
    urdf: &'static str,
    tip: &'static str,
    pose: bool,
}

const fn arm(name: &'static str, urdf: &'static str, tip: &'static str) -> Arm {
    Arm {
        name,
        urdf,
        tip,
        pose: false,
    }
}

const ARMS: &[Arm] = &[
    arm("ur3", "ur3_robot.urdf", "tool0"),
    arm("ur5", "ur5_robot.urdf", "tool0"),
    arm("ur10", "ur10_robot.urdf", "tool0"),
    arm("xarm7", "xarm7.urdf", "link_eef"),
    arm("kinova", "kinova.urdf", "j2s6s200_end_effector"),
    arm("z1", "z1.urdf", "gripperStator"),
    arm("panda", "panda.urdf", "panda_hand_tcp"),
    arm("so100", "so100.urdf", "gripper"),
    Arm {
        name: "ur5-pose",
        urdf: "ur5_robot.urdf",
        tip: "tool0",
        pose: true,
    },
];

/// Poses of a design.
const N: usize = 30;
/// Tracker noise per axis, metres.
const NOISE: f64 = 5e-5;
/// Orientation noise per axis of a full pose, radians: 0.01°, when
/// `select` takes `--orientation-noise` (the design and its prediction
/// weighted for it, `calibrate` estimating the weights from the data);
/// otherwise NOISE over the fixed `orientation_scale` (1 m/rad) that the
/// prediction then assumes.
fn orientation_noise() -> f64 {
    if select_weighs_orientation() {
        0.01f64.to_radians()
    } else {
        NOISE
    }
}

/// Whether this activecal's `select` takes `--orientation-noise`.
fn select_weighs_orientation() -> bool {
    static ONCE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *ONCE.get_or_init(|| {
        run(Command::new(bin()).args(["select", "--help"]))
            .is_ok_and(|h| h.contains("--orientation-noise"))
    })
}
/// Candidate poses of the pool (random, within the limits less 2°).
const POOL: usize = 4096;
/// The acceptance: true RMS ≤ RATIO × predicted.
const RATIO: f64 = 1.3;
/// Noise-free data recover the truth to this, mm.
const EXACT_MM: f64 = 1e-6;
/// Noise draws measured and calibrated at the chosen design: the gate is on
/// their RMS (a single draw's true error scatters by about √(2/k) with k the
/// directions that carry it: on the SO-100, one draw in 100 is 1.43× the
/// prediction while the RMS of the 100 is 0.99×).
const DRAWS: usize = 10;

/// `truth.py measure` of `designs` into `outs` (the k-th with noise seed
/// `(seed, k)`, the first with `seed`).
fn measure_args(
    a: &Arm,
    designs: &[String],
    outs: &[String],
    noise: f64,
    seed: u64,
) -> Vec<String> {
    let mut m: Vec<String> = ["measure", "--truth", "truth.json", "--design"]
        .map(String::from)
        .to_vec();
    m.extend(designs.iter().cloned());
    m.extend([
        "--noise".into(),
        noise.to_string(),
        "--seed".into(),
        seed.to_string(),
    ]);
    if a.pose && noise > 0.0 {
        m.extend([
            "--orientation-noise".into(),
            orientation_noise().to_string(),
        ]);
    }
    m.push("--out".into());
    m.extend(outs.iter().cloned());
    m
}

/// The arms whose `select` writes its `--report` by default.
const REPORT_ARMS: &[&str] = &["ur5"];

/// activecal's predicted true-error RMS (mm) after calibrating with the
/// design `design.csv` in `dir` (as `select --report` computes it: the
/// design's information, 1,000 random configurations of seed 0, σ =
/// [`NOISE`]), and the number of unknowns.
fn library_prediction(a: &Arm, dir: &Path) -> (usize, f64, Option<f64>) {
    let mut text = robot(a).into_string().unwrap();
    text += &sensor(a, dir).1;
    let mut robot = activecal::io::load_robot(&text).unwrap_or_else(|e| panic!("{text}: {e}"));
    if a.pose && select_weighs_orientation() {
        // As `select --orientation-noise` weighs the design.
        robot.orientation_scale = NOISE / orientation_noise();
    }
    let names = activecal::io::measurements::joint_names(&robot);
    let csv = std::fs::read_to_string(dir.join("design.csv")).unwrap();
    let mut lines = csv.lines().filter(|l| !l.trim().is_empty());
    let head: Vec<&str> = lines.next().unwrap().split(',').map(str::trim).collect();
    let cols: Vec<usize> = names
        .iter()
        .map(|n| head.iter().position(|h| h == n).expect("a joint column"))
        .collect();
    let id = head.iter().position(|h| *h == "id");
    let qs: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(str::trim).collect::<Vec<_>>())
        .filter(|c| id.is_none_or(|i| c[i] != "via"))
        .map(|c| cols.iter().map(|&k| c[k].parse::<f64>().unwrap()).collect())
        .collect();
    assert_eq!(qs.len(), N, "{}: design.csv", a.name);
    let table = robot.params(activecal::model::ParamSet::Nominal);
    let x = activecal::blocks::jacobian_of(&robot, table, qs.len(), |k, q| {
        q.copy_from_slice(&qs[k]);
    });
    let info = x.information(&(0..qs.len()).collect::<Vec<_>>());
    let eval_qs = activecal::how_many::random_configurations(&robot, 1000, 0);
    let eval = activecal::blocks::jacobian_of(&robot, table, eval_qs.len(), |k, q| {
        q.copy_from_slice(&eval_qs[k]);
    });
    let e = activecal::how_many::predicted_errors(&robot, &eval, info.as_ref(), NOISE)
        .unwrap_or_else(|| panic!("{}: the design's information is singular", a.name));
    (x.p(), e.position_rms_mm, e.orientation_rms_deg)
}

/// How activecal is told the sensor, as command-line options and as the
/// `#…` fragment of the robot's text form: the chain's tip and the nominal
/// marker (or tool of a full pose). By default a frames file `truth.py
/// sensor-frames` writes (`--frames`, which every activecal since #26
/// reads); with `TRUTH_SENSOR=marker`, `--tip T --marker T@x,y,z` for a
/// point sensor (a full pose keeps the frames file: its tool has a
/// rotation). The one place to change.
fn sensor(a: &Arm, dir: &Path) -> (Vec<OsString>, String) {
    if !a.pose && std::env::var("TRUTH_SENSOR").is_ok_and(|s| s == "marker") {
        let t: Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).unwrap())
                .unwrap();
        let xyz: Vec<String> = t["nominal_tool"]["xyz"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap().to_string())
            .collect();
        let marker = format!("{}@{}", a.tip, xyz.join(","));
        let args = ["--tip", a.tip, "--marker", &marker].map(OsString::from);
        return (args.to_vec(), format!("#tip={};marker={marker}", a.tip));
    }
    let frames = dir.join("nominal.yaml");
    (
        vec!["--frames".into(), frames.clone().into()],
        format!("#frames={}", frames.display()),
    )
}

fn sensor_args(a: &Arm, dir: &Path) -> Vec<OsString> {
    sensor(a, dir).0
}

/// The `--robot` value of an arm.
fn robot(a: &Arm) -> OsString {
    let mut s: OsString = root()
        .join("fixtures/example-robot-data")
        .join(a.urdf)
        .into();
    if a.pose {
        s.push(":pose");
    }
    s
}

/// Runs `cmd`; its stdout, or the error with its stderr.
pub(super) fn run(cmd: &mut Command) -> Result<String, String> {
    let out = cmd.output().map_err(|e| format!("{cmd:?}: {e}"))?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(format!(
            "{cmd:?} exited with {}: {}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

/// `truth.py` with `args`, in `dir`: its JSON.
pub(super) fn truth_py<I, S>(dir: &Path, args: I) -> Value
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    let out = run(Command::new(root().join(".venv/bin/python"))
        .current_dir(dir)
        .args(["-W", "ignore"])
        .arg(root().join("verify/python/truth.py"))
        .args(args))
    .unwrap_or_else(|e| panic!("{e}"));
    serde_json::from_str(&out).unwrap_or_else(|e| panic!("truth.py printed {out:?}: {e}"))
}

/// `activecal ARGS` in `dir`.
pub(super) fn activecal<I, S>(dir: &Path, args: I) -> Result<String, String>
where
    I: IntoIterator<Item = S>,
    S: AsRef<std::ffi::OsStr>,
{
    run(Command::new(bin())
        .current_dir(dir)
        .env("OPENBLAS_NUM_THREADS", "1")
        .args(args))
}

/// `calibrate` from `meas` into `stem.urdf` and `stem.yaml`.
fn calibrate(a: &Arm, dir: &Path, meas: &str, stem: &str) -> Result<(), String> {
    calibrate_with(a, dir, meas, stem, &[])
}

/// `calibrate` with `extra` options.
fn calibrate_with(
    a: &Arm,
    dir: &Path,
    meas: &str,
    stem: &str,
    extra: &[&str],
) -> Result<(), String> {
    let mut args: Vec<OsString> = vec!["calibrate".into(), "--robot".into(), robot(a)];
    args.extend(sensor_args(a, dir));
    args.extend(extra.iter().map(OsString::from));
    for x in [
        "--measurements",
        meas,
        "--out",
        &format!("{stem}.urdf"),
        "--out",
        &format!("{stem}.yaml"),
        "--force",
        "--json",
    ] {
        args.push(x.into());
    }
    let out = activecal(dir, &args)?;
    std::fs::write(dir.join(format!("{stem}.json")), out).unwrap();
    Ok(())
}

/// The 3-D RMS (mm) at the random configurations of each `(urdf, yaml)`.
pub(super) fn compare(dir: &Path, seed: u64, cals: &[String]) -> Vec<f64> {
    let mut args: Vec<String> = vec![
        "compare".into(),
        "--truth".into(),
        "truth.json".into(),
        "--seed".into(),
        seed.to_string(),
        "--urdf".into(),
    ];
    args.extend(cals.iter().map(|s| format!("{s}.urdf")));
    args.push("--frames".into());
    args.extend(cals.iter().map(|s| format!("{s}.yaml")));
    let v = truth_py(dir, &args);
    let list = match v {
        Value::Array(a) => a,
        one => vec![one],
    };
    list.iter()
        .map(|c| c["random"]["rms_mm"].as_f64().unwrap())
        .collect()
}

/// `x ≤ limit`, false for NaN (a NaN figure fails the gate).
fn at_most(x: f64, limit: f64) -> bool {
    x <= limit
}

/// One arm's figures.
struct Row {
    name: &'static str,
    unknowns: usize,
    rank: usize,
    predicted: f64,
    /// `select --report`'s figure, when it ran.
    reported: Option<f64>,
    /// The true RMS of the first noise draw.
    true_rms: f64,
    /// The true RMS of each of [`DRAWS`] noise draws (the first first).
    true_draws: Vec<f64>,
    /// The control: the last unknown held at nominal in the noise-free fit,
    /// and the true RMS that leaves (mm).
    control: (String, f64),
    /// A full pose: (predicted, true over the draws) orientation RMS in
    /// degrees, and whether the design was weighed for the orientation
    /// noise (then the prediction is asserted).
    orientation: Option<(f64, f64, bool)>,
    design_rms: f64,
    exact: f64,
    nominal: f64,
    random: Vec<f64>,
    same_design: bool,
    seconds: f64,
}

impl Row {
    fn rms_of_draws(&self) -> f64 {
        let n = self.true_draws.len() as f64;
        (self.true_draws.iter().map(|x| x * x).sum::<f64>() / n).sqrt()
    }

    fn median_random(&self) -> Option<f64> {
        let mut r: Vec<f64> = self.random.clone();
        if r.is_empty() {
            return None;
        }
        r.sort_by(f64::total_cmp);
        let n = r.len();
        Some(if n % 2 == 1 {
            r[n / 2]
        } else {
            0.5 * (r[n / 2 - 1] + r[n / 2])
        })
    }
}

fn one_arm(a: &Arm, seed: u64, randoms: usize, report: bool, base: &Path) -> Row {
    let t0 = Instant::now();
    let dir = base.join(a.name);
    std::fs::create_dir_all(&dir).unwrap();
    let fx = root().join("fixtures/example-robot-data");
    let mut make: Vec<OsString> = vec!["make".into(), "--urdf".into(), fx.join(a.urdf).into()];
    for x in [
        "--tip",
        a.tip,
        "--seed",
        &seed.to_string(),
        "--out",
        "truth.json",
    ] {
        make.push(x.into());
    }
    if a.pose {
        make.push("--pose".into());
    }
    truth_py(&dir, &make);
    truth_py(
        &dir,
        [
            "sensor-frames",
            "--truth",
            "truth.json",
            "--out",
            "nominal.yaml",
        ],
    );
    let sensor = sensor_args(a, &dir);
    let fail = |e: String| -> ! { panic!("{}: {e}", a.name) };
    // The pool select chooses from, written so that random designs come
    // from the same one.
    let mut pool: Vec<OsString> = vec!["pool".into(), "--robot".into(), robot(a)];
    pool.extend(sensor.iter().cloned());
    for x in [
        "--pool",
        "random",
        "--count",
        &POOL.to_string(),
        "--pool-seed",
        &seed.to_string(),
        "--out",
        "pool.csv",
        "--force",
    ] {
        pool.push(x.into());
    }
    activecal(&dir, &pool).unwrap_or_else(|e| fail(e));
    let mut select: Vec<OsString> = vec!["select".into(), "--robot".into(), robot(a)];
    select.extend(sensor.iter().cloned());
    for x in [
        "--pool",
        "file:pool.csv",
        "--n",
        &N.to_string(),
        "--seed",
        &seed.to_string(),
        "--force",
        "--json",
        "--out",
        "design.csv",
    ] {
        select.push(x.into());
    }
    // The design weighed for the orientation noise of a full pose: as
    // `select --orientation-noise` weighs with `--noise`, which it takes
    // only with `--report` (else 1 cm), such an arm always has the report.
    let weighs = a.pose && select_weighs_orientation();
    let report = report || weighs;
    if report {
        select.extend(["--noise".into(), NOISE.to_string().into()]);
        select.extend(["--report".into(), "report".into()]);
    }
    if weighs {
        select.extend([
            "--orientation-noise".into(),
            orientation_noise().to_string().into(),
        ]);
    }
    activecal(&dir, &select).unwrap_or_else(|e| fail(e));
    let (unknowns, predicted, predicted_deg) = library_prediction(a, &dir);
    let mut reported = None;
    let mut same_design = true;
    if report {
        let r: Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("report/report.json")).unwrap())
                .unwrap();
        let curve = &r["how_many_poses"];
        assert_eq!(curve["p"].as_u64(), Some(unknowns as u64), "{}", a.name);
        let point = curve["points"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["n"].as_u64() == Some(N as u64))
            .unwrap_or_else(|| fail(format!("no N = {N} on the report's curve: {curve}")));
        let sorted = |v: &Value| {
            let mut p: Vec<u64> = v
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_u64().unwrap())
                .collect();
            p.sort_unstable();
            p
        };
        same_design = sorted(&point["poses"]) == sorted(&r["selection"]["poses"]);
        let figure = point["predicted"]["position_rms_mm"].as_f64().unwrap();
        if let (true, Some(deg), Some(lib)) = (
            same_design,
            point["predicted"]["orientation_rms_deg"].as_f64(),
            predicted_deg,
        ) {
            assert!(
                (deg - lib).abs() <= 1e-9 * lib,
                "{}: select --report predicts {deg}°, the library {lib}° for the same design",
                a.name
            );
        }
        if same_design {
            assert!(
                (figure - predicted).abs() <= 1e-9 * predicted,
                "{}: select --report predicts {figure} mm, the library {predicted} mm for the same design",
                a.name
            );
        }
        reported = Some(figure);
    }
    let rank = truth_py(&dir, ["rank", "--truth", "truth.json", "--n", "60"])["rank"]
        .as_u64()
        .unwrap() as usize;
    // Measured with noise (DRAWS draws), and without.
    let draws: Vec<String> = (0..DRAWS).map(|k| format!("cal{k}")).collect();
    let designs = vec!["design.csv".to_string(); DRAWS];
    let meas: Vec<String> = draws.iter().map(|s| format!("{s}-meas.csv")).collect();
    truth_py(&dir, measure_args(a, &designs, &meas, NOISE, seed));
    truth_py(
        &dir,
        measure_args(a, &designs[..1], &["exact.csv".into()], 0.0, 0),
    );
    for (m, stem) in meas.iter().zip(&draws) {
        calibrate(a, &dir, m, stem).unwrap_or_else(|e| fail(e));
    }
    calibrate(a, &dir, "exact.csv", "exact").unwrap_or_else(|e| fail(e));
    // The control: the same noise-free fit with its last unknown (not a
    // marker offset) held at nominal, as the 26-of-27 sampler did, must not
    // recover the truth.
    let fit: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("exact.json")).unwrap()).unwrap();
    let last = fit["parameters"]
        .as_array()
        .and_then(|p| {
            // Marker offsets are always estimated: the last other one.
            p.iter()
                .filter_map(|p| p["name"].as_str())
                .rfind(|n| !n.starts_with("marker"))
        })
        .unwrap_or_else(|| fail(format!("no parameters in calibrate --json: {fit}")))
        .to_string();
    calibrate_with(a, &dir, "exact.csv", "fixed", &["--fix", &last]).unwrap_or_else(|e| fail(e));
    // cal0 (with the design's own poses), exact, fixed, then the other draws.
    let mut stems = vec![draws[0].clone(), "exact".into(), "fixed".into()];
    stems.extend(draws[1..].iter().cloned());
    let mut args: Vec<String> = ["compare", "--truth", "truth.json", "--seed"]
        .map(String::from)
        .to_vec();
    args.push(seed.to_string());
    args.push("--urdf".into());
    args.extend(stems.iter().map(|s| format!("{s}.urdf")));
    args.push("--frames".into());
    args.extend(stems.iter().map(|s| format!("{s}.yaml")));
    args.extend(["--design".into(), "design.csv".into()]);
    let c = truth_py(&dir, &args);
    let rms = |k: usize| c[k]["random"]["rms_mm"].as_f64().unwrap();
    let true_rms = rms(0);
    let design_rms = c[0]["design"]["rms_mm"].as_f64().unwrap();
    let exact = rms(1);
    let control = (last, rms(2));
    let mut true_draws = vec![true_rms];
    true_draws.extend((3..stems.len()).map(rms));
    // A full pose's orientation error (degrees): RMS over the draws.
    let orientation = predicted_deg.map(|p| {
        let deg: Vec<f64> = std::iter::once(0)
            .chain(3..stems.len())
            .map(|k| c[k]["random"]["orientation_rms_deg"].as_f64().unwrap())
            .collect();
        let rms = (deg.iter().map(|x| x * x).sum::<f64>() / deg.len() as f64).sqrt();
        (p, rms, weighs)
    });
    let nominal = truth_py(
        &dir,
        [
            "compare",
            "--truth",
            "truth.json",
            "--nominal",
            "--seed",
            &seed.to_string(),
        ],
    )["random"]["rms_mm"]
        .as_f64()
        .unwrap();
    // Random designs of the same pool, measured with the same noise.
    let mut random = Vec::new();
    if randoms > 0 {
        let names: Vec<String> = (0..randoms).map(|k| format!("rand{k}")).collect();
        let mut rd: Vec<String> = vec![
            "random-design".into(),
            "--pool".into(),
            "pool.csv".into(),
            "--n".into(),
            N.to_string(),
            "--seed".into(),
            (1000 + seed).to_string(),
            "--out".into(),
        ];
        rd.extend(names.iter().map(|s| format!("{s}.csv")));
        truth_py(&dir, &rd);
        let files: Vec<String> = names.iter().map(|s| format!("{s}.csv")).collect();
        let outs: Vec<String> = names.iter().map(|s| format!("{s}-meas.csv")).collect();
        truth_py(&dir, measure_args(a, &files, &outs, NOISE, seed));
        let mut ok = Vec::new();
        for s in &names {
            match calibrate(a, &dir, &format!("{s}-meas.csv"), &format!("{s}-cal")) {
                Ok(()) => ok.push(format!("{s}-cal")),
                // A random design that cannot be fitted is infinitely bad.
                Err(e) => {
                    eprintln!("{}: {s}: {e}", a.name);
                    random.push(f64::INFINITY);
                }
            }
        }
        if !ok.is_empty() {
            random.extend(compare(&dir, seed, &ok));
        }
    }
    Row {
        name: a.name,
        unknowns,
        rank,
        predicted: reported.unwrap_or(predicted),
        reported,
        true_rms,
        true_draws,
        control,
        orientation,
        design_rms,
        exact,
        nominal,
        random,
        same_design,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

#[test]
fn calibrated_arms_match_a_known_true_robot() {
    let base = std::env::temp_dir().join(format!("activecal-live-truth-{}", std::process::id()));
    std::fs::create_dir_all(&base).unwrap();
    let randoms: usize = std::env::var("TRUTH_RANDOM")
        .ok()
        .map_or(20, |s| s.parse().expect("TRUTH_RANDOM: a count"));
    let all_reports = std::env::var("TRUTH_REPORT").is_ok_and(|s| s == "all");
    let only: Option<Vec<String>> = std::env::var("TRUTH_ARMS")
        .ok()
        .map(|s| s.split(',').map(str::to_string).collect());
    // Each arm's seed is its place in ARMS (1, 2, …), whichever run.
    let arms: Vec<(u64, &Arm)> = (1..)
        .zip(ARMS)
        .filter(|(_, a)| only.as_ref().is_none_or(|o| o.iter().any(|n| n == a.name)))
        .collect();
    println!(
        "truth gate: {N} poses, σ = {} mm per axis, {POOL} random pool poses, {randoms} random designs per arm",
        NOISE * 1e3
    );
    println!(
        "{:<9} {:>8} {:>4} {:>10} {:>9} {:>9} {:>6} {:>9} {:>10} {:>8} {:>9} {:>8} {:>5}",
        "arm",
        "unknowns",
        "rank",
        "predicted",
        "true(1)",
        "true(10)",
        "ratio",
        "at design",
        "noise-free",
        "nominal",
        "rand.med.",
        "chosen/r",
        "s"
    );
    let mut failures = Vec::new();
    let mut controls = Vec::new();
    for &(seed, a) in &arms {
        let report = all_reports || REPORT_ARMS.contains(&a.name);
        let row = one_arm(a, seed, randoms, report, &base);
        let over_draws = row.rms_of_draws();
        let ratio = over_draws / row.predicted;
        let med = row.median_random();
        println!(
            "{:<9} {:>8} {:>4} {:>10} {:>9.4} {:>9.4} {:>6.2} {:>9.4} {:>10.1e} {:>8.3} {:>9} {:>8} {:>5.1}{}",
            row.name,
            row.unknowns,
            row.rank,
            format!(
                "{:.4}{}",
                row.predicted,
                if row.reported.is_some() { "r" } else { "" }
            ),
            row.true_rms,
            over_draws,
            ratio,
            row.design_rms,
            row.exact,
            row.nominal,
            med.map_or("-".into(), |m| format!("{m:.4}")),
            med.map_or("-".into(), |m| format!("{:.3}", over_draws / m)),
            row.seconds,
            if row.same_design {
                ""
            } else {
                "  (the report's N = 30 design is not the chosen one)"
            }
        );
        controls.push(format!(
            "{} {} {:.2e}",
            row.name, row.control.0, row.control.1
        ));
        if let Some((p, t, weighed)) = row.orientation {
            println!(
                "{:<9} orientation: predicted {p:.5}°, true {t:.5}° over {DRAWS} draws ({:.2}×); σ {:.4}° per axis{}",
                "",
                t / p,
                orientation_noise().to_degrees(),
                if weighed {
                    ", the design weighed for it"
                } else {
                    " (select without --orientation-noise: not asserted)"
                }
            );
            if weighed && !at_most(t, RATIO * p) {
                failures.push(format!(
                    "{}: true orientation RMS {t:.5}° is {:.2}× the predicted {p:.5}°",
                    row.name,
                    t / p
                ));
            }
        }
        // NaN fails too.
        if !at_most(ratio, RATIO) {
            failures.push(format!(
                "{}: true RMS {over_draws:.4} mm over {DRAWS} noise draws is {ratio:.2}× the predicted {:.4} mm ({} unknowns)",
                row.name, row.predicted, row.unknowns
            ));
        }
        if row.unknowns != row.rank {
            failures.push(format!(
                "{}: {} unknowns where Pinocchio's identification Jacobian has rank {}",
                row.name, row.unknowns, row.rank
            ));
        }
        // The gate sees a missing unknown.
        if row.control.1.is_nan() || at_most(row.control.1, 1e3 * EXACT_MM) {
            failures.push(format!(
                "{}: noise-free data with {} held at nominal leave only {:.3e} mm: the gate cannot see a missing unknown",
                row.name, row.control.0, row.control.1
            ));
        }
        if !at_most(row.exact, EXACT_MM) {
            failures.push(format!(
                "{}: noise-free data leave {:.3e} mm of true error",
                row.name, row.exact
            ));
        }
    }
    println!(
        "mm. predicted: r = select --report's figure, else the same function on the chosen design; rank: Pinocchio's; true(1): the first noise draw, true(10): RMS over {DRAWS} draws, ratio = true(10) / predicted; at design: draw 1 at the design's poses; nominal: the uncalibrated model; rand.med.: median of the random designs (one draw each), chosen/r = true(10) / rand.med."
    );
    println!(
        "control, noise-free with the last unknown held at nominal (mm): {}",
        controls.join("; ")
    );
    if only.is_none() {
        assert!(arms.len() >= 8, "{} arms", arms.len());
    }
    std::fs::remove_dir_all(&base).ok();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
