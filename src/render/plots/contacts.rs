//! The figures of `calibrate --report` for a contact file: each placement's
//! consistency and each known distance's error, nominal against calibrated
//! (and held out), and each row's distance to its point's mean, so that the
//! faulty rows of a recording stand out.

use super::{AFTER, Area, BEFORE, FONT, legend};
use crate::error::Result;
use crate::render::figure::{both, err};
use plotters::prelude::*;
use std::path::Path;

/// The held-out series' colour.
const HELD: RGBColor = RGBColor(40, 150, 70);

/// The size of the bar figure, pixels (two panels side by side).
pub const BARS: (u32, u32) = (1300, 620);
/// The size of the row figure with one panel, pixels.
pub const ROWS_ONE: (u32, u32) = (1300, 560);
/// The size of the row figure with two panels (in-sample and held out).
pub const ROWS_TWO: (u32, u32) = (1300, 980);

/// One bar group: nominal, calibrated (in-sample) and held-out figures in
/// millimetres.
#[derive(Clone, Debug)]
pub struct BarGroup {
    /// What the group is (a placement, a distance).
    pub label: String,
    /// The nominal model's, mm.
    pub nominal_mm: f64,
    /// The calibrated model's on its own rows, mm.
    pub calibrated_mm: f64,
    /// The calibrated model's on rows it was not fitted to, mm.
    pub held_out_mm: Option<f64>,
}

/// One contact row for the row figure.
#[derive(Clone, Debug)]
pub struct RowMark {
    /// Its position on the x axis (1-based; the rows of a placement
    /// together, and a row at the same place in every panel).
    pub rank: usize,
    /// Index of its placement (the figure's segments).
    pub placement: usize,
    /// Its file line.
    pub line: usize,
    /// Its distance to its point's mean, mm.
    pub mm: f64,
    /// Whether a robust loss down-weighted it.
    pub downweighted: bool,
}

/// `[lo, hi]` of a log axis holding every positive finite value of `v`.
fn log_range(v: &[f64]) -> (f64, f64) {
    let pos: Vec<f64> = v
        .iter()
        .copied()
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    let hi = pos.iter().copied().fold(1e-6, f64::max) * 2.0;
    let least = pos
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
        .min(hi / 10.0);
    // Down to a power of ten below the least value (a hair below it, so
    // that the axis labels it): the axis starts at a labelled decade.
    (0.99 * 10f64.powf((least / 1.5).log10().floor()), hi)
}

