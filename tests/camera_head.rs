//! A camera on the robot's own head: FIGAROH's TIAGo, its head camera
//! (`head_2_link`, moved by `head_1_joint` and `head_2_joint` on the
//! torso) seeing a board on the arm's tip (`arm_tool_link`, seven joints
//! on the same torso). One chain from the head to the tip
//! (`activecal::io::urdf_branch`), checked against the URDF tree walked
//! directly; a true TIAGo whose every joint origin (head, torso, arm) is
//! off by 0.5–2 mm and 0.05–0.3° in random directions, written into the
//! URDF text itself, gives the pixels (σ 0.3 px).

use activecal::frames::camera::camera_frames;
use activecal::identify::LmSettings;
use activecal::identify::camera::simulate::simulate_observations;
use activecal::identify::camera::{CameraFit, camera_robot, fit_camera};
use activecal::io::calibrated::{Format, render};
use activecal::io::camera_target::Target;
use activecal::io::urdf::{UrdfOptions, parse};
use activecal::io::urdf_branch::camera_branch;
use activecal::kinematics::Evaluator;
use activecal::measure::camera::{CameraSensor, Mounting};
use activecal::measure::pinhole::Intrinsics;
use activecal::model::{ParamTable, Robot, Symbol};
use activecal::observability::generic_configurations;
use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use rand::RngExt as _;
use std::collections::HashMap;

const URDF: &str = "fixtures/figaroh/tiago.urdf";
const HEAD: &str = "head_2_link";

fn text() -> String {
    std::fs::read_to_string(URDF).unwrap()
}

/// The arm's chain (root to `arm_tool_link`) of URDF `text`, unperturbed.
fn arm(text: &str) -> Robot {
    let opts = UrdfOptions {
        tip: Some("arm_tool_link".into()),
        perturb_real: false,
        ..UrdfOptions::default()
    };
    parse(text, URDF, &opts).unwrap()
}

fn intrinsics() -> Intrinsics {
    // The Xtion's RGB camera, roughly: 640 × 480, 525 px focal length.
    Intrinsics {
        width: 640,
        height: 480,
        fx: 525.0,
        fy: 525.0,
        cx: 319.5,
        cy: 239.5,
        distortion: [0.03, -0.08, 2e-4, -1e-4, 0.0],
    }
}

/// A 5 × 7 board of 20 mm squares.
fn board() -> Target {
    Target::checkerboard(5, 7, 0.02)
}

