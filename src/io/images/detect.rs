//! A checkerboard's inner corners found in an image and labelled with the
//! ids of activecal's `checkerboard:` target (id = row · cols + col at
//! `(col · square, row · square, 0)`).
//!
//! **Finding.** The crate `calib-targets-chessboard` finds X-junctions
//! (ChESS corners) and labels those that form one grid with integer
//! coordinates; its three parameter sets (`ChessboardParams::
//! sweep_default`) are tried in turn on the same corners until one gives
//! the whole board, then again on the corners of the image upscaled twice
//! (squares of a few pixels, a far oblique board). A checkerboard's corners carry no ids, so only a
//! board seen whole (every one of its `rows × cols` inner corners) is
//! labelled: a part of it could sit anywhere on the board.
//!
//! **Labelling.** The grid's two axes are matched to the board's columns
//! and rows by their counts, and their directions chosen so that the
//! columns turn into the rows clockwise in the image (`x` right, `y`
//! down): the board's printed face seen with its `z` axis pointing away
//! from the camera, as `findChessboardCorners` orders it. That leaves the
//! board's 180° turn: on a board whose inner-corner counts differ in
//! parity (say 6 × 9) the square diagonally outside corner 0 is black and
//! the one outside the last corner white, and the darker one is taken as
//! corner 0's; on a board that looks the same turned (6 × 8, 7 × 5) the
//! turn with corner 0 nearer the image's top-left is taken, and the
//! camera calibration chooses each pose's labelling by the robot's motion
//! ([`crate::identify::camera::start::labels`]). A board seen from
//! behind (a see-through board) comes out mirrored, also repaired there.

use super::decode::Gray;
use calib_targets_chessboard::{
    ChessCorner, ChessboardDetector, ChessboardParams, GrayImageView, default_chess_config,
    detect_corners,
};
use chess_corners::UpscaleConfig;

/// A board's inner corners found in an image, by id.
#[derive(Clone, Debug, PartialEq)]
pub struct Found {
    /// Each corner's pixel, by id (`row · cols + col`), as the detector
    /// placed it.
    pub px: Vec<[f64; 2]>,
    /// Each corner's shortest square side: the distance to its nearest
    /// grid neighbour, px.
    pub square_px: Vec<f64>,
}

/// A target point found in an image, ready for refinement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Located {
    /// The point's id in the target (its index: the targets activecal
    /// detects number their points 0, 1, …).
    pub id: usize,
    /// Its pixel, as the detector placed it.
    pub px: [f64; 2],
    /// The shortest square side at it, px.
    pub square_px: f64,
    /// How far around it the image holds only the four squares' edges
    /// that meet there, px: half a square on a checkerboard, less on a
    /// ChArUco board (its markers' edges), the refinement's window bound
    /// ([`super::refine::half_window_within`]).
    pub clear_px: f64,
    /// Whether `clear_px` is a disc's radius (a ChArUco corner) rather
    /// than a square window's half width.
    pub round: bool,
}

impl Found {
    /// The corners as [`Located`] points (clear for half a square).
    #[must_use]
    pub fn located(&self) -> Vec<Located> {
        self.px
            .iter()
            .zip(&self.square_px)
            .enumerate()
            .map(|(id, (px, s))| Located {
                id,
                px: *px,
                square_px: *s,
                clear_px: 0.5 * s,
                round: false,
            })
            .collect()
    }
}

/// Finds the `rows × cols` inner corners of a checkerboard in `img`; the
/// error says why none were found, in words.
pub fn find_checkerboard(img: &Gray, rows: usize, cols: usize) -> Result<Found, String> {
    let view = GrayImageView {
        width: img.width,
        height: img.height,
        data: &img.data,
    };
    let want = rows * cols;
    let (mut best, mut candidates) = (0, 0);
    for upscale in [1, 2] {
        let mut config = default_chess_config();
        if upscale > 1 {
            config = config.with_upscale(UpscaleConfig::fixed(upscale));
        }
        let corners = detect_corners(&view, &config);
        candidates = candidates.max(corners.len());
        match grid_of(img, &corners, rows, cols) {
            Ok(found) => return Ok(found),
            Err(n) => best = best.max(n),
        }
    }
    Err(if best == 0 {
        format!("no checkerboard: {candidates} corner-like point(s) but no grid among them")
    } else {
        format!(
            "board not seen whole: a grid of {best} corner(s) found, the board has {want} ({rows} × {cols} inner corners; a checkerboard's corners carry no ids, so a part of it cannot be labelled)"
        )
    })
}

