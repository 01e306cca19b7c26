//! Live check of the camera pool's line of sight
//! (`activecal::pool::line_of_sight`) against Pinocchio + Coal
//! (`verify/python/coal_sight.py`, feature `live`): on example-robot-data's
//! Panda eye-to-hand (the camera and board of `live_camera_truth`'s Panda
//! gate), `activecal select --line-of-sight` chooses 20 poses whose every
//! ray to the board's 48 points is free in Coal too; and on 150
//! configurations the view keeps (before the line of sight), activecal's
//! parry ray casts and Coal's segment collisions agree ray by ray, a
//! disagreement allowed only for a ray that grazes the geometry (Coal's
//! distance from the segment under 0.1 mm: a mesh edge met at a glancing
//! angle, where the two libraries' floating-point tests may differ).

use activecal::collision::CollisionSpec;
use activecal::io::UrdfChain;
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_target::read_target;
use activecal::measure::camera::Mounting;
use activecal::pool::camera_view::CameraView;
use activecal::pool::line_of_sight::{DEFAULT_STOP, LineOfSight, rays};
use serde_json::{Value, json};
use std::path::Path;
use std::process::Command;
use verify::bridge::repo_root as root;

const JOINTS: &str =
    "panda_joint1,panda_joint2,panda_joint3,panda_joint4,panda_joint5,panda_joint6,panda_joint7";
const CAMERA: &str = "1.2,0.6,0.9,-2.0985,0,2.0779";
const TARGET: &str = "-0.0853,0.0568,0.02,3.141592653589793,0,0.03";

fn six(s: &str) -> [f64; 6] {
    s.split(',')
        .map(|v| v.parse().unwrap())
        .collect::<Vec<f64>>()
        .try_into()
        .unwrap()
}

/// The robot Coal checks the rays against: its URDF, package directory,
/// the joints a configuration's values drive (comma separated), the
/// rays' frame, and the joints whose rigid bodies are not checked.
struct Scene<'a> {
    urdf: std::path::PathBuf,
    package_dir: std::path::PathBuf,
    joints: &'a str,
    frame: &'a str,
    carriers: &'a str,
}

/// Coal's verdicts on `cases` ([{q, eye, points}], the scene's frame).
fn coal(scene: &Scene<'_>, cases: &Value, dir: &Path, name: &str) -> Value {
    let r = root();
    let (rays_file, out) = (
        dir.join(format!("{name}.json")),
        dir.join(format!("{name}_coal.json")),
    );
    std::fs::write(&rays_file, cases.to_string()).unwrap();
    let status = Command::new(r.join(".venv/bin/python"))
        .arg(r.join("verify/python/coal_sight.py"))
        .arg(&scene.urdf)
        .arg(&scene.package_dir)
        .args([scene.joints, scene.frame, scene.carriers])
        .arg(&rays_file)
        .arg(&out)
        .status()
        .expect("the venv's python (run scripts/setup)");
    assert!(status.success());
    serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap()
}

/// Asserts that every ray of `cases` ([{q, eye, points}]) is free in Coal.
fn assert_all_free(scene: &Scene<'_>, cases: Vec<Value>, dir: &Path) {
    let verdict = coal(scene, &Value::Array(cases), dir, "chosen");
    for (k, b) in verdict["blocked"].as_array().unwrap().iter().enumerate() {
        let hits = b
            .as_array()
            .unwrap()
            .iter()
            .filter(|x| x.as_bool().unwrap())
            .count();
        assert_eq!(
            hits, 0,
            "chosen pose {k}: {hits} of its rays blocked in Coal"
        );
    }
}

/// Compares activecal's verdicts `ours` (per configuration, per ray) with
/// Coal's on the same `cases`, ray by ray: a disagreement is allowed only
/// for a grazing ray (Coal's distance under 0.1 mm) and for at most one
/// ray in 1,000; the sample must hold configurations with and without a
/// blocked ray (else the check is vacuous).
fn assert_agree(scene: &Scene<'_>, cases: Vec<Value>, ours: &[Vec<bool>], dir: &Path, label: &str) {
    let n = cases.len();
    let verdict = coal(scene, &Value::Array(cases), dir, "sample");
    let (mut rays_n, mut blocked_n, mut grazing, mut configs_blocked) = (0, 0, 0, 0);
    for (k, ours) in ours.iter().enumerate() {
        configs_blocked += usize::from(ours.iter().any(|b| *b));
        for (i, b) in ours.iter().enumerate() {
            rays_n += 1;
            blocked_n += usize::from(*b);
            let theirs = verdict["blocked"][k][i].as_bool().unwrap();
            if *b != theirs {
                let dist = verdict["distance"][k][i].as_f64().unwrap();
                assert!(
                    dist < 1e-4,
                    "configuration {k} ray {i}: activecal {b}, Coal {theirs}, Coal distance {dist} m"
                );
                grazing += 1;
            }
        }
    }
    eprintln!(
        "{label}: {rays_n} rays at {n} configurations: {blocked_n} blocked ({configs_blocked} configurations), {grazing} grazing disagreements"
    );
    assert!(
        configs_blocked > n / 15 && configs_blocked < n - n / 15,
        "{configs_blocked} of {n} blocked: the sample must hold both"
    );
    assert!(
        grazing * 1000 <= rays_n,
        "{grazing} of {rays_n} rays disagree"
    );
}

