//! Figures of the `reproduce` report, each written as PNG and SVG
//! (plotters): the paper's Fig. 2 (random designs), Fig. 4–6 (traces), and
//! the selected poses.

use super::figure::{both, err};
use crate::error::Result;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

type Area<'a, DB> = DrawingArea<DB, Shift>;

fn range(v: &[f64]) -> (f64, f64) {
    let lo = v
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::INFINITY, f64::min);
    let hi = v
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::NEG_INFINITY, f64::max);
    let pad = ((hi - lo) * 0.05).max(1e-12);
    (lo - pad, hi + pad)
}

/// Fig. 2: the OI of each random design, and their histogram.
pub fn random_designs(base: &Path, oi: &[f64], best_eae_oi: f64) -> Result<()> {
    fn draw<DB: DrawingBackend>(root: &Area<DB>, oi: &[f64], eae: f64) -> Result<()> {
        let (left, right) = root.split_horizontally(620);
        let (lo, hi) = range(&[oi, &[eae]].concat());
        let mut c = ChartBuilder::on(&left)
            .caption("OI of random 30-pose designs (Fig. 2)", ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0f64..oi.len() as f64, lo..hi)
            .map_err(err)?;
        c.configure_mesh()
            .x_desc("design")
            .y_desc("OI, eq. (1)")
            .draw()
            .map_err(err)?;
        c.draw_series(
            oi.iter()
                .enumerate()
                .map(|(i, &v)| Circle::new((i as f64, v), 1, BLUE.filled())),
        )
        .map_err(err)?
        .label("random designs")
        .legend(|(x, y)| Circle::new((x, y), 3, BLUE.filled()));
        c.draw_series(LineSeries::new(
            [(0.0, eae), (oi.len() as f64, eae)],
            RED.stroke_width(2),
        ))
        .map_err(err)?
        .label("EAE design")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED));
        c.configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE)
            .draw()
            .map_err(err)?;
        let bins = 40usize;
        let (hlo, hhi) = range(oi);
        let w = (hhi - hlo) / bins as f64;
        let mut counts = vec![0u32; bins];
        for &v in oi.iter().filter(|v| v.is_finite()) {
            counts[(((v - hlo) / w) as usize).min(bins - 1)] += 1;
        }
        let top = *counts.iter().max().unwrap_or(&1) as f64 * 1.1;
        let mut h = ChartBuilder::on(&right)
            .caption("histogram", ("sans-serif", 20))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(hlo..hhi, 0f64..top)
            .map_err(err)?;
        h.configure_mesh()
            .x_desc("OI")
            .y_desc("designs")
            .x_labels(4)
            .draw()
            .map_err(err)?;
        h.draw_series(counts.iter().enumerate().map(|(i, &n)| {
            let x0 = hlo + i as f64 * w;
            Rectangle::new([(x0, 0.0), (x0 + w, n as f64)], BLUE.mix(0.6).filled())
        }))
        .map_err(err)?;
        Ok(())
    }
    both!(base, (1000, 450), |r| draw(r, oi, best_eae_oi))
}

/// Draws each series as a line with markers over its index, and a legend.
fn lines<'a, DB, Y>(
    c: &mut ChartContext<'a, DB, Cartesian2d<plotters::coord::types::RangedCoordf64, Y>>,
    series: &[(&str, Vec<f64>)],
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    Y: plotters::coord::ranged1d::Ranged<ValueType = f64>,
{
    let colors = [RED, BLUE, GREEN, MAGENTA, BLACK];
    for (k, (label, v)) in series.iter().enumerate() {
        let col = colors[k % colors.len()];
        c.draw_series(LineSeries::new(
            v.iter().enumerate().map(|(i, &y)| (i as f64, y)),
            col.stroke_width(2),
        ))
        .map_err(err)?
        .label(*label)
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], col));
        c.draw_series(
            v.iter()
                .enumerate()
                .map(|(i, &y)| Circle::new((i as f64, y), 3, col.filled())),
        )
        .map_err(err)?;
    }
    c.configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()
        .map_err(err)?;
    Ok(())
}

/// A per-iteration trace (Fig. 4: log10 OI_D; Fig. 5: OI; Fig. 6:
/// log10 of 1/OI_D). `series` are (label, values) drawn over their index.
pub fn trace(base: &Path, title: &str, ylabel: &str, series: &[(&str, Vec<f64>)]) -> Result<()> {
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        title: &str,
        ylabel: &str,
        series: &[(&str, Vec<f64>)],
    ) -> Result<()> {
        let all: Vec<f64> = series.iter().flat_map(|(_, v)| v.iter().copied()).collect();
        let n = series
            .iter()
            .map(|(_, v)| v.len())
            .max()
            .unwrap_or(1)
            .max(2) as f64;
        let mut b = ChartBuilder::on(root);
        b.caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70);
        let (lo, hi) = range(&all);
        let mut c = b.build_cartesian_2d(0f64..n - 1.0, lo..hi).map_err(err)?;
        c.configure_mesh()
            .x_desc("iteration")
            .y_desc(ylabel)
            .draw()
            .map_err(err)?;
        lines(&mut c, series)?;
        Ok(())
    }
    both!(base, (800, 500), |r| draw(r, title, ylabel, series))
}

/// The selected poses as joint-angle lattice digits (parallel coordinates:
/// one polyline per pose across joints 1–6), as in the paper's Fig. 3–5 (A).
pub fn poses(base: &Path, title: &str, digits: &[Vec<usize>], levels: usize) -> Result<()> {
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        title: &str,
        digits: &[Vec<usize>],
        levels: usize,
    ) -> Result<()> {
        let dof = digits.first().map_or(6, Vec::len);
        let mut c = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(55)
            .y_label_area_size(70)
            .build_cartesian_2d(0.8f64..dof as f64 + 0.2, -0.3f64..levels as f64 - 0.7)
            .map_err(err)?;
        // Whole numbers only (joints 1..6, digits 0..levels-1), and the
        // axis names in monospace: plotters' bitmap text clips the left of a
        // proportional "j" (the label read ",oint").
        let whole = |v: &f64| {
            if (v - v.round()).abs() < 1e-9 {
                format!("{v:.0}")
            } else {
                String::new()
            }
        };
        c.configure_mesh()
            .x_desc("joint number")
            .y_desc("lattice digit (level index)")
            .axis_desc_style(("monospace", 16))
            .label_style(("monospace", 14))
            .x_labels(dof)
            .y_labels(levels)
            .x_label_formatter(&whole)
            .y_label_formatter(&whole)
            .draw()
            .map_err(err)?;
        for (k, d) in digits.iter().enumerate() {
            // A small vertical offset per pose keeps coincident segments visible.
            let off = (k as f64 / digits.len().max(1) as f64 - 0.5) * 0.3;
            let col = HSLColor(k as f64 / digits.len().max(1) as f64 * 0.8, 0.8, 0.45);
            c.draw_series(LineSeries::new(
                d.iter()
                    .enumerate()
                    .map(|(j, &v)| ((j + 1) as f64, v as f64 + off)),
                col.stroke_width(1),
            ))
            .map_err(err)?;
            c.draw_series(
                d.iter()
                    .enumerate()
                    .map(|(j, &v)| Circle::new(((j + 1) as f64, v as f64 + off), 3, col.filled())),
            )
            .map_err(err)?;
        }
        Ok(())
    }
    both!(base, (800, 500), |r| draw(r, title, digits, levels))
}
