//! Poses an operator can run (issue 27): pools without repeated poses,
//! `pool` with every source and filter, designs written as .json, .csv and
//! .yaml that read back the same, the visiting order, margins, and the
//! collision filter's per-pair counts.

use crate::common;

use common::{fails_with, json_of, run};
use std::path::PathBuf;

const UR10: &str = "fixtures/figaroh/ur10_robot.urdf";
const PANDA: &str = "fixtures/example-robot-data/panda.urdf";
const PANDA_SRDF: &str = "fixtures/example-robot-data/panda.srdf";

fn scratch(name: &str) -> PathBuf {
    common::scratch_dir("cli-op", name)
}

#[test]
fn the_ur10_lattice_has_no_repeated_pose() {
    // Joints with ±2π limits: 5 levels 2π/5 apart from the lower limit,
    // not −2π, −π, 0, π, 2π (two angles). With the default 2° margin joint
    // 3 (±π) is laid on the circle too, from −π + 2° with it.
    for margin in ["2", "0"] {
        let v = json_of(&[
            "pool",
            "--robot",
            UR10,
            "--tip",
            "wrist_3_link",
            "--levels",
            "5",
            "--margin",
            margin,
            "--json",
        ]);
        assert_eq!(v["size"], 15_625, "margin {margin}");
        assert_eq!(v["distinct"], 15_625, "margin {margin}");
        let joints = v["lattice"].as_array().unwrap();
        assert!(joints.iter().all(|j| j["distinct"] == 5), "{joints:?}");
        let turns = joints.iter().filter(|j| j["full_turn"] == true).count();
        assert_eq!(turns, 6, "margin {margin}");
    }
}

#[test]
fn pool_writes_the_kept_poses_with_per_filter_counts() {
    let d = scratch("pool-out");
    let out = d.join("p.csv");
    let out_s = out.to_str().unwrap();
    let v = json_of(&[
        "pool",
        "--robot",
        PANDA,
        "--tip",
        "panda_hand_tcp",
        "--pool",
        "sobol",
        "--count",
        "512",
        "--self-collision",
        "--srdf",
        PANDA_SRDF,
        "--floor",
        "0.05",
        "--out",
        out_s,
        "--json",
    ]);
    let kept = v["pool_stats"]["kept"].as_u64().unwrap() as usize;
    let filters = v["pool_stats"]["filters"].as_array().unwrap();
    assert_eq!(filters.len(), 2);
    let removed: u64 = filters.iter().map(|f| f["removed"].as_u64().unwrap()).sum();
    assert_eq!(kept as u64 + removed, 512);
    // Each collision filter says which pairs removed its candidates.
    for f in filters {
        let c = &f["contacts"];
        let by_kind = c["self_collision"].as_u64().unwrap() + c["obstacle"].as_u64().unwrap();
        assert_eq!(by_kind, f["removed"].as_u64().unwrap(), "{f}");
        let top: u64 = c["top"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| p["removed"].as_u64().unwrap())
            .sum();
        assert!(top <= by_kind);
    }
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert_eq!(
        header,
        "panda_joint1,panda_joint2,panda_joint3,panda_joint4,panda_joint5,panda_joint6,panda_joint7,id"
    );
    assert_eq!(lines.count(), kept);
    // The file is a pool again, with the same poses.
    let again = json_of(&[
        "pool",
        "--robot",
        PANDA,
        "--tip",
        "panda_hand_tcp",
        "--pool",
        &format!("file:{out_s}"),
        "--json",
    ]);
    assert_eq!(again["size"].as_u64().unwrap() as usize, kept);
    // Without the SRDF the Panda's hand touches its flange link in every
    // pose: the warning names the pair and the SRDF.
    let out = run(&[
        "pool",
        "--robot",
        PANDA,
        "--tip",
        "panda_hand_tcp",
        "--pool",
        "random",
        "--count",
        "64",
        "--self-collision",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("disable_collisions"),
        "{err}"
    );
    assert!(err.contains("the pair that removed most is"), "{err}");
    fails_with(
        &["pool", "--out", d.join("p.txt").to_str().unwrap()],
        ".csv or .json",
    );
}

/// `select` on the UR10 from a random pool, written to `out`.
fn ur10_select(out: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "select",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        "random",
        "--count",
        "1500",
        "--n",
        "20",
        "--starts",
        "1",
        "--ils",
        "0",
        "--out",
        out,
        "--json",
    ];
    args.extend_from_slice(extra);
    json_of(&args)
}

