//! The pixels of a bag's `sensor_msgs/msg/Image` and `CompressedImage`
//! messages as the image detection reads them
//! ([`crate::io::images::decode::Gray`]).

use super::messages::ImageData;
use crate::io::images::decode::{Gray, decode_jpeg, decode_png};

/// Decodes a ROS image message's pixels into grey levels: a raw `Image`
/// in `mono8`, `rgb8`, `bgr8`, `rgba8` or `bgra8` (`width × height`, rows
/// `step` bytes apart; colour turned grey by its luma as a PNG's is), or a
/// `CompressedImage` holding a PNG or a JPEG (`format` `png` or `jpeg`,
/// or image_transport's `… png compressed …`, `… jpeg compressed …`).
/// Any other encoding (16-bit, Bayer, YUV) is an error naming it.
pub fn decode_message(m: &ImageData<'_>) -> Result<Gray, String> {
    if m.compressed {
        let f = m.encoding.to_ascii_lowercase();
        if f.contains("png") {
            return decode_png(m.data);
        }
        if f.contains("jpeg") || f.contains("jpg") {
            return decode_jpeg(m.data);
        }
        return Err(format!(
            "a compressed image in format '{}': activecal decodes PNG- and JPEG-compressed images (format 'png' or 'jpeg') and raw ones (mono8, rgb8, bgr8, rgba8, bgra8)",
            m.encoding
        ));
    }
    let (channels, rgb) = match m.encoding.as_str() {
        "mono8" | "8UC1" => (1, [0, 0, 0]),
        "rgb8" => (3, [0, 1, 2]),
        "bgr8" => (3, [2, 1, 0]),
        "rgba8" => (4, [0, 1, 2]),
        "bgra8" => (4, [2, 1, 0]),
        other => {
            return Err(format!(
                "a raw image in encoding '{other}': activecal reads mono8, rgb8, bgr8, rgba8 and bgra8 (and PNG-compressed images)"
            ));
        }
    };
    let (width, height, step) = (m.width as usize, m.height as usize, m.step as usize);
    if width < 2 || height < 2 {
        return Err(format!("an image of {width} × {height} px"));
    }
    if step < width * channels || m.data.len() < step * (height - 1) + width * channels {
        return Err(format!(
            "{} byte(s) of pixels for {width} × {height} px {} with rows {step} bytes apart",
            m.data.len(),
            m.encoding
        ));
    }
    let mut data = Vec::with_capacity(width * height);
    for row in 0..height {
        let line = &m.data[row * step..row * step + width * channels];
        for px in line.chunks(channels) {
            let g = if channels == 1 {
                f64::from(px[0])
            } else {
                0.299 * f64::from(px[rgb[0]])
                    + 0.587 * f64::from(px[rgb[1]])
                    + 0.114 * f64::from(px[rgb[2]])
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
    use crate::io::bag::messages::Header;

    fn encode(width: u32, height: u32, data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        let mut e = png::Encoder::new(&mut out, width, height);
        e.set_color(png::ColorType::Grayscale);
        e.set_depth(png::BitDepth::Eight);
        e.write_header().unwrap().write_image_data(data).unwrap();
        out
    }

    fn raw<'a>(encoding: &str, w: u32, h: u32, step: u32, data: &'a [u8]) -> ImageData<'a> {
        ImageData {
            header: Header {
                stamp: 0.0,
                frame_id: String::new(),
            },
            width: w,
            height: h,
            encoding: encoding.into(),
            step,
            compressed: false,
            data,
        }
    }

    #[test]
    fn raw_messages_decode_to_their_levels_with_padded_rows() {
        // mono8 with rows padded to 3 bytes: the padding is not a pixel.
        let g = decode_message(&raw("mono8", 2, 2, 3, &[1, 2, 99, 3, 4, 99])).unwrap();
        assert_eq!(g.data, vec![1, 2, 3, 4]);
        // Pure red in rgb8 and in bgr8: the same luma as the PNG's (76).
        let rgb = [255, 0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0];
        assert_eq!(
            decode_message(&raw("rgb8", 2, 2, 6, &rgb)).unwrap().data,
            vec![76; 4]
        );
        let bgr = [0, 0, 255, 0, 0, 255, 0, 0, 255, 0, 0, 255];
        assert_eq!(
            decode_message(&raw("bgr8", 2, 2, 6, &bgr)).unwrap().data,
            vec![76; 4]
        );
    }

    #[test]
    fn unknown_encodings_and_short_data_are_named() {
        let e = decode_message(&raw("yuv422", 2, 2, 4, &[0; 8])).unwrap_err();
        assert!(e.contains("encoding 'yuv422'"), "{e}");
        let e = decode_message(&raw("mono8", 4, 4, 4, &[0; 10])).unwrap_err();
        assert!(e.contains("10 byte(s) of pixels for 4 × 4 px mono8"), "{e}");
        let mut tiff = raw("tiff", 0, 0, 0, &[0x49, 0x49]);
        tiff.compressed = true;
        let e = decode_message(&tiff).unwrap_err();
        assert!(e.contains("format 'tiff'"), "{e}");
        let mut jpeg = raw("jpeg", 0, 0, 0, &[0xff, 0xd8]);
        jpeg.compressed = true;
        let e = decode_message(&jpeg).unwrap_err();
        assert!(e.contains("not a readable JPEG image"), "{e}");
        let mut png = raw("png", 0, 0, 0, &[]);
        let bytes = encode(2, 2, &[5, 6, 7, 8]);
        png.data = &bytes;
        png.compressed = true;
        assert_eq!(decode_message(&png).unwrap().data, vec![5, 6, 7, 8]);
    }
}
