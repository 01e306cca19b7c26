//! Live checks of calibration from contacts (issue 29; feature `live`,
//! needs the project venv), against Pinocchio's forward kinematics of
//! MUKCa's Panda URDF (`fixtures/mukca`):
//!
//! * every configuration `select --point` chooses for a socket at
//!   `front_left/0` reaches the socket to 0.1 mm by Pinocchio's placement of
//!   `ball_link` (the acceptance);
//! * the point and plane unknowns of a contact fit agree with Pinocchio:
//!   the calibrated URDF (the chain's origins written by
//!   `with_origins`), composed with the calibrated measurement frame, tool
//!   and the fitted tool offset, gives each row's tool point; each fitted
//!   point is the mean of its rows' tool points and each unknown plane the
//!   least-squares plane of its rows' (what an L2 fit's optimality
//!   conditions make them);
//! * the files `calibrate --out` writes for a contact fit (the calibrated
//!   URDF and the frames file), loaded by Pinocchio and the frames reader,
//!   give the fitted tool point of every row.

use activecal::data::{ContactFile, NamedDistance};
use activecal::frames::contact::contact_frames;
use activecal::frames::decompose;
use activecal::frames::report::FitBlock;
use activecal::identify::contact::ContactFit;
use activecal::identify::contact::project::project_to_point;
use activecal::identify::contact::select::Socket;
use activecal::identify::contact::{
    ContactSettings, best_plane, fit_contacts, group_means, placement_of, resolve_distances,
    tool_points,
};
use activecal::io::contacts::read_contacts;
use activecal::io::frames_file;
use activecal::io::load_robot;
use activecal::io::urdf_edit::with_origins;
use activecal::measure::contact::{DISTANCE_WEIGHT, Plane, PlaneKind};
use activecal::model::Robot;
use activecal::select::contact::socket_design::{SocketDesignSettings, design_for_sockets};
use activecal::units::{Units, joint_names};
use activecal::write::calibrated::{Format, render};
use nalgebra::{Matrix3, Vector3};
use std::path::{Path, PathBuf};
use verify::bridge::Bridge;
use verify::export::compose;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/mukca");

fn panda() -> Robot {
    load_robot(&format!("{DIR}/panda.urdf#tip=ball_link")).expect("MUKCa's Panda")
}

fn panda_2(robot: &Robot) -> ContactFile {
    read_contacts(
        Path::new(&format!("{DIR}/panda_2.csv")),
        robot,
        Units::default(),
    )
    .expect("panda_2")
}

/// Pinocchio's placement of `ball_link` in the root's frame of the URDF at
/// `path`, at `qs`, as (rotation, position).
fn pinocchio_ball(
    bridge: &Bridge,
    path: &Path,
    robot: &Robot,
    qs: &[Vec<f64>],
) -> Vec<verify::erd_fk::Placement> {
    bridge
        .urdf_relative_poses(path, None, "ball_link", &joint_names(robot), qs)
        .expect("Pinocchio's placements")
}

/// The acceptance: 30 configurations chosen for a socket at the
/// nominal mean tool point of `front_left/0` each reach it to 0.1 mm by
/// Pinocchio's forward kinematics of the same URDF (the projection stops
/// at 1e-7 m and the two kinematics agree to ~1e-15 m, so 1e-6 m is also
/// asserted: a tenth of a micrometre of slack above the projection's).
#[test]
fn selected_configurations_reach_the_socket_in_pinocchio() {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let robot = panda();
    let real = panda_2(&robot);
    let g = real.point_index("front_left/0").unwrap();
    let pts = tool_points(&robot, &robot.nominal, &[0.0; 3], &real.qs);
    let socket = group_means(&pts, &real.groups, real.points.len())[g];
    let sockets = [Socket {
        name: "front_left/0".into(),
        position: socket.into(),
    }];
    let d = design_for_sockets(
        &robot,
        &robot.nominal,
        &sockets,
        &SocketDesignSettings::default(),
    )
    .unwrap();
    assert_eq!(d.configurations.len(), 30);
    let qs: Vec<Vec<f64>> = d.configurations.iter().map(|c| c.q.clone()).collect();
    let pin = pinocchio_ball(
        &bridge,
        Path::new(&format!("{DIR}/panda.urdf")),
        &robot,
        &qs,
    );
    let worst = pin
        .iter()
        .map(|p| (Vector3::from(p.position) - socket).norm())
        .fold(0.0f64, f64::max);
    println!(
        "predicted {:.4} σ, random median {:.4} σ ({:.3}×), bound {:.4} σ; largest distance to the socket by Pinocchio: {worst:.3e} m",
        d.consistency.predicted_sigma,
        d.consistency.random.median_sigma,
        d.consistency.ratio_to_random,
        d.consistency.bound.certified_sigma
    );
    // NaN fails too.
    assert!(worst <= 1e-4, "{worst} m");
    assert!(worst <= 1e-6, "{worst} m");
}

