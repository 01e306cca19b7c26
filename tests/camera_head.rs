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
use activecal::io::camera_target::Target;
use activecal::io::urdf::{UrdfOptions, parse};
use activecal::io::urdf_branch::camera_branch;
use activecal::kinematics::Evaluator;
use activecal::measure::camera::{CameraSensor, Mounting};
use activecal::measure::pinhole::{Distortion, Intrinsics};
use activecal::model::{ParamTable, Robot, Symbol};
use activecal::observability::generic_configurations;
use activecal::write::calibrated::{Format, render};
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
        distortion: Distortion::PlumbBob([0.03, -0.08, 2e-4, -1e-4, 0.0]),
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

/// A URDF joint: name, type, parent link, origin, axis.
type Joint = (String, String, String, Isometry3<f64>, Vector3<f64>);

/// The joints of a URDF by child link.
struct Tree(HashMap<String, Joint>);

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
        for j in doc
            .root_element()
            .children()
            .filter(|c| c.has_tag_name("joint"))
        {
            let child = |tag: &str| j.children().find(|c| c.has_tag_name(tag));
            let link = |tag: &str| child(tag).unwrap().attribute("link").unwrap().to_string();
            let o = child("origin");
            let origin = iso(nums(o, "xyz", [0.0; 3]), nums(o, "rpy", [0.0; 3]));
            let axis = Vector3::from(nums(child("axis"), "xyz", [1.0, 0.0, 0.0]));
            let kind = j.attribute("type").unwrap().to_string();
            m.insert(
                link("child"),
                (
                    j.attribute("name").unwrap().to_string(),
                    kind,
                    link("parent"),
                    origin,
                    axis,
                ),
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
    let chosen = |n: &str| {
        n.starts_with("arm_") && n.ends_with("_joint")
            || n.starts_with("head_")
            || n == "torso_lift_joint"
    };
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
    assert_eq!(
        cr.n_unknowns(),
        4 * 9 + 6 - 12,
        "{:?}",
        cr.parameter_names()
    );
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

fn six(t: &Isometry3<f64>) -> [f64; 6] {
    let (r, p, y) = t.rotation.euler_angles();
    let v = t.translation.vector;
    [v.x, v.y, v.z, r, p, y]
}

/// The view `select` filters with: every point at least 20 px inside the
/// image, at most 60° off the board's face, 0.25–1.5 m away.
fn view() -> activecal::pool::camera_view::CameraView {
    let (cam, tgt) = truth_placements();
    activecal::pool::camera_view::CameraView {
        intrinsics: intrinsics(),
        mounting: Mounting::EyeToHand,
        points: board().points.iter().map(|p| [p.x, p.y, p.z]).collect(),
        face: [0.0, 0.0, 1.0],
        camera: six(&cam),
        target: six(&tgt),
        min_fraction: 1.0,
        margin_px: 20.0,
        max_view_angle: 60f64.to_radians(),
        distance: [0.25, 1.5],
    }
}

/// A simulated head-camera calibration: the nominal chain (its unknowns
/// a camera's), the true chain (from the perturbed URDF: its nominal
/// table is the truth), the true placements, the fit's start (placements
/// 2 cm and about 2° off) and the observations.
struct Head {
    robot: Robot,
    truth: Robot,
    placements: (Isometry3<f64>, Isometry3<f64>),
    start: CameraSensor,
    own_start: Vec<f64>,
    obs: activecal::data::CameraObservations,
}

impl Head {
    fn fit(&self) -> CameraFit {
        fit_camera(
            &self.robot,
            &self.start,
            &self.own_start,
            &self.obs,
            &LmSettings::default(),
        )
        .expect("a simulated head case fits")
    }

    /// A point of the board (its centroid, `at = true`, or its frame's
    /// origin) in the camera's frame, truth against fit, RMS over 1,000
    /// random configurations (seen or not), metres.
    fn true_error(&self, fit: &CameraFit, centroid: bool) -> f64 {
        let (cam_t, tgt_t) = self.placements;
        let s = if centroid {
            board().centroid()
        } else {
            Vector3::zeros()
        };
        let qs = generic_configurations(&self.robot, 1000, 7);
        let ss: f64 = qs
            .iter()
            .map(|q| {
                let a = cam_t.inverse() * end(&self.truth, &self.truth.nominal, q) * tgt_t;
                let b = fit.camera.inverse() * end(&fit.robot, &fit.table, q) * fit.target;
                (a * Point3::from(s) - b * Point3::from(s)).norm_squared()
            })
            .sum();
        (ss / qs.len() as f64).sqrt()
    }
}

/// Configurations where the nominal head sees the whole board well
/// ([`view`]), `n` of them from `pool` generic ones.
fn visible(robot: &Robot, pool: usize, n: usize) -> Vec<Vec<f64>> {
    let v = view();
    let out: Vec<Vec<f64>> = generic_configurations(robot, pool, 41)
        .into_iter()
        .filter(|q| v.keeps(robot, &robot.nominal, q))
        .take(n)
        .collect();
    assert_eq!(out.len(), n, "too few visible configurations");
    out
}

/// The head case of the true URDF `truth_seed` at configurations `qs`
/// (40 visible ones when `None`), pixel noise `sigma`, noise seed `seed`.
fn head(truth_seed: u64, sigma: f64, seed: u64, qs: Option<&[Vec<f64>]>) -> Head {
    let robot = camera_robot(&camera_branch(&arm(&text()), HEAD).unwrap()).unwrap();
    let truth = camera_branch(&arm(&perturbed_text(truth_seed)), HEAD).unwrap();
    let (cam, tgt) = truth_placements();
    let points = board().points;
    let sensor = CameraSensor::new(
        intrinsics(),
        Mounting::EyeToHand,
        points.clone(),
        &cam,
        &tgt,
    );
    let own = CameraSensor::start_own(&cam, &tgt);
    let qs = qs.map_or_else(|| visible(&robot, 40_000, 40), <[Vec<f64>]>::to_vec);
    let mut rng = activecal::identify::trial_rng(seed, 1);
    let obs = simulate_observations(
        &truth,
        &truth.nominal,
        &sensor,
        &own,
        &qs,
        sigma,
        0.0,
        &mut rng,
    );
    let off = Isometry3::from_parts(
        Translation3::new(0.02, -0.015, 0.01),
        UnitQuaternion::from_euler_angles(0.03, -0.02, 0.025),
    );
    let (cam0, tgt0) = (cam * off, tgt * off.inverse());
    Head {
        start: CameraSensor::new(intrinsics(), Mounting::EyeToHand, points, &cam0, &tgt0),
        own_start: CameraSensor::start_own(&cam0, &tgt0),
        robot,
        truth,
        placements: (cam, tgt),
        obs,
    }
}

/// Noise-free pixels of the true TIAGo recover it: the board's centre in
/// the camera's frame to 1e-6 mm at 1,000 configurations (LM's floor on
/// pixels of O(1e2–1e3) and lengths of O(1) is ~1e-12 relative), and the
/// calibrated URDF written from the fit, read back and walked from the
/// head with the frames file's placements, predicts the same to 1e-6 mm:
/// the head joints' changes reach the file's joints. Only the origins of
/// the joints the chain holds change (not the torso's lift, not the last
/// head joint's, which the arm's first origin takes).
#[test]
fn noise_free_pixels_recover_the_true_tiago() {
    let h = head(1, 0.0, 3, None);
    let fit = h.fit();
    assert!(fit.converged, "{:?}", fit.stop);
    assert!(
        fit.given_rms_px > 10.0,
        "the start is off: {} px",
        fit.given_rms_px
    );
    assert!(fit.rms_px < 1e-6, "{} px", fit.rms_px);
    assert_eq!(fit.estimate.len(), 42);
    let e = h.true_error(&fit, true);
    println!(
        "head camera, noise-free: true 3-D error {:.1e} mm, {:.1e} px",
        1e3 * e,
        fit.rms_px
    );
    assert!(e < 1e-9, "true error {} mm", 1e3 * e);
    // The URDF and the frames file written.
    let (f, report) = camera_frames(&fit).unwrap().expect("a URDF robot");
    // The frames file's joints: the file's joints whose origins the chain
    // holds, each once (the head's first joint has no origin of its own).
    let names: Vec<&str> = report.joints.0.iter().map(|j| j.name.as_str()).collect();
    let arm_joints: Vec<String> = (1..=7).map(|k| format!("arm_{k}_joint")).collect();
    assert_eq!(names[0], "head_2_joint");
    assert_eq!(
        names[1..],
        arm_joints.iter().map(String::as_str).collect::<Vec<_>>()[..]
    );
    let cam_block = &report.camera.as_ref().unwrap().camera;
    assert_eq!(cam_block.parent, HEAD);
    let written = render(
        Format::Urdf,
        &fit.robot,
        &fit.table,
        Some((&f, &report)),
        "",
    )
    .unwrap();
    let cal = camera_branch(&arm(&written), HEAD).unwrap();
    let cam = f.measurement.inverse() * fit.camera;
    let tgt = f.tool * fit.target;
    let c = Point3::from(board().centroid());
    let (cam_t, tgt_t) = h.placements;
    let mut worst: f64 = 0.0;
    for q in generic_configurations(&h.robot, 1000, 7) {
        let a = cam_t.inverse() * end(&h.truth, &h.truth.nominal, &q) * tgt_t * c;
        let b = cam.inverse() * end(&cal, &cal.nominal, &q) * tgt * c;
        worst = worst.max((a - b).norm());
    }
    println!(
        "head camera, written URDF: worst 3-D error {:.1e} mm",
        1e3 * worst
    );
    assert!(
        worst < 1e-9,
        "the written URDF is off by {} mm",
        1e3 * worst
    );
    let (before, after) = (Tree::of(&text()), Tree::of(&written));
    let origin = |t: &Tree, name: &str| t.0.values().find(|j| j.0 == name).unwrap().3;
    for name in ["torso_lift_joint", "head_1_joint"] {
        assert_eq!(origin(&before, name), origin(&after, name), "{name}");
    }
    for name in ["head_2_joint", "arm_1_joint", "arm_4_joint"] {
        let d = origin(&before, name).inverse() * origin(&after, name);
        assert!(
            d.translation.vector.norm() > 1e-5 || d.rotation.angle() > 1e-5,
            "{name} unchanged"
        );
    }
}

/// The true robot in the fit's parameters (an `r`-perturbed model robot):
/// the chain's true unknowns, then the true placements in the charts.
fn truth_vector(
    robot: &Robot,
    truth: &ParamTable,
    fit: &CameraFit,
    p: (Isometry3<f64>, Isometry3<f64>),
) -> Vec<f64> {
    let mut v = robot.unknown_values(truth);
    let (cam0, tgt0) = fit.sensor.placements(&[0.0; 12]);
    for (t, t0) in [(p.0, cam0), (p.1, tgt0)] {
        v.extend(t.translation.vector.iter());
        v.extend((t0.rotation.inverse() * t.rotation).scaled_axis().iter());
    }
    v
}

/// With σ 0.3 px every one of the 42 unknowns (30 of the head-to-tip
/// chain, 6 + 6 of the placements) lands within 3σ of a true robot given
/// in the fit's own parameters (each unknown off by ±(0.5–2) mm or
/// ±(0.05–0.3)°): a 3σ miss has probability 0.27 % per unknown, about
/// one run in nine of 42 would see one by chance (the seeds are fixed);
/// σ estimated within 5 % (2 × 35 × 40 rows: σ̂'s spread ≈ 1.7 %).
#[test]
fn noisy_pixels_put_every_head_unknown_within_three_sigma() {
    let h = head(1, 0.3, 5, None);
    let mut rng = activecal::identify::trial_rng(9, 0);
    let mut truth = h.robot.nominal.clone();
    for &u in &h.robot.unknowns {
        let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
        let size = match u.symbol {
            Symbol::A | Symbol::D => 1e-3 * (0.5 + 1.5 * rng.random::<f64>()),
            _ => (0.05 + 0.25 * rng.random::<f64>()).to_radians(),
        };
        truth.set(u, truth.get(u) + sign * size);
    }
    let (cam, tgt) = h.placements;
    let sensor = CameraSensor::new(
        intrinsics(),
        Mounting::EyeToHand,
        board().points,
        &cam,
        &tgt,
    );
    let own = CameraSensor::start_own(&cam, &tgt);
    let mut rng = activecal::identify::trial_rng(5, 1);
    let obs = simulate_observations(
        &h.robot, &truth, &sensor, &own, &h.obs.qs, 0.3, 0.0, &mut rng,
    );
    let fit = fit_camera(
        &h.robot,
        &h.start,
        &h.own_start,
        &obs,
        &LmSettings::default(),
    )
    .unwrap();
    assert!(fit.converged, "{:?}", fit.stop);
    let s = fit.sigma_px.unwrap();
    assert!((s / 0.3 - 1.0).abs() < 0.05, "σ {s} px");
    let tv = truth_vector(&fit.robot, &truth, &fit, h.placements);
    let std = fit.std.as_ref().unwrap();
    let mut worst: f64 = 0.0;
    for (k, name) in fit.names.iter().enumerate() {
        let z = (fit.estimate[k] - tv[k]) / std[k];
        worst = worst.max(z.abs());
        assert!(z.abs() < 3.0, "{name}: {} off by {z:.2}σ", fit.estimate[k]);
    }
    println!("head camera, σ 0.3 px: σ̂ {s:.4} px, largest miss {worst:.2}σ of 42 unknowns");
}

/// `select` for the head camera: 30 poses chosen on the pixel Jacobian
/// from 20,000 configurations (those where the nominal head sees the
/// whole board well), each seeing every point, with a larger `ln det
/// XᵀX` than each of 20 random designs of 30 from the same visible pool.
/// The true error of the board's frame origin in the camera's frame,
/// fitted from σ 0.3 px against the true TIAGo of the URDF, RMS over 20
/// noise draws, is within 1.3× of what `select` predicts (one draw's
/// error is a quadratic form dominated by a few directions; 20 draws
/// pool about 20× the degrees of freedom); the random designs' median
/// true error is printed beside the chosen design's.
#[test]
fn select_predicts_the_head_cameras_true_error() {
    use activecal::select::camera::{camera_blocks, camera_design};
    let branch = camera_branch(&arm(&text()), HEAD).unwrap();
    let robot = camera_robot(&branch).unwrap();
    let v = view();
    let candidates = generic_configurations(&robot, 20_000, 13);
    let n = 30;
    let settings = activecal::select::Settings::builder().n(n).build().unwrap();
    let d = camera_design(&branch, &v, &candidates, &settings).unwrap();
    assert_eq!(d.qs.len(), n);
    assert!(d.seen.iter().all(|&s| s == 35), "{:?}", d.seen);
    let predicted = 0.3 * d.predicted_error_per_px.expect("a regular design");
    let mut ss = 0.0;
    for draw in 0..20 {
        let h = head(1, 0.3, 200 + draw, Some(&d.qs));
        let fit = h.fit();
        assert!(fit.converged, "draw {draw}: {:?}", fit.stop);
        ss += h.true_error(&fit, false).powi(2);
    }
    let rms = (ss / 20.0).sqrt();
    println!(
        "head camera design: {} of {} candidates visible; select predicts {:.4} mm at σ 0.3 px, true {:.4} mm RMS over 20 draws (ratio {:.2})",
        d.visible,
        candidates.len(),
        1e3 * predicted,
        1e3 * rms,
        rms / predicted
    );
    assert!(
        rms < 1.3 * predicted && predicted < 1.3 * rms,
        "true {rms} m, predicted {predicted} m"
    );
    // Against 20 random designs from the same visible pool.
    let pool: Vec<Vec<f64>> = candidates
        .iter()
        .filter(|q| v.keeps(&robot, &robot.nominal, q))
        .cloned()
        .collect();
    assert_eq!(pool.len(), d.visible);
    let blocks = camera_blocks(&robot, &v, &pool);
    let mut rng = activecal::identify::trial_rng(17, 0);
    let chosen = head(1, 0.3, 21, Some(&d.qs));
    let chosen_error = chosen.true_error(&chosen.fit(), false);
    let mut random = Vec::new();
    for _ in 0..20 {
        let mut idx: Vec<usize> = (0..pool.len()).collect();
        for i in 0..n {
            let j = i + (rng.random::<f64>() * (pool.len() - i) as f64) as usize;
            idx.swap(i, j.min(pool.len() - 1));
        }
        idx.truncate(n);
        let m = blocks.information(&idx);
        let m = nalgebra::DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)]);
        let ln_det = m.cholesky().map_or(f64::NEG_INFINITY, |c| {
            2.0 * c.l().diagonal().iter().map(|x| x.ln()).sum::<f64>()
        });
        assert!(
            ln_det < d.ln_det,
            "a random design: {ln_det} against {}",
            d.ln_det
        );
        let qs: Vec<Vec<f64>> = idx.iter().map(|&k| pool[k].clone()).collect();
        let h = head(1, 0.3, 21, Some(&qs));
        random.push(h.true_error(&h.fit(), false));
    }
    random.sort_by(f64::total_cmp);
    let median = 0.5 * (random[9] + random[10]);
    println!(
        "head camera design: chosen {n} poses: true 3-D error {:.4} mm, median of 20 random designs {:.4} mm (ratio {:.2})",
        1e3 * chosen_error,
        1e3 * median,
        chosen_error / median
    );
}

