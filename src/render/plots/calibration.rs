//! The figures of `calibrate --report`: errors before and after calibration
//! (sorted, histograms, hold-out splits), parameter changes and the
//! correlation matrix.

use super::{AFTER, Area, BEFORE, DOUBLE, FONT, TALL, WIDE, legend, range};
use crate::error::Result;
use crate::render::figure::{both, err};
use plotters::prelude::*;
use std::path::Path;

/// Each pose's error before and after calibration, each series sorted
/// increasing (rank on x): the nominal and the calibrated model's errors
/// side by side.
pub fn sorted_errors(
    base: &Path,
    title: &str,
    unit: &str,
    before: &[f64],
    after: &[f64],
) -> Result<()> {
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        title: &str,
        unit: &str,
        before: &[f64],
        after: &[f64],
    ) -> Result<()> {
        let sort = |v: &[f64]| {
            let mut s = v.to_vec();
            s.sort_unstable_by(f64::total_cmp);
            s
        };
        // A log scale: the calibrated errors are often a hundredth of the
        // nominal ones, and would lie flat on a linear axis. Zero errors sit
        // on the axis's floor.
        let all: Vec<f64> = before
            .iter()
            .chain(after)
            .copied()
            .filter(|v| v.is_finite())
            .collect();
        let top = all.iter().copied().fold(0.0f64, f64::max).max(1e-12) * 1.5;
        let floor = all
            .iter()
            .copied()
            .filter(|v| *v > 0.0)
            .fold(f64::INFINITY, f64::min)
            .min(top / 10.0)
            / 1.5;
        let clamp = |v: &[f64]| -> Vec<f64> { sort(v).into_iter().map(|x| x.max(floor)).collect() };
        let (b, a) = (clamp(before), clamp(after));
        let n = b.len().max(a.len()).max(2);
        let mut c = ChartBuilder::on(root)
            .caption(title, (FONT, 22))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(80)
            .build_cartesian_2d(0.5f64..n as f64 + 0.5, (floor..top).log_scale())
            .map_err(err)?;
        c.configure_mesh()
            .x_desc("pose, by increasing error (rank)")
            .y_desc(format!("error ({unit}, log scale)"))
            .y_label_formatter(&|y| match *y {
                v if v >= 10.0 => format!("{v:.0}"),
                v if v >= 1.0 => format!("{v:.1}"),
                v => format!("{v:.3}"),
            })
            .axis_desc_style((FONT, 17))
            .label_style((FONT, 14))
            .x_label_formatter(&|x| format!("{x:.0}"))
            .draw()
            .map_err(err)?;
        for (v, col, label, r) in [
            (&b, BEFORE, "nominal model", rms(before)),
            (&a, AFTER, "calibrated model", rms(after)),
        ] {
            c.draw_series(LineSeries::new(
                v.iter().enumerate().map(|(i, &y)| ((i + 1) as f64, y)),
                col.stroke_width(2),
            ))
            .map_err(err)?
            .label(format!("{label} (RMS {r:.3} {unit})"))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], col.stroke_width(2)));
            c.draw_series(
                v.iter()
                    .enumerate()
                    .map(|(i, &y)| Circle::new(((i + 1) as f64, y), 3, col.filled())),
            )
            .map_err(err)?;
        }
        // Sorted curves rise to the right: the lower right is free.
        legend(&mut c, SeriesLabelPosition::LowerRight)
    }
    both!(base, WIDE, |r| draw(r, title, unit, before, after))
}

/// The root mean square of `v` (0 when empty).
fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt()
}

