//! activecal's forward kinematics and joint Jacobian against the reference
//! values in `fixtures/*.json`, computed by Pinocchio and cross-checked with
//! MuJoCo (regenerate with `cargo run -p verify --features live -- regen`).
//! No Python needed here.
//!
//! Tolerance 1e-12 m (and m/rad): the values are at most ~21 m and each side
//! composes ~10 rigid transforms, so rounding stays below
//! ~100 · 1.1e-16 · 21 m ≈ 2e-13 m (at most 7.2e-15 is observed), while any real
//! kinematic mistake (a flipped α, a swapped Hayati rotation order, a
//! parameter off by 1e-9) moves the end point by 1e-8 m or far more. The
//! stored numbers are the shortest decimals that round-trip, so reading them
//! adds no error. See `verify::TOLERANCE`.

use activecal::measure::JacobianEvaluator;
use activecal::model::{ParamSet, Robot};
use serde::Deserialize;
use std::path::{Path, PathBuf};

const TOLERANCE: f64 = 1e-12;
const REGEN: &str = "cargo run -p verify --features live -- regen";

#[derive(Deserialize)]
struct Fixture {
    format: u32,
    robot: String,
    param_set: String,
    params: Vec<[f64; 5]>,
    versions: serde_json::Value,
    samples: Vec<Sample>,
}

#[derive(Deserialize)]
struct Sample {
    q: Vec<f64>,
    position: [f64; 3],
    jacobian: Vec<f64>,
}

fn fixture_files() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_builtin_robot_has_fixtures_for_both_parameter_sets() {
    let names: Vec<String> = fixture_files()
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    for robot in activecal::model::BUILTIN {
        for set in ["nominal", "real"] {
            let want = format!("{robot}_{set}.json");
            assert!(
                names.contains(&want),
                "fixtures/{want} is missing: run `{REGEN}`"
            );
        }
    }
}

#[test]
fn position_and_joint_jacobian_match_pinocchio_fixtures() {
    let files = fixture_files();
    assert!(!files.is_empty(), "no fixtures: run `{REGEN}`");
    for path in files {
        let name = path.display();
        let text = std::fs::read_to_string(&path).unwrap();
        let f: Fixture = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(f.format, 1, "{name}: unknown format");
        let robot = Robot::builtin(&f.robot).unwrap();
        let set: ParamSet =
            serde_json::from_value(serde_json::Value::String(f.param_set.clone())).unwrap();
        let table = robot.params(set);
        assert_eq!(
            f.params, table.rows,
            "{name}: the robot's {} parameters changed since the fixture was made: run `{REGEN}`",
            f.param_set
        );
        // Enough samples to mean something: random ones plus the 2^dof corners.
        assert!(
            f.samples.len() >= 100 + (1 << robot.dof()),
            "{name}: too few samples"
        );
        let dof = robot.dof();
        let mut ev = JacobianEvaluator::new(&robot, table);
        // Full-pose robots have 6 rows; the fixtures hold the first 3.
        let mut jac = vec![0.0; robot.rows_per_pose() * dof];
        let (mut worst_p, mut worst_j) = (0.0f64, 0.0f64);
        for (k, s) in f.samples.iter().enumerate() {
            robot.check_q(&s.q).unwrap();
            assert_eq!(s.jacobian.len(), 3 * dof, "{name}: sample {k}");
            let p = ev.joint_jacobian(&s.q, &mut jac);
            let dp = (0..3)
                .map(|r| (p[r] - s.position[r]).powi(2))
                .sum::<f64>()
                .sqrt();
            let dj = jac[..3 * dof]
                .iter()
                .zip(&s.jacobian)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                dp <= TOLERANCE,
                "{name}: sample {k} q={:?}: position off by {dp:e} m",
                s.q
            );
            assert!(
                dj <= TOLERANCE,
                "{name}: sample {k} q={:?}: joint Jacobian off by {dj:e} m/rad",
                s.q
            );
            worst_p = worst_p.max(dp);
            worst_j = worst_j.max(dj);
        }
        println!(
            "{name} ({}, {} samples): max|Δposition| {worst_p:.2e} m, max|ΔJ| {worst_j:.2e} m/rad",
            f.versions,
            f.samples.len()
        );
    }
}
