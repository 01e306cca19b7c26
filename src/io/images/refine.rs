//! Sub-pixel refinement of a checkerboard corner and the sharpness of the
//! edges around it.
//!
//! The refinement is Förstner's corner operator as OpenCV's
//! `cornerSubPix` iterates it: at the corner `q` every image gradient
//! `g(p)` near it is orthogonal to `p − q` (a point on an edge has its
//! gradient across the edge, which runs through `q`; a point in a flat
//! square has none), so `q` minimises `Σ w(p) (g(p)ᵀ (p − q))²`, whose
//! normal equations are `(Σ w g gᵀ) q = Σ w g gᵀ p`. The window is the
//! square `[−h, h]²` about the current estimate, sampled at the image's
//! pixel spacing by bilinear interpolation, weighted by `w = exp(−(dx² +
//! dy²)/h²)`, and re-centred until the step is below [`STEP_TOL`].
//!
//! The window must stay inside the four squares that meet at the corner:
//! its gradients then all point at this corner. A window wider than a
//! square reaches the next corners' edges, which pull the estimate by
//! pixels (OpenCV's tutorial window of 11 px each side moved corners of
//! far, oblique boards by 6–8 px on the rendered images of
//! `verify/python/camera_images.py`). [`half_window`] keeps it under half
//! the shortest side of the squares at the corner.
//!
//! An aprilgrid's corners are refined otherwise, to the centre of point
//! symmetry of a disc about them ([`refine_symmetric`]): their clear disc
//! is a fifth of a tag's side (a few pixels on small tags), where
//! Förstner's operator has too few gradients (its 95th percentile was
//! worse than the detector's own corners, docs/cameras.md).

use super::decode::Gray;

/// The refinement stops when a step moves the corner less than this, px.
pub const STEP_TOL: f64 = 1e-4;
/// At most this many steps.
const MAX_STEPS: usize = 50;
/// The largest half window, px: OpenCV's tutorial window (11, 11). Larger
/// windows average more of the edges' noise: capped at 6 px, the corners
/// of near boards (squares of 20–60 px) were 0.031 px off in the median
/// against 0.026 px for `cornerSubPix` with (11, 11) on the same images
/// (`verify/tests/live_images.rs`).
pub const MAX_HALF_WINDOW: usize = 11;
/// The smallest half window refined, px: a window of 3 × 3 pixels (squares
/// under 6 px) holds too few gradients to place the corner better than
/// the detector did (on the rendered images, refining such corners moved
/// some by 1.2–1.5 px, while the detector's own were within 0.5 px).
pub const MIN_HALF_WINDOW: usize = 2;
/// The farthest a refinement may move the detector's corner, px: the
/// detector's corners were within 0.5 px of the truth on the rendered
/// images, so a longer move means the window holds another corner's edges,
/// and the detector's corner is kept.
pub const MAX_SHIFT: f64 = 0.75;

/// The half width `h` of the window for a corner whose shortest square
/// side is `square_px`: `h = ⌊square_px / 2 − 1⌋`, under half a square,
/// so the window `[−h, h]²` and its gradients' one-pixel margin stay
/// inside the four squares at the corner; at least 1 and at most
/// [`MAX_HALF_WINDOW`].
#[must_use]
pub fn half_window(square_px: f64) -> usize {
    half_window_within(0.5 * square_px)
}

/// The half width `h = ⌊clear_px − 1⌋` of a window that stays, with its
/// gradients' one-pixel margin, within `clear_px` of the corner (half a
/// square on a checkerboard, [`half_window`]; the distance to the nearest
/// marker's edge on a ChArUco board); at least 1 and at most
/// [`MAX_HALF_WINDOW`].
#[must_use]
pub fn half_window_within(clear_px: f64) -> usize {
    let h = (clear_px - 1.0).floor();
    if h.is_finite() && h > 1.0 {
        (h as usize).min(MAX_HALF_WINDOW)
    } else {
        1
    }
}

/// A refined corner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refined {
    /// The corner, px.
    pub px: [f64; 2],
    /// How far the refinement moved it from the detector's estimate, px.
    pub shift: f64,
}

/// The Förstner refinement of the corner near `start` in `img`, with the
/// half window `h` px; `None` when the window holds no corner (its
/// gradients all parallel or none) or the estimate leaves the window.
#[must_use]
pub fn refine_corner(img: &Gray, start: [f64; 2], h: usize) -> Option<Refined> {
    refine_corner_in(img, start, h, false)
}