/// Histograms of the errors before (left) and after calibration (right),
/// each on its own bins: the calibrated errors are often a hundredth of the
/// nominal ones, and shared bins would put them all in one.
pub fn histograms(
    base: &Path,
    title: &str,
    unit: &str,
    before: &[f64],
    after: &[f64],
) -> Result<()> {
    fn panel<DB: DrawingBackend>(
        area: &Area<DB>,
        title: &str,
        unit: &str,
        v: &[f64],
        col: RGBColor,
    ) -> Result<()> {
        let (_, hi) = range(v, true);
        let bins = 20usize;
        let w = hi / bins as f64;
        let mut counts = vec![0u32; bins];
        for &x in v.iter().filter(|x| x.is_finite()) {
            counts[((x / w) as usize).min(bins - 1)] += 1;
        }
        let top = counts.iter().copied().max().unwrap_or(1).max(1) as f64 * 1.15;
        let mut c = ChartBuilder::on(area)
            .caption(title, (FONT, 19))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(60)
            .build_cartesian_2d(0f64..hi, 0f64..top)
            .map_err(err)?;
        c.configure_mesh()
            .x_desc(format!("error ({unit})"))
            .y_desc("poses")
            .axis_desc_style((FONT, 16))
            .label_style((FONT, 13))
            .x_labels(6)
            // Counts are whole: a tick between two whole numbers stays unlabelled
            // (it read "2, 2, 2" for 1.5, 2, 2.5).
            .y_label_formatter(&|y| {
                if (y - y.round()).abs() < 1e-9 {
                    format!("{y:.0}")
                } else {
                    String::new()
                }
            })
            .draw()
            .map_err(err)?;
        c.draw_series(
            counts
                .iter()
                .enumerate()
                .filter(|(_, n)| **n > 0)
                .map(|(i, &n)| {
                    let x0 = i as f64 * w;
                    Rectangle::new([(x0, 0.0), (x0 + w, f64::from(n))], col.mix(0.7).filled())
                }),
        )
        .map_err(err)?;
        Ok(())
    }
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        title: &str,
        unit: &str,
        before: &[f64],
        after: &[f64],
    ) -> Result<()> {
        let root = root.titled(title, (FONT, 22)).map_err(err)?;
        let (l, r) = root.split_horizontally(DOUBLE.0 / 2);
        panel(
            &l,
            &format!("nominal model (RMS {:.3} {unit})", rms(before)),
            unit,
            before,
            BEFORE,
        )?;
        panel(
            &r,
            &format!("calibrated model (RMS {:.3} {unit})", rms(after)),
            unit,
            after,
            AFTER,
        )
    }
    both!(base, DOUBLE, |r| draw(r, title, unit, before, after))
}

/// Held-out position RMS of each split: the nominal model against the
/// calibrated one (grouped bars), mm.
pub fn splits(base: &Path, nominal: &[f64], calibrated: &[f64]) -> Result<()> {
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        nominal: &[f64],
        calibrated: &[f64],
    ) -> Result<()> {
        let n = nominal.len().max(1);
        let (_, hi) = range(&[nominal, calibrated].concat(), true);
        let mut c = ChartBuilder::on(root)
            .caption("Held-out position error per split", (FONT, 22))
            .margin(15)
            .x_label_area_size(55)
            .y_label_area_size(80)
            .build_cartesian_2d(0.4f64..n as f64 + 0.6, 0f64..hi * 1.1)
            .map_err(err)?;
        c.configure_mesh()
            .x_desc("split")
            .y_desc("held-out position RMS (mm)")
            .axis_desc_style((FONT, 17))
            .label_style((FONT, 14))
            .x_labels(n)
            .x_label_formatter(&|x| {
                if (x - x.round()).abs() < 1e-6 && *x >= 1.0 {
                    format!("{x:.0}")
                } else {
                    String::new()
                }
            })
            .disable_x_mesh()
            .draw()
            .map_err(err)?;
        for (k, (v, col, label)) in [
            (nominal, BEFORE, "nominal model"),
            (calibrated, AFTER, "calibrated model"),
        ]
        .into_iter()
        .enumerate()
        {
            let off = if k == 0 { -0.35 } else { 0.0 };
            c.draw_series(v.iter().enumerate().map(|(i, &y)| {
                let x0 = (i + 1) as f64 + off;
                Rectangle::new([(x0, 0.0), (x0 + 0.35, y)], col.filled())
            }))
            .map_err(err)?
            .label(label)
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 16, y + 6)], col.filled()));
        }
        legend(&mut c, SeriesLabelPosition::UpperRight)
    }
    both!(base, WIDE, |r| draw(r, nominal, calibrated))
}

