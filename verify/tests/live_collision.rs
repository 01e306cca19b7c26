//! Live check of the self-collision filter against Pinocchio + Coal
//! (feature `live`, needs the project venv): `verify/python/coal_collision.py`
//! computes Coal's verdicts on the Panda (URDF, STL meshes and SRDF copied in
//! `fixtures/example-robot-data/`) at 2,000 random configurations; the
//! committed fixture must equal them (the plain `tests/collision.rs` compares
//! activecal with the fixture), and with `REGEN=1` this test rewrites it.
//! Then `activecal select --self-collision` on the Panda's 78,125-pose
//! lattice and on 20,000 random poses: every pose it selects is collision
//! free by Coal.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

const JOINTS: &str =
    "panda_joint1,panda_joint2,panda_joint3,panda_joint4,panda_joint5,panda_joint6,panda_joint7";

fn coal(n: &str, out: &Path) -> serde_json::Value {
    let r = root();
    let fx = r.join("fixtures/example-robot-data");
    let status = Command::new(r.join(".venv/bin/python"))
        .arg(r.join("verify/python/coal_collision.py"))
        .args([
            fx.join("panda.urdf"),
            fx.join("panda.srdf"),
            r.join("fixtures"),
        ])
        .args([JOINTS, n, "15"])
        .arg(out)
        .status()
        .expect("the venv's python (run scripts/setup)");
    assert!(status.success());
    serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap()
}

#[test]
fn panda_collision_fixture_matches_coal_and_selected_poses_are_free() {
    let dir = std::env::temp_dir().join(format!("activecal-live-collision-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fixture = root().join("fixtures/example-robot-data/panda_collision_coal.json");
    let fresh = coal("2000", &dir.join("coal.json"));
    if std::env::var_os("REGEN").is_some() {
        std::fs::copy(dir.join("coal.json"), &fixture).unwrap();
    }
    let committed: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&fixture).unwrap()).unwrap();
    for key in ["configs", "collides", "collides_1mm", "pairs", "joints"] {
        assert_eq!(
            fresh[key], committed[key],
            "{key}: the fixture is not what Coal computes now (REGEN=1 rewrites it)"
        );
    }
    let bin = root().join("target/debug/activecal");
    let bin = if bin.exists() {
        bin
    } else {
        root().join("target/release/activecal")
    };
    let fx = root().join("fixtures/example-robot-data");
    for pool in [
        vec!["--levels", "5"],
        vec!["--pool", "random", "--count", "20000"],
    ] {
        let design = dir.join("design.json");
        let out = Command::new(&bin)
            .current_dir(root())
            .args(["select", "--robot"])
            .arg(fx.join("panda.urdf"))
            .args(["--tip", "panda_hand_tcp", "--self-collision", "--srdf"])
            .arg(fx.join("panda.srdf"))
            .args(&pool)
            .args(["--n", "30", "--starts", "2", "--force", "--json", "--out"])
            .arg(&design)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let stats = &report["pool_stats"]["filters"][0];
        eprintln!(
            "Panda {pool:?}: self-collision removed {} of {}",
            stats["removed"], stats["seen"]
        );
        assert!(stats["removed"].as_u64().unwrap() > 0);
        let d: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&design).unwrap()).unwrap();
        let qs = d["q"].clone();
        assert_eq!(
            qs.as_array().map(Vec::len),
            Some(30),
            "the design stores its 30 joint vectors"
        );
        std::fs::write(dir.join("qs.json"), qs.to_string()).unwrap();
        let verdict = coal(
            &format!("file:{}", dir.join("qs.json").display()),
            &dir.join("sel.json"),
        );
        let hits: Vec<usize> = (0..30)
            .filter(|&k| verdict["collides"][k].as_bool().unwrap())
            .collect();
        assert!(hits.is_empty(), "selected poses {hits:?} collide by Coal");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// FIGAROH's TIAGo (COLLADA collision meshes from example-robot-data,
