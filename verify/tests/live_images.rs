//! Calibration from a camera's images against a known truth (issue #51;
//! feature `live`, the project venv with Pinocchio and OpenCV, and
//! `target/debug/activecal`). Pinocchio plays the real UR5
//! (`fixtures/ur5.urdf`, every chain joint's origin off by 0.5–2 mm and
//! 0.05–0.3°, `camera_truth.py make`), the camera rides on its flange
//! (eye-in-hand, `fixtures/camera/camera_info.yaml`: 1280 × 960, plumb_bob)
//! and looks at a checkerboard of 25 mm squares fixed 0.45 m out;
//! `verify/python/camera_images.py render` renders what it records at
//! configurations where the true robot shows the whole board (the last
//! few far and oblique: squares of 6–15 px), exactly (rays cast through
//! the true distortion, 4 × 4 anti-aliasing, blur 0.6 px, gamma 2.2, noise
//! 2 grey levels) with the true pixel of every corner beside the images.
//! `activecal calibrate --images` detects, fits and writes URDF + frames
//! (start placements computed from the pixels); `truth.py compare` gives
//! the true error of the target's origin in the camera's frame at 1,000
//! random configurations.
//!
//! The scene's helpers are shared with the truth gates
//! (`live_images_truth.rs`: eye-in-hand and eye-to-hand, checkerboard and
//! ChArUco); here the boards whose labels the detector cannot fix:
//!
//! * [`live_images_flipped_symmetric_board`]: a 5 × 7 board, which looks
//!   the same turned 180°: its corners are labelled in either order; every
//!   image whose order is not the truth's is relabelled (or dropped) by the
//!   robot's motion, and the true error is within 1.3× of the fit on the
//!   same corners labelled by the truth.
//! * [`live_images_board_seen_from_behind`]: a 6 × 9 board seen through
//!   from behind: its pattern is mirrored in every image, which the
//!   detector labels consistently as the board's mirror image (no
//!   labelling by the robot's motion can tell a consistent mirror: it is a
//!   fixed turn of the board's frame); the robot and the camera's placement
//!   come out as the truth-labelled corners give them, to a hundredth of
//!   their σ, and the target's frame turned 180° about an axis in its
//!   plane.

use activecal::experiment::camera::{CameraSetup, calibrate_camera};
use activecal::identify::LmSettings;
use activecal::identify::camera::predict::predicted_error;
use activecal::io::camera_info::read_camera_info;
use activecal::io::camera_observations::read_observations;
use activecal::io::camera_target::read_target;
use activecal::lsq::outliers::OutlierChoice;
use activecal::measure::camera::Mounting;
use activecal::observability::generic_configurations;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use verify::bridge::{python, repo_root as root, run};

/// The gate's ratio (as the camera truth gate's).
pub(crate) const RATIO: f64 = 1.3;
/// The board's square, m.
pub(crate) const SQUARE: f64 = 0.025;

pub(crate) fn six(t: &Isometry3<f64>) -> String {
    let (r, p, y) = t.rotation.euler_angles();
    let v = t.translation.vector;
    format!("{},{},{},{r},{p},{y}", v.x, v.y, v.z)
}

/// A true robot with its camera and target (the truth `camera_truth.py
/// make` perturbs): the URDF (from the repository's root), the chain's
/// base and tip links, the mounting, the camera's optical frame and the
/// target's frame (in the base or tip link as the mounting says), and the
/// distances (m) of the near images.
pub(crate) struct Rig {
    pub name: &'static str,
    pub urdf: &'static str,
    pub base: &'static str,
    pub tip: &'static str,
    pub mounting: Mounting,
    pub camera: Isometry3<f64>,
    pub target: Isometry3<f64>,
    pub near: [f64; 2],
}

impl Rig {
    /// The robot as `--robot` names it.
    pub fn robot_ref(&self) -> String {
        format!("{}#tip={}", root().join(self.urdf).display(), self.tip)
    }
}

