//! The 3D page ([`super::page`]) of each report folder, assembled from the
//! report it shows: the poses in visiting order, the tour's moves, the
//! scene of the pool's collision filter, the sensor, the tables and the
//! figures just drawn.

use super::page::{Page, SensorView, figure, table};
use crate::collision::CollisionSpec;
use crate::error::Result;
use crate::how_many::PoseCountCurve;
use crate::model::{MeasurementKind, Robot};
use crate::pool::PoolFilter;
use crate::report::SelectReport;
use nalgebra::Point3;
use std::path::Path;

/// The figures of a report folder, embedded (stems and captions).
pub fn add_figures(page: &mut Page, out: &Path, figs: &[(String, String)]) {
    for (stem, caption) in figs {
        if let Some(f) = figure(caption, &out.join(format!("{stem}.png"))) {
            page.figures.push(f);
        }
    }
}

/// The page's scene (floor, obstacles) from a collision filter's spec.
pub fn add_scene(page: &mut Page, spec: &CollisionSpec) {
    page.floor = spec.floor;
    page.obstacles = spec.obstacles.clone();
}

/// A tracker at the measurement frame's origin, for point and pose
/// measurements (in the base link's frame).
pub fn add_tracker(page: &mut Page, robot: &Robot) {
    if matches!(
        robot.measurement,
        MeasurementKind::Point | MeasurementKind::Pose
    ) {
        let mount = robot.source.as_ref().filter(|_| page.urdf).map(|s| s.mount);
        let at = mount.map_or(Point3::origin(), |m| m.inverse() * Point3::origin());
        page.sensor = Some(SensorView::Tracker {
            position: [at.x, at.y, at.z],
        });
    }
}

/// The "how many poses" table.
fn curve_table(curve: &PoseCountCurve) -> String {
    let rows: Vec<Vec<String>> = curve
        .points
        .iter()
        .map(|p| {
            vec![
                p.n.to_string(),
                format!("{:.4}", p.d_efficiency),
                format!("{:.4}", p.predicted.position_rms_mm),
                format!("{:.4}", p.predicted.position_error_p95_mm),
            ]
        })
        .collect();
    table(
        "How many poses: the best design at each N, its D-efficiency against the certified bound, and the predicted position error",
        &[
            "N",
            "D-efficiency",
            "predicted RMS (mm)",
            "95th percentile (mm)",
        ],
        &rows,
    )
}

/// The collision filter of a pool, if it has one.
fn collision_spec(report: &SelectReport) -> Option<&CollisionSpec> {
    report.pool.pool.filters.iter().find_map(|f| match f {
        PoolFilter::Collision(c) => Some(&c.spec),
        _ => None,
    })
}

/// The page of `select --report`.
pub fn selection(
    out: &Path,
    robot: &Robot,
    report: &SelectReport,
    curve: &PoseCountCurve,
    figs: &[(String, String)],
) -> Result<()> {
    let spec = collision_spec(report);
    let dirs = spec.map(|s| s.package_dirs.clone()).unwrap_or_default();
    let mut page = Page::new(
        &format!(
            "Pose selection: {} poses of {}",
            report.poses.len(),
            robot.name
        ),
        robot,
        &dirs,
    );
    let poses: Vec<(String, Vec<f64>)> = report
        .configurations
        .iter()
        .enumerate()
        .map(|(k, c)| (format!("pose {} (pool id {})", k + 1, c.id), c.q.clone()))
        .collect();
    page.add_poses(robot, &robot.nominal, &poses);
    let vias: Vec<(Option<usize>, usize, Vec<f64>)> = report
        .moves
        .iter()
        .flat_map(|m| m.via.iter().map(|v| (v.from, v.to, v.q.clone())))
        .collect();
    let home = report.tour.as_ref().and_then(|t| t.home.as_deref());
    page.add_moves(robot, &robot.nominal, home, &vias);
    if let Some(s) = spec {
        add_scene(&mut page, s);
    }
    add_tracker(&mut page, robot);
    let mut summary = vec![
        vec!["poses".into(), report.poses.len().to_string()],
        vec![
            "log10 OI_D (det XᵀX)".into(),
            format!("{:.4}", report.log10_oid),
        ],
    ];
    if let (Some(d), Some(b)) = (report.d_efficiency, report.log10_bound) {
        summary.push(vec![
            "D-efficiency against the bound".into(),
            format!("{d:.4}"),
        ]);
        summary.push(vec![
            "log10 of the certified bound".into(),
            format!("{b:.4}"),
        ]);
    }
    if let Some(t) = &report.tour {
        summary.push(vec![
            "tour time (s), visiting order".into(),
            format!("{:.2}", t.visiting_order.time_s),
        ]);
    }
    page.sections
        .push(table("The design", &["", "value"], &summary));
    page.sections.push(curve_table(curve));
    add_figures(&mut page, out, figs);
    page.write(out)
}
