//! The calibrated robot back in the user's terms (`activecal::frames`): the
//! split into measurement frame, joint origins and tool reproduces the
//! fitted model exactly, through the user's own URDF edited in place; and
//! on synthetic truth (a tracker 3 m away and turned 100°, a tool 5–20 cm
//! off, every joint origin off by 0.5–3 mm and 0.05–0.3°) calibration
//! recovers every frame and origin within 3σ, with no frame leaking into a
//! robot link.

use activecal::data::Measurements;
use activecal::frames::{CalibratedFrames, decompose, uncertainty::sigmas};
use activecal::identify::{LmSettings, identify};
use activecal::io::urdf::{UrdfOptions, parse, remount};
use activecal::io::urdf_edit::with_origins;
use activecal::kinematics::pose;
use activecal::model::source::UrdfSource;
use activecal::model::{MeasurementKind, Robot};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

fn read(path: &str) -> String {
    std::fs::read_to_string(format!("{}/{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

fn import(
    text: &str,
    path: &str,
    tip: &str,
    m: MeasurementKind,
    mount: Isometry3<f64>,
    tool: Isometry3<f64>,
) -> Robot {
    let opts = UrdfOptions {
        tip: Some(tip.into()),
        measurement: m,
        mount,
        tool,
        perturb_real: true,
        ..UrdfOptions::default()
    };
    parse(text, path, &opts).unwrap()
}

fn random_q(robot: &Robot, rng: &mut ChaCha8Rng) -> Vec<f64> {
    robot
        .limits
        .iter()
        .map(|[lo, hi]| lo + (hi - lo) * (0.05 + 0.9 * rng.random::<f64>()))
        .collect()
}

fn src(robot: &Robot) -> &UrdfSource {
    robot.source.as_deref().unwrap()
}

/// The calibrated URDF (the input with only the chain's origins changed),
/// read by urdf_rs and composed with the split's measurement frame and tool,
/// predicts what the fitted model predicts, at 100 random configurations.
fn check_export(path: &str, tip: &str, m: MeasurementKind) {
    let robot = import(
        &read(path),
        path,
        tip,
        m,
        Isometry3::identity(),
        Isometry3::identity(),
    );
    // The "real" table: every unknown perturbed, as a calibration finds.
    let table = robot.real.clone();
    let f = decompose(&robot, &table).unwrap();
    let origins: Vec<(String, Isometry3<f64>)> = f
        .joints
        .iter()
        .map(|j| (j.name.clone(), j.calibrated))
        .collect();
    let s = src(&robot);
    let text = with_origins(&s.text, path, &origins).unwrap();
    let u = urdf_rs::read_from_string(&text).unwrap();
    let locked: HashMap<String, f64> = s
        .joints
        .iter()
        .filter_map(|j| j.locked.map(|v| (j.name.clone(), v)))
        .collect();
    let names = s.driven_names();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut worst: f64 = 0.0;
    for _ in 0..100 {
        let q = random_q(&robot, &mut rng);
        let mut qm = locked.clone();
        qm.extend(names.iter().cloned().zip(q.iter().copied()));
        let direct = f.measurement * common::urdf_fk(&u, &s.base, &s.tip, &qm) * f.tool;
        let (r, p) = pose(&robot, &table, &q);
        worst = worst.max((direct.translation.vector - p).norm());
        if m == MeasurementKind::Pose {
            let dr = (direct.rotation.to_rotation_matrix().matrix() - r)
                .abs()
                .max();
            worst = worst.max(dr);
        }
    }
    // Two chains of ~20 products of metre-size transforms, and rpy written
    // as shortest round-trip decimals: rounding is ~1e-14 m; 1e-9 m (the
    // issue's bar) is far above it and far below any modelling error.
    assert!(worst < 1e-9, "{path}: largest difference {worst:e}");
}

#[test]
fn the_exported_urdf_and_frames_reproduce_the_fitted_model() {
    check_export(
        "fixtures/figaroh/ur10_robot.urdf",
        "wrist_3_link",
        MeasurementKind::Pose,
    );
    check_export(
        "fixtures/example-robot-data/panda.urdf",
        "panda_hand_tcp",
        MeasurementKind::Pose,
    );
    check_export("fixtures/ur5.urdf", "target", MeasurementKind::Point);
    check_export("fixtures/puma560.urdf", "tip", MeasurementKind::Point);
}

#[test]
fn only_the_chains_origins_change_in_the_exported_urdf() {
    let path = "fixtures/figaroh/tiago.urdf";
    let text = read(path);
    let opts = UrdfOptions {
        tip: Some("arm_tool_link".into()),
        base: Some("torso_lift_link".into()),
        ..UrdfOptions::default()
    };
    let robot = parse(&text, path, &opts).unwrap();
    let f = decompose(&robot, &robot.real).unwrap();
    let origins: Vec<(String, Isometry3<f64>)> = f
        .joints
        .iter()
        .map(|j| (j.name.clone(), j.calibrated))
        .collect();
    let out = with_origins(&text, path, &origins).unwrap();
    // Remove every origin of the chain's joints from both texts: what is
    // left must be byte for byte the same.
    let strip = |t: &str| -> String {
        let doc = roxmltree::Document::parse(t).unwrap();
        let mut ranges: Vec<std::ops::Range<usize>> = doc
            .descendants()
            .filter(|n| n.tag_name().name() == "joint")
            .filter(|n| {
                origins
                    .iter()
                    .any(|(name, _)| n.attribute("name") == Some(name))
            })
            .filter_map(|n| n.children().find(|c| c.tag_name().name() == "origin"))
            .map(|o| o.range())
            .collect();
        ranges.sort_by_key(|r| std::cmp::Reverse(r.start));
        let mut s = t.to_string();
        for r in ranges {
            s.replace_range(r, "");
        }
        s
    };
    assert!(text.len() > 10_000, "the TIAGo URDF has 60+ links");
    assert_eq!(strip(&text), strip(&out));
    assert_ne!(text, out);
}

/// A truth: the nominal URDF with every driven joint's origin moved by
/// 0.5–3 mm and 0.05–0.3° per component (random signs).
fn perturbed(s: &UrdfSource, path: &str, rng: &mut ChaCha8Rng) -> String {
    let mut draw = |lo: f64, hi: f64| {
        let v = lo + (hi - lo) * rng.random::<f64>();
        if rng.random::<bool>() { v } else { -v }
    };
    let origins: Vec<(String, Isometry3<f64>)> = s
        .joints
        .iter()
        .filter(|j| j.is_driven())
        .map(|j| {
            let dt = Vector3::new(draw(5e-4, 3e-3), draw(5e-4, 3e-3), draw(5e-4, 3e-3));
            let dr = Vector3::new(draw(0.05, 0.3), draw(0.05, 0.3), draw(0.05, 0.3))
                .map(f64::to_radians);
            let d =
                Isometry3::from_parts(Translation3::from(dt), UnitQuaternion::from_scaled_axis(dr));
            (j.name.clone(), j.origin * d)
        })
        .collect();
    with_origins(&s.text, path, &origins).unwrap()
}

/// Points (and orientations) of `robot` at `qs`, with noise `sigma` (metres;
/// orientation noise σ rad about random axes).
fn measure(robot: &Robot, qs: &[Vec<f64>], sigma: f64, rng: &mut ChaCha8Rng) -> Measurements {
    let mut gauss = || {
        // Box–Muller.
        let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let mut points = Vec::new();
    let mut rots = Vec::new();
    let offsets = robot.nominal.markers.clone();
    for q in qs {
        let (r, p) = pose(robot, &robot.nominal, q);
        for o in &offsets {
            let m = p + r * Vector3::from(*o);
            points.push([
                m.x + sigma * gauss(),
                m.y + sigma * gauss(),
                m.z + sigma * gauss(),
            ]);
        }
        if !offsets.is_empty() {
            continue;
        }
        points.push([
            p.x + sigma * gauss(),
            p.y + sigma * gauss(),
            p.z + sigma * gauss(),
        ]);
        if robot.measurement == MeasurementKind::Pose {
            let e =
                UnitQuaternion::from_scaled_axis(Vector3::new(gauss(), gauss(), gauss()) * sigma);
            let rm = e.to_rotation_matrix().matrix() * r;
            rots.push(std::array::from_fn(|i| std::array::from_fn(|j| rm[(i, j)])));
        }
    }
    let m = Measurements::unchecked(qs.to_vec(), offsets.len().max(1), points, rots);
    m.check(robot).unwrap();
    m
}

/// Every figure of the split `f` against `truth`: (name, difference) of the
/// translations and of the rotation (a rotation vector in the frame's own
/// axes, as the σ are).
fn differences(f: &CalibratedFrames, truth: &CalibratedFrames) -> Vec<(String, f64)> {
    let mut v = Vec::new();
    let mut frame = |name: &str, t: &Isometry3<f64>, w: &Isometry3<f64>| {
        for (i, x) in (t.translation.vector - w.translation.vector)
            .iter()
            .enumerate()
        {
            v.push((format!("{name}.xyz[{i}]"), *x));
        }
        for (i, x) in (w.rotation.inverse() * t.rotation)
            .scaled_axis()
            .iter()
            .enumerate()
        {
            v.push((format!("{name}.rot[{i}]"), *x));
        }
    };
    frame("measurement", &f.measurement, &truth.measurement);
    frame("tool", &f.tool, &truth.tool);
    for (j, w) in f.joints.iter().zip(&truth.joints) {
        frame(&j.name, &j.calibrated, &w.calibrated);
    }
    for (k, (m, w)) in f.markers.iter().zip(&truth.markers).enumerate() {
        for i in 0..3 {
            v.push((format!("marker{}.xyz[{i}]", k + 1), m[i] - w[i]));
        }
    }
    v
}

fn sigma_list(s: &activecal::frames::uncertainty::FramesSigma) -> Vec<f64> {
    let mut v = Vec::new();
    for f in std::iter::once(&s.measurement)
        .chain(std::iter::once(&s.tool))
        .chain(&s.joints)
    {
        v.extend(f.xyz);
        v.extend(f.rot);
    }
    for m in &s.markers {
        v.extend(m);
    }
    v
}

fn synthetic_truth(path: &str, tip: &str, m: MeasurementKind, base: Option<&str>) {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let kind = if m.markers() > 0 {
        MeasurementKind::Point
    } else {
        m
    };
    let load = |text: &str, mount, tool| {
        let opts = UrdfOptions {
            tip: Some(tip.into()),
            base: base.map(str::to_string),
            measurement: kind,
            mount,
            tool,
            ..UrdfOptions::default()
        };
        parse(text, path, &opts).unwrap()
    };
    let nominal = load(&read(path), Isometry3::identity(), Isometry3::identity());
    let truth_text = perturbed(src(&nominal), path, &mut rng);
    // The tracker 3 m away, turned 100°; the tool 5–20 cm off and turned 20°.
    let mount = Isometry3::from_parts(
        Translation3::from(Vector3::new(2.0, -2.0, 1.0).normalize() * 3.0),
        UnitQuaternion::from_axis_angle(
            &Unit::new_normalize(Vector3::new(0.3, 0.5, 0.8)),
            100f64.to_radians(),
        ),
    );
    let tool = Isometry3::from_parts(
        Translation3::new(0.05, -0.12, 0.15),
        UnitQuaternion::from_axis_angle(
            &Unit::new_normalize(Vector3::new(1.0, -0.4, 0.2)),
            20f64.to_radians(),
        ),
    );
    // Markers 5–20 cm off the tip link (the tool is then theirs to carry).
    let truth = if m.markers() > 0 {
        let offsets: Vec<[f64; 3]> = (0..m.markers())
            .map(|k| {
                let t = k as f64;
                [0.05 + 0.04 * t, -0.08 + 0.06 * t, 0.12 - 0.05 * t]
            })
            .collect();
        let t = load(&truth_text, mount, Isometry3::identity());
        t.with_markers(&offsets).unwrap()
    } else {
        load(&truth_text, mount, tool)
    };
    let qs: Vec<Vec<f64>> = (0..80).map(|_| random_q(&nominal, &mut rng)).collect();
    let sigma = 5e-5;
    let meas = measure(&truth, &qs, sigma, &mut rng);
    // Start: the nominal robot mounted by the rigid fit of its points.
    let a = activecal::frames::align::measurement_frame(&nominal, &meas).unwrap();
    let lm = LmSettings::builder().max_iterations(500).build().unwrap();
    let mounted = remount(&nominal, a.motion, a.tool).unwrap();
    // The data's sensor (markers: offsets from a first fit), as calibrate.
    let s0 = activecal::identify::for_measurements(&mounted, &meas, &lm).unwrap();
    let start = s0.robot;
    let id = identify(&start, &s0.table, &meas, &lm).unwrap();
    assert!(id.converged(), "{path}: {:?} {:?}", id.status, id.stop);
    eprintln!(
        "{path}: align {:.4} -> {:.4} m; rss {:e}, start rss {:e}, iterations {}",
        a.rms_before, a.rms_after, id.rss, id.initial_rss, id.iterations
    );
    let cal = decompose(&start, &id.table).unwrap();
    let sig = sigmas(&start, &id.table, &id.covariance.as_ref().unwrap().matrix).unwrap();
    // The truth in the same terms: the same model fitted to noise-free data
    // at many poses reproduces the truth exactly (the model spans every
    // identifiable combination), and is split by the same rule.
    let more: Vec<Vec<f64>> = (0..200).map(|_| random_q(&nominal, &mut rng)).collect();
    let exact = measure(&truth, &more, 0.0, &mut rng);
    let id_true = identify(&start, &id.table, &exact, &lm).unwrap();
    assert!(
        id_true.rss < 1e-18,
        "{path}: the truth is not in the model: rss {:e}",
        id_true.rss
    );
    let truth_split = decompose(&start, &id_true.table).unwrap();
    let (diff, s) = (differences(&cal, &truth_split), sigma_list(&sig));
    let mut worst = (0.0, String::new());
    for ((name, d), s) in diff.iter().zip(&s) {
        // A point sensor sees no tool rotation; markers carry the tool.
        let unseen = (m == MeasurementKind::Point && name.starts_with("tool.rot"))
            || (m.markers() > 0 && name.starts_with("tool."));
        if unseen {
            continue;
        }
        let z = d.abs() / s.max(1e-15);
        if z > worst.0 {
            worst = (z, name.clone());
        }
    }
    // Gaussian noise, ~60 figures: each within 3σ (the bar).
    assert!(worst.0 <= 3.0, "{path}: {} off by {:.2}σ", worst.1, worst.0);
    // No frame leaks into a link: every joint origin's change stays of the
    // size of the truth's (≤ 3 mm and 0.3° per component, a few mm after
    // the gauge moves slides along axes), never the decimetres of the
    // measurement frame or tool.
    for j in &cal.joints {
        let dt = (j.calibrated.translation.vector - j.nominal.translation.vector)
            .abs()
            .max();
        let dr = (j.nominal.rotation.inverse() * j.calibrated.rotation).angle();
        assert!(
            dt < 0.01 && dr < 1f64.to_radians(),
            "{path}: {} moved {dt} m, {dr} rad",
            j.name
        );
    }
    // And the frames themselves are found.
    // (Joint 1's origin change, ≤ 0.3° and 3 mm per component, is the
    // measurement frame's in the split: up to 0.52° times joint 1's
    // distance from the base link, the PUMA's 20 m tracker arm included.)
    let lever = cal.joints[0].nominal.translation.vector.norm();
    let off = (cal.measurement.translation.vector - mount.translation.vector).norm();
    assert!(
        off < 0.01 + 0.0091 * lever,
        "{path}: measurement frame {off} m off"
    );
}

#[test]
fn synthetic_truth_is_recovered_within_three_sigma_ur10_full_pose() {
    synthetic_truth(
        "fixtures/figaroh/ur10_robot.urdf",
        "wrist_3_link",
        MeasurementKind::Pose,
        None,
    );
}

#[test]
fn synthetic_truth_is_recovered_within_three_sigma_ur5_full_pose() {
    synthetic_truth("fixtures/ur5.urdf", "target", MeasurementKind::Pose, None);
}

#[test]
fn synthetic_truth_is_recovered_within_three_sigma_puma_points() {
    synthetic_truth("fixtures/puma560.urdf", "tip", MeasurementKind::Point, None);
}

#[test]
fn synthetic_truth_is_recovered_within_three_sigma_tiago_four_markers() {
    synthetic_truth(
        "fixtures/figaroh/tiago.urdf",
        "arm_tool_link",
        MeasurementKind::Markers(4),
        Some("torso_lift_link"),
    );
}

#[test]
fn synthetic_truth_is_recovered_within_three_sigma_panda_points() {
    synthetic_truth(
        "fixtures/example-robot-data/panda.urdf",
        "panda_hand_tcp",
        MeasurementKind::Point,
        None,
    );
}

use crate::common;

/// `calibrate --out cal.urdf --out cal.yaml`, then `evaluate` of the
/// calibrated URDF mounted by `--frames cal.yaml` on the same data: the
/// fitted errors again, with no fitting (the written origins and frames are
/// the fitted model).
#[test]
fn the_written_urdf_and_frames_evaluate_to_the_fitted_errors() {
    let dir = std::env::temp_dir().join(format!("activecal-frames-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (urdf, yaml) = (dir.join("ur10_cal.urdf"), dir.join("ur10_frames.yaml"));
    let data = "fixtures/figaroh/ur10_full_pose.csv";
    let v = common::json_of(&[
        "calibrate",
        "--robot",
        "fixtures/figaroh/ur10_robot.urdf:pose",
        "--tip",
        "wrist_3_link",
        "--measurements",
        data,
        // Every pose kept: `evaluate` below judges the written model on all.
        "--outliers",
        "keep",
        "--out",
        urdf.to_str().unwrap(),
        "--out",
        yaml.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(v["out"].as_array().unwrap().len(), 2);
    // The report's blocks: the frames apart, the joints in URDF terms.
    let f = &v["frames"];
    assert_eq!(f["measurement_frame"]["child"], "world");
    assert_eq!(f["tool"]["parent"], "wrist_3_link");
    assert_eq!(f["joints"].as_object().unwrap().len(), 6);
    let e = common::json_of(&[
        "evaluate",
        "--robot",
        &format!("{}:pose", urdf.display()),
        "--frames",
        yaml.to_str().unwrap(),
        "--measurements",
        data,
        "--json",
    ]);
    let (a, b) = (
        e["residuals"]["position_rms_mm"].as_f64().unwrap(),
        v["residuals"]["position_rms_mm"].as_f64().unwrap(),
    );
    // Shortest round-trip decimals in both files: the same model, to the
    // rounding of re-importing it (1e-9 of a few mm).
    assert!((a - b).abs() < 1e-6, "evaluate {a} mm vs calibrate {b} mm");
    let (a, b) = (
        e["residuals"]["orientation_rms_deg"].as_f64().unwrap(),
        v["residuals"]["orientation_rms_deg"].as_f64().unwrap(),
    );
    assert!((a - b).abs() < 1e-6, "evaluate {a}° vs calibrate {b}°");
    // Read back through the same YAML crate: the numbers are the report's.
    let back: serde_json::Value = serde_json::to_value(
        serde_saphyr::from_str::<serde_json::Value>(&std::fs::read_to_string(&yaml).unwrap())
            .unwrap(),
    )
    .unwrap();
    assert_eq!(
        back["measurement_frame"]["xyz"],
        f["measurement_frame"]["xyz"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}