/// [`refine_corner`] with the window `[−h, h]²`, or with `round` the disc
/// of radius `h` in it (a ChArUco corner: the markers' edges nearest the
/// corner are diagonal to it, at `√2` times their distance along the
/// board's axes, so a disc reaches farther than a square clear of them).
#[must_use]
pub fn refine_corner_in(img: &Gray, start: [f64; 2], h: usize, round: bool) -> Option<Refined> {
    let hi = h as i64;
    let hf = h as f64;
    let mut q = start;
    for _ in 0..MAX_STEPS {
        let (mut a, mut b, mut c, mut r0, mut r1) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for j in -hi..=hi {
            for i in -hi..=hi {
                if round && i * i + j * j > hi * hi {
                    continue;
                }
                let (x, y) = (q[0] + i as f64, q[1] + j as f64);
                let gx = 0.5 * (img.bilinear(x + 1.0, y) - img.bilinear(x - 1.0, y));
                let gy = 0.5 * (img.bilinear(x, y + 1.0) - img.bilinear(x, y - 1.0));
                let w = (-((i * i + j * j) as f64) / (hf * hf)).exp();
                let (gxx, gxy, gyy) = (w * gx * gx, w * gx * gy, w * gy * gy);
                a += gxx;
                b += gxy;
                c += gyy;
                r0 += gxx * x + gxy * y;
                r1 += gxy * x + gyy * y;
            }
        }
        let det = a * c - b * b;
        // Parallel gradients (an edge, no corner) or none: no corner.
        if !(det > 1e-9 * (a + c) * (a + c)) {
            return None;
        }
        let next = [(c * r0 - b * r1) / det, (a * r1 - b * r0) / det];
        let step = (next[0] - q[0]).hypot(next[1] - q[1]);
        q = next;
        if (q[0] - start[0]).hypot(q[1] - start[1]) > hf + 1.0 {
            return None;
        }
        if step < STEP_TOL {
            break;
        }
    }
    Some(Refined {
        px: q,
        shift: (q[0] - start[0]).hypot(q[1] - start[1]),
    })
}

/// The smallest radius [`refine_symmetric`] is given, px: a disc of
/// radius 1.5 holds 4 pixel pairs, the fewest that fix both coordinates
/// of an X-junction whose edges are not along the pixel axes.
pub const MIN_SYMMETRIC_RADIUS: f64 = 1.5;

/// The centre of point symmetry near `start` of the disc of radius
/// `radius` px about it: an X-junction (two straight edges crossing, the
/// opposite quadrants alike, as where a Kalibr aprilgrid's tag touches its
/// corner square) looks the same turned 180° about its centre `q`, so `q`
/// minimises `Σ w(p) (I(q + p) − I(q − p))²` over the pixel offsets `p`
/// of the disc (one of each pair `±p`), `w = exp(−|p|²/radius²)`, `I`
/// sampled by bilinear interpolation. Gauss–Newton: the residual's
/// derivative in `q` is `∇I(q + p) − ∇I(q − p)` (central differences),
/// iterated until the step is below [`STEP_TOL`].
///
/// Any point-wise grey mapping (gamma, contrast) and any blur symmetric
/// about the centre keep the junction point-symmetric, so, unlike a
/// saddle point fitted to a blurred image, the estimate is not pulled by
/// what lies beyond the disc (the tag's data bits, the corner square's far
/// edges) as long as the disc and the image's blur stay clear of it.
/// `None` when the residuals do not fix the centre (a flat or one-edged
/// disc) or the estimate leaves the disc.
#[must_use]
pub fn refine_symmetric(img: &Gray, start: [f64; 2], radius: f64) -> Option<Refined> {
    let r = radius.floor() as i64;
    let offsets: Vec<(f64, f64, f64)> = (0..=r)
        .flat_map(|j| (-r..=r).map(move |i| (i, j)))
        .filter(|&(i, j)| (j > 0 || i > 0) && ((i * i + j * j) as f64) <= radius * radius)
        .map(|(i, j)| {
            let d2 = (i * i + j * j) as f64;
            (i as f64, j as f64, (-d2 / (radius * radius)).exp())
        })
        .collect();
    let grad = |x: f64, y: f64| {
        [
            0.5 * (img.bilinear(x + 1.0, y) - img.bilinear(x - 1.0, y)),
            0.5 * (img.bilinear(x, y + 1.0) - img.bilinear(x, y - 1.0)),
        ]
    };
    let mut q = start;
    for _ in 0..MAX_STEPS {
        let (mut a, mut b, mut c, mut r0, mut r1) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for &(i, j, w) in &offsets {
            let (xa, ya, xb, yb) = (q[0] + i, q[1] + j, q[0] - i, q[1] - j);
            let res = img.bilinear(xa, ya) - img.bilinear(xb, yb);
            let (ga, gb) = (grad(xa, ya), grad(xb, yb));
            let (jx, jy) = (ga[0] - gb[0], ga[1] - gb[1]);
            a += w * jx * jx;
            b += w * jx * jy;
            c += w * jy * jy;
            r0 += w * jx * res;
            r1 += w * jy * res;
        }
        let det = a * c - b * b;
        if !(det > 1e-9 * (a + c) * (a + c)) {
            return None;
        }
        // The Gauss–Newton step −(JᵀWJ)⁻¹ JᵀW r.
        let step = [-(c * r0 - b * r1) / det, -(a * r1 - b * r0) / det];
        q = [q[0] + step[0], q[1] + step[1]];
        if (q[0] - start[0]).hypot(q[1] - start[1]) > radius + 1.0 {
            return None;
        }
        if step[0].hypot(step[1]) < STEP_TOL {
            break;
        }
    }
    Some(Refined {
        px: q,
        shift: (q[0] - start[0]).hypot(q[1] - start[1]),
    })
}

