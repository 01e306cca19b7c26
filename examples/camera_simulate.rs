//! Simulates a camera calibration's input files: a UR5 (fixtures/ur5.urdf)
//! whose identifiable joint-origin parameters are off by 0.5–2 mm and
//! 0.05–0.3°, a fixed camera 1.3 m away (eye-to-hand) seeing a 6 × 8
//! checkerboard of 25 mm squares on the flange, pixels with σ 0.3 px, 40
//! configurations where the whole board is seen at most 60° off its face.
//!
//! Writes `fixtures/camera/`: `camera_info.yaml` (ROS), `board.yaml`,
//! `ur5_eye_to_hand.csv`, and prints the true placements and the start
//! placements to give `calibrate` (2 cm and about 2° off).
//!
//! `cargo run --example camera_simulate`

use activecal::identify::camera::camera_robot;
use activecal::identify::camera::simulate::simulate_observations;
use activecal::io::camera_observations::observations_csv;
use activecal::io::camera_target::Target;
use activecal::kinematics::Evaluator;
use activecal::measure::camera::{CameraSensor, Mounting};
use activecal::model::Symbol;
use activecal::observability::generic_configurations;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::RngExt as _;

const CAMERA_INFO: &str = "image_width: 1280
image_height: 960
camera_name: cell_camera
camera_matrix:
  rows: 3
  cols: 3
  data: [1000.0, 0.0, 640.0, 0.0, 1000.0, 480.0, 0.0, 0.0, 1.0]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.08, 0.04, 0.0005, -0.0003, -0.01]
";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let intrinsics =
        activecal::io::camera_info::parse_camera_info(CAMERA_INFO, "camera_info.yaml")?;
    let target = Target::checkerboard(6, 8, 0.025);
    let robot = camera_robot(&activecal::io::load_robot("fixtures/ur5.urdf")?)?;
    let mut rng = activecal::identify::trial_rng(41, 0);
    let mut truth = robot.nominal.clone();
    for &u in &robot.unknowns {
        let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
        let size = match u.symbol {
            Symbol::A | Symbol::D => 1e-3 * (0.5 + 1.5 * rng.random::<f64>()),
            _ => (0.05 + 0.25 * rng.random::<f64>()).to_radians(),
        };
        truth.set(u, truth.get(u) + sign * size);
    }
    let eye = Vector3::new(1.2, 0.6, 0.9);
    let z = (Vector3::new(0.3, 0.1, 0.3) - eye).normalize();
    let x = z.cross(&Vector3::z()).normalize();
    let r = nalgebra::Rotation3::from_basis_unchecked(&[x, z.cross(&x), z]);
    let camera = Isometry3::from_parts(eye.into(), UnitQuaternion::from_rotation_matrix(&r));
    let board = Isometry3::from_parts(
        Translation3::new(0.004, -0.003, 0.02),
        UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.03),
    ) * Translation3::from(-target.centroid());
    let sensor = CameraSensor::new(
        intrinsics.clone(),
        Mounting::EyeToHand,
        target.points.clone(),
        &camera,
        &board,
    );
    let own = CameraSensor::start_own(&camera, &board);
    let mut ev = Evaluator::new(&robot, &truth);
    let qs: Vec<Vec<f64>> = generic_configurations(&robot, 40_000, 41)
        .into_iter()
        .filter(|q| {
            let v = sensor.view(&ev.end_frame(q), &own, 20.0);
            v.seen == target.points.len()
                && v.angle < 60f64.to_radians()
                && (0.3..2.0).contains(&v.distance)
        })
        .take(40)
        .collect();
    let mut noise = activecal::identify::trial_rng(41, 1);
    let obs = simulate_observations(&robot, &truth, &sensor, &own, &qs, 0.3, 0.0, &mut noise);
    std::fs::create_dir_all("fixtures/camera")?;
    std::fs::write("fixtures/camera/camera_info.yaml", CAMERA_INFO)?;
    std::fs::write(
        "fixtures/camera/board.yaml",
        "# A 6 × 8 checkerboard (inner corners) of 25 mm squares.\ncheckerboard: {rows: 6, cols: 8, square: 0.025}\n",
    )?;
    std::fs::write(
        "fixtures/camera/ur5_eye_to_hand.csv",
        observations_csv(&obs, &robot, &target),
    )?;
    let off = Isometry3::from_parts(
        Translation3::new(0.02, -0.015, 0.01),
        UnitQuaternion::from_euler_angles(0.03, -0.02, 0.025),
    );
    let show = |name: &str, t: &Isometry3<f64>| {
        let (r, p, y) = t.rotation.euler_angles();
        let v = t.translation.vector;
        println!(
            "{name}: {:.4},{:.4},{:.4},{r:.4},{p:.4},{y:.4}",
            v.x, v.y, v.z
        );
    };
    show("true camera", &camera);
    show("true target", &board);
    show("start camera (--camera-pose)", &(camera * off));
    show("start target (--target-pose)", &(board * off.inverse()));
    println!("{} poses, {} points seen", obs.qs.len(), obs.n_seen());
    Ok(())
}