/// The UR5 eye-in-hand: the camera on the flange, a board of `rows ×
/// cols` inner corners centred 0.45 m out in the base link, face down (its
/// z away from a camera above it), or face up when seen from `behind`.
pub(crate) fn ur5_eye_in_hand(name: &'static str, rows: usize, cols: usize, behind: bool) -> Rig {
    let roll = if behind { 0.0 } else { std::f64::consts::PI };
    Rig {
        name,
        urdf: "fixtures/ur5.urdf",
        base: "base_link",
        tip: "target",
        mounting: Mounting::EyeInHand,
        camera: Isometry3::from_parts(
            Translation3::new(0.06, 0.0, 0.03),
            UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        ),
        target: Isometry3::from_parts(
            Translation3::new(0.45, 0.15, 0.0),
            UnitQuaternion::from_euler_angles(roll, 0.0, 0.03),
        ) * Translation3::new(
            -0.5 * (cols - 1) as f64 * SQUARE,
            -0.5 * (rows - 1) as f64 * SQUARE,
            0.0,
        ),
        near: [0.3, 0.9],
    }
}

/// A board as the target file names it and as the renderer draws it.
pub(crate) struct Board {
    /// The target file's YAML.
    pub yaml: String,
    /// `camera_images.py render`'s arguments for it.
    pub render: Vec<String>,
    /// Whether its points carry ids (a part of it is labelled).
    pub ids: bool,
}

/// A checkerboard of `rows × cols` inner corners, [`SQUARE`] squares.
pub(crate) fn checkerboard(rows: usize, cols: usize) -> Board {
    Board {
        yaml: format!("checkerboard: {{rows: {rows}, cols: {cols}, square: {SQUARE}}}\n"),
        render: vec![format!("--board={rows},{cols},{SQUARE}")],
        ids: false,
    }
}

/// A rendered scene: its folder, rig, truth, target file and each draw's
/// folder of images.
pub(crate) struct Scene {
    pub dir: PathBuf,
    pub rig: Rig,
    pub truth: PathBuf,
    pub board: PathBuf,
    pub draws: Vec<PathBuf>,
    /// Whether the board's points carry ids (ChArUco), compared with
    /// OpenCV's on the corners both found.
    pub board_has_ids: bool,
}

