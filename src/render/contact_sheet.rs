//! The contact sheet of a camera's images (`contact_sheet.png`): one
//! thumbnail per image, four to a row (the board's region, a quarter of
//! its size around it, when points were detected; else the whole image),
//! with the points detected drawn on it (coloured by row of the board, each labelled with its id where the
//! squares are large enough, else the first and last), the residual of
//! each point after the fit as an arrow from the point (magnified by one
//! factor for the whole sheet, stated in its title), and the images left
//! out framed in red with the reason under them.

use super::figure::err;
use crate::error::Error;
use crate::io::atomic::write_atomic;
use crate::io::images::decode::Gray;
use plotters::prelude::*;
use std::path::Path;

/// A result whose error defaults to the library's.
type Result<T, E = Error> = std::result::Result<T, E>;

/// One image of the sheet.
#[derive(Clone, Debug)]
pub struct SheetImage {
    /// The image's file name.
    pub name: String,
    /// Its pixels.
    pub gray: Gray,
    /// Each target point's pixel, by id, where detected.
    pub points: Vec<Option<[f64; 2]>>,
    /// The board's inner corners per row (ids `row · cols + col`).
    pub cols: usize,
    /// Each point's residual after the fit (prediction less pixel), px.
    pub residuals: Vec<Option<[f64; 2]>>,
    /// Why the image was left out (by the detection or by the fit).
    pub left_out: Option<String>,
    /// A line about it: points found, shifts, RMS residual.
    pub caption: String,
}

/// Thumbnail width, px.
const THUMB_W: u32 = 300;
/// Thumbnails per row.
const PER_ROW: u32 = 4;
/// Space under a thumbnail for its caption, px.
const CAPTION_H: u32 = 58;
/// Margin around a cell, px.
const PAD: u32 = 8;
/// Height of the sheet's title, px.
const TITLE_H: u32 = 46;
/// The longest residual arrow drawn, thumbnail px.
const LONGEST_ARROW: f64 = 24.0;

/// The residual arrows' length per pixel of residual (thumbnail pixels
/// per image pixel, one for the whole sheet, whatever each thumbnail's
/// zoom): the largest of 1, 2, 5, 10, 20, 50 … at which the longest arrow
/// is at most [`LONGEST_ARROW`] thumbnail pixels.
#[must_use]
fn arrow_factor(images: &[SheetImage]) -> f64 {
    let largest = images
        .iter()
        .flat_map(|i| i.residuals.iter().flatten().map(|r| r[0].hypot(r[1])))
        .fold(0.0, f64::max);
    nice_at_most(LONGEST_ARROW / largest.max(1e-12)).max(1.0)
}

/// The largest of 1, 2, 5 × 10ⁿ (n from −6 to 8) at most `x` (1e-6 when
/// none is).
fn nice_at_most(x: f64) -> f64 {
    let mut f = 1e-6;
    for k in -6..=8 {
        for m in [1.0, 2.0, 5.0] {
            let c = m * 10f64.powi(k);
            if c <= x {
                f = c;
            }
        }
    }
    f
}

/// The scale bar's residual (px) for arrows of `factor` thumbnail pixels
/// per pixel: a round value drawn at most [`LONGEST_ARROW`] long.
fn scale_bar(factor: f64) -> f64 {
    nice_at_most(LONGEST_ARROW / factor)
}

