//! A camera's images read into its observations
//! ([`CameraObservations`], what the observations CSV gives): the target's
//! points detected in each image ([`detect`]), refined to a fraction of a
//! pixel with a window under half a square ([`refine`]), and paired with
//! the joint values at which the image was taken ([`joints`]).
//!
//! Each image is one pose, whose id is the image's place in the sorted
//! list of files ([`files`]). An image that cannot be used is left out
//! with its reason (unreadable, another size than the camera_info's, no
//! board, the board not seen whole); one that can is reported with the
//! points found, the shortest square side, the refinement's window and
//! shift, and the edges' width (sharpness). An image without a row in the
//! joints file is refused before any detection: its pose is unknown.
//!
//! Checkerboards (the `checkerboard:` target, [`detect`]), ChArUco
//! boards (the `charuco:` target, [`charuco`]) and Kalibr's aprilgrids
//! (the `aprilgrid:` target, [`aprilgrid`]) are detected; point lists are
//! refused with that reason.

pub mod aprilgrid;
pub mod charuco;
pub mod decode;
pub mod detect;
pub mod files;
pub mod joints;
pub mod layout;
pub mod refine;

use super::camera_target::{AprilgridPattern, CharucoPattern, Target};
use crate::data::CameraObservations;
use crate::error::{Error, Result};
use crate::measure::camera::MIN_POINTS_PER_POSE;
use crate::measure::pinhole::Intrinsics;
use joints::ImageJoints;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What became of one image.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImageReport {
    /// The image's file name.
    pub file: String,
    /// Its pose id in the observations, when it was used.
    pub pose: Option<i64>,
    /// Found or left out.
    #[serde(flatten)]
    pub outcome: ImageOutcome,
}

/// An image used, with its figures, or left out, with the reason.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum ImageOutcome {
    /// The board was found.
    Found {
        /// Points found and refined.
        points: usize,
        /// The shortest square side over the board, px.
        square_px: f64,
        /// The refinement's half window: the smallest and largest over
        /// the points, px (0: a corner kept as the detector placed it,
        /// [`refine::MIN_HALF_WINDOW`], [`refine::MAX_SHIFT`]).
        window_px: [usize; 2],
        /// How far the refinement moved the detector's corners: median and
        /// largest, px.
        shift_px: [f64; 2],
        /// The edges' width at the corners, median, px
        /// ([`refine::edge_width`]: 2 px for an edge sharp to the pixel).
        edge_width_px: f64,
    },
    /// The image was left out.
    LeftOut {
        /// Why, in words.
        reason: String,
    },
}

/// A camera's images read: the observations of the images used, and the
/// report of every image.
#[derive(Clone, Debug)]
pub struct ImageObservations {
    /// The observations: one pose per image used.
    pub observations: CameraObservations,
    /// Every image, in order, with what became of it.
    pub images: Vec<ImageReport>,
    /// Every image's path, in the same order.
    pub files: Vec<PathBuf>,
}

/// Reads the images `spec` names ([`files::image_files`]) with the joint
/// values of `joints`, for the camera `intrinsics` and the `target`.
pub fn read_images(
    spec: &Path,
    joints: &ImageJoints,
    target: &Target,
    intrinsics: &Intrinsics,
) -> Result<ImageObservations> {
    let files = files::image_files(spec)?;
    read_image_list(
        &spec.display().to_string(),
        files,
        joints,
        target,
        intrinsics,
    )
}