/// The design `select --line-of-sight` wrote to `design` (its run's
/// output `out`, which must have succeeded), checked to have had rays to
/// block: the line of sight removed some configurations the view keeps.
fn design_in_sight(out: &std::process::Output, design: &Path, label: &str) -> Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let d: Value = serde_json::from_str(&std::fs::read_to_string(design).unwrap()).unwrap();
    let removed = d["out_of_sight"].as_u64().unwrap();
    eprintln!(
        "{label}: {} in sight, {removed} more seen but out of sight",
        d["visible"]
    );
    assert!(
        removed > 0,
        "the line of sight removed nothing: the check would be vacuous"
    );
    d
}

#[test]
fn panda_line_of_sight_agrees_with_coal() {
    let dir = std::env::temp_dir().join(format!("activecal-live-sight-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let r = root();
    let scene = Scene {
        urdf: r.join("fixtures/example-robot-data/panda.urdf"),
        package_dir: r.join("fixtures"),
        joints: JOINTS,
        frame: "panda_link0",
        carriers: "panda_joint7",
    };
    let robot_ref = format!(
        "{}#tip=panda_hand_tcp",
        r.join("fixtures/example-robot-data/panda.urdf").display()
    );
    let robot = activecal::io::load_robot(&robot_ref).unwrap();
    let view = CameraView {
        intrinsics: read_camera_info(&r.join("fixtures/camera/camera_info.yaml")).unwrap(),
        mounting: Mounting::EyeToHand,
        face: [0.0, 0.0, 1.0],
        points: read_target(&r.join("fixtures/camera/board.yaml"))
            .unwrap()
            .points
            .iter()
            .map(|p| [p.x, p.y, p.z])
            .collect(),
        camera: six(CAMERA),
        target: six(TARGET),
        min_fraction: 1.0,
        margin_px: 20.0,
        max_view_angle: 60f64.to_radians(),
        distance: [0.3, 2.0],
    };
    let case = |q: &[f64]| {
        let (eye, pts, _) = rays(&view, &robot, &robot.nominal, q);
        json!({"q": q, "eye": [eye.x, eye.y, eye.z],
               "points": pts.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>()})
    };
    // The chosen poses of `select --line-of-sight`: every ray free in Coal.
    let bin = r.join("target/debug/activecal");
    let design = dir.join("design.json");
    let out = Command::new(&bin)
        .current_dir(&r)
        .args([
            "select",
            "--robot",
            &robot_ref,
            "--camera-info",
            "fixtures/camera/camera_info.yaml",
        ])
        .args([
            "--target",
            "fixtures/camera/board.yaml",
            "--mounting",
            "eye-to-hand",
        ])
        .arg(format!("--camera-pose={CAMERA}"))
        .arg(format!("--target-pose={TARGET}"))
        .args([
            "--image-margin",
            "20",
            "--distance",
            "0.3,2.0",
            "--n",
            "20",
            "--count",
            "5000",
        ])
        .args(["--line-of-sight", "--force", "--out"])
        .arg(&design)
        .output()
        .unwrap();
    let d = design_in_sight(&out, &design, "Panda eye-to-hand");
    let chosen: Vec<Vec<f64>> = serde_json::from_value(d["poses"].clone()).unwrap();
    assert_eq!(chosen.len(), 20);
    assert_all_free(&scene, chosen.iter().map(|q| case(q)).collect(), &dir);
    // A sample the view keeps, before the line of sight: ray by ray.
    let chain = UrdfChain::of(&robot).unwrap();
    let sight = LineOfSight::new(CollisionSpec {
        urdf: chain.file,
        text: Some(chain.text),
        joints: chain.joints,
        lock: chain.lock,
        base: Some(chain.base),
        ..CollisionSpec::default()
    });
    let model = sight.load().unwrap();
    let sample: Vec<Vec<f64>> = activecal::observability::generic_configurations(&robot, 5000, 7)
        .into_iter()
        .filter(|q| view.keeps(&robot, &robot.nominal, q))
        .take(150)
        .collect();
    assert_eq!(sample.len(), 150);
    let ours: Vec<Vec<bool>> = sample
        .iter()
        .map(|q| {
            let (eye, pts, _) = rays(&view, &robot, &robot.nominal, q);
            model.blocked_rays(q, &eye, &pts, DEFAULT_STOP, true)
        })
        .collect();
    assert_agree(
        &scene,
        sample.iter().map(|q| case(q)).collect(),
        &ours,
        &dir,
        "Panda eye-to-hand",
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The head camera of `fixtures/camera/tiago_*` (`--camera-link
/// head_2_link`, the board on the arm's tool link), line of sight in the
/// whole TIAGo tree (FIGAROH's URDF, example-robot-data's meshes): the
/// chain's joints (the head's, walked backwards, and the arm's) drive the
/// tree by name, the rays leave from the camera's link, and the head's and
/// the tool's rigid bodies (the camera's and the board's carriers) are not
/// checked. `select --line-of-sight` chooses 30 poses whose every ray is
/// free in Coal, and on 150 configurations the view keeps activecal's
/// verdicts and Coal's agree ray by ray (grazing rays as above).
#[test]
fn head_camera_line_of_sight_agrees_with_coal() {
    let dir =
        std::env::temp_dir().join(format!("activecal-live-head-sight-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let r = root();
    let pkg =
        r.join(".venv/lib/python3.11/site-packages/cmeel.prefix/share/example-robot-data/robots");
    let (camera, target) = (
        "0.0908,0.0800,-0.0220,-3.1416,-1.5708,0.0000",
        "0.0800,-0.0400,0.0600,0.0000,1.5708,0.0000",
    );
    let robot_ref = format!(
        "{}#tip=arm_tool_link",
        r.join("fixtures/figaroh/tiago.urdf").display()
    );
    let robot = activecal::io::urdf_branch::camera_branch(
        &activecal::io::load_robot(&robot_ref).unwrap(),
        "head_2_link",
    )
    .unwrap();
    let chain = UrdfChain::of(&robot).unwrap();
    let joints = chain.joints.join(",");
    let scene = Scene {
        urdf: r.join("fixtures/figaroh/tiago.urdf"),
        package_dir: pkg.clone(),
        joints: &joints,
        frame: "head_2_link",
        carriers: "arm_7_joint,head_2_joint",
    };
    let view = CameraView {
        intrinsics: read_camera_info(&r.join("fixtures/camera/tiago_xtion.yaml")).unwrap(),
        mounting: Mounting::EyeToHand,
        points: read_target(&r.join("fixtures/camera/tiago_board.yaml"))
            .unwrap()
            .points
            .iter()
            .map(|p| [p.x, p.y, p.z])
            .collect(),
        face: [0.0, 0.0, 1.0],
        camera: six(camera),
        target: six(target),
        min_fraction: 1.0,
        margin_px: 20.0,
        max_view_angle: 60f64.to_radians(),
        distance: [0.25, 1.5],
    };
    let case = |q: &[f64]| {
        let (eye, pts, _) = rays(&view, &robot, &robot.nominal, q);
        json!({"q": q, "eye": [eye.x, eye.y, eye.z],
               "points": pts.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>()})
    };
    let design = dir.join("design.json");
    let out = Command::new(r.join("target/debug/activecal"))
        .current_dir(&r)
        .args([
            "select",
            "--robot",
            &robot_ref,
            "--camera-link",
            "head_2_link",
        ])
        .args(["--camera-info", "fixtures/camera/tiago_xtion.yaml"])
        .args(["--target", "fixtures/camera/tiago_board.yaml"])
        .arg(format!("--camera-pose={camera}"))
        .arg(format!("--target-pose={target}"))
        .args([
            "--image-margin",
            "20",
            "--distance",
            "0.25,1.5",
            "--n",
            "30",
        ])
        .args(["--count", "20000", "--line-of-sight", "--package-dir"])
        .arg(&pkg)
        .args(["--force", "--out"])
        .arg(&design)
        .output()
        .unwrap();
    let d = design_in_sight(&out, &design, "TIAGo head camera");
    assert_eq!(
        d["joint_names"].as_array().unwrap().len(),
        chain.joints.len()
    );
    let chosen: Vec<Vec<f64>> = serde_json::from_value(d["poses"].clone()).unwrap();
    assert_eq!(chosen.len(), 30);
    assert_all_free(&scene, chosen.iter().map(|q| case(q)).collect(), &dir);
    let sight = LineOfSight::from_link(
        CollisionSpec {
            urdf: chain.file,
            text: Some(chain.text),
            joints: chain.joints.clone(),
            lock: chain.lock,
            package_dirs: vec![pkg.display().to_string()],
            ..CollisionSpec::default()
        },
        "head_2_link",
    );
    let model = sight.load().unwrap();
    let sample: Vec<Vec<f64>> = activecal::observability::generic_configurations(&robot, 20000, 7)
        .into_iter()
        .filter(|q| view.keeps(&robot, &robot.nominal, q))
        .take(150)
        .collect();
    assert_eq!(sample.len(), 150);
    let ours: Vec<Vec<bool>> = sample
        .iter()
        .map(|q| {
            let (eye, pts, _) = rays(&view, &robot, &robot.nominal, q);
            model
                .blocked_rays_from_link(q, "head_2_link", &eye, &pts, DEFAULT_STOP)
                .unwrap()
        })
        .collect();
    assert_agree(
        &scene,
        sample.iter().map(|q| case(q)).collect(),
        &ours,
        &dir,
        "head camera",
    );
    std::fs::remove_dir_all(&dir).ok();
}
