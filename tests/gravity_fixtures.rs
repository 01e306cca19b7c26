//! Gravity torques (issue #31) against Pinocchio without Python: each
//! `fixtures/gravity/<case>.json` holds, for a chain whose URDF is in the
//! repository (FIGAROH's UR10 and TIAGo, torso free and locked, and the
//! `example-robot-data` arms copied into `fixtures/example-robot-data/`),
//! Pinocchio's `computeGeneralizedGravity` of that URDF at 100 random
//! configurations. activecal's torques from the same URDF's `<inertial>`
//! elements must equal them to 1e-10 relative to the configuration's largest
//! torque (a vertical joint's torque is 0 to rounding): both sides sum
//! products of masses and lever arms after ~30 rigid transforms, rounding
//! ~1e-14 (the live check sees at most 2e-14); a centre of mass off by a
//! micrometre shows at 1e-6.
//!
//! Regenerate with `cargo run -p verify --features live -- regen`; the live
//! check is `verify/tests/live_gravity.rs`.

use activecal::io::inertia::{InertiaOptions, gravity_model};
use activecal::io::urdf::{UrdfOptions, parse};
use serde::Deserialize;

const TOL: f64 = 1e-10;

#[derive(Deserialize)]
struct Fixture {
    format: u32,
    case: String,
    description: String,
    base: Option<String>,
    tip: Option<String>,
    lock: Vec<(String, f64)>,
    joints: Vec<String>,
    samples: Vec<Sample>,
}

#[derive(Deserialize)]
struct Sample {
    q: Vec<f64>,
    tau: Vec<f64>,
}

fn fixtures() -> Vec<Fixture> {
    let mut paths: Vec<_> = std::fs::read_dir("fixtures/gravity")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap())
        .collect()
}

#[test]
fn gravity_torques_equal_pinocchio_on_every_stored_arm() {
    let all = fixtures();
    // FIGAROH's three chains and the arms whose URDFs are copied.
    assert!(all.len() >= 20, "{} fixtures", all.len());
    for f in &all {
        assert_eq!(f.format, 1, "{}", f.case);
        let text = std::fs::read_to_string(&f.description).unwrap();
        let opts = UrdfOptions {
            base: f.base.clone(),
            tip: f.tip.clone(),
            lock: f.lock.clone(),
            ..UrdfOptions::default()
        };
        let robot = parse(&text, &f.description, &opts).unwrap();
        assert_eq!(
            robot.source.as_ref().unwrap().driven_names(),
            f.joints,
            "{}",
            f.case
        );
        let g = gravity_model(&robot, &InertiaOptions::default()).unwrap();
        assert_eq!(f.samples.len(), 100, "{}", f.case);
        let mut seen = 0.0f64;
        for s in &f.samples {
            let ours = g.torques_at(&s.q);
            let scale = s.tau.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            seen = seen.max(scale);
            let d = ours
                .iter()
                .zip(&s.tau)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(
                d <= TOL * scale.max(1e-300),
                "{} at {:?}: {ours:?} vs Pinocchio {:?}",
                f.case,
                s.q,
                s.tau
            );
        }
        assert!(seen > 0.1, "{}: no torque to compare", f.case);
    }
}

#[test]
fn a_gram_more_on_the_forearm_is_seen() {
    // One gram 0.3 m along the UR10's forearm: the fixture's torques no
    // longer match to 1e-10 (the change is ~1e-5 relative).
    let f = fixtures()
        .into_iter()
        .find(|f| f.case == "figaroh_ur10")
        .unwrap();
    let text = std::fs::read_to_string(&f.description).unwrap();
    let opts = UrdfOptions {
        tip: f.tip.clone(),
        ..UrdfOptions::default()
    };
    let robot = parse(&text, &f.description, &opts).unwrap();
    let mut g = gravity_model(&robot, &InertiaOptions::default()).unwrap();
    assert!(g.add_point_mass("forearm_link", 1e-3, nalgebra::Vector3::new(0.3, 0.0, 0.0)));
    let worst = f
        .samples
        .iter()
        .map(|s| {
            let ours = g.torques_at(&s.q);
            let scale = s.tau.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            ours.iter()
                .zip(&s.tau)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                / scale
        })
        .fold(0.0f64, f64::max);
    assert!(worst > 1e3 * TOL, "{worst:e}");
}