/// One parameter of [`parameter_changes`].
pub struct ParamBar {
    /// Name.
    pub name: String,
    /// Change from nominal, in the panel's unit.
    pub change: f64,
    /// σ in the same unit, when known.
    pub sigma: Option<f64>,
}

/// Each parameter's change from nominal with ±σ bars: lengths (mm) in the
/// left panel, angles (degrees) in the right one, names on the y axis.
pub fn parameter_changes(base: &Path, lengths: &[ParamBar], angles: &[ParamBar]) -> Result<()> {
    fn panel<DB: DrawingBackend>(
        area: &Area<DB>,
        title: &str,
        unit: &str,
        bars: &[ParamBar],
    ) -> Result<()> {
        let ends: Vec<f64> = bars
            .iter()
            .flat_map(|b| {
                let s = b.sigma.unwrap_or(0.0);
                [b.change - s, b.change + s]
            })
            .collect();
        let (lo, hi) = range(&ends, true);
        let n = bars.len().max(1);
        let names: Vec<String> = bars.iter().map(|b| b.name.clone()).collect();
        let mut c = ChartBuilder::on(area)
            .caption(title, (FONT, 20))
            .margin(12)
            .x_label_area_size(55)
            .y_label_area_size(200)
            // Two empty rows at the bottom hold the legend, clear of the bars.
            .build_cartesian_2d(lo..hi, -2.5f64..n as f64 - 0.5)
            .map_err(err)?;
        c.configure_mesh()
            .x_desc(format!("estimate − nominal ({unit}), bars ±σ"))
            .axis_desc_style((FONT, 16))
            .label_style((FONT, 13))
            .x_labels(6)
            .y_labels(n + 3)
            .y_label_formatter(&|y| {
                let k = y.round();
                if (y - k).abs() < 1e-6 && k >= 0.0 {
                    names.get(n - 1 - k as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            })
            .disable_y_mesh()
            .draw()
            .map_err(err)?;
        c.draw_series(std::iter::once(PathElement::new(
            [(0.0, -0.5), (0.0, n as f64 - 0.5)],
            BLACK,
        )))
        .map_err(err)?;
        let y = |k: usize| (n - 1 - k) as f64;
        c.draw_series(bars.iter().enumerate().map(|(k, b)| {
            Rectangle::new(
                [(0.0, y(k) - 0.3), (b.change, y(k) + 0.3)],
                AFTER.mix(0.6).filled(),
            )
        }))
        .map_err(err)?
        .label("change")
        .legend(|(x, y)| Rectangle::new([(x, y - 6), (x + 16, y + 6)], AFTER.mix(0.6).filled()));
        c.draw_series(bars.iter().enumerate().filter_map(|(k, b)| {
            b.sigma.map(|s| {
                ErrorBar::new_horizontal(
                    y(k),
                    b.change - s,
                    b.change,
                    b.change + s,
                    BLACK.stroke_width(2),
                    8,
                )
            })
        }))
        .map_err(err)?
        .label("±σ")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLACK.stroke_width(2)));
        legend(&mut c, SeriesLabelPosition::LowerRight)
    }
    fn draw<DB: DrawingBackend>(
        root: &Area<DB>,
        lengths: &[ParamBar],
        angles: &[ParamBar],
    ) -> Result<()> {
        let (l, r) = root.split_horizontally(TALL.0 / 2);
        panel(&l, "Length parameters", "mm", lengths)?;
        panel(&r, "Angle parameters", "degrees", angles)
    }
    both!(base, TALL, |r| draw(r, lengths, angles))
}

