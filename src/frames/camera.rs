//! The calibrated robot of a camera fit ([`crate::identify::camera`]) in
//! the user's terms: the split of [`super::decompose`] (measurement frame,
//! joint origins) and a `camera` block with the camera's and the target's
//! placements in the URDF's links and the pixel noise.
//!
//! The frames file mounts the calibrated URDF in the frame of the fixed
//! one of the two (its `measurement_frame` is the base link's pose in the
//! camera's optical frame for eye-to-hand, in the target's frame for
//! eye-in-hand) with the moving one as its `tool` (the target's frame,
//! or the camera's optical frame, in the tip link), so that a reader of
//! frames files maps a point of the moving one into the fixed one's frame.
//!
//! The fit places the fixed one of the two (the camera in eye-to-hand,
//! the target in eye-in-hand) in the model's base frame, which the split's
//! measurement frame `M` places the chain's base link in: its placement in
//! the base link is `M⁻¹ T`. The moving one rides on the model's end
//! frame, which the split's tool `T_tool` places in the tip link: its
//! placement in the tip link is `T_tool T`. Their σ's are those of the
//! fit's own placement unknowns (translations along the parent's axes,
//! small rotations about the placed frame's own axes), the robot's
//! unknowns held at the estimate: the placements' share of the
//! covariance.

use super::report::{CameraBlock, FramesReport, frame_block};
use super::uncertainty::FrameSigma;
use super::{CalibratedFrames, FramesError, calibrated};
use crate::identify::camera::CameraFit;
use crate::measure::camera::Mounting;
use crate::model::MeasurementKind;

/// The split of a camera fit's robot and its report with the `camera`
/// block. `None` for a robot not imported from a URDF.
pub fn camera_frames(
    fit: &CameraFit,
) -> Result<Option<(CalibratedFrames, FramesReport)>, FramesError> {
    let mut robot = fit.robot.clone();
    // As a full pose: the split's tool is the end frame in the tip link
    // (builds a kind for the frames' split, decides nothing).
    robot.measurement = MeasurementKind::Pose;
    let n = robot.n_unknowns();
    let cov: Option<Vec<Vec<f64>>> = fit
        .covariance
        .as_ref()
        .map(|c| c.iter().take(n).map(|r| r[..n].to_vec()).collect());
    let Some((f, mut report)) = calibrated(&robot, &fit.table, cov.as_deref(), None)? else {
        return Ok(None);
    };
    let src = robot
        .source
        .as_ref()
        .expect("calibrated gives frames for a URDF robot");
    let sigma = |k: usize| {
        fit.std.as_ref().map(|s| FrameSigma {
            xyz: [s[n + k], s[n + k + 1], s[n + k + 2]],
            rot: [s[n + k + 3], s[n + k + 4], s[n + k + 5]],
        })
    };
    let (in_base, on_end) = (f.measurement.inverse(), f.tool);
    let (camera, target) = match fit.sensor.mounting() {
        Mounting::EyeToHand => (
            frame_block(
                &src.base,
                Some("camera_optical"),
                &(in_base * fit.camera),
                sigma(0).as_ref(),
            ),
            frame_block(
                &src.tip,
                Some("target"),
                &(on_end * fit.target),
                sigma(6).as_ref(),
            ),
        ),
        Mounting::EyeInHand => (
            frame_block(
                &src.tip,
                Some("camera_optical"),
                &(on_end * fit.camera),
                sigma(0).as_ref(),
            ),
            frame_block(
                &src.base,
                Some("target"),
                &(in_base * fit.target),
                sigma(6).as_ref(),
            ),
        ),
    };
    // Mounted as a frames file mounts any calibration: in the fixed one's
    // frame (the sensor's), with the moving one as the tool.
    // (The own unknowns: the camera's from 0, the target's from 6.)
    let (fixed, moving, moving_own) = match fit.sensor.mounting() {
        Mounting::EyeToHand => (in_base * fit.camera, on_end * fit.target, 6),
        Mounting::EyeInHand => (in_base * fit.target, on_end * fit.camera, 0),
    };
    report.measurement_frame = frame_block("measurement", Some(&src.base), &fixed.inverse(), None);
    report.tool = Some(frame_block(
        &src.tip,
        None,
        &moving,
        sigma(moving_own).as_ref(),
    ));
    report.camera = Some(CameraBlock {
        mounting: fit.sensor.mounting(),
        camera_link: None,
        camera,
        target,
        pixel_sigma_px: fit.sigma_px,
        rms_px: fit.rms_px,
        pixel_rows: fit.rows,
    });
    Ok(Some((f, report)))
}
