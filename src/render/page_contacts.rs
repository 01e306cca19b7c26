//! The 3D page of a contact calibration (`calibrate --measurements
//! contacts.csv --report DIR`): the robot at each contact's configuration,
//! the fitted sockets as spheres and the planes as translucent squares
//! about the contacts that touched them, the text report and the figures.

use super::contact_figures::ContactReport;
use super::page::{Page, PlaneView, SensorView, SocketView};
use super::pages::add_figures;
use crate::error::Result;
use crate::identify::contact::tool_points;
use nalgebra::{Isometry3, Point3, Vector3};
use std::path::Path;

/// Least half-width of a plane's square (metres): a plane touched once is
/// still drawn as a visible patch.
const PLANE_HALF_MIN: f64 = 0.05;
/// Margin of a plane's square beyond its farthest contact (metres).
const PLANE_MARGIN: f64 = 0.03;

/// The sockets and planes of `r`'s fit in the page's frame (`to_page`:
/// from the base frame the fit is expressed in).
fn contact_view(r: &ContactReport<'_>, to_page: &Isometry3<f64>) -> SensorView {
    let at = |p: &Vector3<f64>| {
        let b = to_page * Point3::from(*p);
        [b.x, b.y, b.z]
    };
    let sockets = r
        .fit
        .points
        .iter()
        .zip(&r.fit.point_positions)
        .map(|(name, p)| SocketView {
            name: name.clone(),
            position: at(&Vector3::from(*p)),
        })
        .collect();
    let tips = tool_points(&r.fit.robot, &r.fit.table, &r.fit.tool_offset, &r.file.qs);
    let n_points = r.file.points.len();
    let planes = r
        .fit
        .planes
        .iter()
        .enumerate()
        .map(|(k, plane)| {
            let n = Vector3::from(plane.normal).normalize();
            // The contacts on the plane, projected onto it.
            let on: Vec<Vector3<f64>> = tips
                .iter()
                .zip(&r.file.groups)
                .filter(|(_, g)| **g == n_points + k)
                .map(|(p, _)| p - (n.dot(p) - plane.offset_m) * n)
                .collect();
            let centre = if on.is_empty() {
                n * plane.offset_m
            } else {
                on.iter().sum::<Vector3<f64>>() / on.len() as f64
            };
            let half = on
                .iter()
                .map(|p| (p - centre).norm() + PLANE_MARGIN)
                .fold(PLANE_HALF_MIN, f64::max);
            // Two unit vectors spanning the plane.
            let seed = if n.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            let u = n.cross(&seed).normalize();
            let v = n.cross(&u);
            let corner = |a: f64, b: f64| at(&(centre + half * (a * u + b * v)));
            PlaneView {
                name: plane.name.clone(),
                corners: [
                    corner(-1.0, -1.0),
                    corner(1.0, -1.0),
                    corner(1.0, 1.0),
                    corner(-1.0, 1.0),
                ],
            }
        })
        .collect();
    SensorView::Contacts { sockets, planes }
}

/// Writes the page of a contact calibration into `out`: the robot at each
/// contact's configuration (`poses`, labelled), the sockets and planes of
/// the fit, the text report and the figures.
pub fn contacts(
    out: &Path,
    r: &ContactReport<'_>,
    text: &str,
    poses: &[(String, Vec<f64>)],
    figs: &[(String, String)],
) -> Result<()> {
    let robot = r.robot;
    let mut page = Page::new(
        &format!("Contact calibration of {}", robot.name),
        robot,
        &[],
    );
    page.add_poses(robot, &robot.nominal, poses);
    let q0 = poses
        .first()
        .map_or_else(|| vec![0.0; robot.dof()], |p| p.1.clone());
    let to_page = page.measurement_to_page(&q0, page.mount());
    page.sensor = Some(contact_view(r, &to_page));
    page.sections
        .push(format!("<pre>{}</pre>\n", super::page::encode::html(text)));
    add_figures(&mut page, out, figs);
    page.write(out)
}
