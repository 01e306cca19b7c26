//! Live check of every serial arm of `example-robot-data` (feature `live`,
//! needs the project venv): each arm of `verify::erd::ARMS` is imported by
//! activecal as the command line does (`file.urdf#base=…;tip=…;lock=…`), and
//! its end frame — position and rotation — equals Pinocchio's
//! `oMf(base)⁻¹ · oMf(tip)` on the same installed URDF at 20 joint vectors
//! within Pinocchio's limits, to `verify::TOLERANCE` (1e-12 m and 1e-12 on
//! rotation entries). Also: the table covers every URDF of the installed
//! package; Pinocchio's chain is the table's; the import without a tip does
//! what the table says; the "same chain" claims behind the fixtures hold;
//! the committed fixtures and URDF copies match a fresh regeneration; and
//! the comparison sees a wrong base and a joint off by a microradian.

use activecal::io::urdf::{self, UrdfOptions};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use verify::TOLERANCE;
use verify::bridge::Bridge;
use verify::erd::{ARMS, Arm, Coverage, ERD_VERSION, NOT_ARMS, Tipless};
use verify::erd_fk::live::{make_fixture, pinocchio_poses, reference, robots_dir};
use verify::erd_fk::{
    self, FkFixture, N_SAMPLES, activecal_poses, chain_joints, load, pose_deviation,
};
use verify::fixture::REGEN_COMMAND;

fn setup() -> (Bridge, PathBuf) {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let dir = robots_dir(&bridge).unwrap();
    (bridge, dir)
}