/// Reads the image `files` (given as `origin`, for messages: a folder, a
/// pattern, a list) with the joint values of `joints`, for the camera
/// `intrinsics` and the `target`: each image one pose, its id its place in
/// `files`.
pub fn read_image_list(
    origin: &str,
    files: Vec<PathBuf>,
    joints: &ImageJoints,
    target: &Target,
    intrinsics: &Intrinsics,
) -> Result<ImageObservations> {
    let origin = origin.to_string();
    let board = Board::of(target, &origin)?;
    let names: Vec<String> = files
        .iter()
        .map(|f| {
            f.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        })
        .collect();
    if let Some(n) = names.iter().find(|n| joints.of(n).is_none()) {
        return Err(Error::Parse {
            path: joints.origin.clone(),
            message: format!(
                "no row for image '{n}' (of {origin}): each image needs its joint values, in a row whose 'image' cell is its file name"
            ),
        });
    }
    let mut obs = CameraObservations {
        origin: origin.clone(),
        pose_ids: Vec::new(),
        qs: Vec::new(),
        seen: Vec::new(),
    };
    let mut images = Vec::new();
    for (k, (path, name)) in files.iter().zip(&names).enumerate() {
        let outcome = match one_image(path, &board, target.ids.len(), intrinsics) {
            Ok((seen, outcome)) => {
                obs.pose_ids.push(k as i64);
                obs.qs.push(joints.of(name).unwrap_or_default().to_vec());
                obs.seen.push(seen);
                outcome
            }
            Err(reason) => ImageOutcome::LeftOut { reason },
        };
        images.push(ImageReport {
            file: name.clone(),
            pose: matches!(outcome, ImageOutcome::Found { .. }).then_some(k as i64),
            outcome,
        });
    }
    if obs.pose_ids.is_empty() {
        let why: Vec<String> = images
            .iter()
            .filter_map(|r| match &r.outcome {
                ImageOutcome::LeftOut { reason } => Some(format!("{}: {reason}", r.file)),
                ImageOutcome::Found { .. } => None,
            })
            .collect();
        return Err(Error::Parse {
            path: origin,
            message: format!("no image could be used:\n  {}", why.join("\n  ")),
        });
    }
    Ok(ImageObservations {
        observations: obs,
        images,
        files,
    })
}

/// A board activecal detects.
#[derive(Clone, Copy, Debug)]
pub enum Board<'a> {
    /// A checkerboard's inner corners (rows, cols).
    Checkerboard((usize, usize)),
    /// A ChArUco board.
    Charuco(&'a CharucoPattern),
    /// A Kalibr aprilgrid.
    Aprilgrid(&'a AprilgridPattern),
}

impl<'a> Board<'a> {
    /// The board of `target` (read from `origin`, for messages); a target
    /// that is not a checkerboard, a ChArUco board or an aprilgrid is
    /// refused.
    pub fn of(target: &'a Target, origin: &str) -> Result<Self> {
        if let Some(p) = &target.aprilgrid {
            return Ok(Board::Aprilgrid(p));
        }
        match (&target.charuco, target.grid) {
            (Some(p), _) => {
                charuco::check_pattern(p).map_err(|message| Error::Parse {
                    path: origin.to_string(),
                    message: format!("the target: {message}"),
                })?;
                Ok(Board::Charuco(p))
            }
            (None, Some(grid)) => Ok(Board::Checkerboard(grid)),
            (None, None) => Err(Error::Parse {
                path: origin.to_string(),
                message: "activecal detects checkerboards, ChArUco boards and aprilgrids in images (a 'checkerboard:', 'charuco:' or 'aprilgrid:' target); a point list is not detected: detect its points yourself and give them as --observations".into(),
            }),
        }
    }
}

/// One image file's points (by target id; `n` of them) and figures, or
/// why it is left out.
fn one_image(
    path: &Path,
    board: &Board,
    n: usize,
    intrinsics: &Intrinsics,
) -> std::result::Result<(Vec<Option<[f64; 2]>>, ImageOutcome), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("unreadable ({e})"))?;
    let img = decode::decode_image(&bytes)?;
    detect_in(&img, board, n, intrinsics)
}

