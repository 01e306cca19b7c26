//! Live check of the tour's moves against Pinocchio + Coal (issue #27):
//! `activecal select` on a random pool of 20,000 for the Panda (its SRDF,
//! on a table) and the UR10 (on a table, beside a wall), then
//! `verify/python/coal_moves.py` checks every pose and every straight
//! joint-space move of the visiting order by its own conservative
//! advancement on Coal's distances, at 1 mm of link-point motion near
//! contact. activecal's verdict on each move (free, or where it first hits
//! and which pair) must be Coal's, and the visiting order must take at most
//! 0.75 of the selection order's move time. The moves and Coal's verdicts
//! are the fixture `fixtures/example-robot-data/tour_moves_coal.json`
//! (rewritten with `REGEN=1`; otherwise Coal must still give its
//! verdicts), with long moves across the tour added (pose k to pose k +
//! 11), against which plain `cargo test` checks activecal's move check
//! (`tests/tour_moves.rs`).

use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// A robot in a cell: its URDF (in `fixtures/example-robot-data`), tip,
/// SRDF, table height and boxes (`cx, cy, cz, sx, sy, sz` in the base
/// frame, metres).
struct Scene {
    name: &'static str,
    urdf: &'static str,
    tip: &'static str,
    srdf: Option<&'static str>,
    floor: f64,
    boxes: &'static [[f64; 6]],
    /// Moves the tour may leave colliding (named in the report, Coal
    /// agreeing on each): see the UR10's.
    colliding_allowed: usize,
}

const SCENES: [Scene; 2] = [
    Scene {
        name: "panda",
        urdf: "panda.urdf",
        tip: "panda_hand_tcp",
        srdf: Some("panda.srdf"),
        floor: 0.0,
        boxes: &[],
        colliding_allowed: 0,
    },
    Scene {
        name: "ur10",
        urdf: "ur10_robot.urdf",
        tip: "tool0",
        srdf: None,
        floor: 0.0,
        // A wall 0.65 m behind the base, 3 m wide and 1.2 m high.
        boxes: &[[0.0, -0.7, 0.6, 3.0, 0.1, 1.2]],
        // Since the unknowns are judged on generic configurations (#39) the
        // UR10's design had a pose so near the wall that no reversal,
        // relocation, whole turn or via freed its move to the next: it is
        // exchanged for the pool pose keeping the most ln OI_D whose moves
        // are free (ln OI_D 46.065 -> 45.974), and every move is free.
        colliding_allowed: 0,
    },
];

/// `activecal select` on the scene: its report and its design file.
fn select(scene: &Scene, dir: &Path) -> (Value, Value) {
    let fx = root().join("fixtures/example-robot-data");
    let design = dir.join(format!("{}.json", scene.name));
    let mut cmd = Command::new(root().join("target/debug/activecal"));
    cmd.current_dir(root())
        .args(["select", "--robot"])
        .arg(fx.join(scene.urdf))
        .args(["--tip", scene.tip, "--self-collision"]);
    if let Some(srdf) = scene.srdf {
        cmd.arg("--srdf").arg(fx.join(srdf));
    }
    cmd.args(["--floor", &scene.floor.to_string()]);
    for b in scene.boxes {
        let b: Vec<String> = b.iter().map(f64::to_string).collect();
        cmd.args(["--obstacle", &format!("box:{}", b.join(","))]);
    }
    let out = cmd
        .args(["--pool", "random", "--count", "20000", "--n", "30"])
        .args(["--force", "--json", "--out"])
        .arg(&design)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = serde_json::from_slice(&out.stdout).unwrap();
    let design = serde_json::from_str(&std::fs::read_to_string(&design).unwrap()).unwrap();
    (report, design)
}

/// The scene's moves for `coal_moves.py` (paths relative to the root).
fn spec(scene: &Scene, joints: &Value, moves: &[[Vec<f64>; 2]]) -> Value {
    json!({
        "urdf": format!("fixtures/example-robot-data/{}", scene.urdf),
        "srdf": scene.srdf.map(|s| format!("fixtures/example-robot-data/{s}")),
        "package_dir": "fixtures",
        "joints": joints,
        "base": null,
        "floor": scene.floor,
        "boxes": scene.boxes,
        "resolution": 1e-3,
        "moves": moves,
    })
}

/// Coal's verdicts on a spec's moves.
fn coal(spec: &Value, dir: &Path, name: &str) -> Value {
    let (input, output) = (
        dir.join(format!("{name}-spec.json")),
        dir.join(format!("{name}-coal.json")),
    );
    std::fs::write(&input, spec.to_string()).unwrap();
    let status = Command::new(root().join(".venv/bin/python"))
        .current_dir(root())
        .args(["-W", "ignore"])
        .arg(root().join("verify/python/coal_moves.py"))
        .args([&input, &output])
        .status()
        .expect("the venv's python (run scripts/setup)");
    assert!(status.success());
    serde_json::from_str(&std::fs::read_to_string(output).unwrap()).unwrap()
}

/// A contact's two names as activecal gives them: links (Coal names a
/// geometry `LINK_K`) or an obstacle, sorted.
fn pair_names(names: &Value) -> Vec<String> {
    let mut v: Vec<String> = names
        .as_array()
        .unwrap()
        .iter()
        .map(|n| {
            let n = n.as_str().unwrap();
            match n.rsplit_once('_') {
                Some((link, k)) if k.parse::<usize>().is_ok() => link.to_string(),
                _ => n.to_string(),
            }
        })
        .collect();
    v.sort();
    v
}

