//! Live identification-Jacobian checks (feature `live`, needs the project
//! venv): activecal's analytic identification Jacobian against central
//! differences of Pinocchio's end frame over every unknown (positions and
//! `pin.log3` orientation rows), models rebuilt from the perturbed table by
//! `verify::model`, at 200 random configurations, for the built-ins in point
//! and pose form and the two example-robot-data arms; and the committed
//! `fixtures/idjac/` against a fresh regeneration. Tolerance
//! `verify::idjac::REL_TOL · L` (1e-8 · L, derived in `verify/src/idjac.rs`
//! from the step h = 1e-5).

use activecal::model::Robot;
use verify::bridge::Bridge;
use verify::idjac::live::{check, make_fixture, pinocchio_jacobians};
use verify::idjac::{self, IdFixture, REL_TOL, STEP, activecal_jacobians, id_deviation, sources};
use verify::sample::random_configurations;

const CONFIGS: usize = 200;
const SEED: u64 = 20_251_117;

#[test]
fn identification_jacobians_agree_with_pinocchio_central_differences() {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    for source in sources() {
        let robot = source.robot().unwrap();
        let d = check(&bridge, &robot, CONFIGS, SEED).unwrap();
        println!(
            "{:<22} {}x{:<3} L {:6.2}  max|ΔJ| {:8.2e}  relative {:8.2e}  orientation rows {:8.2e}",
            d.robot, d.shape[0], d.shape[1], d.size, d.absolute, d.relative, d.orientation
        );
        assert_eq!(d.configurations, CONFIGS);
        assert!(d.within(REL_TOL), "{d:?}");
    }
}

#[test]
fn the_check_sees_a_wrong_parameter_and_a_wrong_step() {
    // activecal differentiated at a table with one length off by 1 mm (the
    // lever arms of every upstream rotation column change by 1 mm), and the
    // finite differences divided by a wrong step: both far outside.
    let bridge = Bridge::new().unwrap();
    let robot = Robot::builtin("ur5:pose").unwrap();
    let qs = random_configurations(&robot, 20, SEED);
    let fd = pinocchio_jacobians(&bridge, &robot, &robot.nominal, &qs, STEP).unwrap();
    let id = robot.param_id("a_2").unwrap();
    let mut off = robot.nominal.clone();
    off.set(id, off.get(id) + 1e-3);
    let d = id_deviation(&robot, &fd, &activecal_jacobians(&robot, &off, &qs)).unwrap();
    assert!(d.relative > 1e-5, "{d:?}");
    let mut halved = fd.clone();
    for j in &mut halved.jacobian {
        for v in j.iter_mut() {
            *v *= 0.5;
        }
    }
    let ours = activecal_jacobians(&robot, &robot.nominal, &qs);
    assert!(id_deviation(&robot, &halved, &ours).unwrap().relative > 0.1);
    assert!(id_deviation(&robot, &fd, &ours).unwrap().within(REL_TOL));
}

#[test]
fn committed_idjac_fixtures_match_a_fresh_regeneration() {
    let bridge = Bridge::new().unwrap();
    for source in sources() {
        let fresh = make_fixture(&bridge, &source).unwrap();
        let path = idjac::default_dir().join(format!("{}.json", source.file_stem()));
        let stale = format!(
            "{} is stale: run `{}`",
            path.display(),
            verify::fixture::REGEN_COMMAND
        );
        let file = IdFixture::read(&path).unwrap();
        assert_eq!(file.source, fresh.source, "{stale}");
        assert_eq!(file.unknowns, fresh.unknowns, "{stale}");
        assert_eq!(file.params, fresh.params, "{stale}");
        assert_eq!(file.versions, fresh.versions, "{stale}");
        assert_eq!(file.configurations(), fresh.configurations(), "{stale}");
        // Same software, same inputs: the same numbers (the text too).
        assert_eq!(file.to_json(), fresh.to_json(), "{stale}");
    }
}