/// One image's points (by target id; `n` of them, the target's point
/// count) and figures, refined ([`refine`]), or why it is left out (another
/// size than the camera's, the board not found, too few corners).
pub fn detect_in(
    img: &decode::Gray,
    board: &Board,
    n: usize,
    intrinsics: &Intrinsics,
) -> std::result::Result<(Vec<Option<[f64; 2]>>, ImageOutcome), String> {
    let (w, h) = (intrinsics.width as usize, intrinsics.height as usize);
    if (img.width, img.height) != (w, h) {
        return Err(format!(
            "{} × {} px, the camera_info's images are {w} × {h} px",
            img.width, img.height
        ));
    }
    let found = match board {
        Board::Checkerboard((rows, cols)) => {
            detect::find_checkerboard(img, *rows, *cols)?.located()
        }
        Board::Charuco(p) => charuco::find_charuco(img, p)?,
        Board::Aprilgrid(p) => aprilgrid::find_aprilgrid(img, p)?,
    };
    let mut seen = vec![None; n];
    let (mut shifts, mut widths, mut windows) = (Vec::new(), Vec::new(), Vec::new());
    for c in found.iter().filter(|c| c.id < n) {
        let (refined, half) = refine_located(img, board, c);
        // Not refined (a window too small, or a move too long to be this
        // corner's): the detector's corner on a checkerboard (only a whole
        // board is labelled) and an aprilgrid (the crate's own saddle
        // point); left out on a ChArUco board, whose corners carry ids
        // (its detector placed one 1.6 px off on the rendered images of
        // `verify/tests/live_images_truth.rs`, a move the refinement
        // refused).
        if refined.is_none() && matches!(board, Board::Charuco(_)) {
            continue;
        }
        let r = refined.unwrap_or(refine::Refined {
            px: c.px,
            shift: 0.0,
        });
        // An aprilgrid's edges are measured in its clear disc even when
        // the corner is the crate's.
        let width_half = if refined.is_some() || matches!(board, Board::Aprilgrid(_)) {
            half
        } else {
            0
        };
        let half = if refined.is_some() { half } else { 0 };
        let inside =
            (-0.5..w as f64 - 0.5).contains(&r.px[0]) && (-0.5..h as f64 - 0.5).contains(&r.px[1]);
        if !inside {
            continue;
        }
        seen[c.id] = Some(r.px);
        shifts.push(r.shift);
        windows.push(half);
        if let Some(e) = refine::edge_width(img, r.px, width_half) {
            widths.push(e);
        }
    }
    if shifts.len() < MIN_POINTS_PER_POSE {
        return Err(format!(
            "{} of {n} corners found in the image; a pose needs at least {MIN_POINTS_PER_POSE}",
            shifts.len(),
        ));
    }
    let outcome = ImageOutcome::Found {
        points: shifts.len(),
        square_px: found
            .iter()
            .map(|c| c.square_px)
            .fold(f64::INFINITY, f64::min),
        window_px: [
            windows.iter().copied().min().unwrap_or(0),
            windows.iter().copied().max().unwrap_or(0),
        ],
        shift_px: [
            median(&mut shifts.clone()),
            shifts.iter().copied().fold(0.0, f64::max),
        ],
        edge_width_px: median(&mut widths),
    };
    Ok((seen, outcome))
}

/// The refinement of the detector's corner `c` on `board` (`None`: kept
/// as the detector placed it, or left out, [`detect_in`]) and the half
/// width of its window, px.
///
/// Checkerboards and ChArUco boards: Förstner's operator
/// ([`refine::refine_corner_in`]) in the window clear of other edges.
/// Kalibr's aprilgrid: the X-junction's centre of point symmetry
/// ([`refine::refine_symmetric`]) in the disc clear of other edges less
/// a pixel (the image's blur), from the crate's saddle point, whose
/// blurred fit is pulled by the tag's data bits and its corner square's
/// far edges (tags of 15–25 px had their corners 0.02 px outward); on
/// the 20 renders of `live_images_eye_in_hand_aprilgrid`, see
/// docs/cameras.md for the figures
/// (`live_images_aprilgrid_corner_bias`). A disc under
/// [`refine::MIN_SYMMETRIC_RADIUS`] keeps the crate's corner.
fn refine_located(
    img: &decode::Gray,
    board: &Board,
    c: &detect::Located,
) -> (Option<refine::Refined>, usize) {
    let half = refine::half_window_within(c.clear_px);
    let refined = if let Board::Aprilgrid(_) = board {
        let radius = (c.clear_px - 1.0).min(refine::MAX_HALF_WINDOW as f64);
        (radius >= refine::MIN_SYMMETRIC_RADIUS)
            .then(|| refine::refine_symmetric(img, c.px, radius))
            .flatten()
    } else {
        (half >= refine::MIN_HALF_WINDOW)
            .then(|| refine::refine_corner_in(img, c.px, half, c.round))
            .flatten()
    };
    (refined.filter(|r| r.shift <= refine::MAX_SHIFT), half)
}

/// The median of `v` (NaN when empty).
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}
