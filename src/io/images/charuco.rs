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
//! even number of rows ([`super::layout`]); the crate reads only the
//! current layout. A legacy board of `rows × cols` squares is the lower
//! `rows` rows of a current-layout board of `rows + 1` rows whose first
//! row's `⌊cols / 2⌋` markers are not printed: the crate is given that
//! board, its markers numbered as the legacy board's after that first
//! row's (codes of the dictionary the board does not use), and its
//! corners' ids less `cols − 1` (the first row of inner corners, on the
//! printed board's edge, is dropped).
//!
//! **Ids checked.** Every detection's ids are checked against the image
//! itself ([`super::layout`]): the markers read in the squares whose four
//! corners were found must be those the layout puts there. A board
//! printed in the other layout than the target says is refused with that
//! reason, never labelled with another corner's ids.

use super::decode::Gray;
use super::detect::Located;
use super::layout::{self, Layout};
use crate::io::camera_target::CharucoPattern;
use calib_targets_charuco::{
    CharucoBoardSpec, CharucoDetector, CharucoParams, Dictionary, GrayImageView, MarkerLayout,
    resolve_dictionary,
};
use chess_corners::UpscaleConfig;
use std::collections::HashMap;
use std::sync::{Mutex, PoisonError};

/// Why `p` cannot be detected in images, if it cannot: no dictionary
/// named, or a legacy board whose dictionary holds too few markers for
/// the crate's board (see the module documentation).
pub fn check_pattern(p: &CharucoPattern) -> Result<(), String> {
    let Some(name) = &p.dictionary else {
        return Err("a ChArUco board is detected by its markers: the target's 'charuco.dictionary' must name their ArUco dictionary (OpenCV's name, e.g. DICT_4X4_50)".into());
    };
    let Some(dictionary) = resolve_dictionary(name) else {
        return Err(format!(
            "'{name}' is not an ArUco dictionary activecal knows"
        ));
    };
    crate_board(p, dictionary).map(|_| ())
}

/// The board the crate is given for `p`, and how much to take off its
/// corners' ids (see the module documentation).
fn crate_board(
    p: &CharucoPattern,
    dictionary: Dictionary,
) -> Result<(CharucoBoardSpec, usize), String> {
    let (rows, dictionary, shift) = if p.legacy_pattern && p.rows % 2 == 0 {
        (
            p.rows + 1,
            legacy_dictionary(dictionary, p.rows, p.cols)?,
            p.cols - 1,
        )
    } else {
        (p.rows, dictionary, 0)
    };
    let spec = CharucoBoardSpec::new(
        rows as u32,
        p.cols as u32,
        (1e3 * p.square) as f32,
        (p.marker / p.square) as f32,
        dictionary,
    )
    .with_marker_layout(MarkerLayout::OpenCvCharuco);
    Ok((spec, shift))
}