fn iso(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// The true placements: the RGB optical frame in `head_2_link` as the
/// URDF's fixed xtion joints give it, and the board 8 cm past the tool
/// along its approach axis (x), its face looking back along x.
fn truth_placements() -> (Isometry3<f64>, Isometry3<f64>) {
    use std::f64::consts::FRAC_PI_2;
    let cam = iso([0.0908, 0.08, 0.0], [-FRAC_PI_2, 0.0, 0.0])
        * iso([0.0, 0.022, 0.0], [0.0; 3])
        * iso([0.0; 3], [-FRAC_PI_2, 0.0, -FRAC_PI_2]);
    let c = board().centroid();
    let tgt = iso([0.08, 0.0, 0.0], [0.0, FRAC_PI_2, 0.0]) * Translation3::from(-c);
    (cam, tgt)
}

/// The joints of a URDF by child link: (name, type, parent, origin, axis).
struct Tree(HashMap<String, (String, String, String, Isometry3<f64>, Vector3<f64>)>);

impl Tree {
    fn of(text: &str) -> Tree {
        let doc = roxmltree::Document::parse(text).unwrap();
        let mut m = HashMap::new();
        let nums = |n: Option<roxmltree::Node>, a: &str, d: [f64; 3]| -> [f64; 3] {
            n.and_then(|n| n.attribute(a)).map_or(d, |s| {
                let v: Vec<f64> = s.split_whitespace().map(|x| x.parse().unwrap()).collect();
                [v[0], v[1], v[2]]
            })
        };
        for j in doc.root_element().children().filter(|c| c.has_tag_name("joint")) {
            let child = |tag: &str| j.children().find(|c| c.has_tag_name(tag));
            let link = |tag: &str| child(tag).unwrap().attribute("link").unwrap().to_string();
            let o = child("origin");
            let origin = iso(nums(o, "xyz", [0.0; 3]), nums(o, "rpy", [0.0; 3]));
            let axis = Vector3::from(nums(child("axis"), "xyz", [1.0, 0.0, 0.0]));
            let kind = j.attribute("type").unwrap().to_string();
            m.insert(
                link("child"),
                (j.attribute("name").unwrap().to_string(), kind, link("parent"), origin, axis),
            );
        }
        Tree(m)
    }

    /// The link's pose in the root at joint values `q` (by name; 0 else).
    fn pose(&self, link: &str, q: &HashMap<String, f64>) -> Isometry3<f64> {
        let mut t = Isometry3::identity();
        let mut at = link.to_string();
        while let Some((name, kind, parent, origin, axis)) = self.0.get(&at) {
            let v = q.get(name).copied().unwrap_or(0.0);
            let motion = match kind.as_str() {
                "revolute" | "continuous" => Isometry3::rotation(axis.normalize() * v),
                "prismatic" => Isometry3::translation(axis.x * v, axis.y * v, axis.z * v),
                _ => Isometry3::identity(),
            };
            t = origin * motion * t;
            at = parent.clone();
        }
        t
    }
}

/// The URDF text with every joint origin on the head's and the arm's
/// chains and the torso's off by ±(0.5–2) mm along a random direction and
/// ±(0.05–0.3)° about a random axis, seeded.
fn perturbed_text(seed: u64) -> String {
    let text = text();
    let tree = Tree::of(&text);
    let mut rng = activecal::identify::trial_rng(seed, 7);
    let mut unit = || {
        let v = Vector3::new(
            rng.random::<f64>() - 0.5,
            rng.random::<f64>() - 0.5,
            rng.random::<f64>() - 0.5,
        );
        (v.normalize(), rng.random::<f64>())
    };
    let mut names: Vec<&String> = tree.0.values().map(|j| &j.0).collect();
    names.sort();
    let chosen = |n: &str| n.starts_with("arm_") && n.ends_with("_joint") || n.starts_with("head_") || n == "torso_lift_joint";
    let mut origins = Vec::new();
    for j in tree.0.values().filter(|j| chosen(&j.0)) {
        let (d, s) = unit();
        let (a, r) = unit();
        let dt = d * 1e-3 * (0.5 + 1.5 * s);
        let dr = a * (0.05 + 0.25 * r).to_radians();
        origins.push((j.0.clone(), j.3 * Isometry3::new(dt, dr)));
    }
    origins.sort_by(|a, b| a.0.cmp(&b.0));
    activecal::io::urdf_edit::with_origins(&text, URDF, &origins).unwrap()
}

fn end(robot: &Robot, table: &ParamTable, q: &[f64]) -> Isometry3<f64> {
    let e = Evaluator::new(robot, table).end_frame(q);
    Isometry3::from_parts(
        e.position.into(),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(e.rotation)),
    )
}

/// The head chain, walked from the head to the tip, is the URDF tree:
/// at 200 random configurations (the torso's lift too, which cancels) the
/// tip's pose in `head_2_link` equals the tree's to 1e-12 m and rad.
#[test]
fn the_head_chain_is_the_tree_seen_from_the_head() {
    let text = text();
    let r = camera_branch(&arm(&text), HEAD).unwrap();
    let names = r.source.as_ref().unwrap().driven_names();
    assert_eq!(names[..2], ["head_2_joint", "head_1_joint"], "{names:?}");
    assert_eq!(names.len(), 9, "{names:?}");
    // 9 revolute joints and a whole frame seen: 4·9 + 6, less the 12
    // rigid motions the two placements take.
    let cr = camera_robot(&r).unwrap();
    assert_eq!(cr.n_unknowns(), 4 * 9 + 6 - 12, "{:?}", cr.parameter_names());
    let tree = Tree::of(&text);
    let mut rng = activecal::identify::trial_rng(1, 0);
    for q in generic_configurations(&r, 200, 3) {
        let mut by: HashMap<String, f64> = names.iter().cloned().zip(q.iter().copied()).collect();
        by.insert("torso_lift_joint".into(), 0.35 * rng.random::<f64>());
        let want = tree.pose(HEAD, &by).inverse() * tree.pose("arm_tool_link", &by);
        let got = end(&r, &r.nominal, &q);
        let d = want.inverse() * got;
        assert!(d.translation.vector.norm() < 1e-12, "{q:?}: {d}");
        assert!(d.rotation.angle() < 1e-12, "{q:?}: {d}");
    }
    // Not a camera on its own chain: the arm's link, an unknown link.
    assert!(camera_branch(&arm(&text), "arm_3_link").is_err());
    assert!(camera_branch(&arm(&text), "no_such_link").is_err());
}