#[test]
fn a_design_round_trips_through_csv_and_yaml() {
    let d = scratch("design-out");
    let csv = d.join("d.csv");
    let json = d.join("d.json");
    let yaml = d.join("d.yaml");
    let sel = ur10_select(csv.to_str().unwrap(), &[]);
    let sel_json = ur10_select(json.to_str().unwrap(), &[]);
    let sel_yaml = ur10_select(yaml.to_str().unwrap(), &[]);
    assert_eq!(sel["poses"], sel_json["poses"]);
    assert_eq!(sel["poses"], sel_yaml["poses"]);
    // The report names the joints and gives every pose's values, in
    // visiting order, with the tour's figures.
    assert_eq!(sel["joint_names"][0], "shoulder_pan_joint");
    let confs = sel["configurations"].as_array().unwrap();
    assert_eq!(confs.len(), 20);
    assert!(sel["tour"]["reordered"] == true);
    // Some poses are reached a whole turn away (the UR10's joints but the
    // elbow turn ±2π): the files hold those values, and they still score
    // and calibrate as the pool's.
    assert!(sel["tour"]["turned_poses"].as_u64().unwrap() > 0);
    // The CSV, scored as a file pool: the same ln OI_D. Tolerance: the sums
    // of XᵀX in another order (visiting, not selection) differ by a few
    // ulps of ln det (~ 1e-14 here).
    let score = json_of(&[
        "score",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        &format!("file:{}", csv.display()),
        "--json",
    ]);
    let (a, b) = (
        sel["ln_oid"].as_f64().unwrap(),
        score["ln_oid"].as_f64().unwrap(),
    );
    assert!((a - b).abs() <= 1e-12, "{a} vs {b}");
    // The CSV lists the poses in visiting order with their ids.
    let text = std::fs::read_to_string(&csv).unwrap();
    let ids: Vec<u64> = text
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
        .collect();
    let visit: Vec<u64> = confs.iter().map(|c| c["id"].as_u64().unwrap()).collect();
    assert_eq!(ids, visit);
    // The JSON design names its joints; YAML and JSON calibrate alike.
    let dj: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(dj["joint_names"], sel["joint_names"]);
    let cal = |p: &PathBuf| {
        let mut v = json_of(&[
            "calibrate",
            "--robot",
            UR10,
            "--tip",
            "wrist_3_link",
            "--design",
            p.to_str().unwrap(),
            "--trials",
            "3",
            "--seed",
            "5",
            "--json",
        ]);
        v.as_object_mut()
            .unwrap()
            .retain(|k, _| !k.contains("design") && !k.contains("seconds"));
        v
    };
    // Wall-clock times aside, the same simulated result.
    let (cy, cj) = (cal(&yaml), cal(&json));
    for (k, v) in cj.as_object().unwrap() {
        assert_eq!(
            &cy[k], v,
            "calibrate's '{k}' differs between .yaml and .json"
        );
    }
    assert_eq!(cy.as_object().unwrap().len(), cj.as_object().unwrap().len());
    // A design file is accepted as --existing.
    let ext = json_of(&[
        "select",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        "random",
        "--count",
        "500",
        "--n",
        "5",
        "--starts",
        "1",
        "--ils",
        "0",
        "--existing",
        json.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(ext["existing"]["poses"], 20);
    let ext = json_of(&[
        "select",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        "random",
        "--count",
        "500",
        "--n",
        "5",
        "--starts",
        "1",
        "--ils",
        "0",
        "--existing",
        yaml.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(ext["existing"]["poses"], 20);
}

#[test]
fn bad_operator_inputs_are_refused_by_name() {
    let d = scratch("bad");
    fails_with(
        &[
            "select",
            "--n",
            "5",
            "--out",
            d.join("d.txt").to_str().unwrap(),
        ],
        ".yaml",
    );
    fails_with(
        &[
            "select",
            "--robot",
            UR10,
            "--tip",
            "wrist_3_link",
            "--n",
            "5",
            "--home",
            "0,0,0",
        ],
        "3 joint values, the robot has 6 joints",
    );
    fails_with(
        &[
            "pool",
            "--robot",
            PANDA,
            "--tip",
            "panda_hand_tcp",
            "--margin",
            "90",
        ],
        "joint 4 'panda_joint4'",
    );
    // A design whose joint the robot does not have.
    let sel = d.join("d.json");
    ur10_select(sel.to_str().unwrap(), &["--order", "none"]);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sel).unwrap()).unwrap();
    v["joint_names"][2] = "no_such_joint".into();
    let bad = d.join("bad.json");
    std::fs::write(&bad, v.to_string()).unwrap();
    fails_with(
        &["score", "--design", bad.to_str().unwrap()],
        "no_such_joint",
    );
}