/// Draws the sheet of `images` (all of one size) and writes it to `path`
/// as a PNG, atomically.
pub fn write_contact_sheet(path: &Path, images: &[SheetImage]) -> Result<()> {
    let Some(first) = images.first() else {
        return Err(Error::Draw("a contact sheet of no image".into()));
    };
    let whole = f64::from(THUMB_W) / first.gray.width as f64;
    let thumb_h = (first.gray.height as f64 * whole).round() as u32;
    let views: Vec<View> = images.iter().map(|i| view_of(i, thumb_h, whole)).collect();
    let rows = (images.len() as u32).div_ceil(PER_ROW);
    let (cell_w, cell_h) = (THUMB_W + 2 * PAD, thumb_h + CAPTION_H + 2 * PAD);
    let size = (PER_ROW * cell_w, TITLE_H + rows * cell_h);
    let mut rgb = vec![255u8; size.0 as usize * size.1 as usize * 3];
    let origin = |k: usize| {
        let (c, r) = (k as u32 % PER_ROW, k as u32 / PER_ROW);
        (c * cell_w + PAD, TITLE_H + r * cell_h + PAD)
    };
    for (k, (im, v)) in images.iter().zip(&views).enumerate() {
        paint_thumbnail(&mut rgb, size.0, origin(k), im, v, thumb_h);
    }
    let factor = arrow_factor(images);
    let bar = scale_bar(factor);
    super::typeset::register_fonts()?;
    {
        let root =
            super::typeset::Typeset(BitMapBackend::with_buffer(&mut rgb, size)).into_drawing_area();
        let used = images.iter().filter(|i| i.left_out.is_none()).count();
        let title = format!(
            "{} images, {used} used. Points coloured by board row, ids drawn; red arrows: each point's residual after the fit (prediction less detection), {factor} thumbnail px per px of residual in every image:",
            images.len()
        );
        root.draw(&Text::new(
            title,
            (PAD as i32, 8),
            ("sans-serif", 14).into_font(),
        ))
        .map_err(err)?;
        // The scale bar: `bar` px of residual as an arrow draws it.
        let (bx, by) = (PAD as i32, 32);
        let len = (bar * factor).round() as i32;
        root.draw(&PathElement::new(
            vec![(bx, by), (bx + len, by)],
            RED.stroke_width(2),
        ))
        .map_err(err)?;
        root.draw(&Text::new(
            format!("= {bar} px of residual"),
            (bx + len + 6, by - 7),
            ("sans-serif", 12).into_font(),
        ))
        .map_err(err)?;
        for (k, (im, v)) in images.iter().zip(&views).enumerate() {
            let (x0, y0) = origin(k);
            draw_cell(&root, (x0 as i32, y0 as i32), im, v, thumb_h, factor)?;
        }
        root.present().map_err(err)?;
    }
    let png = super::figure::png_bytes(&rgb, size).map_err(err)?;
    write_atomic(path, &png)
}

/// The part of an image a thumbnail shows: image pixel `(x, y)` is drawn
/// at thumbnail pixel `((x − x0) · scale, (y − y0) · scale)`.
#[derive(Clone, Copy, Debug)]
struct View {
    x0: f64,
    y0: f64,
    scale: f64,
}

/// The view of `im` in a thumbnail of [`THUMB_W`] × `h` (the image's
/// aspect; `whole` the scale that shows all of it): the detected points'
/// box grown by a quarter of its size each side, or the whole image;
/// never zoomed out beyond the whole image and moved inside it, so that no
/// part of the thumbnail falls outside the image.
fn view_of(im: &SheetImage, h: u32, whole: f64) -> View {
    let (w, hh) = (im.gray.width as f64, im.gray.height as f64);
    let pts: Vec<[f64; 2]> = im.points.iter().flatten().copied().collect();
    let (mut x0, mut y0, mut x1, mut y1) = (0.0, 0.0, w, hh);
    if pts.len() >= 2 {
        let lo = [0, 1].map(|k| pts.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1].map(|k| pts.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max));
        let pad = 0.25 * (hi[0] - lo[0]).max(hi[1] - lo[1]) + 10.0;
        (x0, y0, x1, y1) = (lo[0] - pad, lo[1] - pad, hi[0] + pad, hi[1] + pad);
    }
    let scale = (f64::from(THUMB_W) / (x1 - x0))
        .min(f64::from(h) / (y1 - y0))
        .max(whole);
    // Centre the region in the thumbnail, then move the window inside the
    // image (it is no larger: the scale is at least the whole image's).
    let (ww, wh) = (f64::from(THUMB_W) / scale, f64::from(h) / scale);
    let inside = |c: f64, win: f64, size: f64| c.min(size - 0.5 - win).max(-0.5);
    View {
        x0: inside(0.5 * (x0 + x1) - 0.5 * ww, ww, w),
        y0: inside(0.5 * (y0 + y1) - 0.5 * wh, wh, hh),
        scale,
    }
}

