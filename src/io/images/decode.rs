//! An image as activecal reads it: 8-bit grey levels, row by row, decoded
//! from a PNG of any colour type and depth (palette and low depths
//! expanded, 16 bits cut to 8, colour turned grey by its luma
//! `0.299 R + 0.587 G + 0.114 B`, alpha ignored).

/// A grey image, `width × height` levels row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct Gray {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// The levels, `width · height` of them, row by row.
    pub data: Vec<u8>,
}

impl Gray {
    /// The level at pixel `(x, y)` (which must be inside the image).
    #[must_use]
    pub fn at(&self, x: usize, y: usize) -> f64 {
        f64::from(self.data[y * self.width + x])
    }

    /// The level at `(x, y)` (OpenCV's convention: `(0, 0)` is the centre
    /// of the top-left pixel) interpolated bilinearly; a point outside the
    /// image takes its nearest edge pixel's level.
    #[must_use]
    pub fn bilinear(&self, x: f64, y: f64) -> f64 {
        let xm = (self.width - 1) as f64;
        let ym = (self.height - 1) as f64;
        let (x, y) = (x.clamp(0.0, xm), y.clamp(0.0, ym));
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as usize, y0 as usize);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let top = self.at(x0, y0) * (1.0 - fx) + self.at(x1, y0) * fx;
        let bottom = self.at(x0, y1) * (1.0 - fx) + self.at(x1, y1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// Decodes a PNG file's bytes into grey levels; the error says what is
/// wrong with the file, in words.
pub fn decode_png(bytes: &[u8]) -> Result<Gray, String> {
    let mut decoder = png::Decoder::new(bytes);
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("not a readable PNG image ({e})"))?;
    let mut buf = vec![0u8; reader.output_buffer_size()];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| format!("a damaged PNG image ({e})"))?;
    let (width, height) = (info.width as usize, info.height as usize);
    if width < 2 || height < 2 {
        return Err(format!("an image of {width} × {height} px"));
    }
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => return Err("a palette PNG that was not expanded".into()),
    };
    let mut data = Vec::with_capacity(width * height);
    for row in buf.chunks(info.line_size).take(height) {
        for px in row.chunks(channels).take(width) {
            let g = if channels >= 3 {
                0.299 * f64::from(px[0]) + 0.587 * f64::from(px[1]) + 0.114 * f64::from(px[2])
            } else {
                f64::from(px[0])
            };
            data.push(g.round().clamp(0.0, 255.0) as u8);
        }
    }
    Ok(Gray {
        width,
        height,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode(width: u32, height: u32, color: png::ColorType, data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut e = png::Encoder::new(&mut out, width, height);
        e.set_color(color);
        e.set_depth(png::BitDepth::Eight);
        e.write_header().unwrap().write_image_data(data).unwrap();
        out
    }

    #[test]
    fn grey_and_colour_pngs_decode_to_their_levels() {
        let g = decode_png(&encode(2, 2, png::ColorType::Grayscale, &[0, 10, 200, 255])).unwrap();
        assert_eq!(
            (g.width, g.height, g.data.clone()),
            (2, 2, vec![0, 10, 200, 255])
        );
        // Pure red, green, blue and white: their luma by the weights above.
        let rgb = [255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255];
        let c = decode_png(&encode(2, 2, png::ColorType::Rgb, &rgb)).unwrap();
        assert_eq!(c.data, vec![76, 150, 29, 255]);
    }

    #[test]
    fn bilinear_interpolates_between_pixel_centres() {
        let g = Gray {
            width: 2,
            height: 2,
            data: vec![0, 100, 50, 150],
        };
        assert_eq!(g.bilinear(0.0, 0.0), 0.0);
        assert_eq!(g.bilinear(0.5, 0.0), 50.0);
        assert_eq!(g.bilinear(0.5, 0.5), 75.0);
        // Outside: the nearest edge.
        assert_eq!(g.bilinear(-3.0, 1.0), 50.0);
    }

    #[test]
    fn a_file_that_is_not_a_png_is_refused_in_words() {
        let e = decode_png(b"not an image at all").unwrap_err();
        assert!(e.contains("not a readable PNG image"), "{e}");
    }
}
