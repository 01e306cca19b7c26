//! The line of sight of a camera pool (`activecal::pool::line_of_sight`)
//! on example-robot-data's Panda: a camera placed so that the fourth link
//! stands between it and the board on the hand is refused; the same board
//! seen from the other side is kept.

use activecal::collision::CollisionSpec;
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_target::read_target;
use activecal::io::{UrdfChain, load_robot};
use activecal::kinematics::Evaluator;
use activecal::measure::camera::Mounting;
use activecal::pool::camera_view::CameraView;
use activecal::pool::line_of_sight::{LineOfSight, rays};
use nalgebra::{Point3, UnitQuaternion, Vector3};

const PANDA: &str = "fixtures/example-robot-data/panda.urdf";

/// A view of the board 2 cm past the TCP from a camera at `eye` (base
/// frame) looking at `at`.
fn view_from(eye: &Point3<f64>, at: &Point3<f64>) -> CameraView {
    let r = UnitQuaternion::face_towards(&(at - eye), &Vector3::z());
    let (roll, pitch, yaw) = r.euler_angles();
    CameraView {
        intrinsics: read_camera_info(std::path::Path::new("fixtures/camera/camera_info.yaml"))
            .unwrap(),
        mounting: Mounting::EyeToHand,
        points: read_target(std::path::Path::new("fixtures/camera/board.yaml"))
            .unwrap()
            .points
            .iter()
            .map(|p| [p.x, p.y, p.z])
            .collect(),
        face: [0.0, 0.0, 1.0],
        camera: [eye.x, eye.y, eye.z, roll, pitch, yaw],
        target: [-0.0853, 0.0568, 0.02, std::f64::consts::PI, 0.0, 0.03],
        min_fraction: 1.0,
        margin_px: 0.0,
        max_view_angle: std::f64::consts::FRAC_PI_2,
        distance: [0.1, 5.0],
    }
}

/// The board's centroid in the base frame at `q`, with its points.
fn centroid(v: &CameraView, robot: &activecal::model::Robot, q: &[f64]) -> Point3<f64> {
    let (_, pts, _) = rays(v, robot, &robot.nominal, q);
    Point3::from(pts.iter().map(|p| p.coords).sum::<Vector3<f64>>() / pts.len() as f64)
}

#[test]
fn a_link_between_camera_and_board_removes_the_configuration() {
    let robot = load_robot(&format!("{PANDA}#tip=panda_hand_tcp")).unwrap();
    let upper = load_robot(&format!("{PANDA}#tip=panda_link4")).unwrap();
    let chain = UrdfChain::of(&robot).unwrap();
    let sight = LineOfSight::new(CollisionSpec {
        urdf: chain.file,
        text: Some(chain.text),
        joints: chain.joints,
        lock: chain.lock,
        base: Some(chain.base),
        ..CollisionSpec::default()
    });
    let q = [0.3, 0.4, 0.2, -2.0, 0.1, 1.8, 0.5];
    let probe = view_from(&Point3::new(1.0, 0.0, 1.0), &Point3::origin());
    let board = centroid(&probe, &robot, &q);
    // The fourth link's frame (the elbow, inside its mesh) at q.
    let elbow = Point3::from(
        Evaluator::new(&upper, &upper.nominal)
            .end_frame(&q[..4])
            .position,
    );
    let away = (elbow - board).normalize();
    // Behind the elbow as seen from the board: the elbow blocks the
    // central rays.
    let blocked = view_from(&(elbow + 0.6 * away), &board);
    // Every point inside the image (the test is of the line of sight, not
    // of the framing), the centroid's ray through the elbow's frame.
    let (_, _, inside) = rays(&blocked, &robot, &robot.nominal, &q);
    assert!(inside.iter().all(|i| *i));
    let in_sight = sight.seen_in_sight(&blocked, &robot, &robot.nominal, &q);
    let free = in_sight.iter().filter(|s| **s).count();
    assert!(
        free < in_sight.len(),
        "{free} of {} in sight",
        in_sight.len()
    );
    assert!(!sight.keeps(&blocked, &robot, &robot.nominal, &q));
    // The board seen face on, 0.8 m out along its normal (against its z
    // axis, which points into it): the hand and the fingers are behind it.
    let e = Evaluator::new(&robot, &robot.nominal).end_frame(&q);
    let normal = e.rotation
        * UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.03)
            .to_rotation_matrix()
            .matrix()
        * Vector3::z();
    let clear = view_from(&(board - 0.8 * normal), &board);
    let (_, _, inside) = rays(&clear, &robot, &robot.nominal, &q);
    assert!(inside.iter().all(|i| *i));
    assert!(sight.keeps(&clear, &robot, &robot.nominal, &q));
}

/// `select --line-of-sight` on the Panda eye-to-hand: the JSON says how
/// many seen configurations the line of sight removed, every chosen pose
/// sees all 48 points; `--self-collision` turns it on with the collision
/// filter, whose removals are reported; a built-in robot (no collision
/// geometry) is refused.
#[test]
fn cli_line_of_sight_reports_its_removals_and_refuses_what_it_cannot_check() {
    let base = [
        "select",
        "--robot",
        "fixtures/example-robot-data/panda.urdf#tip=panda_hand_tcp",
        "--camera-info",
        "fixtures/camera/camera_info.yaml",
        "--target",
        "fixtures/camera/board.yaml",
        "--mounting",
        "eye-to-hand",
        "--camera-pose=1.2,0.6,0.9,-2.0985,0,2.0779",
        "--target-pose=-0.0853,0.0568,0.02,3.141592653589793,0,0.03",
        "--image-margin",
        "20",
        "--distance",
        "0.3,2.0",
        "--n",
        "20",
        "--count",
        "2000",
        "--json",
    ];
    let plain = crate::common::json_of(&base);
    assert!(plain["out_of_sight"].is_null() && plain["collision_removed"].is_null());
    let mut args = base.to_vec();
    args.push("--line-of-sight");
    let v = crate::common::json_of(&args);
    let (seen, out) = (
        plain["visible"].as_u64().unwrap(),
        v["out_of_sight"].as_u64().unwrap(),
    );
    assert!(
        out > 0 && v["visible"].as_u64().unwrap() + out == seen,
        "{v}"
    );
    assert!(v["points_seen"].as_array().unwrap().iter().all(|s| s == 48));
    let mut args = base.to_vec();
    args.extend([
        "--self-collision",
        "--srdf",
        "fixtures/example-robot-data/panda.srdf",
    ]);
    let c = crate::common::json_of(&args);
    assert!(c["collision_removed"].as_u64().unwrap() > 0);
    assert!(c["out_of_sight"].as_u64().unwrap() > 0);
    let mut args = base.to_vec();
    args[2] = "ur5";
    args.push("--line-of-sight");
    crate::common::fails_with(&args, "needs a URDF robot with collision geometry");
}
