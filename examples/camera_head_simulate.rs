//! Simulates a head camera's calibration input: FIGAROH's TIAGo
//! (fixtures/figaroh/tiago.urdf) whose every head, torso and arm joint
//! origin is off by 0.5–2 mm along a random direction and 0.05–0.3° about
//! a random axis (written into the URDF text), its head camera (the
//! Xtion's RGB optical frame on `head_2_link`, 640 × 480) seeing a 5 × 7
//! checkerboard of 20 mm squares 8 cm past `arm_tool_link`, pixels with
//! σ 0.3 px, 40 configurations of the head and the arm (and a random
//! torso lift, which the camera cannot see) where the nominal head sees
//! the whole board at least 20 px inside the image, at most 60° off its
//! face, 0.25–1.5 m away.
//!
//! Writes `fixtures/camera/`: `tiago_xtion.yaml` (ROS camera_info),
//! `tiago_board.yaml`, `tiago_head.csv` (every joint: head, torso, arm),
//! and prints the placements to give `calibrate` (2 cm and about 2° off
//! the truth).
//!
//! `cargo run --example camera_head_simulate`

use activecal::identify::camera::simulate::simulate_observations;
use activecal::io::camera_observations::observations_csv;
use activecal::io::camera_target::Target;
use activecal::io::urdf::{UrdfOptions, parse};
use activecal::io::urdf_branch::camera_branch;
use activecal::measure::camera::{CameraSensor, Mounting};
use activecal::observability::generic_configurations;
use activecal::pool::camera_view::CameraView;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::RngExt as _;
use std::f64::consts::FRAC_PI_2;

const URDF: &str = "fixtures/figaroh/tiago.urdf";

const CAMERA_INFO: &str = "image_width: 640
image_height: 480
camera_name: xtion_rgb
camera_matrix:
  rows: 3
  cols: 3
  data: [525.0, 0.0, 319.5, 0.0, 525.0, 239.5, 0.0, 0.0, 1.0]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0.03, -0.08, 0.0002, -0.0001, 0.0]
";