/// The whole board among `corners`, or the size of the largest grid
/// found.
fn grid_of(img: &Gray, corners: &[ChessCorner], rows: usize, cols: usize) -> Result<Found, usize> {
    let mut best = 0;
    for params in ChessboardParams::sweep_default() {
        let Ok(detector) = ChessboardDetector::new(params) else {
            continue;
        };
        let Some(d) = detector.detect(corners) else {
            continue;
        };
        let grid: Vec<([i64; 2], [f64; 2])> = d
            .corners
            .iter()
            .map(|c| {
                (
                    [i64::from(c.grid.u), i64::from(c.grid.v)],
                    [f64::from(c.position.x), f64::from(c.position.y)],
                )
            })
            .collect();
        best = best.max(grid.len());
        if let Some(f) = label(img, &grid, rows, cols) {
            return Ok(f);
        }
    }
    Err(best)
}

/// One way of reading the grid's `(u, v)` as the board's `(col, row)`.
#[derive(Clone, Copy, Debug)]
struct Axes {
    swap: bool,
    flip_u: bool,
    flip_v: bool,
}

/// The grid's corners as the board's, by id; `None` unless the grid is
/// the whole board.
fn label(img: &Gray, grid: &[([i64; 2], [f64; 2])], rows: usize, cols: usize) -> Option<Found> {
    if grid.len() != rows * cols {
        return None;
    }
    let lo = [0, 1].map(|k| grid.iter().map(|(g, _)| g[k]).min().unwrap_or(0));
    let hi = [0, 1].map(|k| grid.iter().map(|(g, _)| g[k]).max().unwrap_or(0));
    let n = [hi[0] - lo[0] + 1, hi[1] - lo[1] + 1];
    let mut candidates: Vec<Vec<[f64; 2]>> = Vec::new();
    for bits in 0..8u8 {
        let a = Axes {
            swap: bits & 1 != 0,
            flip_u: bits & 2 != 0,
            flip_v: bits & 4 != 0,
        };
        let (nc, nr) = if a.swap { (n[1], n[0]) } else { (n[0], n[1]) };
        if (nc, nr) != (cols as i64, rows as i64) {
            continue;
        }
        let mut px = vec![[f64::NAN; 2]; rows * cols];
        for (g, p) in grid {
            let (mut u, mut v) = (g[0] - lo[0], g[1] - lo[1]);
            if a.flip_u {
                u = n[0] - 1 - u;
            }
            if a.flip_v {
                v = n[1] - 1 - v;
            }
            let (c, r) = if a.swap { (v, u) } else { (u, v) };
            px[r as usize * cols + c as usize] = *p;
        }
        if px.iter().any(|p| p[0].is_nan()) || !front_face(&px, rows, cols) {
            continue;
        }
        candidates.push(px);
    }
    let asymmetric = (rows + cols) % 2 == 1;
    let px = if asymmetric {
        candidates
            .into_iter()
            .min_by(|a, b| outer_darkness(img, a, cols).total_cmp(&outer_darkness(img, b, cols)))?
    } else {
        candidates
            .into_iter()
            .min_by(|a, b| (a[0][0] + a[0][1]).total_cmp(&(b[0][0] + b[0][1])))?
    };
    let square_px = shortest_sides(&px, rows, cols);
    Some(Found { px, square_px })
}

/// Whether the columns turn into the rows clockwise in the image (the
/// printed face seen, see the module documentation).
fn front_face(px: &[[f64; 2]], rows: usize, cols: usize) -> bool {
    let o = px[0];
    let ex = px[cols - 1];
    let ey = px[(rows - 1) * cols];
    let (a, b) = ([ex[0] - o[0], ex[1] - o[1]], [ey[0] - o[0], ey[1] - o[1]]);
    a[0] * b[1] - a[1] * b[0] > 0.0
}

/// The level of the square diagonally outside corner 0 less that of its
/// neighbour outside the first row (black less white on the board's
/// printed convention: negative when corner 0 is where it should be).
fn outer_darkness(img: &Gray, px: &[[f64; 2]], cols: usize) -> f64 {
    let (o, x, y) = (px[0], px[1], px[cols]);
    let at = |a: f64, b: f64| {
        img.bilinear(
            o[0] + a * (x[0] - o[0]) + b * (y[0] - o[0]),
            o[1] + a * (x[1] - o[1]) + b * (y[1] - o[1]),
        )
    };
    at(-0.5, -0.5) - at(0.5, -0.5)
}

/// Each corner's distance to its nearest grid neighbour, px.
fn shortest_sides(px: &[[f64; 2]], rows: usize, cols: usize) -> Vec<f64> {
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    (0..rows * cols)
        .map(|k| {
            let (r, c) = (k / cols, k % cols);
            let mut s = f64::INFINITY;
            if c > 0 {
                s = s.min(d(px[k], px[k - 1]));
            }
            if c + 1 < cols {
                s = s.min(d(px[k], px[k + 1]));
            }
            if r > 0 {
                s = s.min(d(px[k], px[k - cols]));
            }
            if r + 1 < rows {
                s = s.min(d(px[k], px[k + cols]));
            }
            s
        })
        .collect()
}