/// found through the package directory; no SRDF): activecal's verdicts with
/// the pairs that touch in nearly every configuration skipped agree with
/// Pinocchio + Coal given those pairs as an SRDF, on random configurations
/// of the torso and arm. As for the Panda, a disagreement is allowed only
/// within 1 mm of contact. 200 configurations keep the check near 1 min of
/// Python (Coal tests all 1,785 geometry pairs per configuration).
#[test]
fn tiago_self_collision_with_always_touching_pairs_skipped_agrees_with_coal() {
    use activecal::collision::{AlwaysTouching, CollisionModel, CollisionSpec};
    let bridge = verify::bridge::Bridge::new().unwrap();
    let robots = verify::erd_fk::live::robots_dir(&bridge).unwrap();
    let r = root();
    let urdf = r.join("fixtures/figaroh/tiago.urdf");
    let joints: Vec<String> = std::iter::once("torso_lift_joint".to_string())
        .chain((1..=7).map(|k| format!("arm_{k}_joint")))
        .collect();
    let spec = CollisionSpec {
        urdf: urdf.display().to_string(),
        joints: joints.clone(),
        self_collision: true,
        always_touching: Some(AlwaysTouching::default()),
        package_dirs: vec![robots.display().to_string()],
        ..CollisionSpec::default()
    };
    let model = CollisionModel::load(&spec).unwrap();
    let skipped = model.always_touching();
    // The hand's fingers inside its safety box, and nothing of the arm.
    assert!(skipped.len() >= 20, "{skipped:?}");
    assert!(skipped.iter().all(|p| p.fraction >= 0.95));
    assert!(
        skipped
            .iter()
            .all(|p| !p.link.starts_with("arm_") && !p.other.starts_with("arm_")),
        "{skipped:?}"
    );
    let dir = std::env::temp_dir().join(format!("activecal-live-tiago-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let srdf: String = skipped
        .iter()
        .map(|p| {
            format!(
                "<disable_collisions link1=\"{}\" link2=\"{}\" reason=\"Always\"/>\n",
                p.link, p.other
            )
        })
        .collect();
    std::fs::write(
        dir.join("tiago.srdf"),
        format!("<robot name=\"tiago\">\n{srdf}</robot>\n"),
    )
    .unwrap();
    let out = dir.join("coal.json");
    let status = Command::new(r.join(".venv/bin/python"))
        .arg(r.join("verify/python/coal_collision.py"))
        .args([&urdf, &dir.join("tiago.srdf"), &robots])
        .args([&joints.join(","), "200", "15"])
        .arg(&out)
        .status()
        .expect("the venv's python (run scripts/setup)");
    assert!(status.success());
    let coal: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let configs = coal["configs"].as_array().unwrap();
    let (mut hits, mut disagree) = (0, Vec::new());
    for (k, q) in configs.iter().enumerate() {
        let q: Vec<f64> = q
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let ours = model.contact(&q).is_some();
        let theirs = coal["collides"][k].as_bool().unwrap();
        hits += usize::from(theirs);
        if ours != theirs {
            disagree.push(k);
            // Only we see contact: Coal finds the links within 1 mm. Only
            // Coal does: its penetration is at most 1 mm.
            let near = if ours {
                coal["collides_1mm"][k].as_bool().unwrap()
            } else {
                coal["depth"][k].as_f64().unwrap() <= 1e-3
            };
            assert!(
                near,
                "configuration {k}: activecal {ours}, Coal {theirs}, q = {q:?}"
            );
        }
    }
    eprintln!(
        "TIAGo: {} pairs skipped as always touching; Coal finds {hits} of {} in collision; {} disagreements, each within 1 mm of contact",
        skipped.len(),
        configs.len(),
        disagree.len()
    );
    assert!(
        hits >= 10,
        "the sample must hold collisions to test anything: {hits}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