/// Rows touching an unknown plane `z = z0` (a table under the sockets):
/// 30 targets spread over a 0.3 m square about `centre`, reached by
/// projecting `seeds` with the nominal robot.
fn with_table(robot: &Robot, file: &ContactFile, centre: &Vector3<f64>) -> ContactFile {
    let mut out = file.clone();
    let g = out.points.len();
    out.planes.push(Plane {
        name: "table".into(),
        kind: PlaneKind::Unknown {
            n0: [0.0, 0.0, 1.0],
        },
    });
    let mut rows = 0;
    for (k, q) in file.qs.iter().enumerate().step_by(3) {
        let (u, v) = ((k % 7) as f64 / 6.0 - 0.5, (k % 5) as f64 / 4.0 - 0.5);
        let target = centre + Vector3::new(0.3 * u, 0.3 * v, -0.05);
        let margin = 2f64.to_radians();
        if let Some(q) =
            project_to_point(robot, &robot.nominal, &[0.0; 3], &target, q, margin, 1e-9)
        {
            out.qs.push(q);
            out.groups.push(g);
            out.lines.push(100_000 + k);
            rows += 1;
        }
        if rows == 30 {
            break;
        }
    }
    assert_eq!(rows, 30, "table rows reached");
    out
}

/// Each row's tool point by Pinocchio: `ball_link`'s placement in the
/// calibrated URDF, composed with the fit's measurement frame and tool,
/// plus the fitted tool offset in that end frame.
fn pinocchio_tool_points(
    bridge: &Bridge,
    robot: &Robot,
    table: &activecal::model::ParamTable,
    offset: &[f64; 3],
    qs: &[Vec<f64>],
) -> Vec<Vector3<f64>> {
    let frames = decompose(robot, table).expect("calibrated frames");
    let src = robot.source.as_deref().expect("a URDF robot");
    let origins: Vec<_> = frames
        .joints
        .iter()
        .map(|j| (j.name.clone(), j.calibrated))
        .collect();
    let text = with_origins(&src.text, &src.path, &origins).expect("calibrated URDF");
    let path: PathBuf = std::env::temp_dir().join(format!(
        "activecal-live-contacts-{}.urdf",
        std::process::id()
    ));
    std::fs::write(&path, text).unwrap();
    let pin = pinocchio_ball(bridge, &path, robot, qs);
    let _ = std::fs::remove_file(&path);
    pin.iter()
        .map(|p| {
            let c = compose(Some(&frames), p)[0];
            let r = Matrix3::from_fn(|i, j| c.rotation[i][j]);
            Vector3::from(c.position) + r * Vector3::from(*offset)
        })
        .collect()
}

