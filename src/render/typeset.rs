//! The text of the figures: the embedded DejaVu fonts, and a drawing
//! backend that wraps plotters' pixel backend and sets text itself with
//! ab_glyph. plotters' own ab_glyph text drops each glyph's left bearing
//! ("50.0" read "50. 0", a "j" lost its hook); here every glyph is drawn at
//! its pen position plus its bearing, kerned, on one baseline.

use crate::error::Error;
use ab_glyph::{Font, FontRef, Glyph, PxScale, ScaleFont, point};

/// A result whose error defaults to the library's.
type Result<T, E = Error> = std::result::Result<T, E>;
use plotters::style::{FontStyle, register_font};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
    FontFamily,
};
use std::sync::OnceLock;

/// DejaVu Sans, for plotters' "sans-serif" and every other family
/// (assets/fonts/NOTICE.md).
const SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
/// DejaVu Sans Mono, for plotters' "monospace".
const MONO: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");

/// The parsed embedded fonts, sans and mono.
fn fonts() -> Result<&'static (FontRef<'static>, FontRef<'static>)> {
    static FONTS: OnceLock<Option<(FontRef<'static>, FontRef<'static>)>> = OnceLock::new();
    FONTS
        .get_or_init(|| {
            Some((
                FontRef::try_from_slice(SANS).ok()?,
                FontRef::try_from_slice(MONO).ok()?,
            ))
        })
        .as_ref()
        .ok_or_else(|| Error::Draw("an embedded font does not parse".into()))
}

/// Registers the embedded fonts with plotters (once per process): the SVG
/// backend sizes its label areas with them. Also checks that they parse.
pub(crate) fn register_fonts() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    fonts()?;
    let ok = *REGISTERED.get_or_init(|| {
        [("sans-serif", SANS), ("monospace", MONO)]
            .into_iter()
            .all(|(name, bytes)| register_font(name, FontStyle::Normal, bytes).is_ok())
    });
    ok.then_some(())
        .ok_or_else(|| Error::Draw("plotters refused an embedded font".into()))
}

/// A line of text laid out in one font: its glyphs on the baseline, its
/// advance width and its height (ascent − descent), pixels.
struct Line {
    glyphs: Vec<Glyph>,
    width: f32,
    height: f32,
}

/// Lays `text` out at `size` pixels (ab_glyph's scale: ascent − descent),
/// the pen starting at 0 and the baseline at the ascent.
fn lay_out(font: &FontRef<'static>, size: f64, text: &str) -> Line {
    let scaled = font.as_scaled(PxScale::from(size as f32));
    let mut pen = 0.0f32;
    let mut previous = None;
    let mut glyphs = Vec::with_capacity(text.len());
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = previous {
            pen += scaled.kern(p, id);
        }
        glyphs.push(id.with_scale_and_position(scaled.scale(), point(pen, scaled.ascent())));
        pen += scaled.h_advance(id);
        previous = Some(id);
    }
    Line {
        glyphs,
        width: pen,
        height: scaled.ascent() - scaled.descent(),
    }
}

/// The font drawn for a plotters family.
fn font_for(family: FontFamily<'_>) -> Result<&'static FontRef<'static>> {
    let (sans, mono) = fonts()?;
    Ok(if family.as_str() == "monospace" {
        mono
    } else {
        sans
    })
}

/// The offset of a text box's top-left corner from its anchor.
fn anchor_offset(anchor: plotters_backend::text_anchor::Pos, w: i32, h: i32) -> (i32, i32) {
    let dx = match anchor.h_pos {
        HPos::Left => 0,
        HPos::Center => -w / 2,
        HPos::Right => -w,
    };
    let dy = match anchor.v_pos {
        VPos::Top => 0,
        VPos::Center => -h / 2,
        VPos::Bottom => -h,
    };
    (dx, dy)
}

/// A drawing backend that draws everything through `B` but sets text
/// itself ([`lay_out`]).
pub(crate) struct Typeset<B>(pub B);

impl<B: DrawingBackend> Typeset<B> {
    /// The covered pixels of `text` drawn at `pos` in `style`, with their
    /// coverage (0–1), clipped to the backend's size.
    fn text_pixels<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<Vec<(BackendCoord, f32)>> {
        let font = font_for(style.family())?;
        let line = lay_out(font, style.size(), text);
        let (dx, dy) = anchor_offset(style.anchor(), line.width as i32, line.height as i32);
        let transform = style.transform();
        let (w, h) = self.0.get_size();
        let mut pixels = Vec::new();
        for glyph in line.glyphs {
            let Some(outline) = font.outline_glyph(glyph) else {
                continue; // a space: nothing to draw
            };
            let bounds = outline.px_bounds();
            let (x0, y0) = (bounds.min.x as i32 + dx, bounds.min.y as i32 + dy);
            outline.draw(|x, y, coverage| {
                let (tx, ty) = transform.transform(x0 + x as i32, y0 + y as i32);
                let (px, py) = (pos.0 + tx, pos.1 + ty);
                if coverage > 0.0 && px >= 0 && py >= 0 && px < w as i32 && py < h as i32 {
                    pixels.push(((px, py), coverage.min(1.0)));
                }
            });
        }
        Ok(pixels)
    }
}

/// A font error as the backend reports it.
fn font_error<E: std::error::Error + Send + Sync>(e: Error) -> DrawingErrorKind<E> {
    DrawingErrorKind::FontError(e.into())
}

impl<B: DrawingBackend> DrawingBackend for Typeset<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.0.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.0.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.0.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.0.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.0.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.0.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.0.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.0.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.0.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        self.0.blit_bitmap(pos, size, src)
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<B::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        for (p, coverage) in self.text_pixels(text, style, pos).map_err(font_error)? {
            let alpha = color.alpha * f64::from(coverage);
            self.0.draw_pixel(
                p,
                BackendColor {
                    alpha,
                    rgb: color.rgb,
                },
            )?;
        }
        Ok(())
    }

    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<B::ErrorType>> {
        let font = font_for(style.family()).map_err(font_error)?;
        let line = lay_out(font, style.size(), text);
        Ok((line.width.ceil() as u32, line.height.ceil() as u32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The laid-out glyphs advance left to right and a glyph's outline
    /// starts at its pen position plus its own left bearing: the ink of
    /// "." in the monospace font sits inside its cell, not at the cell's
    /// left edge (the fault of plotters' ab_glyph text).
    #[test]
    fn glyphs_keep_their_bearings() {
        let (_, mono) = fonts().unwrap();
        let line = lay_out(mono, 40.0, "0.0");
        let xs: Vec<f32> = line.glyphs.iter().map(|g| g.position.x).collect();
        assert!(xs[0] < xs[1] && xs[1] < xs[2], "pen positions {xs:?}");
        // Every monospace advance is the same: the cells are equal.
        let cell = xs[1] - xs[0];
        assert!((xs[2] - xs[1] - cell).abs() < 1e-3, "cells {xs:?}");
        let dot = mono
            .outline_glyph(line.glyphs[1].clone())
            .unwrap()
            .px_bounds();
        // The period's ink is centred in its cell: it starts more than a
        // quarter of a cell right of the cell's left edge.
        assert!(
            dot.min.x > xs[1] + cell / 4.0,
            "dot at {} in cell {}..{}",
            dot.min.x,
            xs[1],
            xs[1] + cell
        );
        // The baseline: the period's ink ends at most a pixel below it.
        let baseline = line.glyphs[1].position.y;
        assert!(dot.max.y <= baseline + 1.0 && dot.max.y > baseline - 0.2 * 40.0);
    }
}
