//! activecal's analytic identification Jacobian (`blocks::jacobian_of`)
//! against the reference values in `fixtures/idjac/*.json`: central
//! differences of Pinocchio's end frame over every unknown DH/Hayati
//! parameter, position rows `(p(θ+h) − p(θ−h))/2h` and orientation rows
//! `w · log3(R(θ+h) R(θ−h)ᵀ)/2h`, with the Pinocchio models rebuilt from the
//! perturbed parameter table by `verify`'s own model builder (not by
//! activecal's kinematics). Every column of every robot is gated: the
//! built-ins in point and pose form and two `example-robot-data` arms (Panda,
//! Kinova Jaco). No Python needed here; regenerate with
//! `cargo run -p verify --features live -- regen`.
//!
//! Tolerance `1e-8 · L`, `L = max(1 m, max |p|, max |J|)` over the fixture's
//! samples. Derivation (also in `verify/src/idjac.rs`): every parameter moves
//! the downstream chain by one fixed screw, so central differences have no
//! truncation error for `a`, `d` and the orientation rows, and at most
//! `h²/6 · dist(p, axis) ≤ h²/6 · L` for the positions of `γ`, `α`, `β`;
//! rounding in two evaluations of ~12 composed transforms (≤ 30 ε L each,
//! ε = 1.1e-16) divided by `2h` adds at most `30 ε L / h`. With `h = 1e-5`:
//! `(1.7e-11 + 3.3e-10) · L ≈ 3.5e-10 · L`, so `1e-8 · L` has a margin of
//! ~30 (observed: ≤ 3e-11 · L). A wrong column — axis, sign, lever arm off
//! by a millimetre, a missing orientation scale, columns swapped — is off by
//! ≥ 1e-3 · L.

use activecal::blocks::jacobian_of;
use activecal::io::urdf::{UrdfOptions, load};
use activecal::kinematics::pose;
use activecal::model::{MeasurementKind, Robot};
use serde::Deserialize;
use std::path::{Path, PathBuf};

const REL_TOL: f64 = 1e-8;
const STEP: f64 = 1e-5;
const REGEN: &str = "cargo run -p verify --features live -- regen";

#[derive(Deserialize)]
#[serde(rename_all = "snake_case")]
enum Source {
    Builtin {
        name: String,
    },
    Urdf {
        path: String,
        tip: String,
        measurement: MeasurementKind,
        orientation_scale: f64,
    },
}

#[derive(Deserialize)]
struct Fixture {
    format: u32,
    robot: String,
    source: Source,
    rows: usize,
    orientation_scale: f64,
    unknowns: Vec<String>,
    params: Vec<[f64; 5]>,
    step: f64,
    versions: serde_json::Value,
    samples: Vec<Sample>,
}

#[derive(Deserialize)]
struct Sample {
    q: Vec<f64>,
    position: [f64; 3],
    jacobian: Vec<f64>,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn fixture_files() -> Vec<PathBuf> {
    let dir = root().join("fixtures").join("idjac");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}: run `{REGEN}`", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    files
}

fn read(path: &Path) -> Fixture {
    let text = std::fs::read_to_string(path).unwrap();
    let f: Fixture =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(f.format, 1, "{}: unknown format", path.display());
    f
}

fn robot_of(source: &Source) -> Robot {
    match source {
        Source::Builtin { name } => Robot::builtin(name).unwrap(),
        Source::Urdf {
            path,
            tip,
            measurement,
            orientation_scale,
        } => {
            let opts = UrdfOptions {
                tip: Some(tip.clone()),
                measurement: *measurement,
                ..UrdfOptions::default()
            };
            let mut r = load(&root().join(path), &opts).unwrap();
            r.orientation_scale = *orientation_scale;
            r
        }
    }
}

/// `L = max(1, max |p|, max |J|)` of the fixture's (Pinocchio's) values.
fn size(f: &Fixture) -> f64 {
    f.samples.iter().fold(1.0f64, |acc, s| {
        let p = s.position.iter().map(|v| v * v).sum::<f64>().sqrt();
        let j = s.jacobian.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        acc.max(p).max(j)
    })
}

/// activecal's identification Jacobian at the fixture's configurations,
/// row-major `t × p` per sample.
fn analytic(robot: &Robot, f: &Fixture) -> Vec<Vec<f64>> {
    let x = jacobian_of(robot, &robot.nominal, f.samples.len(), |k, q| {
        q.copy_from_slice(&f.samples[k].q);
    });
    let (t, p) = (x.t(), x.p());
    (0..f.samples.len())
        .map(|k| (0..t * p).map(|e| x.block(k)[(e / p, e % p)]).collect())
        .collect()
}

