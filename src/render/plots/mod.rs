//! The figures of `calibrate --report` and `select --report`, each written
//! as PNG and SVG (plotters): labelled axes with their units, a legend
//! wherever there are several series, label areas wide enough for the
//! labels. This file holds what they share (sizes, font, colours, axis
//! ranges, legends); the figures are in `calibration.rs`, `contacts.rs` and `selection.rs`.

mod calibration;
mod contacts;
mod selection;

pub use calibration::{
    ParamBar, correlation, histograms, parameter_changes, sorted_errors, splits,
};
pub use contacts::{BarGroup, RowMark, consistency_bars, row_distances};
pub use selection::{CurveRow, JointRow, how_many, joints_vs_limits, tour};

use crate::error::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::figure::err;

/// A drawing area of any backend.
type Area<DB> = DrawingArea<DB, Shift>;

/// The size of a one-panel figure, pixels.
pub const WIDE: (u32, u32) = (900, 560);
/// The size of a two-panel figure, pixels.
pub const DOUBLE: (u32, u32) = (1200, 560);
/// The size of the parameter and correlation figures, pixels.
pub const TALL: (u32, u32) = (1100, 950);

/// Monospace (the embedded DejaVu Sans Mono): labels of numbers and names
/// line up from one tick to the next.
const FONT: &str = "monospace";
const BEFORE: RGBColor = RGBColor(200, 60, 40);
const AFTER: RGBColor = RGBColor(30, 90, 200);

/// `[lo, hi]` of the finite values, padded by 5 % (and never empty);
/// `zero` includes 0.
fn range(v: &[f64], zero: bool) -> (f64, f64) {
    let mut lo = v
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::INFINITY, f64::min);
    let mut hi = v
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    if zero {
        (lo, hi) = (lo.min(0.0), hi.max(0.0));
    }
    let pad = ((hi - lo) * 0.05).max(1e-9);
    (if zero && lo == 0.0 { 0.0 } else { lo - pad }, hi + pad)
}

/// Draws the series' legend at `pos`.
fn legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    c: &mut ChartContext<'a, DB, CT>,
    pos: SeriesLabelPosition,
) -> Result<()> {
    c.configure_series_labels()
        .position(pos)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .label_font((FONT, 15))
        .draw()
        .map_err(err)
}