/// The dictionary of the crate's board for a legacy board of `rows` (even)
/// × `cols` squares: `⌊cols / 2⌋` codes the board does not print (those
/// after its `rows · cols / 2` markers), then the board's own. Built once
/// per dictionary and board size (the crate keeps codes for the program's
/// life).
fn legacy_dictionary(d: Dictionary, rows: usize, cols: usize) -> Result<Dictionary, String> {
    static BUILT: Mutex<Vec<((&str, usize, usize), Dictionary)>> = Mutex::new(Vec::new());
    let (n, pad) = (rows * cols / 2, cols / 2);
    let codes = d.codes();
    if codes.len() < n + pad {
        return Err(format!(
            "a ChArUco board of {rows} × {cols} squares in OpenCV's legacy layout (legacy_pattern: true) is detected with {pad} more markers than its {n} from its dictionary, and {} has {}",
            d.name(),
            codes.len()
        ));
    }
    let mut built = BUILT.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some((_, b)) = built.iter().find(|(k, _)| *k == (d.name(), rows, cols)) {
        return Ok(*b);
    }
    let v: Vec<u64> = codes[n..n + pad]
        .iter()
        .chain(&codes[..n])
        .copied()
        .collect();
    let b = Dictionary::from_static_codes(
        d.name(),
        d.marker_size(),
        d.max_correction_bits(),
        Box::leak(v.into_boxed_slice()),
    )
    .map_err(|e| format!("the legacy board's dictionary ({e:?})"))?;
    built.push(((d.name(), rows, cols), b));
    Ok(b)
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
    let (spec, shift) = crate_board(p, dictionary)?;
    let layout = Layout::opencv(p.rows, p.cols, p.legacy_pattern);
    let view = GrayImageView {
        width: img.width,
        height: img.height,
        data: &img.data,
    };
    let n = (p.rows - 1) * (p.cols - 1);
    let mut best: Option<Vec<(usize, [f64; 2])>> = None;
    let mut refused: Option<(usize, String)> = None;
    let mut why = String::from("no ChArUco board");
    for upscale in [1, 2] {
        for mut params in CharucoParams::sweep_for_board(&spec) {
            if upscale > 1 {
                params.chess = params.chess.with_upscale(UpscaleConfig::fixed(upscale));
            }
            let Ok(detector) = CharucoDetector::new(params) else {
                continue;
            };
            let d = match detector.detect(&view) {
                Ok(d) => d,
                Err(e) => {
                    why = format!("no ChArUco board ({e})");
                    continue;
                }
            };
            let corners: Vec<(usize, [f64; 2])> = d
                .corners
                .iter()
                .filter_map(|c| {
                    let id = (c.id as usize).checked_sub(shift)?;
                    (id < n).then(|| (id, [f64::from(c.position.x), f64::from(c.position.y)]))
                })
                .collect();
            match check_ids(img, &corners, p, dictionary, &layout) {
                Ok(()) if best.as_ref().is_none_or(|b| corners.len() > b.len()) => {
                    best = Some(corners);
                }
                Ok(()) => {}
                Err(e) if refused.as_ref().is_none_or(|r| corners.len() > r.0) => {
                    refused = Some((corners.len(), e));
                }
                Err(_) => {}
            }
        }
        if best.is_some() {
            break;
        }
    }
    let corners = match (best, refused) {
        (Some(c), _) => c,
        (None, Some((_, e))) => return Err(e),
        (None, None) => return Err(why),
    };
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

/// Whether the markers read in the squares of the `corners` found (by id
/// on the board `p`) are those `layout` puts there; the error says which
/// layout they are, in words.
fn check_ids(
    img: &Gray,
    corners: &[(usize, [f64; 2])],
    p: &CharucoPattern,
    dictionary: Dictionary,
    layout: &Layout,
) -> Result<(), String> {
    let inner = p.cols - 1;
    let by_corner: HashMap<[i64; 2], [f64; 2]> = corners
        .iter()
        .map(|&(id, px)| ([(id % inner + 1) as i64, (id / inner + 1) as i64], px))
        .collect();
    let Some(grid) = layout::Grid::new(&by_corner) else {
        return Err(format!(
            "{} corner(s) found, too few to check their ids against the markers",
            corners.len()
        ));
    };
    let rel = p.marker / p.square;
    let reads = layout::read_markers(img, &grid, (p.rows, p.cols), dictionary, rel);
    let a = layout::agreement(layout, &reads);
    let white = layout::white_where_black(img, &grid, layout, rel).unwrap_or(0);
    if a.disagree == 0 && white == 0 {
        return Ok(());
    }
    let counts = format!(
        "{} of the {} markers read on and around the board are not where its layout puts them, {white} of its squares without a marker are not black",
        a.disagree,
        reads.len()
    );
    let other = Layout::opencv(p.rows, p.cols, !p.legacy_pattern);
    Err(
        if other != *layout && layout::explained_by(&other, &reads) {
            if p.legacy_pattern {
                format!(
                    "{counts}: the markers read are those of OpenCV's current layout (4.6 and later): is the board printed without setLegacyPattern(true)? remove `legacy_pattern: true`"
                )
            } else {
                format!(
                    "{counts}: the markers read are those of OpenCV's legacy layout: is the board printed with setLegacyPattern(true)? say `legacy_pattern: true`"
                )
            }
        } else {
            format!("markers disagree with the board's layout ({counts})")
        },
    )
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
    fn a_board_without_its_dictionary_or_too_large_for_its_legacy_detection_is_refused_in_words() {
        let e = check_pattern(&pattern(4, None, false)).unwrap_err();
        assert!(e.contains("'charuco.dictionary'"), "{e}");
        assert!(check_pattern(&pattern(4, Some("DICT_4X4_50"), true)).is_ok());
        assert!(check_pattern(&pattern(5, Some("DICT_4X4_50"), true)).is_ok());
        // A legacy board of 20 × 5 squares uses DICT_4X4_50's 50 markers;
        // the crate's board needs 2 more.
        let mut big = pattern(20, Some("DICT_4X4_50"), true);
        big.cols = 5;
        let e = check_pattern(&big).unwrap_err();
        assert!(
            e.contains("2 more markers than its 50") && e.contains("has 50"),
            "{e}"
        );
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