/// `rig`'s truth and `draws` renders of `count` images (the last 3 far
/// and oblique when `far`) of `board`, seen from the front or from
/// `behind`.
pub(crate) fn scene(
    rig: Rig,
    board: &Board,
    behind: bool,
    (count, far): (usize, bool),
    draws: usize,
) -> Scene {
    let dir = std::env::temp_dir().join(format!(
        "activecal-live-images-{}-{}",
        rig.name,
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let r = root();
    let truth = dir.join("truth.json");
    run(python()
        .arg(r.join("verify/python/camera_truth.py"))
        .args(["make", "--base", rig.base, "--tip", rig.tip, "--seed", "3"])
        .args(["--mounting", rig.mounting.name(), "--urdf"])
        .arg(r.join(rig.urdf))
        .arg(format!("--camera={}", six(&rig.camera)))
        .arg(format!("--target={}", six(&rig.target)))
        .arg("--out")
        .arg(&truth));
    let images = dir.join("images");
    let mut c = python();
    c.arg(r.join("verify/python/camera_images.py"))
        .args(["render", "--truth"])
        .arg(&truth)
        .arg("--camera-info")
        .arg(r.join("fixtures/camera/camera_info.yaml"))
        .args(&board.render)
        .arg(format!("--count={count}"))
        .args(["--far", if far { "3" } else { "0" }, "--seed", "5"])
        .arg(format!("--near-range={},{}", rig.near[0], rig.near[1]))
        .arg(format!("--draws={draws}"))
        .arg("--out")
        .arg(&images);
    if behind {
        c.arg("--behind");
    }
    println!("{}: {}", rig.name, run(&mut c).trim());
    let path = dir.join("board.yaml");
    std::fs::write(&path, &board.yaml).unwrap();
    let draws = if draws == 1 {
        vec![images]
    } else {
        (0..draws)
            .map(|d| images.join(format!("draw_{d}")))
            .collect()
    };
    Scene {
        dir,
        rig,
        truth,
        board: path,
        draws,
        board_has_ids: board.ids,
    }
}

/// `activecal calibrate` with `data` (`--images DIR --joints …` or
/// `--observations FILE`), writing `stem.urdf` and `stem.yaml`: the JSON
/// report and the true error, mm.
pub(crate) fn calibrate(s: &Scene, data: &[&std::ffi::OsStr], stem: &str) -> (Value, f64) {
    let r = root();
    let (u, y) = (
        s.dir.join(format!("{stem}.urdf")),
        s.dir.join(format!("{stem}.yaml")),
    );
    let out = run(Command::new(r.join("target/debug/activecal"))
        .arg("calibrate")
        .arg("--robot")
        .arg(s.rig.robot_ref())
        .args(data)
        .arg("--camera-info")
        .arg(r.join("fixtures/camera/camera_info.yaml"))
        .arg("--target")
        .arg(&s.board)
        .args(["--mounting", s.rig.mounting.name()])
        .args(["--json", "--force", "--out"])
        .arg(&u)
        .arg("--out")
        .arg(&y));
    let report: Value = serde_json::from_str(&out).unwrap();
    let cmp: Value = serde_json::from_str(&run(python()
        .arg(r.join("verify/python/truth.py"))
        .args(["compare", "--truth"])
        .arg(&s.truth)
        .arg("--urdf")
        .arg(&u)
        .arg("--frames")
        .arg(&y)
        .args(["--n", "1000", "--seed", "1"])))
    .unwrap();
    (report, cmp["random"]["rms_mm"].as_f64().unwrap())
}

/// Calibrates a draw's images (saving the pixels detected as `stem.csv`):
/// the report, the true error (mm) and the pixels' file.
pub(crate) fn from_images(s: &Scene, draw: &Path, stem: &str) -> (Value, f64, PathBuf) {
    let saved = s.dir.join(format!("{stem}.csv"));
    let args: Vec<std::ffi::OsString> = vec![
        "--images".into(),
        draw.into(),
        "--joints".into(),
        draw.join("joints.csv").into(),
        "--save-observations".into(),
        saved.clone().into(),
    ];
    let refs: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let (report, t) = calibrate(s, &refs, stem);
    (report, t, saved)
}

/// The fit's predicted true error (mm) of the pixels in `obs`, as the
/// command fits them (in process: start computed, relabelled, screened).
pub(crate) fn predicted(s: &Scene, obs: &Path) -> f64 {
    let robot = activecal::io::load_robot(&s.rig.robot_ref()).unwrap();
    let intrinsics = read_camera_info(&root().join("fixtures/camera/camera_info.yaml")).unwrap();
    let target = read_target(&s.board).unwrap();
    let o = read_observations(obs, &robot, &target, &intrinsics, Default::default()).unwrap();
    let setup = CameraSetup {
        intrinsics,
        target,
        target_origin: s.board.display().to_string(),
        mounting: s.rig.mounting,
        camera_link: None,
        camera: None,
        target_pose: None,
        refine_intrinsics: false,
        outliers: OutlierChoice::default(),
        pixel_noise: None,
    };
    let cal = calibrate_camera(&robot, o, &setup, &LmSettings::default()).unwrap();
    1e3 * predicted_error(&cal.fit, &generic_configurations(&cal.fit.robot, 1000, 0)).unwrap()
}

/// An observations CSV by pose: the header, and each pose's joint cells
/// and `{feature: (u, v)}`.
pub(crate) struct Pixels {
    pub head: String,
    pub poses: BTreeMap<i64, (String, BTreeMap<i64, [f64; 2]>)>,
}

pub(crate) fn read_pixels(path: &Path) -> Pixels {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().to_string();
    let mut poses: BTreeMap<i64, (String, BTreeMap<i64, [f64; 2]>)> = BTreeMap::new();
    for l in lines.filter(|l| !l.trim().is_empty()) {
        let c: Vec<&str> = l.split(',').collect();
        let n = c.len();
        let e = poses
            .entry(c[0].parse().unwrap())
            .or_insert_with(|| (c[1..n - 3].join(","), BTreeMap::new()));
        e.1.insert(
            c[n - 3].parse().unwrap(),
            [c[n - 2].parse().unwrap(), c[n - 1].parse().unwrap()],
        );
    }
    Pixels { head, poses }
}

pub(crate) fn write_pixels(p: &Pixels, path: &Path) {
    let mut s = p.head.clone() + "\n";
    for (id, (joints, pts)) in &p.poses {
        for (f, [u, v]) in pts {
            s += &format!("{id},{joints},{f},{u:.6},{v:.6}\n");
        }
    }
    std::fs::write(path, s).unwrap();
}

/// The detected corners of each pose labelled by the truth (each the id
/// of the nearest true corner), and the poses whose detected labels were
/// not the truth's.
pub(crate) fn truth_labelled(detected: &Pixels, truth: &Pixels) -> (Pixels, Vec<i64>) {
    let mut out = Pixels {
        head: detected.head.clone(),
        poses: BTreeMap::new(),
    };
    let mut misordered = Vec::new();
    for (id, (joints, pts)) in &detected.poses {
        let true_pts = &truth.poses[id].1;
        let mut relabelled = BTreeMap::new();
        for (f, p) in pts {
            let (g, d) = true_pts
                .iter()
                .map(|(g, t)| (*g, (t[0] - p[0]).hypot(t[1] - p[1])))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(
                d < 1.0,
                "pose {id} corner {f}: {d} px from the nearest true corner"
            );
            relabelled.insert(g, *p);
        }
        if relabelled.keys().zip(pts.keys()).any(|(a, b)| a != b)
            || pts.iter().any(|(f, p)| relabelled.get(f) != Some(p))
        {
            misordered.push(*id);
        }
        out.poses.insert(*id, (joints.clone(), relabelled));
    }
    (out, misordered)
}

/// `truth`'s pixels of the poses of `detected`, with Gaussian noise of
/// `sigma` px per coordinate (SplitMix64 and Box–Muller, `seed`).
pub(crate) fn noisy_truth(detected: &Pixels, truth: &Pixels, sigma: f64, seed: u64) -> Pixels {
    let mut state = seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x5EED;
    let mut uniform = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (((z ^ (z >> 31)) >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    };
    let mut normal = || {
        let (u, v) = (uniform(), uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let mut out = Pixels {
        head: truth.head.clone(),
        poses: BTreeMap::new(),
    };
    for id in detected.poses.keys() {
        let (joints, pts) = &truth.poses[id];
        let noisy = pts
            .iter()
            .map(|(f, p)| (*f, [p[0] + sigma * normal(), p[1] + sigma * normal()]))
            .collect();
        out.poses.insert(*id, (joints.clone(), noisy));
    }
    out
}

/// The errors (px) of corners labelled by the truth against the truth.
pub(crate) fn corner_errors(labelled: &Pixels, truth: &Pixels) -> Vec<f64> {
    let mut e = Vec::new();
    for (id, (_, pts)) in &labelled.poses {
        for (f, p) in pts {
            let t = truth.poses[id].1[f];
            e.push((t[0] - p[0]).hypot(t[1] - p[1]));
        }
    }
    e.sort_by(f64::total_cmp);
    e
}

pub(crate) fn quantile(sorted: &[f64], q: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

pub(crate) fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// OpenCV's route `args` on `draw`'s images, scored against the truth
/// (`camera_images.py score`): detected images, median and p95 px.
pub(crate) fn opencv(s: &Scene, draw: &Path, args: &[String], stem: &str) -> (f64, f64, f64) {
    let script = root().join("verify/python/camera_images.py");
    let det = s.dir.join(format!("{stem}.csv"));
    run(python()
        .arg(&script)
        .args(["opencv", "--dir"])
        .arg(draw)
        .args(args)
        .arg("--out")
        .arg(&det));
    let v: Value = serde_json::from_str(&run(python()
        .arg(&script)
        .args(["score", "--dir"])
        .arg(draw)
        .arg("--detections")
        .arg(&det)))
    .unwrap();
    let f = |k: &str| v[k].as_f64().unwrap_or(f64::INFINITY);
    (f("detected"), f("median_px"), f("p95_px"))
}

/// A board whose labelling the detector cannot tell (see the module
/// documentation): every misordered pose relabelled or dropped, the true
/// error within [`RATIO`] of the truth-labelled corners'.
fn relabelled_case(name: &'static str, board: (usize, usize)) {
    let rig = ur5_eye_in_hand(name, board.0, board.1, false);
    let s = scene(rig, &checkerboard(board.0, board.1), false, (20, true), 1);
    let draw = &s.draws[0];
    let (report, true_mm, saved) = from_images(&s, draw, "images");
    let detected = read_pixels(&saved);
    let truth = read_pixels(&draw.join("truth.csv"));
    let (labelled, misordered) = truth_labelled(&detected, &truth);
    let ids = |k: &str, f: &str| -> Vec<i64> {
        report[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v[f].as_i64().unwrap())
            .collect()
    };
    let (relabelled, dropped) = (ids("relabelled", "pose"), ids("dropped_poses", "pose"));
    println!(
        "{name}: {} of {} images, {} in another order than the truth's: relabelled {relabelled:?}, dropped {dropped:?}",
        detected.poses.len(),
        truth.poses.len(),
        misordered.len()
    );
    assert!(
        !misordered.is_empty(),
        "no image in another order: the case tests nothing"
    );
    for p in &misordered {
        assert!(
            relabelled.contains(p) || dropped.contains(p),
            "pose {p} misordered, kept as detected"
        );
    }
    for p in &relabelled {
        assert!(
            misordered.contains(p),
            "pose {p} was in the truth's order, relabelled"
        );
    }
    let reference = s.dir.join("truth_labelled.csv");
    write_pixels(&labelled, &reference);
    let (_, ref_mm) = calibrate(
        &s,
        &["--observations".as_ref(), reference.as_os_str()],
        "truth_labelled",
    );
    println!("{name}: true error {true_mm:.4} mm, truth-labelled corners {ref_mm:.4} mm");
    assert!(
        true_mm <= RATIO * ref_mm,
        "{true_mm} mm against {ref_mm} mm"
    );
}

#[test]
fn live_images_flipped_symmetric_board() {
    relabelled_case("flipped", (5, 7));
}

/// A board seen from behind (see the module documentation): every image
/// labelled as the board's mirror image, consistently, so the fit is that
/// of a front-seen board whose frame is turned 180° about an axis in its
/// plane (a mirrored planar grid is the grid so turned): the same robot
/// and camera placement as the truth-labelled corners give, to a hundredth
/// of their σ; only the target's frame differs.
#[test]
fn live_images_board_seen_from_behind() {
    let rig = ur5_eye_in_hand("behind", 6, 9, true);
    let s = scene(rig, &checkerboard(6, 9), true, (20, true), 1);
    let draw = &s.draws[0];
    let (report, _, saved) = from_images(&s, draw, "images");
    let detected = read_pixels(&saved);
    let truth = read_pixels(&draw.join("truth.csv"));
    let (labelled, misordered) = truth_labelled(&detected, &truth);
    println!(
        "behind: {} of {} images, {} mirrored against the truth",
        detected.poses.len(),
        truth.poses.len(),
        misordered.len()
    );
    assert_eq!(
        misordered.len(),
        detected.poses.len(),
        "not every image mirrored"
    );
    assert!(report["relabelled"].as_array().unwrap().is_empty());
    let reference = s.dir.join("truth_labelled.csv");
    write_pixels(&labelled, &reference);
    let (truth_fit, ref_mm) = calibrate(
        &s,
        &["--observations".as_ref(), reference.as_os_str()],
        "truth_labelled",
    );
    println!("behind: truth-labelled corners' true error {ref_mm:.4} mm");
    let names = report["names"].as_array().unwrap();
    let (a, b, sd) = (
        &report["estimate"],
        &truth_fit["estimate"],
        &truth_fit["std"],
    );
    let mut worst: f64 = 0.0;
    for (k, n) in names.iter().enumerate() {
        let n = n.as_str().unwrap();
        if n.starts_with("camera_") || n.starts_with("target_") {
            continue;
        }
        let d = (a[k].as_f64().unwrap() - b[k].as_f64().unwrap()).abs() / sd[k].as_f64().unwrap();
        worst = worst.max(d);
    }
    let camera = |r: &Value, k: usize| r["camera"]["camera"]["xyz"][k].as_f64().unwrap();
    for k in 0..3 {
        let sigma = 1e-3
            * truth_fit["camera"]["camera"]["sigma_xyz_mm"][k]
                .as_f64()
                .unwrap();
        worst = worst.max((camera(&report, k) - camera(&truth_fit, k)).abs() / sigma);
    }
    println!("behind: robot and camera placement within {worst:.2e} σ of the truth-labelled fit");
    assert!(worst < 0.01, "{worst} σ");
}