#[test]
fn every_robot_has_point_and_pose_fixtures() {
    let names: Vec<String> = fixture_files()
        .iter()
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    for robot in activecal::model::BUILTIN {
        for want in [robot.to_string(), format!("{robot}_pose")] {
            assert!(
                names.contains(&want),
                "fixtures/idjac/{want}.json is missing: run `{REGEN}`"
            );
        }
    }
    // The two example-robot-data arms, each in both forms.
    let urdf: Vec<(String, MeasurementKind)> = fixture_files()
        .iter()
        .filter_map(|p| match read(p).source {
            Source::Urdf {
                path, measurement, ..
            } => Some((path, measurement)),
            Source::Builtin { .. } => None,
        })
        .collect();
    for arm in ["panda.urdf", "kinova.urdf"] {
        for m in [MeasurementKind::Point, MeasurementKind::Pose] {
            assert!(
                urdf.iter()
                    .any(|(p, mm)| p.ends_with(&format!("example-robot-data/{arm}")) && *mm == m),
                "no {} fixture of {arm}: run `{REGEN}`",
                m.name()
            );
        }
    }
}

#[test]
fn identification_jacobian_matches_pinocchio_central_differences() {
    let files = fixture_files();
    assert!(files.len() >= 10, "fixtures/idjac/: run `{REGEN}`");
    for path in files {
        let name = path.display();
        let f = read(&path);
        let robot = robot_of(&f.source);
        let stale = format!("{name} is stale: run `{REGEN}`");
        assert_eq!(f.robot, robot.name, "{stale}");
        assert_eq!(f.unknowns, robot.parameter_names(), "{stale}");
        assert_eq!(f.params, robot.nominal.rows, "{stale}");
        assert_eq!(f.rows, robot.rows_per_pose(), "{stale}");
        assert_eq!(f.orientation_scale, robot.orientation_scale, "{stale}");
        assert_eq!(
            f.step, STEP,
            "{name}: the tolerance is derived for h = {STEP}"
        );
        assert!(f.samples.len() >= 20, "{name}: too few samples");
        let (t, p) = (f.rows, f.unknowns.len());
        let l = size(&f);
        let tol = REL_TOL * l;
        let ours = analytic(&robot, &f);
        let mut worst = 0.0f64;
        for (k, (s, j)) in f.samples.iter().zip(&ours).enumerate() {
            robot.check_q(&s.q).unwrap();
            assert_eq!(s.jacobian.len(), t * p, "{name}: sample {k}");
            // The configuration and model are the fixture's: the end point
            // agrees with Pinocchio's to rounding (see tests/fixtures.rs for
            // the 1e-12 m tolerance).
            let (_, pos) = pose(&robot, &robot.nominal, &s.q);
            let dp = (0..3)
                .map(|r| (pos[r] - s.position[r]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(dp <= 1e-12, "{name}: sample {k}: end point off by {dp:e} m");
            for (e, (a, b)) in j.iter().zip(&s.jacobian).enumerate() {
                let d = (a - b).abs();
                assert!(
                    d <= tol,
                    "{name}: sample {k} q={:?}: row {} column {} ({}): analytic {a} vs \
                     Pinocchio central difference {b} (|Δ| = {d:e} > {tol:e})",
                    s.q,
                    e / p,
                    e % p,
                    f.unknowns[e % p]
                );
                worst = worst.max(d);
            }
        }
        println!(
            "{name} ({}, {} samples, {t}x{p}, L = {l:.2}): max|ΔJ| {worst:.2e}, relative {:.2e} \
             (tolerance {REL_TOL:e})",
            f.versions,
            f.samples.len(),
            worst / l
        );
    }
}

/// The comparison can fail: two swapped columns, or a pose robot's
/// orientation rows with a wrong scale, are far outside the tolerance for
/// every fixture (so a column-order or scaling mistake cannot slip through).
#[test]
fn the_comparison_sees_swapped_columns_and_a_wrong_orientation_scale() {
    for path in fixture_files() {
        let name = path.display();
        let f = read(&path);
        let robot = robot_of(&f.source);
        let (t, p) = (f.rows, f.unknowns.len());
        let tol = REL_TOL * size(&f);
        // Largest difference between the fixture and `ours` over all samples.
        let off = |ours: &[Vec<f64>]| {
            ours.iter()
                .zip(&f.samples)
                .flat_map(|(j, s)| j.iter().zip(&s.jacobian).map(|(a, b)| (a - b).abs()))
                .fold(0.0f64, f64::max)
        };
        let good = analytic(&robot, &f);
        // Every pair of columns differs somewhere by far more than the
        // tolerance: swapping them would be caught.
        for c in 0..p {
            for c2 in c + 1..p {
                let mut swapped = good.clone();
                for j in &mut swapped {
                    for r in 0..t {
                        j.swap(r * p + c, r * p + c2);
                    }
                }
                assert!(
                    off(&swapped) > 1e3 * tol,
                    "{name}: columns {} and {} are indistinguishable",
                    f.unknowns[c],
                    f.unknowns[c2]
                );
            }
        }
        if t == 6 {
            let mut wrong = robot.clone();
            wrong.orientation_scale *= 1.5;
            assert!(off(&analytic(&wrong, &f)) > 1e3 * tol, "{name}");
        }
    }
}