/// The sharpness of the edges at a corner: their width, px, the window's
/// contrast (its brightest level less its darkest) over its steepest
/// gradient (central differences), i.e. the width of the linear ramp that
/// would rise as steeply. An edge sharp to the pixel reads 2 px (a central
/// difference spans two pixels), one blurred by a Gaussian of σ ≫ 1 px
/// reads `σ √(2π) ≈ 2.5 σ`; an image out of focus reads several pixels.
/// `None` for a window without contrast.
#[must_use]
pub fn edge_width(img: &Gray, at: [f64; 2], h: usize) -> Option<f64> {
    let hi = h as i64 + 1;
    let (mut lo, mut up, mut steepest) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    for j in -hi..=hi {
        for i in -hi..=hi {
            let (x, y) = (at[0] + i as f64, at[1] + j as f64);
            let v = img.bilinear(x, y);
            lo = lo.min(v);
            up = up.max(v);
            let gx = 0.5 * (img.bilinear(x + 1.0, y) - img.bilinear(x - 1.0, y));
            let gy = 0.5 * (img.bilinear(x, y + 1.0) - img.bilinear(x, y - 1.0));
            steepest = steepest.max(gx.hypot(gy));
        }
    }
    (steepest > 0.0 && up - lo > 0.0).then(|| (up - lo) / steepest)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A checkerboard corner at `(cx, cy)` drawn exactly with 8 × 8
    /// sub-pixels per pixel, squares `side` px, black 20 and white 220.
    fn corner_image(cx: f64, cy: f64, side: f64, n: usize) -> Gray {
        let mut data = Vec::with_capacity(n * n);
        for y in 0..n {
            for x in 0..n {
                let mut s = 0.0f64;
                for sy in 0..8 {
                    for sx in 0..8 {
                        let u = x as f64 - 0.5 + (sx as f64 + 0.5) / 8.0 - cx;
                        let v = y as f64 - 0.5 + (sy as f64 + 0.5) / 8.0 - cy;
                        let (a, b) = ((u / side).floor() as i64, (v / side).floor() as i64);
                        s += if (a + b).rem_euclid(2) == 0 {
                            20.0
                        } else {
                            220.0
                        };
                    }
                }
                data.push((s / 64.0).round() as u8);
            }
        }
        Gray {
            width: n,
            height: n,
            data,
        }
    }

    #[test]
    fn a_drawn_corner_is_found_to_a_tenth_of_a_pixel_from_a_pixel_off() {
        // The exact corner is known; the start is 1.16 px off. On a corner
        // sharp to the pixel (no blur: the gradients of a one-pixel ramp,
        // sampled by central differences, are lopsided) the operator is
        // biased by a few hundredths of a pixel (0.067 px here): under a
        // tenth, and more than ten times closer than the start.
        let (cx, cy) = (20.37, 19.71);
        let start = [21.2, 18.9];
        let img = corner_image(cx, cy, 12.0, 40);
        let r = refine_corner(&img, start, half_window(12.0)).unwrap();
        let e = (r.px[0] - cx).hypot(r.px[1] - cy);
        let e0 = (start[0] - cx).hypot(start[1] - cy);
        assert!(
            e < 0.1 && e < e0 / 10.0,
            "{:?} is {e} px off (start {e0} px)",
            r.px
        );
        let moved = (r.px[0] - start[0]).hypot(r.px[1] - start[1]);
        assert!((r.shift - moved).abs() < 1e-12);
    }

    #[test]
    fn the_window_stays_under_half_a_square() {
        assert_eq!(half_window(40.0), MAX_HALF_WINDOW);
        assert_eq!(half_window(10.0), 4);
        assert_eq!(half_window(7.0), 2);
        assert_eq!(half_window(3.0), 1);
        assert_eq!(half_window(f64::NAN), 1);
        for s in [5.0, 6.5, 9.6, 13.0] {
            assert!(((2 * half_window(s) + 1) as f64) < s, "{s}");
        }
    }

    #[test]
    fn a_flat_window_has_no_corner() {
        let img = Gray {
            width: 20,
            height: 20,
            data: vec![128; 400],
        };
        assert!(refine_corner(&img, [10.0, 10.0], 3).is_none());
        assert!(edge_width(&img, [10.0, 10.0], 3).is_none());
    }

    #[test]
    fn a_sharp_edge_is_two_pixels_wide_and_a_blurred_one_wider() {
        // The corner on a pixel's centre column: the pixels either side
        // of that column are black and white, so the steepest central
        // difference is half the contrast: 2 px.
        let img = corner_image(20.0, 20.0, 12.0, 40);
        let w = edge_width(&img, [20.0, 20.0], 4).unwrap();
        assert!((w - 2.0).abs() < 0.05, "{w}");
        // A 1-2-1 blur along rows and columns (a Gaussian of σ ≈ 0.7 px):
        // the edge rises over more pixels.
        let blurred = blur121(&img);
        let wb = edge_width(&blurred, [20.0, 20.0], 4).unwrap();
        assert!(wb > w + 0.3, "{wb} against {w}");
    }

    #[test]
    fn point_symmetry_finds_a_corner_centred_on_the_pixel_grid_exactly() {
        // The corner on a pixel column's centre and between two rows:
        // the mirror of every pixel centre about it is a pixel centre, the
        // 8 × 8 sub-pixels are placed symmetrically about it, so the image
        // (and its bilinear interpolation) is exactly point-symmetric about
        // it, sharp or blurred: the estimate is the corner to the solver's
        // tolerance, from 1.1 px off.
        let (cx, cy) = (20.0, 19.5);
        let start = [20.8, 20.3];
        let sharp = corner_image(cx, cy, 12.0, 40);
        for img in [blur121(&sharp), sharp] {
            let r = refine_symmetric(&img, start, 4.0).unwrap();
            let e = (r.px[0] - cx).hypot(r.px[1] - cy);
            assert!(e < 10.0 * STEP_TOL, "{:?} is {e} px off", r.px);
        }
    }

    #[test]
    fn point_symmetry_places_a_blurred_corner_anywhere_better_than_forstner() {
        // A corner off the pixel grid: bilinear interpolation is the only
        // asymmetry; on the 1-2-1 blurred corner both operators are within
        // a tenth of a pixel, point symmetry the closer.
        let (cx, cy) = (20.37, 19.71);
        let start = [21.2, 18.9];
        let img = blur121(&corner_image(cx, cy, 12.0, 40));
        let off = |p: [f64; 2]| (p[0] - cx).hypot(p[1] - cy);
        let s = off(refine_symmetric(&img, start, 4.0).unwrap().px);
        let f = off(refine_corner_in(&img, start, 4, true).unwrap().px);
        assert!(s < 0.1 && s <= f, "point symmetry {s} px, Förstner {f} px");
    }

    #[test]
    fn point_symmetry_ignores_what_lies_beyond_its_disc() {
        // A dark block in a white square 9 px from the corner (a tag's
        // data bits): the disc of radius 4, its gradients' pixel and the
        // interpolation's pixel reach 6 px from an estimate within 1.2 px
        // of the corner, so the estimate is the same to the bit.
        let (cx, cy) = (20.37, 19.71);
        let start = [21.2, 18.9];
        let img = corner_image(cx, cy, 12.0, 40);
        let mut marked = img.clone();
        for y in 27..31 {
            for x in 12..16 {
                marked.data[y * 40 + x] = 20;
            }
        }
        assert_ne!(img.data, marked.data);
        let a = refine_symmetric(&img, start, 4.0).unwrap();
        let b = refine_symmetric(&marked, start, 4.0).unwrap();
        assert_eq!(a, b);
        assert!(
            refine_symmetric(
                &Gray {
                    width: 20,
                    height: 20,
                    data: vec![128; 400]
                },
                [10.0, 10.0],
                3.0
            )
            .is_none()
        );
    }

    fn blur121(img: &Gray) -> Gray {
        let n = img.width;
        let at = |x: i64, y: i64| {
            img.at(
                x.clamp(0, n as i64 - 1) as usize,
                y.clamp(0, n as i64 - 1) as usize,
            )
        };
        let mut data = Vec::with_capacity(n * n);
        for y in 0..n as i64 {
            for x in 0..n as i64 {
                let mut s = 0.0f64;
                for (dy, wy) in [(-1, 1.0), (0, 2.0), (1, 1.0)] {
                    for (dx, wx) in [(-1, 1.0), (0, 2.0), (1, 1.0)] {
                        s += wx * wy * at(x + dx, y + dy);
                    }
                }
                data.push((s / 16.0).round() as u8);
            }
        }
        Gray {
            width: n,
            height: n,
            data,
        }
    }
}
