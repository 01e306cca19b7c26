//! The 3D page ([`super::page`]) of each report folder, assembled from the
//! report it shows: the poses in visiting order, the tour's moves, the
//! scene of the pool's collision filter, the sensor, the tables and the
//! figures just drawn.

use super::page::{Page, SensorView, figure, table};
pub use super::summary::FitPoses;
use crate::collision::CollisionSpec;
use crate::error::Result;
use crate::how_many::PoseCountCurve;
use crate::measure::ToolRecord;
use crate::model::Robot;
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

/// A tracker at the measurement frame's origin, for sensors that record a
/// tool point or frame ([`crate::measure::Sensor::tool_record`]; markers
/// have their own view) (in the base link's frame, the base at `mount` in the
/// measurement frame).
pub fn add_tracker(page: &mut Page, robot: &Robot, mount: nalgebra::Isometry3<f64>) {
    if matches!(
        crate::measure::sensor_for(robot).tool_record(),
        ToolRecord::Point | ToolRecord::Frame
    ) {
        let q0 = page
            .poses
            .first()
            .map(|p| p.q.clone())
            .unwrap_or_else(|| vec![0.0; robot.dof()]);
        let at = page.measurement_to_page(&q0, mount) * Point3::origin();
        page.sensor = Some(SensorView::Tracker {
            position: [at.x, at.y, at.z],
        });
    }
}

/// The "how many poses" table.
pub(super) fn curve_table(curve: &PoseCountCurve) -> String {
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
fn collision_filter(report: &SelectReport) -> Option<&crate::collision::CollisionFilter> {
    report.pool.pool.filters.iter().find_map(|f| match f {
        PoolFilter::Collision(c) => Some(c),
        _ => None,
    })
}

/// The least clearance of each pose and move, by the pool's collision
/// filter (a note when its model does not load).
fn add_clearances(page: &mut Page, filter: &crate::collision::CollisionFilter) {
    match filter.load() {
        Ok(model) => {
            page.add_clearances(&model);
            page.notes.push("Clearance: the least distance between the links (and obstacles) the collision filter checks, at each pose and over each move's drawn samples; the two closest are drawn red.".into());
        }
        Err(e) => page.notes.push(format!("clearances are not shown: {e}")),
    }
}

/// The page of `select --report`.
pub fn selection(
    out: &Path,
    robot: &Robot,
    report: &SelectReport,
    curve: &PoseCountCurve,
    figs: &[(String, String)],
) -> Result<()> {
    let filter = collision_filter(report);
    let spec = filter.map(|f| &f.spec);
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
    if let Some(f) = filter {
        add_scene(&mut page, &f.spec);
        add_clearances(&mut page, f);
    }
    let mount = page.mount();
    add_tracker(&mut page, robot, mount);
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

/// A power of ten that draws the largest of `sizes` (metres) at about
/// 5 cm: the magnification of residuals and of the calibrated robot's
/// difference, between 1 and 10⁴.
#[must_use]
pub fn magnification(sizes: impl Iterator<Item = f64>) -> f64 {
    let largest = sizes.filter(|x| x.is_finite()).fold(0.0, f64::max);
    if largest <= 0.0 {
        return 1.0;
    }
    10f64.powf((0.05 / largest).log10().floor().clamp(0.0, 4.0))
}

/// The parameter table of a calibration: each parameter's change and σ,
/// lengths in mm and angles in degrees.
fn parameter_table(params: &[(String, f64, Option<f64>)]) -> String {
    let rows: Vec<Vec<String>> = params
        .iter()
        .map(|(name, change, sigma)| {
            let (to, unit) = if super::summary::is_angle(name) {
                (180.0 / std::f64::consts::PI, "°")
            } else {
                (1e3, " mm")
            };
            vec![
                name.clone(),
                format!("{:.4}{unit}", change * to),
                sigma.map_or("-".into(), |v| format!("{:.4}{unit}", v * to)),
            ]
        })
        .collect();
    table(
        "Parameters: change from nominal and σ (the calibrated robot is drawn orange over the nominal one)",
        &["parameter", "change", "σ"],
        &rows,
    )
}

/// The page of `calibrate --report`.
pub fn calibration(
    out: &Path,
    s: &super::summary::CalibrationSummary<'_>,
    figs: &[(String, String)],
) -> Result<()> {
    let robot = s.robot;
    let mut page = Page::new(&format!("Calibration of {}", robot.name), robot, &[]);
    if let Some(f) = &s.poses {
        let labels: Vec<(String, Vec<f64>)> =
            f.qs.iter()
                .enumerate()
                .map(|(k, q)| (format!("pose {}", k + 1), q.clone()))
                .collect();
        page.add_poses(robot, &robot.nominal, &labels);
        let mount = add_fit(&mut page, robot, &s.id.table, f);
        add_tracker(&mut page, robot, mount);
    }
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
    page.sections.push(table(
        &format!("Position error per {} (mm)", s.what),
        &["", "nominal", "calibrated"],
        &[vec![
            "RMS".into(),
            format!("{:.4}", rms(&s.position_mm.0)),
            format!("{:.4}", rms(&s.position_mm.1)),
        ]],
    ));
    page.sections.push(parameter_table(&s.params));
    add_figures(&mut page, out, figs);
    page.write(out)
}

/// The calibrated robot, the measured and fitted points and the marks of
/// a fit's poses (already added to `page`, in order); returns the
/// calibrated measurement frame (the base link's pose in it).
fn add_fit(
    page: &mut Page,
    robot: &Robot,
    fitted: &crate::model::ParamTable,
    f: &FitPoses,
) -> nalgebra::Isometry3<f64> {
    // The calibrated model in its own measurement frame: its base drawn on
    // the nominal base, so the difference shown is the robot's.
    let mount = crate::frames::decompose(robot, fitted)
        .map(|f| f.measurement)
        .unwrap_or_else(|_| page.mount());
    let (mut sizes, mut residuals) = (Vec::new(), Vec::new());
    for (k, q) in f.qs.iter().enumerate() {
        let to_page = page.measurement_to_page(q, mount);
        let point = |p: nalgebra::Vector3<f64>| {
            let b = to_page * Point3::from(p);
            [b.x, b.y, b.z]
        };
        let cal: Vec<[f64; 16]> = page
            .place_mounted(robot, fitted, q, mount)
            .iter()
            .map(super::page::column_major)
            .collect();
        // The measured point: the end point, or the first marker on it.
        let (r, e) = crate::kinematics::pose(robot, fitted, q);
        let fit = fitted
            .markers
            .first()
            .map_or(e, |o| e + r * nalgebra::Vector3::from(*o));
        let pose = &mut page.poses[k];
        for (c, n) in cal.iter().zip(&pose.links) {
            sizes.push(
                ((c[12] - n[12]).powi(2) + (c[13] - n[13]).powi(2) + (c[14] - n[14]).powi(2))
                    .sqrt(),
            );
        }
        pose.calibrated = Some(cal);
        pose.fitted = Some(point(fit));
        if let Some(m) = f.measured.as_ref().and_then(|m| m.get(k)) {
            let m = nalgebra::Vector3::from(*m);
            pose.measured = Some(point(m));
            if !f.flagged.contains(&k) {
                residuals.push((m - fit).norm());
            }
        }
        if f.flagged.contains(&k) {
            pose.mark = Some("flagged".into());
        }
    }
    page.magnify = Some(magnification(residuals.into_iter()));
    page.magnify_robot = Some(magnification(sizes.into_iter()));
    mount
}
