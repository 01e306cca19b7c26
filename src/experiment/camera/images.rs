//! A calibration from a camera's images, shown: the contact sheet's
//! images ([`crate::render::contact_sheet`]) from what the detection found
//! in each image and what the fit made of it (the points as fitted,
//! relabelled where the board's symmetry turned them, the residuals, the
//! poses the fit left out and why), and the text lines of the per-image
//! report.

use super::CameraCalibration;
use crate::identify::camera::screen::{CameraUnit, pixel_residuals};
use crate::io::camera_target::Target;
use crate::io::images::decode::{Gray, decode_image};
use crate::io::images::{ImageObservations, ImageOutcome, ImageReport};
use crate::render::contact_sheet::SheetImage;
use std::path::Path;

/// Writes the folder `dir` of a calibration from images (replaced whole,
/// atomically, [`crate::render::folder::camera_images`]): the contact
/// sheet of `read`'s images as `cal` fitted them, and what became of each
/// image; `target`'s inner corners per row number the sheet's points.
pub fn write_sheet_folder(
    dir: &Path,
    read: &ImageObservations,
    cal: &CameraCalibration,
    target: &Target,
) -> crate::error::Result<()> {
    let cols = match (target.grid, &target.charuco) {
        (Some((_, cols)), _) => cols,
        (None, Some(p)) => p.cols - 1,
        (None, None) => 1,
    };
    let sheet = sheet_images(read, Some(cal), cols);
    crate::render::folder::camera_images(dir, &sheet, &read.images)
}

/// The sheet's images: every image read, in order, with its points
/// (as fitted when `cal` is given), residuals and reason for being left
/// out; `cols` the board's inner corners per row.
#[must_use]
pub fn sheet_images(
    read: &ImageObservations,
    cal: Option<&CameraCalibration>,
    cols: usize,
) -> Vec<SheetImage> {
    let grays: Vec<Option<Gray>> = read
        .files
        .iter()
        .map(|f| std::fs::read(f).ok().and_then(|b| decode_image(&b).ok()))
        .collect();
    let (w, h) = grays
        .iter()
        .flatten()
        .next()
        .map_or((640, 480), |g| (g.width, g.height));
    let fitted = cal.map(|c| (c, pixel_residuals(&c.fit, &c.observations)));
    read.images
        .iter()
        .zip(grays)
        .map(|(r, g)| {
            let gray = g
                .filter(|g| (g.width, g.height) == (w, h))
                .unwrap_or_else(|| Gray {
                    width: w,
                    height: h,
                    data: vec![96; w * h],
                });
            let detected = r
                .pose
                .and_then(|p| read.observations.pose_ids.iter().position(|&q| q == p))
                .map(|i| read.observations.seen[i].clone())
                .unwrap_or_default();
            let mut im = SheetImage {
                name: r.file.clone(),
                gray,
                points: detected,
                cols,
                residuals: Vec::new(),
                left_out: None,
                caption: caption(r),
            };
            match &r.outcome {
                ImageOutcome::LeftOut { reason } => im.left_out = Some(reason.clone()),
                ImageOutcome::Found { .. } => {
                    if let (Some((c, res)), Some(p)) = (&fitted, r.pose) {
                        as_fitted(&mut im, c, res, p);
                    }
                }
            }
            im
        })
        .collect()
}

/// Pose `pose`'s points and residuals as the fit `cal` has them, or why
/// the fit left it out.
fn as_fitted(
    im: &mut SheetImage,
    cal: &CameraCalibration,
    res: &[Vec<Option<[f64; 2]>>],
    pose: i64,
) {
    if let Some(d) = cal.labels.dropped.iter().find(|d| d.pose == pose) {
        im.left_out = Some(format!("by the fit: {}", d.reason));
        return;
    }
    let Some(i) = cal.observations.pose_ids.iter().position(|&q| q == pose) else {
        let out = cal.outliers.iter().find(|o| o.pose_id == pose);
        im.left_out = Some(out.map_or_else(
            || "by the fit".to_string(),
            |o| {
                format!(
                    "by the fit, a gross error (residual {:.2} px RMS)",
                    o.residual_px
                )
            },
        ));
        return;
    };
    im.points.clone_from(&cal.observations.seen[i]);
    im.residuals.clone_from(&res[i]);
    let n = res[i].iter().flatten().count().max(1) as f64;
    let rms = (res[i]
        .iter()
        .flatten()
        .map(|r| r[0] * r[0] + r[1] * r[1])
        .sum::<f64>()
        / n)
        .sqrt();
    im.caption += &format!(", residual {rms:.2} px RMS");
    if let Some(l) = cal.labels.relabelled.iter().find(|l| l.pose == pose) {
        im.caption += &format!(", relabelled ({})", l.labelling.name());
    }
    let points_out = cal
        .outliers
        .iter()
        .filter(|o| o.pose_id == pose && matches!(o.unit, CameraUnit::Point { .. }))
        .count();
    if points_out > 0 {
        im.caption += &format!(", {points_out} point(s) left out");
    }
}

/// The detection's figures of one image, for the sheet.
fn caption(r: &ImageReport) -> String {
    match &r.outcome {
        ImageOutcome::Found {
            points, shift_px, ..
        } => format!("{points} points, shift ≤ {:.2} px", shift_px[1]),
        ImageOutcome::LeftOut { .. } => "not used".into(),
    }
}
