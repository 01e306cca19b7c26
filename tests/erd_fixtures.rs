//! The serial arms of `example-robot-data` without Python: each arm of the
//! table `verify/src/erd.rs` that has a fixture is imported from the copy of
//! its URDF in `fixtures/example-robot-data/` by name, as the command line
//! does (`file.urdf#base=…;tip=…;lock=…`), and its end frame equals the
//! placements in `fixtures/example-robot-data/fk/<arm>.json` — Pinocchio's
//! `oMf(base)⁻¹ · oMf(tip)` on the same file — to 1e-12 m in position and
//! 1e-12 in every rotation entry, at 20 joint vectors within Pinocchio's
//! limits. Every other arm of the table is covered by the live check
//! (`cargo test -p verify --features live --test all live_erd::`), which also
//! confirms the chains said to be the same as a fixture's. Regenerate with
//! `cargo run -p verify --features live -- regen`.
//!
//! Tolerance (derived in `verify/src/lib.rs`, `TOLERANCE`): the arms reach at
//! most 2 m from their base through at most ~25 composed transforms, so
//! rounding stays below 100 ε · 2 m ≈ 2e-14 m; a wrong frame, axis, sign or
//! joint is off by millimetres, and a joint off by a microradian by more than
//! 1e-8 (checked below).

#[allow(dead_code)]
#[path = "../verify/src/erd.rs"]
mod erd;

use activecal::io::{ChainChoice, load_robot};
use activecal::kinematics::Evaluator;
use activecal::model::Robot;
use erd::{ARMS, Arm, Coverage};
use serde::Deserialize;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

const TOL: f64 = 1e-12;
const REGEN: &str = "cargo run -p verify --features live -- regen";

#[derive(Deserialize)]
struct Fixture {
    format: u32,
    arm: String,
    urdf: String,
    upstream: String,
    example_robot_data: String,
    base: Option<String>,
    tip: String,
    lock: Vec<(String, f64)>,
    joints: Vec<String>,
    samples: Vec<Sample>,
}

#[derive(Deserialize)]
struct Sample {
    q: Vec<f64>,
    position: [f64; 3],
    rotation: [[f64; 3]; 3],
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn fk_dir() -> PathBuf {
    root()
        .join("fixtures")
        .join("example-robot-data")
        .join("fk")
}

fn fixture_arms() -> impl Iterator<Item = &'static Arm> {
    ARMS.iter().filter(|a| a.coverage == Coverage::Fixture)
}

fn read(arm: &Arm) -> Fixture {
    let path = fk_dir().join(format!("{}.json", arm.name));
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}: run `{REGEN}`", path.display()));
    let f: Fixture =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(f.format, 1, "{}: unknown format", path.display());
    f
}