/// Copies `im`'s thumbnail (box-averaged, greyed when left out; the
/// sheet's white outside the image, which [`view_of`] keeps out of view)
/// into the sheet's pixels at `at`.
fn paint_thumbnail(rgb: &mut [u8], width: u32, at: (u32, u32), im: &SheetImage, v: &View, h: u32) {
    let step = 1.0 / v.scale;
    let (gw, gh) = (im.gray.width as f64, im.gray.height as f64);
    for ty in 0..h {
        for tx in 0..THUMB_W {
            let (fx, fy) = (v.x0 + f64::from(tx) * step, v.y0 + f64::from(ty) * step);
            let mut g = if fx < -0.5 || fy < -0.5 || fx + step > gw + 0.5 || fy + step > gh + 0.5 {
                255.0
            } else {
                let (x0, y0) = (fx.max(0.0) as usize, fy.max(0.0) as usize);
                let (x1, y1) = (
                    ((fx + step) as usize).clamp(x0 + 1, im.gray.width),
                    ((fy + step) as usize).clamp(y0 + 1, im.gray.height),
                );
                let (mut s, mut n) = (0.0f64, 0.0f64);
                for y in y0.min(im.gray.height - 1)..y1 {
                    for x in x0.min(im.gray.width - 1)..x1 {
                        s += im.gray.at(x, y);
                        n += 1.0;
                    }
                }
                s / n.max(1.0)
            };
            if im.left_out.is_some() {
                g = 0.5 * g + 64.0;
            }
            let i = (((at.1 + ty) * width + at.0 + tx) * 3) as usize;
            rgb[i..i + 3].fill(g.round() as u8);
        }
    }
}

/// The colour of board row `r` of `rows`: orange to blue (red is the
/// arrows').
fn row_colour(r: usize, rows: usize) -> RGBColor {
    let t = r as f64 / rows.saturating_sub(1).max(1) as f64;
    let (r, g, b) = HSLColor(0.12 + 0.6 * t, 0.9, 0.4).to_rgba().rgb();
    RGBColor(r, g, b)
}

/// Draws one cell's points, ids, arrows, frame and caption.
fn draw_cell<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    (x0, y0): (i32, i32),
    im: &SheetImage,
    v: &View,
    thumb_h: u32,
    factor: f64,
) -> Result<()> {
    let scale = v.scale;
    let at = |p: [f64; 2]| {
        (
            x0 + ((p[0] - v.x0) * scale).round() as i32,
            y0 + ((p[1] - v.y0) * scale).round() as i32,
        )
    };
    let n = im.points.len();
    let cols = im.cols.max(1);
    let rows = n / cols;
    let all_ids = smallest_gap(&im.points, cols) * scale >= 14.0;
    let last = im.points.iter().rposition(Option::is_some);
    for (k, p) in im.points.iter().enumerate() {
        let Some(p) = p else { continue };
        let c = row_colour(k / cols, rows);
        root.draw(&Circle::new(at(*p), 2, c.filled()))
            .map_err(err)?;
        if all_ids || k == 0 || Some(k) == last {
            let (x, y) = at(*p);
            root.draw(&Text::new(
                k.to_string(),
                (x + 3, y - 10),
                ("sans-serif", 9).into_font().color(&c),
            ))
            .map_err(err)?;
        }
    }
    for (p, r) in im.points.iter().zip(&im.residuals) {
        let (Some(p), Some(r)) = (p, r) else { continue };
        let a = at(*p);
        let b = (
            a.0 + (factor * r[0]).round() as i32,
            a.1 + (factor * r[1]).round() as i32,
        );
        root.draw(&PathElement::new(vec![a, b], RED.stroke_width(2)))
            .map_err(err)?;
    }
    let frame = if im.left_out.is_some() {
        RED.stroke_width(3)
    } else {
        BLACK.mix(0.3).stroke_width(1)
    };
    root.draw(&Rectangle::new(
        [(x0, y0), (x0 + THUMB_W as i32, y0 + thumb_h as i32)],
        frame,
    ))
    .map_err(err)?;
    let font = ("sans-serif", 11).into_font();
    let y = y0 + thumb_h as i32 + 4;
    let mut lines: Vec<(String, RGBColor)> = wrap(&format!("{}: {}", im.name, im.caption), 48)
        .into_iter()
        .map(|l| (l, BLACK))
        .collect();
    if let Some(why) = &im.left_out {
        lines.extend(
            wrap(&format!("LEFT OUT: {why}"), 48)
                .into_iter()
                .map(|l| (l, RED)),
        );
    }
    for (i, (line, c)) in lines.into_iter().take(4).enumerate() {
        root.draw(&Text::new(
            line,
            (x0, y + 13 * i as i32),
            font.clone().color(&c),
        ))
        .map_err(err)?;
    }
    Ok(())
}

