//! One figure drawn twice, on a pixel buffer and on an SVG string, and
//! written as `<base>.png` and `<base>.svg` atomically ([`both`]).

use crate::error::Error;
use crate::io::atomic::write_atomic;

/// A result whose error defaults to the library's.
type Result<T, E = Error> = std::result::Result<T, E>;
use std::path::Path;

/// A drawing error of plotters (or of the PNG encoder) as the library
/// reports it.
pub(crate) fn err<E: std::fmt::Debug>(e: E) -> Error {
    Error::Draw(format!("{e:?}"))
}

/// Draws `$body` (with `$r` bound to the root area) once on a pixel buffer
/// and once on an SVG string, then writes `<base>.png` and `<base>.svg`
/// atomically ([`write_figure`]).
macro_rules! both {
    ($base:expr, $size:expr, |$r:ident| $body:expr) => {{
        $crate::render::typeset::register_fonts()?;
        let size: (u32, u32) = $size;
        let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
        {
            let root = $crate::render::typeset::Typeset(BitMapBackend::with_buffer(&mut rgb, size))
                .into_drawing_area();
            root.fill(&WHITE).map_err(err)?;
            let $r = &root;
            $body?;
            root.present().map_err(err)?;
        }
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
            root.fill(&WHITE).map_err(err)?;
            let $r = &root;
            $body?;
            root.present().map_err(err)?;
        }
        $crate::render::figure::write_figure($base, &rgb, size, &svg)
    }};
}
pub(crate) use both;

/// Writes a drawn figure: `<base>.png` from the RGB pixels of `size`
/// (8 bits a channel) and `<base>.svg`, each atomically.
pub(crate) fn write_figure(base: &Path, rgb: &[u8], size: (u32, u32), svg: &str) -> Result<()> {
    let png = png_bytes(rgb, size).map_err(err)?;
    write_atomic(&base.with_extension("png"), &png)?;
    write_atomic(&base.with_extension("svg"), svg.as_bytes())?;
    Ok(())
}

/// Encodes RGB pixels (row by row, 8 bits a channel) as a PNG file's bytes.
pub(crate) fn png_bytes(
    rgb: &[u8],
    (width, height): (u32, u32),
) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}
