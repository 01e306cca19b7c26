//! A ChArUco board's chessboard corners found in an image, with OpenCV's
//! ids (id `i·(cols − 1) + j` at `((j + 1)·square, (i + 1)·square, 0)`,
//! activecal's `charuco:` target).
//!
//! **Finding.** The crate `calib-targets-charuco` finds X-junctions (ChESS
//! corners), builds their grid, decodes the ArUco markers in its white
//! squares and aligns the grid to the board by the markers' ids (OpenCV's
//! layout: markers in the squares whose row and column differ in parity,
//! numbered row by row). Its three parameter sets
//! (`CharucoParams::sweep_for_board`) are tried in turn, then again on the
//! image upscaled twice (squares of a few pixels); the detection with the
//! most corners is kept. The corners carry ids: a part of the board is
//! labelled as well as the whole of it, and a board seen turned or from
//! any side keeps its ids.
//!
//! **Legacy pattern.** OpenCV before 4.6 (and `setLegacyPattern(true)`
//! since) places the markers in the other squares when the board has an
//! even number of rows; the crate reads only the current layout, so such a
//! board is refused before any image is read ([`check_pattern`]). With an
//! odd number of rows both layouts are the same board.

use super::decode::Gray;
use super::detect::Located;
use crate::io::camera_target::CharucoPattern;
use calib_targets_charuco::{
    CharucoBoardSpec, CharucoDetection, CharucoDetector, CharucoParams, GrayImageView,
    MarkerLayout, resolve_dictionary,
};
use chess_corners::UpscaleConfig;

/// Why `p` cannot be detected in images, if it cannot: no dictionary
/// named, or OpenCV's legacy pattern on an even number of rows (see the
/// module documentation).
pub fn check_pattern(p: &CharucoPattern) -> Result<(), String> {
    let Some(name) = &p.dictionary else {
        return Err("a ChArUco board is detected by its markers: the target's 'charuco.dictionary' must name their ArUco dictionary (OpenCV's name, e.g. DICT_4X4_50)".into());
    };
    if resolve_dictionary(name).is_none() {
        return Err(format!(
            "'{name}' is not an ArUco dictionary activecal knows"
        ));
    }
    if p.legacy_pattern && p.rows % 2 == 0 {
        return Err(format!(
            "a ChArUco board of {} rows printed with OpenCV's legacy pattern (legacy_pattern: true) places its markers in the other squares, which activecal does not detect yet; print the board with OpenCV ≥ 4.6's layout (the default), or one with an odd number of rows (both layouts are then the same)",
            p.rows
        ));
    }
    Ok(())
}

/// The corners of the ChArUco board `p` found in `img`, by id, with each
/// corner's shortest square side and clear radius: the distance to the
/// nearest marker's corner (`√2` times its margin in the white square),
/// within half a square, px; the error says why none were found, in words.
pub fn find_charuco(img: &Gray, p: &CharucoPattern) -> Result<Vec<Located>, String> {
    check_pattern(p)?;
    let dictionary = p
        .dictionary
        .as_deref()
        .and_then(resolve_dictionary)
        .ok_or("no dictionary")?;
    let spec = CharucoBoardSpec::new(
        p.rows as u32,
        p.cols as u32,
        (1e3 * p.square) as f32,
        (p.marker / p.square) as f32,
        dictionary,
    )
    .with_marker_layout(MarkerLayout::OpenCvCharuco);
    let view = GrayImageView {
        width: img.width,
        height: img.height,
        data: &img.data,
    };
    let mut best: Option<CharucoDetection> = None;
    let mut why = String::from("no ChArUco board");
    for upscale in [1, 2] {
        for mut params in CharucoParams::sweep_for_board(&spec) {
            if upscale > 1 {
                params.chess = params.chess.with_upscale(UpscaleConfig::fixed(upscale));
            }
            let Ok(detector) = CharucoDetector::new(params) else {
                continue;
            };
            match detector.detect(&view) {
                Ok(d)
                    if best
                        .as_ref()
                        .is_none_or(|b| d.corners.len() > b.corners.len()) =>
                {
                    best = Some(d);
                }
                Ok(_) => {}
                Err(e) => why = format!("no ChArUco board ({e})"),
            }
        }
        if best.is_some() {
            break;
        }
    }
    let d = best.ok_or(why)?;
    let n = (p.rows - 1) * (p.cols - 1);
    let corners: Vec<(usize, [f64; 2])> = d
        .corners
        .iter()
        .filter(|c| (c.id as usize) < n)
        .map(|c| {
            (
                c.id as usize,
                [f64::from(c.position.x), f64::from(c.position.y)],
            )
        })
        .collect();
    // The distance from a corner to the nearest marker corner, in squares
    // (the white square's margin around its marker, diagonally), within
    // half a square.
    let clear = (std::f64::consts::SQRT_2 * 0.5 * (p.square - p.marker) / p.square).min(0.5);
    Ok(corners
        .iter()
        .map(|&(id, px)| {
            let square_px = shortest_side(id, px, &corners, p.cols - 1);
            Located {
                id,
                px,
                square_px,
                clear_px: clear * square_px,
                round: true,
            }
        })
        .collect())
}

