//! The 3D page of a camera design (`select --camera-info … --report`): the
//! robot at the chosen poses, the camera's placement with its field of
//! view, and the board's outline at every pose.

use super::page::{Page, SensorView, column_major};
use super::pages::add_figures;
use crate::error::Result;
use crate::how_many::PoseCountCurve;
use crate::measure::camera::Mounting;
use crate::select::camera::CameraDesign;
use nalgebra::{Isometry3, Point3};
use std::path::Path;

/// The camera's placement and the board's outline at each pose of `d`, in
/// the page's frame.
fn camera_view(d: &CameraDesign, page: &Page) -> SensorView {
    let s = &d.sensor;
    let (cam, tgt) = s.placements(&d.own);
    let mount = page.mount();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in s.points() {
        for i in 0..2 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    let corners = [
        [lo[0], lo[1]],
        [hi[0], lo[1]],
        [hi[0], hi[1]],
        [lo[0], hi[1]],
    ];
    let (mut placements, mut boards) = (Vec::new(), Vec::new());
    for q in &d.qs {
        let to_base = page.measurement_to_page(q, mount);
        let (r, p) = crate::kinematics::pose(&d.robot, &d.robot.nominal, q);
        let end = Isometry3::from_parts(p.into(), nalgebra::UnitQuaternion::from_matrix(&r));
        let (c, t) = match s.mounting() {
            Mounting::EyeToHand => (cam, end * tgt),
            Mounting::EyeInHand => (end * cam, tgt),
        };
        placements.push(column_major(&(to_base * c)));
        boards.push(
            corners
                .iter()
                .map(|[x, y]| {
                    let b = to_base * t * Point3::new(*x, *y, 0.0);
                    [b.x, b.y, b.z]
                })
                .collect(),
        );
    }
    let i = s.intrinsics();
    let fov = [
        2.0 * (f64::from(i.width) / (2.0 * i.fx)).atan(),
        2.0 * (f64::from(i.height) / (2.0 * i.fy)).atan(),
    ];
    SensorView::Camera {
        placements,
        boards,
        fov,
    }
}

/// Writes the page of a camera design into `out`.
pub fn camera_selection(
    out: &Path,
    d: &CameraDesign,
    curve: &PoseCountCurve,
    figs: &[(String, String)],
) -> Result<()> {
    let robot = &d.robot;
    let mut page = Page::new(
        &format!(
            "Camera pose selection: {} poses of {}",
            d.qs.len(),
            robot.name
        ),
        robot,
        &[],
    );
    let poses: Vec<(String, Vec<f64>)> =
        d.qs.iter()
            .zip(&d.candidates)
            .zip(&d.seen)
            .enumerate()
            .map(|(k, ((q, c), seen))| {
                (
                    format!("pose {} (candidate {c}, {seen} points seen)", k + 1),
                    q.clone(),
                )
            })
            .collect();
    page.add_poses(robot, &robot.nominal, &poses);
    page.add_moves(robot, &robot.nominal, None, &[]);
    page.sensor = Some(camera_view(d, &page));
    page.sections.push(super::pages::curve_table(curve));
    add_figures(&mut page, out, figs);
    page.write(out)
}