/// Every `.urdf` under `dir`, relative to it, with `/` separators.
fn urdf_files(dir: &Path) -> BTreeSet<String> {
    fn walk(root: &Path, at: &Path, out: &mut BTreeSet<String>) {
        for e in std::fs::read_dir(at).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else if p.extension().is_some_and(|x| x == "urdf") {
                let rel = p.strip_prefix(root).unwrap();
                let parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.insert(parts.join("/"));
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(dir, dir, &mut out);
    out
}

#[test]
fn the_table_covers_every_urdf_of_the_package() {
    let (_, dir) = setup();
    let installed = urdf_files(&dir);
    let arms: BTreeSet<String> = ARMS.iter().map(|a| a.urdf.to_string()).collect();
    let others: BTreeSet<String> = NOT_ARMS.iter().map(|(f, _)| (*f).to_string()).collect();
    assert!(
        arms.is_disjoint(&others),
        "{:?}",
        arms.intersection(&others)
    );
    let table: BTreeSet<String> = arms.union(&others).cloned().collect();
    let missing: Vec<&String> = installed.difference(&table).collect();
    let gone: Vec<&String> = table.difference(&installed).collect();
    assert!(
        missing.is_empty() && gone.is_empty(),
        "example-robot-data {ERD_VERSION}: URDFs not in verify/src/erd.rs: {missing:?}; \
         in the table but not installed: {gone:?}"
    );
    println!(
        "{} URDFs: {} with {} arms, {} without an arm",
        installed.len(),
        arms.len(),
        ARMS.len(),
        others.len()
    );
    // Names are unique; every claim of coverage points at a fixture.
    let names: BTreeSet<&str> = ARMS.iter().map(|a| a.name).collect();
    assert_eq!(names.len(), ARMS.len());
    for a in ARMS {
        match a.coverage {
            Coverage::Fixture => {}
            Coverage::SameChainAs(other) => assert_eq!(
                Arm::by_name(other).map(|o| o.coverage),
                Some(Coverage::Fixture),
                "{}",
                a.name
            ),
            Coverage::LiveOnly(why) => assert!(!why.is_empty(), "{}", a.name),
        }
        assert!(a.joints.len() >= 4, "{}: not an arm", a.name);
    }
}

/// The acceptance check: every arm imports and its forward kinematics
/// equals Pinocchio's, position and rotation, to 1e-12.
#[test]
fn every_arm_matches_pinocchio() {
    let (bridge, dir) = setup();
    println!(
        "{:<32} {:<56} {:<16} {:<28} {:>3} {:>9} {:>9}",
        "arm", "URDF", "base", "tip", "dof", "max|Δp| m", "max|ΔR|"
    );
    let mut failures = Vec::new();
    for arm in ARMS {
        let path = dir.join(arm.urdf);
        let robot = load(arm, &path).unwrap();
        assert_eq!(
            chain_joints(&robot),
            arm.joints,
            "{}: activecal's chain",
            arm.name
        );
        // The options of the library call give the same robot as the name.
        let opts = UrdfOptions {
            base: arm.base.map(str::to_string),
            tip: Some(arm.tip.to_string()),
            lock: arm.lock.iter().map(|&(n, v)| (n.to_string(), v)).collect(),
            ..UrdfOptions::default()
        };
        let direct = urdf::load(&path, &opts).unwrap();
        assert_eq!(direct.nominal, robot.nominal, "{}", arm.name);
        // `reference` checks that Pinocchio's chain is the table's.
        let (qs, pin) = reference(&bridge, arm, &path).unwrap();
        assert_eq!(qs.len(), N_SAMPLES);
        let d = pose_deviation(&pin, &activecal_poses(&robot, &qs)).unwrap();
        println!(
            "{:<32} {:<56} {:<16} {:<28} {:>3} {:>9.1e} {:>9.1e}",
            arm.name,
            arm.urdf,
            arm.base.unwrap_or("(root)"),
            arm.tip,
            robot.dof(),
            d.position,
            d.rotation
        );
        if !d.within(TOLERANCE) {
            failures.push(format!("{}: {d:?}", arm.name));
        }
    }
    assert!(
        failures.is_empty(),
        "beyond {TOLERANCE:e}: {}",
        failures.join("; ")
    );
}

/// Without a tip, a single chain imports the same arm, a tree is refused
/// with its candidate tips, and a chain ending in a gripper's joint is
/// refused naming that joint.
#[test]
fn without_a_tip_each_urdf_behaves_as_the_table_says() {
    let (_, dir) = setup();
    for arm in ARMS {
        let path = dir.join(arm.urdf);
        let opts = UrdfOptions {
            base: arm.base.map(str::to_string),
            lock: arm.lock.iter().map(|&(n, v)| (n.to_string(), v)).collect(),
            ..UrdfOptions::default()
        };
        let got = urdf::load(&path, &opts);
        match arm.tipless {
            Tipless::SameChain => {
                let r = got.unwrap();
                let with_tip = load(arm, &path).unwrap();
                assert_eq!(r.nominal, with_tip.nominal, "{}", arm.name);
                assert_eq!(chain_joints(&r), arm.joints, "{}", arm.name);
            }
            Tipless::Tree => {
                let e = got.unwrap_err().to_string();
                assert!(
                    e.contains("candidate tips") && e.contains("the chain's tip"),
                    "{}: {e}",
                    arm.name
                );
            }
            Tipless::Gripper(joint) => {
                let e = got.unwrap_err().to_string();
                assert!(
                    e.contains(&format!("'{joint}'")) && e.contains("gripper"),
                    "{}: {e}",
                    arm.name
                );
            }
        }
    }
}

/// An arm covered by another's fixture has the same chain: Pinocchio's
/// placements on both files agree at the other arm's fixture vectors.
#[test]
fn same_chain_claims_hold() {
    let (bridge, dir) = setup();
    let mut n = 0;
    for arm in ARMS {
        let Coverage::SameChainAs(other) = arm.coverage else {
            continue;
        };
        let other = Arm::by_name(other).unwrap();
        let (qs, theirs) = reference(&bridge, other, &dir.join(other.urdf)).unwrap();
        let ours = pinocchio_poses(&bridge, arm, &dir.join(arm.urdf), &qs).unwrap();
        let d = pose_deviation(&theirs, &ours).unwrap();
        assert!(d.within(TOLERANCE), "{} vs {}: {d:?}", arm.name, other.name);
        n += 1;
    }
    assert!(n >= 8, "{n} claims");
}

#[test]
fn committed_fixtures_match_a_fresh_regeneration() {
    let (bridge, dir) = setup();
    let fk = erd_fk::default_dir().join("fk");
    let mut want = BTreeSet::new();
    for arm in ARMS.iter().filter(|a| a.coverage == Coverage::Fixture) {
        let path = fk.join(format!("{}.json", arm.name));
        let stale = format!("{} is stale: run `{REGEN_COMMAND}`", path.display());
        let file =
            FkFixture::read(&path).unwrap_or_else(|e| panic!("{e:#}: run `{REGEN_COMMAND}`"));
        let fresh = make_fixture(&bridge, arm).unwrap();
        // Same software, same inputs: the same text.
        assert_eq!(file.to_json(), fresh.to_json(), "{stale}");
        let copy = erd_fk::default_dir().join(arm.fixture_urdf().unwrap());
        assert_eq!(
            std::fs::read(&copy).unwrap(),
            std::fs::read(dir.join(arm.urdf)).unwrap(),
            "{} is not the package's {}",
            copy.display(),
            arm.urdf
        );
        want.insert(format!("{}.json", arm.name));
    }
    let have: BTreeSet<String> = std::fs::read_dir(&fk)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(have, want, "{}: stray or missing files", fk.display());
}

/// The comparison can fail: the arm taken from the root while Pinocchio's
/// placements are relative to the base link, or one joint off by a
/// microradian, are far outside the tolerance.
#[test]
fn the_check_sees_a_wrong_base_and_a_joint_off_by_a_microradian() {
    let (bridge, dir) = setup();
    for arm in ARMS.iter().filter(|a| a.coverage == Coverage::Fixture) {
        let path = dir.join(arm.urdf);
        let robot = load(arm, &path).unwrap();
        let (qs, pin) = reference(&bridge, arm, &path).unwrap();
        for j in 0..robot.dof() {
            let off: Vec<Vec<f64>> = qs
                .iter()
                .map(|q| {
                    let mut q = q.clone();
                    q[j] += 1e-6;
                    q
                })
                .collect();
            let d = pose_deviation(&pin, &activecal_poses(&robot, &off)).unwrap();
            assert!(
                d.position.max(d.rotation) > 1e-8,
                "{}: joint {} off by 1e-6: {d:?}",
                arm.name,
                arm.joints[j]
            );
        }
        if arm.base.is_some() {
            let from_root = Arm { base: None, ..*arm };
            let r = load(&from_root, &path).unwrap();
            let at_base = |q: &Vec<f64>| {
                // The root chain has the joints below the base too (a torso
                // at 0 may coincide with the root): put them at 0.5 rad or
                // m, and the arm's at q.
                let mut v = vec![0.5; r.dof() - q.len()];
                v.extend_from_slice(q);
                v
            };
            let qr: Vec<Vec<f64>> = qs.iter().map(at_base).collect();
            let d = pose_deviation(&pin, &activecal_poses(&r, &qr)).unwrap();
            assert!(
                d.position.max(d.rotation) > 1e-3,
                "{}: from the root {d:?}",
                arm.name
            );
        }
    }
}