/// Horizontal grouped bars on a log axis: one row of bars a group, the
/// nominal, calibrated and (when any group has one) held-out figures.
fn bar_panel<DB: DrawingBackend>(
    area: &Area<DB>,
    title: &str,
    x_desc: &str,
    groups: &[BarGroup],
) -> Result<()> {
    let all: Vec<f64> = groups
        .iter()
        .flat_map(|g| [g.nominal_mm, g.calibrated_mm, g.held_out_mm.unwrap_or(0.0)])
        .collect();
    let (lo, hi) = log_range(&all);
    let n = groups.len().max(1);
    let held = groups.iter().any(|g| g.held_out_mm.is_some());
    let series = if held { 3.0 } else { 2.0 };
    let mut c = ChartBuilder::on(area)
        .caption(title, (FONT, 19))
        .margin(15)
        .x_label_area_size(55)
        .y_label_area_size(150)
        .build_cartesian_2d((lo..hi).log_scale(), -0.5f64..n as f64 - 0.5)
        .map_err(err)?;
    let labels: Vec<String> = groups.iter().map(|g| g.label.clone()).collect();
    c.configure_mesh()
        .x_desc(x_desc)
        .y_desc("")
        .axis_desc_style((FONT, 16))
        .label_style((FONT, 13))
        .y_labels(n)
        .y_label_formatter(&|y| {
            let k = y.round();
            if (y - k).abs() < 1e-6 && k >= 0.0 {
                // Top to bottom in the given order.
                labels.get(n - 1 - k as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .x_labels(12)
        .x_label_formatter(&|x| match *x {
            v if v >= 1.0 => format!("{v:.0}"),
            v if v >= 0.1 => format!("{v:.1}"),
            v if v >= 0.01 => format!("{v:.2}"),
            v => format!("{v:.3}"),
        })
        .disable_y_mesh()
        .draw()
        .map_err(err)?;
    let h = 0.8 / series;
    for (s, (_, col, pick)) in KINDS.iter().enumerate().take(series as usize) {
        let bars: Vec<Rectangle<(f64, f64)>> = groups
            .iter()
            .enumerate()
            .filter_map(|(k, g)| {
                let v = pick(g).filter(|v| v.is_finite() && *v > 0.0)?;
                let y = (n - 1 - k) as f64 + 0.4 - (s as f64 + 1.0) * h;
                Some(Rectangle::new([(lo, y), (v, y + h * 0.9)], col.filled()))
            })
            .collect();
        c.draw_series(bars).map_err(err)?;
    }
    Ok(())
}

/// A bar series: its legend label, colour and value of a group.
type Kind = (&'static str, RGBColor, fn(&BarGroup) -> Option<f64>);

/// The bar series, in drawing order.
const KINDS: [Kind; 3] = [
    ("nominal", BEFORE, |g| Some(g.nominal_mm)),
    ("calibrated, on its own rows", AFTER, |g| {
        Some(g.calibrated_mm)
    }),
    ("calibrated, held out", HELD, |g| g.held_out_mm),
];

/// A legend in a strip of its own (above the panels, where it hides no
/// bar): a coloured box and the label of each entry, left to right.
fn legend_strip<DB: DrawingBackend>(area: &Area<DB>, entries: &[(&str, RGBColor)]) -> Result<()> {
    let mut x = 180;
    for (label, col) in entries {
        area.draw(&Rectangle::new([(x, 14), (x + 22, 30)], col.filled()))
            .map_err(err)?;
        area.draw(&Text::new(
            label.to_string(),
            (x + 30, 14),
            (FONT, 16).into_font(),
        ))
        .map_err(err)?;
        x += 60 + 10 * label.chars().count() as i32;
    }
    Ok(())
}

/// Each placement's consistency (left) and each known distance's error
/// (right), nominal against calibrated, and held out when given.
pub fn consistency_bars(
    base: &Path,
    placements: &[BarGroup],
    distances: &[BarGroup],
) -> Result<()> {
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        placements: &[BarGroup],
        distances: &[BarGroup],
    ) -> Result<()> {
        let (strip, panels) = root.split_vertically(44);
        let held = placements
            .iter()
            .chain(distances)
            .any(|g| g.held_out_mm.is_some());
        let entries: Vec<(&str, RGBColor)> = KINDS
            .iter()
            .take(if held { 3 } else { 2 })
            .map(|(l, c, _)| (*l, *c))
            .collect();
        legend_strip(&strip, &entries)?;
        let (left, right) = panels.split_horizontally(BARS.0 / 2);
        bar_panel(
            &left,
            "Consistency per placement",
            "RMS distance to the point's mean (mm, log scale)",
            placements,
        )?;
        bar_panel(
            &right,
            "Distance between points vs known",
            "|predicted − known distance| (mm, log scale)",
            distances,
        )
    }
    both!(base, BARS, |r| draw(r, placements, distances))
}

/// One panel of the row figure: each row's distance over its rank (rows
/// in placement order, `n` places), segments by placement, the largest
/// rows named by their file line, the RMS as a line (its value in the
/// title).
fn row_panel<DB: DrawingBackend>(
    area: &Area<DB>,
    title: &str,
    names: &[String],
    rows: &[RowMark],
    n: usize,
) -> Result<()> {
    let top = rows.iter().map(|r| r.mm).fold(0.0f64, f64::max).max(1e-6) * 1.15;
    let rms = (rows.iter().map(|r| r.mm * r.mm).sum::<f64>() / rows.len().max(1) as f64).sqrt();
    let mut c = ChartBuilder::on(area)
        .caption(format!("{title}: RMS {rms:.3} mm (the line)"), (FONT, 18))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(0f64..n as f64 + 1.0, 0f64..top)
        .map_err(err)?;
    c.configure_mesh()
        .x_desc("contact row, grouped by placement (rank)")
        .y_desc("distance to the point's mean (mm)")
        .axis_desc_style((FONT, 16))
        .label_style((FONT, 13))
        .x_label_formatter(&|x| format!("{x:.0}"))
        .disable_x_mesh()
        .draw()
        .map_err(err)?;
    let palette = [
        RGBColor(30, 90, 200),
        RGBColor(200, 60, 40),
        RGBColor(40, 150, 70),
        RGBColor(150, 60, 170),
        RGBColor(220, 130, 20),
        RGBColor(20, 150, 160),
        RGBColor(120, 90, 40),
        RGBColor(200, 50, 130),
        RGBColor(90, 90, 90),
    ];
    // Each placement's segment: a line after its last row, its name above
    // its first.
    for (p, name) in names.iter().enumerate() {
        let ranks = rows.iter().filter(|r| r.placement == p).map(|r| r.rank);
        let (Some(first), Some(last)) = (ranks.clone().min(), ranks.max()) else {
            continue;
        };
        let x1 = last as f64 + 0.5;
        c.draw_series(std::iter::once(PathElement::new(
            [(x1, 0.0), (x1, top)],
            BLACK.mix(0.25),
        )))
        .map_err(err)?;
        c.draw_series(std::iter::once(Text::new(
            name.clone(),
            (first as f64 + 0.5, top * 0.97),
            (FONT, 12).into_font().color(&palette[p % palette.len()]),
        )))
        .map_err(err)?;
    }
    c.draw_series(LineSeries::new(
        [(0.0, rms), (n as f64 + 1.0, rms)],
        BLACK.stroke_width(1),
    ))
    .map_err(err)?;
    c.draw_series(rows.iter().map(|r| {
        Circle::new(
            (r.rank as f64, r.mm),
            3,
            palette[r.placement % palette.len()].filled(),
        )
    }))
    .map_err(err)?;
    if rows.iter().any(|r| r.downweighted) {
        c.draw_series(
            rows.iter()
                .filter(|r| r.downweighted)
                .map(|r| Circle::new((r.rank as f64, r.mm), 6, BLACK.stroke_width(1))),
        )
        .map_err(err)?
        .label("down-weighted by the robust loss")
        .legend(|(x, y)| Circle::new((x + 10, y), 6, BLACK.stroke_width(1)));
        legend(&mut c, SeriesLabelPosition::MiddleRight)?;
    }
    c.draw_series(
        line_labels(rows, top)
            .into_iter()
            .map(|(x, y, text)| Text::new(text, (x + 2.0, y), (FONT, 12).into_font())),
    )
    .map_err(err)?;
    Ok(())
}

/// The labels of the five largest rows (`line N`), rows that would print
/// on one another (within 15 ranks and 4 % of the axis) sharing one label
/// (`lines N, M`): (rank, value, text).
fn line_labels(rows: &[RowMark], top: f64) -> Vec<(f64, f64, String)> {
    let mut order: Vec<usize> = (0..rows.len()).collect();
    order.sort_by(|&a, &b| rows[b].mm.total_cmp(&rows[a].mm));
    let mut labels: Vec<(f64, f64, Vec<usize>)> = Vec::new();
    for &i in order.iter().take(5) {
        let (x, y) = (rows[i].rank as f64, rows[i].mm);
        match labels
            .iter_mut()
            .find(|(lx, ly, _)| (lx - x).abs() <= 15.0 && (ly - y).abs() <= 0.04 * top)
        {
            Some(l) => l.2.push(rows[i].line),
            None => labels.push((x, y, vec![rows[i].line])),
        }
    }
    labels
        .into_iter()
        .map(|(x, y, mut lines)| {
            lines.sort_unstable();
            let list: Vec<String> = lines.iter().map(ToString::to_string).collect();
            let word = if lines.len() > 1 { "lines" } else { "line" };
            (x, y, format!("{word} {}", list.join(", ")))
        })
        .collect()
}

/// Each contact row's distance to its point's mean under the calibrated
/// model: on the rows it was fitted to, and (when given) under the model
/// that held the row's placement out.
pub fn row_distances(
    base: &Path,
    names: &[String],
    in_sample: &[RowMark],
    held_out: Option<&[RowMark]>,
) -> Result<()> {
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        names: &[String],
        in_sample: &[RowMark],
        held_out: Option<&[RowMark]>,
    ) -> Result<()> {
        let first = "Distance to the point's mean, calibrated, rows it was fitted to";
        let n = in_sample.len();
        match held_out {
            Some(h) => {
                let (upper, lower) = root.split_vertically(ROWS_TWO.1 / 2);
                row_panel(&upper, first, names, in_sample, n)?;
                row_panel(
                    &lower,
                    "The same under a model not fitted to the row's placement",
                    names,
                    h,
                    n,
                )
            }
            None => row_panel(root, first, names, in_sample, n),
        }
    }
    let size = if held_out.is_some() {
        ROWS_TWO
    } else {
        ROWS_ONE
    };
    both!(base, size, |r| draw(r, names, in_sample, held_out))
}
