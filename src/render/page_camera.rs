//! The 3D page of a camera design (`select --camera-info … --report`): the
//! robot at the chosen poses, the camera's placement with its field of
//! view, the board's outline and the lines of sight checked at every pose.

use super::page::{Page, RayView, SensorView, column_major};
use super::pages::add_figures;
use crate::error::Result;
use crate::how_many::PoseCountCurve;
use crate::measure::camera::Mounting;
use crate::pool::line_of_sight::SightLines;
use crate::select::camera::CameraDesign;
use nalgebra::{Isometry3, Point3};
use std::path::Path;

/// What the 3D page of a camera design shows: the design, and the lines
/// of sight checked at each of its poses (empty without a check).
#[derive(Clone, Copy, Debug)]
pub struct CameraPage<'a> {
    /// The design.
    pub design: &'a CameraDesign,
    /// The lines of sight at each pose, in order.
    pub lines: &'a [SightLines],
    /// Where `package://` meshes are looked for first.
    pub package_dirs: &'a [String],
}

/// The camera's placement, the board's outline and the lines of sight
/// checked (`lines`, one per pose or none) at each pose of `d`, in the
/// page's frame.
fn camera_view(d: &CameraDesign, lines: &[SightLines], page: &Page) -> SensorView {
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
    let (mut placements, mut boards, mut rays) = (Vec::new(), Vec::new(), Vec::new());
    for (k, q) in d.qs.iter().enumerate() {
        let to_base = page.measurement_to_page(q, mount);
        if let Some(l) = lines.get(k) {
            rays.push(ray_views(l, &to_base));
        }
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
        rays,
    }
}

/// The rays of `l` to the points inside the image (those the check is
/// about), in the page's frame (`to_page` from the camera chain's base).
fn ray_views(l: &SightLines, to_page: &Isometry3<f64>) -> Vec<RayView> {
    let at = |p: &Point3<f64>| {
        let b = to_page * p;
        [b.x, b.y, b.z]
    };
    let from = at(&l.eye);
    l.points
        .iter()
        .zip(&l.inside)
        .zip(&l.blocked)
        .filter(|((_, inside), _)| **inside)
        .map(|((p, _), blocked)| RayView {
            from,
            to: at(p),
            clear: !blocked,
        })
        .collect()
}

/// Writes the page of a camera design into `out`, with the lines of sight
/// checked at its poses (`c.lines`: one per pose, or none).
pub fn camera_selection(
    out: &Path,
    c: &CameraPage<'_>,
    curve: &PoseCountCurve,
    figs: &[(String, String)],
) -> Result<()> {
    let (d, lines) = (c.design, c.lines);
    let robot = &d.robot;
    let mut page = Page::new(
        &format!(
            "Camera pose selection: {} poses of {}",
            d.qs.len(),
            robot.name
        ),
        robot,
        c.package_dirs,
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
    page.sensor = Some(camera_view(d, lines, &page));
    page.sections.push(super::pages::curve_table(curve));
    add_figures(&mut page, out, figs);
    page.write(out)
}