/// The arm imported from the fixture's URDF copy, by name.
fn import(f: &Fixture) -> Robot {
    let choice = ChainChoice {
        base: f.base.clone(),
        tip: Some(f.tip.clone()),
        lock: f.lock.clone(),
        frames: None,
        kinematics: None,
        markers: Vec::new(),
    };
    let name = format!("{}{}", root().join(&f.urdf).display(), choice.fragment());
    load_robot(&name).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn chain_joints(r: &Robot) -> Vec<String> {
    let mut v = vec![String::new(); r.dof()];
    for f in &r.frames {
        if let Some(j) = f.joint {
            v[j].clone_from(&f.label);
        }
    }
    v
}

/// `(max |Δp|, max |ΔR|)` of activecal's end frame at the fixture's vectors
/// (each shifted by `shift`) against the fixture's placements.
fn deviation(r: &Robot, f: &Fixture, shift: impl Fn(&mut Vec<f64>)) -> (f64, f64) {
    let mut ev = Evaluator::new(r, &r.nominal);
    let (mut dp, mut dr) = (0.0f64, 0.0f64);
    for s in &f.samples {
        let mut q = s.q.clone();
        shift(&mut q);
        r.check_q(&q).unwrap();
        let e = ev.end_frame(&q);
        for i in 0..3 {
            dp = dp.max((e.position[i] - s.position[i]).abs());
            for j in 0..3 {
                dr = dr.max((e.rotation[(i, j)] - s.rotation[i][j]).abs());
            }
        }
    }
    (dp, dr)
}

#[test]
fn every_fixture_is_an_arm_of_the_table_and_back() {
    let want: BTreeSet<String> = fixture_arms().map(|a| format!("{}.json", a.name)).collect();
    let have: BTreeSet<String> = std::fs::read_dir(fk_dir())
        .unwrap_or_else(|e| panic!("{}: {e}: run `{REGEN}`", fk_dir().display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(have, want, "fixtures/example-robot-data/fk/: run `{REGEN}`");
    assert!(want.len() >= 30, "{} fixtures", want.len());
    // The other arms name their coverage: another arm's fixture, or a reason.
    for a in ARMS {
        match a.coverage {
            Coverage::Fixture => {}
            Coverage::SameChainAs(o) => assert_eq!(
                Arm::by_name(o).map(|o| o.coverage),
                Some(Coverage::Fixture),
                "{}",
                a.name
            ),
            Coverage::LiveOnly(why) => assert!(why.len() > 10, "{}", a.name),
        }
    }
    // Each fixture is the table's chain, read from a copy of the package's
    // file.
    for arm in fixture_arms() {
        let f = read(arm);
        let stale = format!("{}.json is stale: run `{REGEN}`", arm.name);
        assert_eq!(f.arm, arm.name, "{stale}");
        assert_eq!(f.upstream, arm.urdf, "{stale}");
        assert_eq!(f.example_robot_data, erd::ERD_VERSION, "{stale}");
        assert_eq!(f.base.as_deref(), arm.base, "{stale}");
        assert_eq!(f.tip, arm.tip, "{stale}");
        let lock: Vec<(&str, f64)> = f.lock.iter().map(|(n, v)| (n.as_str(), *v)).collect();
        assert_eq!(lock, arm.lock, "{stale}");
        assert_eq!(f.joints, arm.joints, "{stale}");
        assert_eq!(
            Path::new(&f.urdf).file_name().and_then(|n| n.to_str()),
            arm.fixture_urdf(),
            "{stale}"
        );
        assert!(root().join(&f.urdf).is_file(), "{} is missing", f.urdf);
        assert!(f.samples.len() >= 20, "{}: too few samples", arm.name);
        assert!(
            f.samples.iter().all(|s| s.q.len() == arm.joints.len()),
            "{stale}"
        );
    }
}

/// The acceptance check without Python: each arm's forward kinematics equals
/// Pinocchio's to 1e-12.
#[test]
fn every_arm_with_a_fixture_matches_pinocchio() {
    for arm in fixture_arms() {
        let f = read(arm);
        let r = import(&f);
        assert_eq!(chain_joints(&r), f.joints, "{}: the chain", arm.name);
        let (dp, dr) = deviation(&r, &f, |_| {});
        println!(
            "{:<32} {:<28} {:<24} {} joints: max|Δp| {dp:.1e} m, max|ΔR| {dr:.1e}",
            arm.name,
            f.urdf.trim_start_matches("fixtures/example-robot-data/"),
            f.tip,
            r.dof()
        );
        assert!(
            dp <= TOL && dr <= TOL,
            "{}: {dp:e} m, {dr:e} beyond {TOL:e}",
            arm.name
        );
    }
}

/// The comparison can fail: any one joint off by a microradian (or a
/// micrometre) moves the end frame by far more than the tolerance, on every
/// arm.
#[test]
fn a_joint_off_by_a_microradian_is_seen() {
    for arm in fixture_arms() {
        let f = read(arm);
        let r = import(&f);
        for j in 0..r.dof() {
            let (dp, dr) = deviation(&r, &f, |q| q[j] += 1e-6);
            assert!(
                dp.max(dr) > 1e4 * TOL,
                "{}: joint {} off by 1e-6 gives {dp:e} m, {dr:e}",
                arm.name,
                f.joints[j]
            );
        }
    }
}
