//! An image as activecal reads it: 8-bit grey levels, row by row, decoded
//! from a PNG of any colour type and depth (palette and low depths
//! expanded, 16 bits cut to 8, colour turned grey by its luma
//! `0.299 R + 0.587 G + 0.114 B`, alpha ignored) or from a JPEG (grey, or
//! colour turned grey by the same luma; decoded by the `image` crate's
//! `zune-jpeg`). A file is taken for what its first bytes say it is, not
//! for its name.

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

/// Decodes an image file's bytes, a PNG or a JPEG (by its first bytes),
/// into grey levels; the error says what is wrong with the file, in words.
pub fn decode_image(bytes: &[u8]) -> Result<Gray, String> {
    if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
        decode_jpeg(bytes)
    } else {
        decode_png(bytes)
    }
}

/// Decodes a JPEG file's bytes into grey levels; the error says what is
/// wrong with the file, in words.
pub fn decode_jpeg(bytes: &[u8]) -> Result<Gray, String> {
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Jpeg)
        .map_err(|e| format!("not a readable JPEG image ({e})"))?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    if width < 2 || height < 2 {
        return Err(format!("an image of {width} × {height} px"));
    }
    let data = if img.color().has_color() {
        img.to_rgb8().pixels().map(|p| luma(p.0)).collect()
    } else {
        img.to_luma8().into_raw()
    };
    Ok(Gray {
        width,
        height,
        data,
    })
}

/// The grey level of an RGB pixel: its luma `0.299 R + 0.587 G + 0.114 B`.
fn luma(rgb: [u8; 3]) -> u8 {
    let g = 0.299 * f64::from(rgb[0]) + 0.587 * f64::from(rgb[1]) + 0.114 * f64::from(rgb[2]);
    g.round().clamp(0.0, 255.0) as u8
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
            data.push(if channels >= 3 {
                luma([px[0], px[1], px[2]])
            } else {
                px[0]
            });
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
        let e = decode_image(&[0xff, 0xd8, 0xff, 0xe0, 0, 0]).unwrap_err();
        assert!(e.contains("not a readable JPEG image"), "{e}");
    }

    /// A JPEG encoded by the `image` crate at quality 100 of a flat grey
    /// (no edge for the DCT to ring on) and of pure colours in 8 × 8
    /// blocks (one colour per block: its chroma is not subsampled across
    /// colours): each decodes to its level, or to the colour's luma as a
    /// PNG's, within 2 levels (the round trip's quantisation at quality
    /// 100: a level of 255 / 2 on each of Y, Cb and Cr at most).
    #[test]
    fn grey_and_colour_jpegs_decode_to_their_levels() {
        let enc = |img: image::DynamicImage| {
            let mut out = std::io::Cursor::new(Vec::new());
            img.write_with_encoder(image::codecs::jpeg::JpegEncoder::new_with_quality(
                &mut out, 100,
            ))
            .unwrap();
            out.into_inner()
        };
        let grey = image::GrayImage::from_pixel(16, 16, image::Luma([90]));
        let g = decode_image(&enc(grey.into())).unwrap();
        assert_eq!((g.width, g.height), (16, 16));
        assert!(g.data.iter().all(|&v| v.abs_diff(90) <= 2), "{:?}", g.data);
        for (rgb, want) in [([255, 0, 0], 76u8), ([0, 255, 0], 150), ([0, 0, 255], 29)] {
            let c = image::RgbImage::from_pixel(16, 16, image::Rgb(rgb));
            let g = decode_image(&enc(c.into())).unwrap();
            assert!(
                g.data.iter().all(|&v| v.abs_diff(want) <= 2),
                "{rgb:?}: {:?}",
                &g.data[..4]
            );
        }
    }
}
