//! `select --existing`: new poses chosen on top of poses already measured
//! (the first half of FIGAROH's UR10 data), with the D-efficiency reported
//! against the prior-aware bound, recomputed here independently.

use crate::common;

use activecal::model::ParamSet;
use common::{fails_with, json_of};
use std::path::{Path, PathBuf};

const UR10: &str = "fixtures/figaroh/ur10_robot.urdf:pose";
const UR10_CSV: &str = "fixtures/figaroh/ur10_full_pose.csv";

fn scratch(name: &str) -> PathBuf {
    common::scratch_dir("cli-existing", name)
}

/// The header and the first 12 of the 23 data rows.
fn first_half(dir: &Path) -> PathBuf {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(UR10_CSV)).unwrap();
    let half: Vec<&str> = text.lines().take(13).collect();
    let p = dir.join("ur10_first_half.csv");
    std::fs::write(&p, half.join("\n") + "\n").unwrap();
    p
}

fn ln_det(m: faer::MatRef<'_, f64>) -> f64 {
    let l = m.llt(faer::Side::Lower).expect("positive definite");
    (0..m.nrows()).map(|i| 2.0 * l.L()[(i, i)].ln()).sum()
}

#[test]
fn ur10_new_poses_on_top_of_the_first_half() {
    let d = scratch("ur10");
    let half = first_half(&d);
    let design = d.join("design.json");
    let args = [
        "select",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        "random",
        "--count",
        "2048",
        "--pool-seed",
        "1",
        "--n",
        "8",
        "--existing",
        half.to_str().unwrap(),
        "--gap",
        "--gap-solver",
        "newton",
        "--out",
        design.to_str().unwrap(),
        "--json",
    ];
    let v = json_of(&args);
    let ex = &v["existing"];
    assert_eq!(ex["poses"], 12);
    assert_eq!(ex["rank"], 30);
    assert!(ex["notes"].to_string().contains("phix1"));
    // Recompute ln det(M0 + XᵀX) from the design file's joint values.
    let stored: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&design).unwrap()).unwrap();
    let qs = |v: &serde_json::Value| -> Vec<Vec<f64>> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|q| {
                q.as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect()
            })
            .collect()
    };
    let new_q = qs(&stored["q"]);
    let old_q = qs(&stored["existing"]["q"]);
    assert_eq!(old_q.len(), 12);
    // The design's robot with its chain (stored as its own field).
    let file: activecal::io::design::DesignFile = serde_json::from_value(stored.clone()).unwrap();
    let robot = file.robot_ref().unwrap().load().unwrap().robot;
    let all: Vec<Vec<f64>> = old_q.iter().chain(&new_q).cloned().collect();
    let x = activecal::blocks::jacobian_of(
        &robot,
        robot.params(ParamSet::Nominal),
        all.len(),
        |k, q| {
            q.copy_from_slice(&all[k]);
        },
    );
    let m = x.information(&(0..all.len()).collect::<Vec<_>>());
    let ln = ln_det(m.as_ref());
    let reported = v["ln_oid"].as_f64().unwrap();
    // Same rows, other summation order: rounding of a p = 30 Cholesky.
    assert!(
        (reported - ln).abs() < 1e-8 * ln.abs(),
        "{reported} vs {ln}"
    );
    let m0 = x.information(&(0..12).collect::<Vec<_>>());
    let gain = v["ln_gain"].as_f64().unwrap();
    assert!((gain - (ln - ln_det(m0.as_ref()))).abs() < 1e-8 * ln.abs());
    assert!(gain > 0.0);
    // The D-efficiency is against the prior-aware bound: exp((ln − bound)/p).
    let l10_bound = v["log10_bound"].as_f64().unwrap();
    let eff = v["d_efficiency"].as_f64().unwrap();
    let expect = ((reported - l10_bound * std::f64::consts::LN_10) / 30.0).exp();
    assert!((eff - expect).abs() < 1e-9, "{eff} vs {expect}");
    assert!(eff > 0.0 && eff <= 1.0, "{eff}");
    // That bound is above the bound of the pool alone: M0 only adds.
    let plain = json_of(&[
        "bound",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        "random",
        "--count",
        "2048",
        "--pool-seed",
        "1",
        "--n",
        "8",
        "--solver",
        "newton",
        "--json",
    ]);
    let with = json_of(&[
        "bound",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        "random",
        "--count",
        "2048",
        "--pool-seed",
        "1",
        "--n",
        "8",
        "--solver",
        "newton",
        "--existing",
        half.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(with["with_prior"], true);
    assert_eq!(plain["with_prior"], false);
    assert!((with["log10_bound"].as_f64().unwrap() - l10_bound).abs() < 1e-6);
    assert!(with["ln_bound"].as_f64().unwrap() > plain["ln_bound"].as_f64().unwrap());
    // `gap` on the design file scores it with the stored existing poses,
    // without the CSV.
    std::fs::remove_file(&half).unwrap();
    let g = json_of(&[
        "gap",
        "--design",
        design.to_str().unwrap(),
        "--solver",
        "newton",
        "--json",
    ]);
    assert!((g["ln_oid"].as_f64().unwrap() - reported).abs() < 1e-8 * ln.abs());
    assert!((g["d_efficiency"].as_f64().unwrap() - eff).abs() < 1e-6);
    assert_eq!(g["existing"]["poses"], 12);
    // `calibrate --design` simulates the existing poses and the new ones,
    // in that order, at their stored joint values.
    let saved = d.join("measured.json");
    let _ = json_of(&[
        "calibrate",
        "--robot",
        &format!("{UR10}#tip=wrist_3_link"),
        "--design",
        design.to_str().unwrap(),
        "--save-measurements",
        saved.to_str().unwrap(),
        "--json",
    ]);
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&saved).unwrap()).unwrap();
    let measured = qs(&m["qs"]);
    assert_eq!(
        measured.len(),
        12 + 8,
        "existing and new poses are measured"
    );
    assert_eq!(&measured[..12], &old_q[..]);
    assert_eq!(&measured[12..], &new_q[..]);
}