/// The blue–white–red colour of a correlation in [-1, 1].
fn diverging(v: f64) -> RGBColor {
    let v = v.clamp(-1.0, 1.0);
    let mix = |a: u8, t: f64| (255.0 + (f64::from(a) - 255.0) * t).round() as u8;
    if v >= 0.0 {
        RGBColor(mix(200, v), mix(30, v), mix(30, v))
    } else {
        RGBColor(mix(30, -v), mix(60, -v), mix(200, -v))
    }
}

/// The correlation matrix of the parameters as a heat map (−1 blue, 0
/// white, +1 red), with its colour scale.
pub fn correlation(base: &Path, names: &[String], m: &[Vec<f64>]) -> Result<()> {
    fn draw<DB: DrawingBackend>(root: &Area<DB>, names: &[String], m: &[Vec<f64>]) -> Result<()> {
        let (main, bar) = root.split_horizontally(TALL.0 - 130);
        let n = names.len().max(1);
        // Row k from the top is parameter k (numbered from 1 as on the x axis).
        let whole = |v: f64| {
            let k = v.round();
            ((v - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < n).then_some(k as usize)
        };
        let ylabel = |v: &f64| {
            whole(*v).map_or(String::new(), |k| format!("{} {}", n - k, names[n - 1 - k]))
        };
        let xlabel = |v: &f64| whole(*v).map_or(String::new(), |k| format!("{}", k + 1));
        let font = if n > 30 { 11 } else { 13 };
        let longest = names.iter().map(|s| s.chars().count()).max().unwrap_or(4) + 3;
        let mut c = ChartBuilder::on(&main)
            .caption("Correlation of the parameter estimates", (FONT, 22))
            .margin(12)
            .x_label_area_size(60)
            // Monospace: about 0.62 em a character.
            .y_label_area_size(20 + (longest as f64 * f64::from(font) * 0.62) as u32)
            .build_cartesian_2d(-0.5f64..n as f64 - 0.5, -0.5f64..n as f64 - 0.5)
            .map_err(err)?;
        c.configure_mesh()
            .disable_mesh()
            .x_labels(n)
            .y_labels(n)
            .x_label_formatter(&xlabel)
            .y_label_formatter(&ylabel)
            .x_desc("parameter (number, as on the left)")
            .axis_desc_style((FONT, 15))
            .x_label_style((FONT, font))
            .y_label_style((FONT, font))
            .draw()
            .map_err(err)?;
        c.draw_series((0..n).flat_map(|i| {
            (0..n).map(move |j| {
                let v = m.get(i).and_then(|r| r.get(j)).copied().unwrap_or(f64::NAN);
                let col = if v.is_finite() {
                    diverging(v)
                } else {
                    RGBColor(160, 160, 160)
                };
                let y = (n - 1 - i) as f64;
                Rectangle::new(
                    [(j as f64 - 0.5, y - 0.5), (j as f64 + 0.5, y + 0.5)],
                    col.filled(),
                )
            })
        }))
        .map_err(err)?;
        let mut s = ChartBuilder::on(&bar)
            .margin_top(60)
            .margin_bottom(80)
            .margin_right(10)
            .y_label_area_size(50)
            .build_cartesian_2d(0f64..1.0, -1f64..1.0)
            .map_err(err)?;
        s.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc("correlation")
            .axis_desc_style((FONT, 15))
            .label_style((FONT, 13))
            .y_labels(5)
            .draw()
            .map_err(err)?;
        s.draw_series((0..100).map(|k| {
            let v0 = -1.0 + f64::from(k) * 0.02;
            Rectangle::new([(0.0, v0), (1.0, v0 + 0.02)], diverging(v0 + 0.01).filled())
        }))
        .map_err(err)?;
        Ok(())
    }
    both!(base, TALL, |r| draw(r, names, m))
}