fn iso(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// The URDF text with the head's, the torso's and the arm's joint origins
/// perturbed (see the module documentation).
fn perturbed(text: &str) -> Result<String, Box<dyn std::error::Error>> {
    let doc = roxmltree::Document::parse(text)?;
    let mut rng = activecal::identify::trial_rng(41, 2);
    let mut unit = || {
        let v = Vector3::from_fn(|_, _| rng.random::<f64>() - 0.5);
        (v.normalize(), rng.random::<f64>())
    };
    let mut origins = Vec::new();
    for j in doc
        .root_element()
        .children()
        .filter(|c| c.has_tag_name("joint"))
    {
        let name = j.attribute("name").unwrap_or_default();
        let arm = name.starts_with("arm_") && name.ends_with("_joint");
        if !(arm || name.starts_with("head_") || name == "torso_lift_joint") {
            continue;
        }
        let o = j.children().find(|c| c.has_tag_name("origin"));
        let nums = |a: &str| -> [f64; 3] {
            let v: Vec<f64> = o
                .and_then(|o| o.attribute(a))
                .map(|s| {
                    s.split_whitespace()
                        .filter_map(|x| x.parse().ok())
                        .collect()
                })
                .unwrap_or_default();
            [0, 1, 2].map(|k| v.get(k).copied().unwrap_or(0.0))
        };
        let ((d, s), (a, r)) = (unit(), unit());
        let change = Isometry3::new(
            d * 1e-3 * (0.5 + 1.5 * s),
            a * (0.05 + 0.25 * r).to_radians(),
        );
        origins.push((name.to_string(), iso(nums("xyz"), nums("rpy")) * change));
    }
    Ok(activecal::io::urdf_edit::with_origins(
        text, URDF, &origins,
    )?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let intrinsics =
        activecal::io::camera_info::parse_camera_info(CAMERA_INFO, "tiago_xtion.yaml")?;
    let target = Target::checkerboard(5, 7, 0.02);
    let text = std::fs::read_to_string(URDF)?;
    let opts = UrdfOptions {
        tip: Some("arm_tool_link".into()),
        perturb_real: false,
        ..UrdfOptions::default()
    };
    let nominal = camera_branch(&parse(&text, URDF, &opts)?, "head_2_link")?;
    let truth = camera_branch(&parse(&perturbed(&text)?, URDF, &opts)?, "head_2_link")?;
    let camera = iso([0.0908, 0.08, 0.0], [-FRAC_PI_2, 0.0, 0.0])
        * iso([0.0, 0.022, 0.0], [0.0; 3])
        * iso([0.0; 3], [-FRAC_PI_2, 0.0, -FRAC_PI_2]);
    let board =
        iso([0.08, 0.0, 0.0], [0.0, FRAC_PI_2, 0.0]) * Translation3::from(-target.centroid());
    let six = |t: &Isometry3<f64>| {
        let (r, p, y) = t.rotation.euler_angles();
        let v = t.translation.vector;
        [v.x, v.y, v.z, r, p, y]
    };
    let view = CameraView {
        intrinsics: intrinsics.clone(),
        mounting: Mounting::EyeToHand,
        points: target.points.iter().map(|p| [p.x, p.y, p.z]).collect(),
        face: target.face.into(),
        camera: six(&camera),
        target: six(&board),
        min_fraction: 1.0,
        margin_px: 20.0,
        max_view_angle: 60f64.to_radians(),
        distance: [0.25, 1.5],
    };
    let qs: Vec<Vec<f64>> = generic_configurations(&nominal, 40_000, 41)
        .into_iter()
        .filter(|q| view.keeps(&nominal, &nominal.nominal, q))
        .take(40)
        .collect();
    let sensor = CameraSensor::new(
        intrinsics,
        Mounting::EyeToHand,
        target.points.clone(),
        &camera,
        &board,
    );
    let own = CameraSensor::start_own(&camera, &board);
    let mut noise = activecal::identify::trial_rng(41, 1);
    let obs = simulate_observations(
        &truth,
        &truth.nominal,
        &sensor,
        &own,
        &qs,
        0.3,
        0.0,
        &mut noise,
    );
    // The file a robot's logger writes: every joint, the torso's lift too
    // (random: the head camera sees the arm's tip relative to the head).
    let csv = observations_csv(&obs, &nominal, &target);
    let mut lift = activecal::identify::trial_rng(41, 3);
    let mut lifts = std::collections::HashMap::new();
    let mut out = String::new();
    for (k, line) in csv.lines().enumerate() {
        let (pose, rest) = line.split_once(',').unwrap_or((line, ""));
        let torso = if k == 0 {
            "torso_lift_joint".to_string()
        } else {
            let v = *lifts
                .entry(pose.to_string())
                .or_insert_with(|| 0.35 * lift.random::<f64>());
            format!("{v:.6}")
        };
        out += &format!("{pose},{torso},{rest}\n");
    }
    std::fs::create_dir_all("fixtures/camera")?;
    std::fs::write("fixtures/camera/tiago_xtion.yaml", CAMERA_INFO)?;
    std::fs::write(
        "fixtures/camera/tiago_board.yaml",
        "# A 5 × 7 checkerboard (inner corners) of 20 mm squares.\ncheckerboard: {rows: 5, cols: 7, square: 0.02}\n",
    )?;
    std::fs::write("fixtures/camera/tiago_head.csv", out)?;
    let off = Isometry3::from_parts(
        Translation3::new(0.02, -0.015, 0.01),
        UnitQuaternion::from_euler_angles(0.03, -0.02, 0.025),
    );
    let show = |name: &str, t: &Isometry3<f64>| {
        let v = six(t);
        println!(
            "{name}: {:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
            v[0], v[1], v[2], v[3], v[4], v[5]
        );
    };
    show("true camera", &camera);
    show("true target", &board);
    show("start camera (--camera-pose)", &(camera * off));
    show("start target (--target-pose)", &(board * off.inverse()));
    println!("{} poses, {} points seen", obs.qs.len(), obs.n_seen());
    Ok(())
}