/// An L2 fit of three placements of `panda_2` (six sockets, 50 mm apart
/// in pairs) and 30 rows on an unknown table plane under them: the file,
/// the known distances, their indices and the fit.
fn three_placements_and_a_table(
    robot: &Robot,
) -> (
    ContactFile,
    Vec<NamedDistance>,
    Vec<activecal::measure::contact::KnownDistance>,
    ContactFit,
) {
    let real = panda_2(robot);
    let keep = ["back_left", "front_left", "mid_right"];
    let rows: Vec<usize> = (0..real.qs.len())
        .filter(|&i| keep.contains(&placement_of(&real.points[real.groups[i]])))
        .collect();
    let file = real.subset(&rows);
    let pts = tool_points(robot, &robot.nominal, &[0.0; 3], &file.qs);
    let centre = pts.iter().sum::<Vector3<f64>>() / pts.len() as f64;
    let file = with_table(robot, &file, &centre);
    let settings = ContactSettings::default();
    let given: Vec<NamedDistance> = keep
        .iter()
        .map(|p| NamedDistance {
            a: format!("{p}/0"),
            b: format!("{p}/1"),
            metres: 0.05,
        })
        .collect();
    let known = resolve_distances(&file, &given, true).unwrap();
    let fit = fit_contacts(robot, &robot.nominal, &file, &known, &settings).unwrap();
    assert!(fit.converged, "{:?}", fit.stop);
    (file, given, known, fit)
}

/// A fit of three placements of `panda_2` (six sockets, 50 mm apart in
/// pairs) and 30 rows on an unknown table plane, L2: Pinocchio's tool points of the calibrated URDF
/// equal activecal's calibrated ones to 1e-9 m (the bar of
/// `live_export`), each fitted point is their mean over its rows (moved by
/// its known distance's pull) and the plane their least-squares plane, to
/// 1e-6 m and 1e-6 rad (the fit stops
/// on a step or gradient tolerance, not at the exact optimum: the
/// optimality conditions hold to the last step's size, well below the
/// 0.3 mm residuals; a wrong point or plane convention is off by
/// millimetres or more).
#[test]
fn fitted_points_and_planes_agree_with_pinocchio() {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let robot = panda();
    let (file, _, known, fit) = three_placements_and_a_table(&robot);
    let pin = pinocchio_tool_points(&bridge, &fit.robot, &fit.table, &fit.tool_offset, &file.qs);
    let ours = tool_points(&fit.robot, &fit.table, &fit.tool_offset, &file.qs);
    let dev = pin
        .iter()
        .zip(&ours)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0f64, f64::max);
    // An L2 fit's optimality for point A: Σ_rows (P_A − t_i) plus the
    // distance row's pull w²(‖P_A − P_B‖ − d)·u_AB is zero (w the distance
    // weight): the point is its rows' mean, moved by its distance.
    let at = |g: usize| Vector3::from(fit.point_positions[g]);
    let (mut worst_point, mut plain_mean) = (0.0f64, 0.0f64);
    for g in 0..file.points.len() {
        let rows = file.rows_of(g);
        let mean = rows.iter().map(|&i| pin[i]).sum::<Vector3<f64>>() / rows.len() as f64;
        plain_mean = plain_mean.max((mean - at(g)).norm());
        let mut grad: Vector3<f64> = rows.iter().map(|&i| at(g) - pin[i]).sum();
        for k in known.iter().filter(|k| k.a == g || k.b == g) {
            let v = at(g) - at(if k.a == g { k.b } else { k.a });
            grad += DISTANCE_WEIGHT.powi(2) * (v.norm() - k.metres) * v / v.norm();
        }
        worst_point = worst_point.max(grad.norm() / rows.len() as f64);
    }
    let g0 = file.points.len();
    let plane = &fit.planes[0];
    let on: Vec<Vector3<f64>> = file.rows_of(g0).iter().map(|&i| pin[i]).collect();
    let (n, d) = best_plane(&on);
    let (n, d) = if n.dot(&Vector3::from(plane.normal)) < 0.0 {
        (-n, -d)
    } else {
        (n, d)
    };
    let angle = n.angle(&Vector3::from(plane.normal));
    let offset = (d - plane.offset_m).abs();
    println!(
        "tool points: max |Pinocchio − activecal| {dev:.2e} m; points' optimality vs Pinocchio {worst_point:.2e} m (their rows' plain means {plain_mean:.2e} m off); plane: normal {angle:.2e} rad, offset {offset:.2e} m; σ̂ {:?} m",
        fit.sigma_hat
    );
    assert!(dev <= 1e-9, "{dev}");
    assert!(worst_point <= 1e-6, "{worst_point}");
    assert!(angle <= 1e-6 && offset <= 1e-6, "{angle} rad, {offset} m");
    // The checks can fail: the distance's pull is seen (a point is not its
    // rows' plain mean), and a plane offset shifted by a millimetre would be.
    assert!(plain_mean > 1e-5, "{plain_mean}");
    assert!((d + 1e-3 - plane.offset_m).abs() > 1e-4);
}

