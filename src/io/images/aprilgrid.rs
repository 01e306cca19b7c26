//! A Kalibr aprilgrid's tag corners found in an image, with Kalibr's ids
//! (tag `k`'s corners `4k … 4k + 3`: lower left, lower right, upper right,
//! upper left on the printed face; activecal's `aprilgrid:` target).
//!
//! **Finding.** The crate `aprilgrid` (powei-lin's aprilgrid-rs, a Rust
//! port of Kalibr's detector idea: the grid's X-junctions, where each
//! tag's corner touches the black square Kalibr prints diagonally outside
//! it, found as saddle points of the blurred image, grouped into quads,
//! each quad's 6 × 6 bits read and matched to AprilTag's 36h11 family
//! with its 2-bit border) gives each tag found by id with its four
//! corners. Tags whose id is not on the grid (another tag in the scene,
//! a misread) are dropped. The corners carry ids: a part of the grid is
//! labelled as well as the whole of it.
//!
//! **Refined by point symmetry.** The crate places each corner at the
//! saddle point of a quadratic fitted to the image blurred by a Gaussian
//! of 1.5 px (and a cone), over 5 × 5 pixels about the nearest pixel: a
//! fit that reaches past the four edges through the corner (the tag's
//! data bits two bits in, the corner square's far edges), whose corners
//! are pulled by what lies there: on the renders of
//! `verify/tests/live_images_truth.rs`, tags of 15–25 px had their
//! corners 0.02 px outward and each image's corners a common error of
//! 0.005–0.01 px, the same in every draw of the noise, which moved the
//! calibrated camera (the true error 1.52× the prediction). activecal
//! refines each corner to the centre of point symmetry of the disc
//! clear of other edges, less a pixel for the image's blur
//! ([`super::refine::refine_symmetric`]): the X-junction looks the same
//! turned 180° about its centre whatever the blur and gamma, and nothing
//! beyond the disc enters. Förstner's operator in the same disc was
//! worse than the crate (its 95th percentile 0.111 px against 0.067 px);
//! the figures of the three are in docs/cameras.md
//! (`live_images_aprilgrid_corner_bias`). A disc under 1.5 px (tags
//! under about 12 px) keeps the crate's corner, as does a move of more
//! than [`super::refine::MAX_SHIFT`].
//!
//! **The disc clear of other edges.** At a tag's corner the four
//! quadrants are the
//! tag's black border (2 bits: a fifth of the tag's side, then its data
//! bits), the black corner square (`tag_spacing` times the side) and two
//! white gaps as wide as it: the refinement's disc stays among the four
//! edges through the corner within `min(0.2, tag_spacing)` tag sides of
//! the edges across (measured square to those edges: a tag seen sheared
//! leaves less room along its diagonal; an axis-aligned square window
//! of the same half width placed two corners of the committed renders
//! 0.52 px off, reaching into the data bits).

use super::decode::Gray;
use super::detect::Located;
use crate::io::camera_target::AprilgridPattern;

/// The tag's border over its side: Kalibr prints 36h11 tags (6 × 6 bits)
/// with a 2-bit black border, 10 bits across.
const BORDER_OVER_SIDE: f64 = 0.2;

/// The corners of the aprilgrid `p` found in `img`, by Kalibr's ids, with
/// each corner's tag side (its tag's shortest side, px) and clear
/// half-width (see the module documentation); the error says why none
/// were found, in words.
pub fn find_aprilgrid(img: &Gray, p: &AprilgridPattern) -> Result<Vec<Located>, String> {
    let buffer = image::GrayImage::from_raw(img.width as u32, img.height as u32, img.data.clone())
        .ok_or("the image's levels do not fill its size")?;
    let detector = aprilgrid::detector::TagDetector::new(&aprilgrid::TagFamily::T36H11, None);
    let tags = detector.detect(&image::DynamicImage::ImageLuma8(buffer));
    let n_tags = p.rows * p.cols;
    let mut ids: Vec<u32> = tags.keys().copied().collect();
    ids.sort_unstable();
    let (on, off): (Vec<u32>, Vec<u32>) = ids.into_iter().partition(|&k| (k as usize) < n_tags);
    if on.is_empty() {
        return Err(if off.is_empty() {
            "no aprilgrid: no 36h11 tag found".into()
        } else {
            format!(
                "no aprilgrid: {} 36h11 tag(s) found, none of the grid's ids 0 … {} ({} × {} tags)",
                off.len(),
                n_tags - 1,
                p.rows,
                p.cols
            )
        });
    }
    let clear = BORDER_OVER_SIDE.min(p.tag_spacing);
    let mut out = Vec::with_capacity(4 * on.len());
    for k in on {
        let c = tags[&k];
        let px: [[f64; 2]; 4] = std::array::from_fn(|i| {
            let q = c[CRATE_OF_KALIBR[i]];
            [f64::from(q.0), f64::from(q.1)]
        });
        let d = |a: [f64; 2], b: [f64; 2]| [b[0] - a[0], b[1] - a[1]];
        let side = (0..4)
            .map(|i| d(px[i], px[(i + 1) % 4]))
            .map(|e| e[0].hypot(e[1]))
            .fold(f64::INFINITY, f64::min);
        for (i, q) in px.iter().enumerate() {
            // The tag's edges at this corner, `a` and `b`: the border's
            // inner edges run parallel to them `clear` of the other edge
            // in, at `clear·|a × b| / |a|` and `clear·|a × b| / |b|` from
            // the corner (the corner square's and the gaps' far edges
            // likewise), so a disc of `clear·|a × b| / max(|a|, |b|)`
            // holds only the four edges through the corner, however the
            // tag is turned or sheared in the image.
            let (a, b) = (d(*q, px[(i + 1) % 4]), d(*q, px[(i + 3) % 4]));
            let cross = (a[0] * b[1] - a[1] * b[0]).abs();
            let longer = a[0].hypot(a[1]).max(b[0].hypot(b[1]));
            out.push(Located {
                id: 4 * k as usize + i,
                px: *q,
                square_px: side,
                clear_px: clear * cross / longer,
                round: true,
            });
        }
    }
    Ok(out)
}

/// The crate's corner index of Kalibr's corner `i` of a tag (lower left,
/// lower right, upper right, upper left): the crate gives Kalibr's order
/// (every corner of 587 tags on 17 rendered images had its true id,
/// `verify/python/camera_images.py render --aprilgrid`, and the
/// committed renders' test in `tests/camera_images.rs`).
const CRATE_OF_KALIBR: [usize; 4] = [0, 1, 2, 3];
