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
