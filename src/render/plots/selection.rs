//! The figures of `select --report`: the "how many poses" curve, the
//! selected poses within their joint limits, and the tour.

use super::{AFTER, Area, BEFORE, DOUBLE, FONT, WIDE, legend, range};
use crate::error::Result;
use crate::render::figure::{both, err};
use plotters::prelude::*;
use std::path::Path;

/// One design size of [`how_many`].
pub struct CurveRow {
    /// Poses.
    pub n: usize,
    /// D-efficiency against the certified bound.
    pub d_efficiency: f64,
    /// Predicted RMS position error, mm.
    pub rms_mm: f64,
    /// Predicted 95th percentile of the error, mm.
    pub p95_mm: f64,
}

/// The "how many poses" curve: D-efficiency (left) and the predicted
/// position error, RMS and 95th percentile (right), against N; the chosen N
/// marked.
pub fn how_many(base: &Path, rows: &[CurveRow], chosen: usize, noise: &str) -> Result<()> {
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        rows: &[CurveRow],
        chosen: usize,
        noise: &str,
    ) -> Result<()> {
        let (l, r) = root.split_horizontally(DOUBLE.0 / 2);
        let n0 = rows.first().map_or(1, |r| r.n) as f64 - 0.5;
        let n1 = rows.last().map_or(2, |r| r.n) as f64 + 0.5;
        let eff: Vec<f64> = rows.iter().map(|r| r.d_efficiency).collect();
        let (elo, _) = range(&eff, false);
        let mut c = ChartBuilder::on(&l)
            .caption("Best design found vs the certified bound", (FONT, 19))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(75)
            .build_cartesian_2d(n0..n1, elo.min(0.95)..1.0)
            .map_err(err)?;
        c.configure_mesh()
            .x_desc("poses in the design, N")
            .y_desc("D-efficiency (1 = the bound)")
            .axis_desc_style((FONT, 16))
            .label_style((FONT, 14))
            .x_label_formatter(&|x| format!("{x:.0}"))
            .draw()
            .map_err(err)?;
        c.draw_series(LineSeries::new(
            rows.iter().map(|r| (r.n as f64, r.d_efficiency)),
            AFTER.stroke_width(2),
        ))
        .map_err(err)?
        .label("D-efficiency")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], AFTER.stroke_width(2)));
        c.draw_series(
            rows.iter()
                .map(|r| Circle::new((r.n as f64, r.d_efficiency), 3, AFTER.filled())),
        )
        .map_err(err)?;
        legend(&mut c, SeriesLabelPosition::LowerRight)?;

        let all: Vec<f64> = rows.iter().flat_map(|r| [r.rms_mm, r.p95_mm]).collect();
        let (_, hi) = range(&all, true);
        let mut e = ChartBuilder::on(&r)
            .caption(
                format!("Predicted error after calibration (σ = {noise})"),
                (FONT, 19),
            )
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(75)
            .build_cartesian_2d(n0..n1, 0f64..hi)
            .map_err(err)?;
        e.configure_mesh()
            .x_desc("poses in the design, N")
            .y_desc("position error at random poses (mm)")
            .axis_desc_style((FONT, 16))
            .label_style((FONT, 14))
            .x_label_formatter(&|x| format!("{x:.0}"))
            .draw()
            .map_err(err)?;
        for (f, col, label) in [
            (
                &(|r: &CurveRow| r.rms_mm) as &dyn Fn(&CurveRow) -> f64,
                AFTER,
                "RMS",
            ),
            (
                &|r: &CurveRow| r.p95_mm,
                BEFORE,
                "95th percentile of the error",
            ),
        ] {
            e.draw_series(LineSeries::new(
                rows.iter().map(|r| (r.n as f64, f(r))),
                col.stroke_width(2),
            ))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], col.stroke_width(2)));
            e.draw_series(
                rows.iter()
                    .map(|r| Circle::new((r.n as f64, f(r)), 3, col.filled())),
            )
            .map_err(err)?;
        }
        if rows.iter().any(|r| r.n == chosen) {
            e.draw_series(std::iter::once(PathElement::new(
                [(chosen as f64, 0.0), (chosen as f64, hi)],
                BLACK.stroke_width(1),
            )))
            .map_err(err)?
            .label(format!("N = {chosen} (the design)"))
            .legend(|(x, y)| PathElement::new([(x + 10, y - 7), (x + 10, y + 7)], BLACK));
        }
        legend(&mut e, SeriesLabelPosition::UpperRight)
    }
    both!(base, DOUBLE, |r| draw(r, rows, chosen, noise))
}

/// One joint of [`joints_vs_limits`].
pub struct JointRow {
    /// Name, with its limits and unit (the y-axis label).
    pub label: String,
    /// The design's values as a fraction of the range (0 = lower limit,
    /// 1 = upper).
    pub fractions: Vec<f64>,
}

