//! Live check of the calibrated robot written back (issue #26; feature
//! `live`, needs the project venv): for FIGAROH's UR10 and TIAGo (full
//! pose, torso locked, three markers), every arm of `verify::erd::ARMS` and
//! the built-ins, the URDF activecal exports at the calibrated table (the
//! robot's `real` one, every unknown perturbed), loaded by Pinocchio, gives
//! `oMf(base)⁻¹ · oMf(tip)`; composed with the split's measurement frame
//! and tool (or markers) it reproduces activecal's calibrated predictions —
//! positions and rotation entries — to 1e-9 at 100 random configurations
//! within the limits and at every measured pose of the data files. Also:
//! the committed fixtures `fixtures/export/` equal a fresh computation, and
//! a joint origin off by a microradian is seen.

use std::collections::BTreeSet;
use verify::bridge::Bridge;
use verify::erd_fk::Placement;
use verify::erd_fk::live::robots_dir;
use verify::export::live::{make_fixture, pinocchio_poses};
use verify::export::{
    Case, Export, ExportFixture, N_FIXTURE, N_RANDOM, TOLERANCE, activecal_prediction, cases,
    compose, default_dir, deviation, random_configurations,
};
use verify::fixture::REGEN_COMMAND;

fn setup() -> (Bridge, Vec<Case>) {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let dir = robots_dir(&bridge).unwrap();
    let cases = cases(Some(&dir));
    (bridge, cases)
}

/// `(max |Δp|, max |ΔR|)` between activecal's predictions and Pinocchio's
/// placements of the export composed with its frames, at `qs`.
fn compare(e: &Export, qs: &[Vec<f64>], pin: &[Placement]) -> (f64, f64) {
    let ours: Vec<Vec<Placement>> = qs
        .iter()
        .map(|q| activecal_prediction(&e.robot, &e.table, q))
        .collect();
    let theirs: Vec<Vec<Placement>> = pin.iter().map(|p| compose(e.frames.as_ref(), p)).collect();
    deviation(&ours, &theirs)
}

/// The acceptance check: every case's export in Pinocchio reproduces
/// activecal's calibrated predictions to 1e-9 m (and 1e-9 on rotation
/// entries) at 100 random configurations and at the measured ones.
#[test]
fn every_exported_urdf_reproduces_activecal_in_pinocchio() {
    let (bridge, cases) = setup();
    println!(
        "{:<40} {:<8} {:>3} {:>5} {:>9} {:>9}",
        "case", "sensor", "dof", "poses", "max|Δp| m", "max|ΔR|"
    );
    let mut failures = Vec::new();
    let mut worst = (0.0f64, String::new());
    for case in &cases {
        let e = case.export().unwrap();
        // The calibrated table moves the chain: the file is not the input.
        if let Some(p) = case.path() {
            assert_ne!(e.text, std::fs::read_to_string(p).unwrap(), "{}", case.name);
        }
        let mut qs = random_configurations(&e.robot, N_RANDOM);
        let measured = case
            .measured_configurations(&e.names[..e.robot.dof()])
            .unwrap();
        assert!(
            case.measured.is_none() || measured.len() >= 20,
            "{}: {} measured poses",
            case.name,
            measured.len()
        );
        qs.extend(measured);
        let pin = pinocchio_poses(&bridge, &e, &format!("live-{}", case.name), &qs).unwrap();
        let (dp, dr) = compare(&e, &qs, &pin);
        println!(
            "{:<40} {:<8} {:>3} {:>5} {:>9.1e} {:>9.1e}",
            case.name,
            case.sensor.name(),
            e.robot.dof(),
            qs.len(),
            dp,
            dr
        );
        // NaN fails too.
        if !(dp <= TOLERANCE && dr <= TOLERANCE) {
            failures.push(format!("{}: {dp:e} m, {dr:e}", case.name));
        }
        if dp.max(dr) > worst.0 {
            worst = (dp.max(dr), case.name.clone());
        }
    }
    println!("largest: {:e} ({})", worst.0, worst.1);
    // Every arm of the table, the figaroh robots and the built-ins.
    assert!(
        cases.len() >= verify::erd::ARMS.len() + 10,
        "{}",
        cases.len()
    );
    assert!(
        failures.is_empty(),
        "beyond {TOLERANCE:e}: {}",
        failures.join("; ")
    );
}

/// The comparison can fail: the exported URDF with one chain joint's
/// origin turned by 1e-6 rad (about an axis off every joint axis) is off by
/// more than the tolerance, for every joint of every case; a built-in's
/// export with one frame's α off by 1e-6 rad likewise.
#[test]
fn a_joint_origin_off_by_a_microradian_is_seen() {
    let (bridge, cases) = setup();
    let axis = nalgebra::Unit::new_normalize(nalgebra::Vector3::new(1.0, 2.0, 3.0));
    let turn = nalgebra::UnitQuaternion::from_axis_angle(&axis, 1e-6);
    let mut checked = 0;
    let mut smallest = f64::INFINITY;
    for case in cases.iter().filter(|c| c.fixture) {
        let e = case.export().unwrap();
        let qs = random_configurations(&e.robot, N_FIXTURE);
        let n = e.frames.as_ref().map_or(e.robot.dof(), |f| f.joints.len());
        for k in 0..n {
            let file = format!("off-{}-{k}", case.name);
            let pin = if e.frames.is_some() {
                let bad = case
                    .export_with(&|j, t| {
                        if j == k {
                            t.rotation *= turn;
                        }
                    })
                    .unwrap();
                pinocchio_poses(&bridge, &bad, &file, &qs).unwrap()
            } else {
                // The k-th driven frame's α (column 1) of the table written.
                let mut bad = e.clone();
                let frame = e
                    .robot
                    .frames
                    .iter()
                    .position(|f| f.joint == Some(k))
                    .unwrap();
                bad.table.rows[frame][1] += 1e-6;
                bad.text = activecal::io::urdf::to_urdf(&bad.robot, &bad.table).unwrap();
                pinocchio_poses(&bridge, &bad, &file, &qs).unwrap()
            };
            // The wrong file against the right predictions.
            let (dp, dr) = compare(&e, &qs, &pin);
            assert!(
                dp.max(dr) > 1e-8,
                "{}: joint {k} off by 1e-6 rad unseen: {dp:e} m, {dr:e}",
                case.name
            );
            smallest = smallest.min(dp.max(dr));
            checked += 1;
        }
    }
    println!("{checked} joints off by 1e-6 rad: smallest deviation {smallest:e}");
    assert!(checked > 100, "{checked} joints");
}

#[test]
fn committed_fixtures_match_a_fresh_computation() {
    let (bridge, cases) = setup();
    let dir = default_dir();
    let mut want = BTreeSet::new();
    for case in cases.iter().filter(|c| c.fixture) {
        let path = dir.join(format!("{}.json", case.name));
        let stale = format!("{} is stale: run `{REGEN_COMMAND}`", path.display());
        let file =
            ExportFixture::read(&path).unwrap_or_else(|e| panic!("{e:#}: run `{REGEN_COMMAND}`"));
        let fresh = make_fixture(&bridge, case, &format!("fresh-{}", case.name)).unwrap();
        // Same software, same inputs: the same text.
        assert_eq!(file.to_json(), fresh.to_json(), "{stale}");
        want.insert(format!("{}.json", case.name));
    }
    let have: BTreeSet<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(have, want, "{}: stray or missing files", dir.display());
}