/// The shortest square side at corner `id` (at `px`): the least distance
/// in pixels over grid distance in squares to another corner found; the
/// board's grid is `cols` inner corners across.
fn shortest_side(id: usize, px: [f64; 2], corners: &[(usize, [f64; 2])], cols: usize) -> f64 {
    let (r, c) = ((id / cols) as f64, (id % cols) as f64);
    corners
        .iter()
        .filter(|(k, _)| *k != id)
        .map(|(k, q)| {
            let squares = ((k / cols) as f64 - r).hypot((k % cols) as f64 - c);
            (q[0] - px[0]).hypot(q[1] - px[1]) / squares
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(rows: usize, dictionary: Option<&str>, legacy_pattern: bool) -> CharucoPattern {
        CharucoPattern {
            rows,
            cols: 5,
            square: 0.04,
            marker: 0.03,
            dictionary: dictionary.map(str::to_string),
            legacy_pattern,
        }
    }

    #[test]
    fn a_board_without_its_dictionary_or_in_the_legacy_layout_is_refused_in_words() {
        let e = check_pattern(&pattern(4, None, false)).unwrap_err();
        assert!(e.contains("'charuco.dictionary'"), "{e}");
        let e = check_pattern(&pattern(4, Some("DICT_4X4_50"), true)).unwrap_err();
        assert!(e.contains("legacy pattern") && e.contains("4 rows"), "{e}");
        // An odd number of rows: both layouts are the same board.
        assert!(check_pattern(&pattern(5, Some("DICT_4X4_50"), true)).is_ok());
        assert!(check_pattern(&pattern(4, Some("DICT_5X5_100"), false)).is_ok());
    }

    /// Corners 0 and 1 one square apart along a row (10 px), corner 8 two
    /// rows below corner 0 (24 px): corner 0's shortest side is 10 px;
    /// corner 8's the least of 24 px over 2 squares (to corner 0) and 26
    /// px over √5 squares (to corner 1, one across and two down).
    #[test]
    fn a_corners_shortest_side_is_its_nearest_neighbours_distance_over_their_grid_distance() {
        let corners = [(0, [0.0, 0.0]), (1, [10.0, 0.0]), (8, [0.0, 24.0])];
        assert!((shortest_side(0, [0.0, 0.0], &corners, 4) - 10.0).abs() < 1e-12);
        let want = 26.0 / 5f64.sqrt();
        assert!((shortest_side(8, [0.0, 24.0], &corners, 4) - want).abs() < 1e-12);
    }

    #[test]
    fn a_blank_image_has_no_board() {
        let img = Gray {
            width: 64,
            height: 48,
            data: vec![128; 64 * 48],
        };
        let e = find_charuco(&img, &pattern(5, Some("DICT_4X4_50"), false)).unwrap_err();
        assert!(e.starts_with("no ChArUco board"), "{e}");
    }
}