/// What `calibrate --out cal.urdf --out cal.yaml` writes for a contact fit
/// (the same renderers, [`contact_frames`] and [`render`]), written to
/// files: Pinocchio loads the written URDF, and its `ball_link` placement
/// composed with the written frames file's measurement frame and `point`
/// (read back by the reader `--frames` uses) gives activecal's fitted tool
/// point of every row to 1e-9 m (the bar of `live_export`: rounding is
/// ~1e-15 m over two chains of ~10 metre-size products and shortest
/// round-trip decimals; the fitted tool offset alone is over 1 mm, and a
/// joint origin's change 0.1–1 mm, so a dropped or misplaced frame fails by
/// six orders of magnitude). The fitted points and plane in the file are
/// the fit's.
#[test]
fn the_written_urdf_and_frames_give_the_fitted_tool_points_in_pinocchio() {
    let bridge = Bridge::new().expect("Python bridge (run scripts/setup)");
    let robot = panda();
    let (file, given, _, fit) = three_placements_and_a_table(&robot);
    let block = FitBlock {
        poses: file.qs.len(),
        position_rms_mm: 0.0,
        orientation_rms_deg: None,
    };
    let (frames, report) = contact_frames(&fit, &given, block)
        .expect("the split")
        .expect("a URDF robot");
    let dir = std::env::temp_dir().join(format!(
        "activecal-live-contacts-written-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let (urdf, yaml) = (dir.join("cal.urdf"), dir.join("cal.yaml"));
    for (path, format) in [(&urdf, Format::Urdf), (&yaml, Format::Yaml)] {
        let text = render(format, &fit.robot, &fit.table, Some((&frames, &report)), "").unwrap();
        std::fs::write(path, text).unwrap();
    }
    let read = frames_file::read(&yaml).expect("the written frames file");
    let pin = pinocchio_ball(&bridge, &urdf, &robot, &file.qs);
    let ours = tool_points(&fit.robot, &fit.table, &fit.tool_offset, &file.qs);
    let at = |p: &verify::erd_fk::Placement| {
        let r = Matrix3::from_fn(|i, j| p.rotation[i][j]);
        let ball = Vector3::from(p.position) + r * read.tool.translation.vector;
        read.mount * nalgebra::Point3::from(ball)
    };
    let dev = pin
        .iter()
        .zip(&ours)
        .map(|(p, o)| (at(p).coords - o).norm())
        .fold(0.0f64, f64::max);
    // Without the tool point (the chain's tip alone) it is off by the
    // fitted offset: the check sees a missing tool.
    let bare = pin
        .iter()
        .zip(&ours)
        .map(|(p, o)| (read.mount * nalgebra::Point3::from(Vector3::from(p.position))).coords - o)
        .map(|d| d.norm())
        .fold(f64::INFINITY, f64::min);
    let text = std::fs::read_to_string(&yaml).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    println!(
        "written files in Pinocchio: max |tool point − activecal's| {dev:.2e} m over {} rows; the tip alone is off by at least {bare:.2e} m",
        file.qs.len()
    );
    assert!(dev <= 1e-9, "{dev} m");
    assert!(bare > 1e-4, "{bare} m");
    for name in &fit.points {
        assert!(text.contains(&format!("name: {name}")), "{name}");
    }
    assert!(text.contains("name: table"));
}
