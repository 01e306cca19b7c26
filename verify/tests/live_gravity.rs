//! Live check of the gravity torques (issue #31; feature `live`, needs the
//! project venv): for FIGAROH's UR10 and TIAGo (torso free and locked) and
//! every arm of `verify::erd::ARMS` (the installed `example-robot-data`
//! files for those not copied into the repository), activecal's gravity
//! torques from the URDF's inertials equal Pinocchio's
//! `computeGeneralizedGravity` of the same file to 1e-10 relative at 100
//! random configurations; the committed fixtures `fixtures/gravity/` equal
//! a fresh computation.

use verify::bridge::Bridge;
use verify::erd_fk::live::robots_dir;
use verify::fixture::REGEN_COMMAND;
use verify::gravity::live::{make_fixture, pinocchio_case};
use verify::gravity::{
    GravityFixture, TOLERANCE, activecal_torques, default_dir, gravity_cases, relative_deviation,
};

#[test]
fn gravity_torques_equal_pinocchio_on_every_arm() {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let dir = robots_dir(&bridge).unwrap();
    let cases = gravity_cases(Some(&dir));
    assert!(cases.len() >= 30, "{} cases", cases.len());
    println!(
        "{:<40} {:>3} {:>12} {:>10}",
        "case", "dof", "max |τ| N·m", "rel dev"
    );
    let mut failures = Vec::new();
    let mut worst = 0.0f64;
    for case in &cases {
        let (robot, _, qs, pin) = pinocchio_case(&bridge, case).unwrap();
        let ours = activecal_torques(&robot, &qs).unwrap();
        let d = relative_deviation(&ours, &pin);
        let big = pin.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        println!(
            "{:<40} {:>3} {:>12.3} {:>10.1e}",
            case.name,
            robot.dof(),
            big,
            d
        );
        // A case with no torque at all would compare nothing.
        assert!(big > 1e-3, "{}: no gravity torque", case.name);
        worst = worst.max(d);
        if !(d <= TOLERANCE) {
            failures.push(format!("{}: {d:e}", case.name));
        }
    }
    println!("largest relative deviation {worst:.1e}");
    assert!(failures.is_empty(), "{failures:?}");
}

#[test]
fn gravity_fixtures_are_current() {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    for case in gravity_cases(None).iter().filter(|c| c.fixture) {
        let fresh = make_fixture(&bridge, case).unwrap();
        let path = default_dir().join(format!("{}.json", case.name));
        let stored = GravityFixture::read(&path)
            .unwrap_or_else(|e| panic!("{}: {e} (run {REGEN_COMMAND})", path.display()));
        assert_eq!(stored.samples.len(), fresh.samples.len(), "{}", case.name);
        for (a, b) in stored.samples.iter().zip(&fresh.samples) {
            assert_eq!(
                a.q, b.q,
                "{}: stale configurations (run {REGEN_COMMAND})",
                case.name
            );
            let d = relative_deviation(std::slice::from_ref(&a.tau), std::slice::from_ref(&b.tau));
            assert!(d <= 1e-14, "{}: {d:e} (run {REGEN_COMMAND})", case.name);
        }
    }
}