/// The shortest distance between neighbours along a row, px.
fn smallest_gap(points: &[Option<[f64; 2]>], cols: usize) -> f64 {
    points
        .windows(2)
        .enumerate()
        .filter(|(k, _)| (k + 1) % cols.max(1) != 0)
        .filter_map(|(_, w)| Some((w[0]?, w[1]?)))
        .map(|(a, b)| (a[0] - b[0]).hypot(a[1] - b[1]))
        .fold(f64::INFINITY, f64::min)
}

/// `text` cut into lines of at most `width` characters at spaces.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split(' ') {
        let last = lines.last_mut().expect("one line");
        if !last.is_empty() && last.chars().count() + 1 + word.chars().count() > width {
            lines.push(word.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(word);
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(points: Vec<Option<[f64; 2]>>, residuals: Vec<Option<[f64; 2]>>) -> SheetImage {
        SheetImage {
            name: "a.png".into(),
            gray: Gray {
                width: 320,
                height: 240,
                data: vec![100; 320 * 240],
            },
            points,
            cols: 2,
            residuals,
            left_out: None,
            caption: String::new(),
        }
    }

    /// A board at the image's edge (the black bars of the first sheets):
    /// the view stays inside the image, every thumbnail pixel the image's
    /// grey level, none the sheet's white.
    #[test]
    fn a_board_at_the_edge_is_shown_without_pixels_outside_the_image() {
        let whole = f64::from(THUMB_W) / 320.0;
        let h = (240.0 * whole).round() as u32;
        for pts in [
            vec![Some([2.0, 100.0]), Some([60.0, 160.0])],
            vec![Some([300.0, 5.0]), Some([318.0, 230.0])],
            vec![Some([0.0, 0.0]), Some([319.0, 239.0])],
        ] {
            let im = image(pts, vec![None, None]);
            let v = view_of(&im, h, whole);
            let mut rgb = vec![0u8; (THUMB_W * h * 3) as usize];
            paint_thumbnail(&mut rgb, THUMB_W, (0, 0), &im, &v, h);
            assert!(rgb.iter().all(|&g| g == 100), "{v:?}");
        }
    }

    /// One length per pixel of residual for the whole sheet: the longest
    /// arrow at most LONGEST_ARROW thumbnail px, and within a factor 2.5
    /// of it (the round values 1, 2, 5 are at most 2.5 apart); the scale
    /// bar a round residual drawn no longer.
    #[test]
    fn arrows_have_one_round_scale_and_a_bar_in_px() {
        let im = image(vec![Some([10.0, 10.0])], vec![Some([0.3, 0.4])]);
        let f = arrow_factor(&[im]);
        assert_eq!(f, 20.0);
        assert!(0.5 * f <= LONGEST_ARROW && 0.5 * f * 2.5 > LONGEST_ARROW);
        let bar = scale_bar(f);
        assert_eq!(bar, 1.0);
        assert!(bar * f <= LONGEST_ARROW);
    }
}