#[test]
fn tours_on_the_panda_and_the_ur10_are_checked_as_coal_checks_them() {
    let dir = std::env::temp_dir().join(format!("activecal-live-tour-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fixture_path = root().join("fixtures/example-robot-data/tour_moves_coal.json");
    let mut fixture = Vec::new();
    for scene in &SCENES {
        let (report, design) = select(scene, &dir);
        let tour = &report["tour"];
        let ratio = tour["time_ratio"].as_f64().unwrap();
        eprintln!(
            "{}: move time {:.2} s in selection order, {:.2} s in visiting order ({ratio:.3}); moves {}",
            scene.name,
            tour["selection_order"]["time_s"],
            tour["visiting_order"]["time_s"],
            report["moves"]
        );
        assert!(
            ratio <= 0.75,
            "{}: the tour takes {ratio} of selection order's time",
            scene.name
        );
        // Every pose (a move of length 0), then every move of the tour.
        let qs: Vec<Vec<f64>> = serde_json::from_value(design["q"].clone()).unwrap();
        let mut moves: Vec<[Vec<f64>; 2]> = qs.iter().map(|q| [q.clone(), q.clone()]).collect();
        moves.extend(qs.windows(2).map(|w| [w[0].clone(), w[1].clone()]));
        // And, for the fixture, long moves across the tour (pose k to pose
        // k + 11), many of which collide: the plain test's colliding cases.
        let n = qs.len();
        moves.extend((0..n).map(|k| [qs[k].clone(), qs[(k + 11) % n].clone()]));
        // And the two halves of every move made free through a via
        // configuration.
        let vias: Vec<(usize, Vec<f64>)> = report["moves"]["via"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| {
                (
                    v["from"].as_u64().unwrap() as usize,
                    serde_json::from_value(v["q"].clone()).unwrap(),
                )
            })
            .collect();
        for (from, q) in &vias {
            moves.push([qs[*from].clone(), q.clone()]);
            moves.push([q.clone(), qs[from + 1].clone()]);
        }
        let spec = spec(scene, &design["joint_names"], &moves);
        let verdicts = coal(&spec, &dir, scene.name);
        let v = verdicts["moves"].as_array().unwrap();
        let hits: Vec<usize> = (0..qs.len())
            .filter(|&k| v[k]["collides"] == true)
            .collect();
        assert!(
            hits.is_empty(),
            "{}: selected poses {hits:?} collide by Coal",
            scene.name
        );
        // activecal's colliding moves (by the position they start from)
        // are Coal's, each first hit at the same place by the same pair.
        let halves = &v[3 * n - 1..];
        assert!(
            halves.iter().all(|h| h["collides"] == false),
            "{}: a via configuration's move collides by Coal: {halves:?}",
            scene.name
        );
        let ours: Vec<(usize, f64, Vec<String>)> = report["moves"]["colliding"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| {
                let pair = json!([c["pair"]["link"], c["pair"]["other"]]);
                (
                    c["from"].as_u64().unwrap() as usize,
                    c["at"].as_f64().unwrap(),
                    pair_names(&pair),
                )
            })
            .collect();
        // A move made free through a via collides straight: by Coal too.
        let straight: Vec<usize> = vias.iter().map(|(from, _)| *from).collect();
        for &k in &straight {
            assert_eq!(
                v[n + k]["collides"],
                true,
                "{}: move {k} goes through a via, Coal finds it free straight",
                scene.name
            );
        }
        let theirs: Vec<usize> = (0..qs.len() - 1)
            .filter(|k| !straight.contains(k))
            .filter(|&k| v[qs.len() + k]["collides"] == true)
            .collect();
        assert_eq!(
            ours.iter().map(|c| c.0).collect::<Vec<_>>(),
            theirs,
            "{}: the moves that collide, by activecal and by Coal",
            scene.name
        );
        for (k, at, pair) in &ours {
            let c = &v[qs.len() + k];
            // Both stop at their first check in contact; near contact each
            // steps at most 1 mm of its fastest point's motion (Coal's step
            // is `resolution_s`, activecal's bound on the fastest point is
            // within a factor 2 of Coal's): 3 steps.
            let tol = 3.0 * c["resolution_s"].as_f64().unwrap();
            assert!(
                (at - c["at"].as_f64().unwrap()).abs() <= tol,
                "{}: move {k}: {at} against {c}",
                scene.name
            );
            assert_eq!(pair, &pair_names(&c["pair"]), "{}: move {k}", scene.name);
        }
        // The acceptance of #27: every move of the tour is free (after
        // reordering, whole turns and via configurations), but for the
        // scene's allowance, each of which is named and checked above.
        assert!(
            ours.len() <= scene.colliding_allowed,
            "{}: moves {ours:?} still collide",
            scene.name
        );
        fixture.push(json!({"scene": scene.name, "spec": spec, "coal": verdicts["moves"]}));
    }
    if std::env::var_os("REGEN").is_some() || !fixture_path.exists() {
        let text = serde_json::to_string(&json!({"format": 1, "scenes": fixture})).unwrap();
        std::fs::write(&fixture_path, text).unwrap();
    } else {
        // The committed moves: Coal still gives the committed verdicts.
        let committed: Value =
            serde_json::from_str(&std::fs::read_to_string(&fixture_path).unwrap()).unwrap();
        for s in committed["scenes"].as_array().unwrap() {
            let name = s["scene"].as_str().unwrap();
            let fresh = coal(&s["spec"], &dir, &format!("{name}-fixture"));
            for (a, b) in fresh["moves"]
                .as_array()
                .unwrap()
                .iter()
                .zip(s["coal"].as_array().unwrap())
            {
                assert_eq!(
                    (&a["collides"], &a["pair"]),
                    (&b["collides"], &b["pair"]),
                    "{name}: the fixture is not what Coal computes now (REGEN=1 rewrites it)"
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