/// The camera's link may be a fixed frame below the head's last joint
/// (the Xtion's RGB optical frame, three fixed joints below
/// `head_2_link`): the chain from it is the tree too, at 200
/// configurations to 1e-12. A fixed joint between two moving joints of the
/// camera's chain is refused (no single joint of the file could take the
/// origin between them), with the file named.
#[test]
fn a_camera_link_below_fixed_joints_and_a_refused_chain() {
    let text = text();
    let link = "xtion_rgb_optical_frame";
    let r = camera_branch(&arm(&text), link).unwrap();
    let names = r.source.as_ref().unwrap().driven_names();
    let tree = Tree::of(&text);
    for q in generic_configurations(&r, 200, 5) {
        let by: HashMap<String, f64> = names.iter().cloned().zip(q.iter().copied()).collect();
        let want = tree.pose(link, &by).inverse() * tree.pose("arm_tool_link", &by);
        let d = want.inverse() * end(&r, &r.nominal, &q);
        assert!(
            d.translation.vector.norm() < 1e-12 && d.rotation.angle() < 1e-12,
            "{d}"
        );
    }
    // A fixed joint between head_1_joint and head_2_joint.
    let bent = text
        .replace(
            "<parent link=\"head_1_link\"/>\n    <child link=\"head_2_link\"/>",
            "<parent link=\"head_mid_link\"/>\n    <child link=\"head_2_link\"/>",
        )
        .replace(
            "<joint name=\"head_2_joint\" type=\"revolute\">",
            "<link name=\"head_mid_link\"/>\n  <joint name=\"head_mid_joint\" type=\"fixed\">\n    <parent link=\"head_1_link\"/>\n    <child link=\"head_mid_link\"/>\n    <origin xyz=\"0 0 0.01\" rpy=\"0 0 0\"/>\n  </joint>\n  <joint name=\"head_2_joint\" type=\"revolute\">",
        );
    assert_ne!(bent, text, "the edit applies");
    let e = camera_branch(&arm(&bent), HEAD).unwrap_err().to_string();
    assert!(
        e.contains(URDF) && e.contains("fixed joints lie between"),
        "{e}"
    );
}