/// The selected poses' joint values within their limits: one row per
/// joint, the range from its lower (0 %) to its upper limit (100 %).
pub fn joints_vs_limits(base: &Path, joints: &[JointRow]) -> Result<()> {
    fn draw<DB: DrawingBackend>(root: &Area<DB>, joints: &[JointRow]) -> Result<()> {
        let n = joints.len().max(1);
        let mut c = ChartBuilder::on(root)
            .caption("Selected poses' joint values within the limits", (FONT, 22))
            .margin(15)
            .x_label_area_size(55)
            // Monospace labels at 13 px: about 8 px a character.
            .y_label_area_size(
                20 + 8 * joints
                    .iter()
                    .map(|j| j.label.chars().count())
                    .max()
                    .unwrap_or(4) as u32,
            )
            // Room right of 100 % for the legend, clear of the poses.
            .build_cartesian_2d(-5f64..140.0, -0.6f64..n as f64 - 0.4)
            .map_err(err)?;
        c.configure_mesh()
            .x_desc("position in the joint's range (%: 0 = lower limit, 100 = upper)")
            .x_label_formatter(&|x| {
                if *x <= 100.0 + 1e-9 {
                    format!("{x:.0}")
                } else {
                    String::new()
                }
            })
            .axis_desc_style((FONT, 16))
            .label_style((FONT, 13))
            .y_labels(n)
            .y_label_formatter(&|y| {
                let k = y.round();
                if (y - k).abs() < 1e-6 && k >= 0.0 {
                    joints
                        .get(n - 1 - k as usize)
                        .map(|j| j.label.clone())
                        .unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .disable_y_mesh()
            .draw()
            .map_err(err)?;
        let y = |k: usize| (n - 1 - k) as f64;
        c.draw_series((0..joints.len()).map(|k| {
            Rectangle::new(
                [(0.0, y(k) - 0.25), (100.0, y(k) + 0.25)],
                RGBColor(225, 225, 225).filled(),
            )
        }))
        .map_err(err)?
        .label("joint range")
        .legend(|(x, y)| {
            Rectangle::new(
                [(x, y - 6), (x + 16, y + 6)],
                RGBColor(225, 225, 225).filled(),
            )
        });
        c.draw_series(joints.iter().enumerate().flat_map(|(k, j)| {
            let m = j.fractions.len().max(1) as f64;
            j.fractions.iter().enumerate().map(move |(i, &f)| {
                // A small vertical spread keeps poses on one value apart.
                let dy = (i as f64 / m - 0.5) * 0.4;
                Circle::new((f * 100.0, y(k) + dy), 3, AFTER.filled())
            })
        }))
        .map_err(err)?
        .label("a selected pose")
        .legend(|(x, y)| Circle::new((x + 8, y), 3, AFTER.filled()));
        legend(&mut c, SeriesLabelPosition::UpperRight)
    }
    both!(base, (1000, 120 + 70 * joints.len().max(1) as u32), |r| {
        draw(r, joints)
    })
}

/// The tour: each joint's value (degrees; mm for a prismatic joint) at
/// every pose in visiting order, against the cumulative move time.
pub fn tour(base: &Path, names: &[String], times: &[f64], values: &[Vec<f64>]) -> Result<()> {
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        names: &[String],
        times: &[f64],
        values: &[Vec<f64>],
    ) -> Result<()> {
        let all: Vec<f64> = values.iter().flatten().copied().collect();
        let (lo, hi) = range(&all, false);
        let t1 = times.last().copied().unwrap_or(1.0).max(1e-9);
        let mut c = ChartBuilder::on(root)
            .caption("Visiting order: joint values along the tour", (FONT, 22))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(80)
            .build_cartesian_2d(0f64..t1 * 1.25, lo..hi)
            .map_err(err)?;
        c.configure_mesh()
            .x_desc("cumulative move time at each pose (s)")
            .y_desc("joint value (degrees; mm for prismatic)")
            .axis_desc_style((FONT, 16))
            .label_style((FONT, 14))
            .draw()
            .map_err(err)?;
        for (j, name) in names.iter().enumerate() {
            let col = Palette99::pick(j).to_rgba();
            c.draw_series(LineSeries::new(
                times.iter().zip(values).map(|(&t, q)| (t, q[j])),
                col.stroke_width(2),
            ))
            .map_err(err)?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], col.stroke_width(2)));
            c.draw_series(
                times
                    .iter()
                    .zip(values)
                    .map(|(&t, q)| Circle::new((t, q[j]), 3, col.filled())),
            )
            .map_err(err)?;
        }
        legend(&mut c, SeriesLabelPosition::UpperRight)
    }
    both!(base, WIDE, |r| draw(r, names, times, values))
}