#[test]
fn existing_measurement_files_and_fewer_rows_than_unknowns() {
    let d = scratch("measurements");
    // A measurement file as `calibrate --save-measurements` writes it.
    let design = d.join("design.json");
    let meas = d.join("m.json");
    json_of(&[
        "select",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        "sobol",
        "--count",
        "256",
        "--n",
        "6",
        "--out",
        design.to_str().unwrap(),
        "--json",
    ]);
    json_of(&[
        "calibrate",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--design",
        design.to_str().unwrap(),
        "--validation",
        "5",
        "--save-measurements",
        meas.to_str().unwrap(),
        "--json",
    ]);
    // Two new poses (12 rows) cannot fix 30 unknowns alone; on top of six
    // measured ones they can.
    let v = json_of(&[
        "select",
        "--robot",
        UR10,
        "--tip",
        "wrist_3_link",
        "--pool",
        "sobol",
        "--count",
        "256",
        "--pool-seed",
        "5",
        "--n",
        "2",
        "--existing",
        meas.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(v["existing"]["poses"], 6);
    assert!(v["existing"]["notes"].to_string().contains("points"));
    assert_eq!(v["ln_oid_new_only"], serde_json::Value::Null);
    assert!(v["ln_gain"].as_f64().unwrap() > 0.0);
    fails_with(
        &[
            "select",
            "--robot",
            UR10,
            "--tip",
            "wrist_3_link",
            "--pool",
            "sobol",
            "--count",
            "256",
            "--n",
            "2",
        ],
        "fewer than the 30 unknowns",
    );
    let bad = d.join("bad.csv");
    std::fs::write(
        &bad,
        "shoulder_pan_joint,shoulder_lift_joint,elbow_joint,wrist_1_joint,wrist_2_joint,wrist_3_joint\n0,0,9,0,0,0\n",
    )
    .unwrap();
    fails_with(
        &[
            "select",
            "--robot",
            UR10,
            "--tip",
            "wrist_3_link",
            "--pool",
            "sobol",
            "--count",
            "64",
            "--n",
            "6",
            "--existing",
            bad.to_str().unwrap(),
        ],
        "line 2, column 'elbow_joint'",
    );
}
