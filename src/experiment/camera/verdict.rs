//! Whether a camera calibration may be written, decided in the library so
//! that the command line and Python refuse the same fits with the same
//! message ([`crate::experiment::measured::verdict::Verdict`], exit status
//! 3, nothing written). Refused, the cause first:
//!
//! * a target whose size cannot be right: the camera sees it at a
//!   distance (fixed by the target's size and its pixels) beyond
//!   [`PLACEMENT_REACHES`] times the robot's reach — its squares or points
//!   given in millimetres, or 10× too large — when each pose's PnP fits
//!   its pixels within [`PNP_LIMIT_PX`] (else the distance says nothing
//!   of the target: k1 = 1e6 puts the camera a hundred metres away);
//! * a fit that did not converge;
//! * a pixel σ̂ above [`SIGMA_LIMIT_PX`];
//! * a joint origin moved by more than a tenth of its link
//!   ([`crate::frames::plausible::implausible`]);
//! * the object on the robot's end (the target in eye-to-hand, the camera
//!   in eye-in-hand) beyond the reach from the tip link, or the fixed one
//!   beyond [`PLACEMENT_REACHES`] reaches from the base.

use super::CameraCalibration;
use crate::experiment::measured::verdict::Verdict;
use crate::measure::camera::Mounting;

/// The largest pixel σ̂ a calibration is written with. Sub-pixel corner
/// and tag detectors give 0.1–0.5 px (OpenCV's `cornerSubPix`, AprilTag,
/// ChArUco), a blurred or poorly lit image 1–2 px; 5 px is ten times a
/// good detector's and leaves room for unmodelled compliance, while a
/// wrong model of the data (a fisheye read as plumb_bob: 54 px; rows and
/// columns swapped: 31 px; a locked joint that moved: 145 px, issue 49)
/// lies far above it.
pub const SIGMA_LIMIT_PX: f64 = 5.0;

/// The largest RMS of the start's per-pose PnP with which a distance too
/// far is blamed on the target's size: PnP of a detector's corners fits
/// them to the detector's σ (0.1–0.5 px) plus the lens model's error; 2
/// px is four times the worst of those, while a wrong distortion (k1 =
/// 1e6 on the example: 4.1 px on the few points left in the image) fits
/// worse.
pub const PNP_LIMIT_PX: f64 = 2.0;

/// How many of the robot's reaches the fixed camera (or target) may be
/// from the base, and the camera from the target: a camera looks at a
/// robot's workspace from a few metres at most (a ceiling camera over a
/// 0.85 m UR5 at 3 m is 3.5 reaches); a target in millimetres puts it a
/// thousand reaches away, one 10× too large ten or more.
pub const PLACEMENT_REACHES: f64 = 5.0;

/// The verdict on `cal` (its target read from `target_origin`).
#[must_use]
pub fn camera_verdict(cal: &CameraCalibration, target_origin: &str, extent: f64) -> Verdict {
    // The distance tells the target's size only when each pose's PnP
    // fits its pixels (a wrong distortion also puts the camera far
    // away, with PnP tens of pixels off): the start's PnP RMS, or the
    // fit's σ̂ when both placements were given.
    let fit = &cal.fit;
    let pnp_px = cal
        .start
        .as_ref()
        .map_or(fit.sigma_px.unwrap_or(fit.rms_px), |st| st.pnp_rms_px);
    let why = (pnp_px <= PNP_LIMIT_PX)
        .then(|| scale(cal, target_origin, extent))
        .flatten()
        .or_else(|| unconverged(cal))
        .or_else(|| sigma(cal))
        .or_else(|| {
            crate::frames::plausible::implausible(
                &cal.fit.robot,
                &cal.fit.table,
                cal.frames.as_ref().map(|f| &f.0),
            )
        })
        .or_else(|| placements(cal));
    match why {
        None => Verdict::Calibrated,
        Some(reason) => Verdict::Refused { reason },
    }
}

/// The median over the poses of the camera's distance from the target at
/// the fit's estimate, metres.
fn median_distance(cal: &CameraCalibration) -> f64 {
    let fit = &cal.fit;
    let mut d: Vec<f64> = cal
        .observations
        .qs
        .iter()
        .map(|q| crate::identify::camera::predict::probe(fit, &fit.estimate, q).norm())
        .filter(|d| d.is_finite())
        .collect();
    if d.is_empty() {
        return f64::NAN;
    }
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

/// A target `extent` metres across seen beyond [`PLACEMENT_REACHES`]
/// reaches: its size is wrong, with the likely unit.
fn scale(cal: &CameraCalibration, origin: &str, extent: f64) -> Option<String> {
    let reach = crate::units::reach(&cal.fit.robot);
    let d = median_distance(cal);
    let ratio = d / reach;
    (ratio > PLACEMENT_REACHES).then(|| {
        let likely = if ratio > 200.0 {
            "its squares or points are likely in millimetres (a square of 25 for 0.025 m): give metres"
        } else if ratio > 30.0 {
            "its squares or points are likely in centimetres, or 100× too large: give metres"
        } else {
            "its squares or points are likely 10× too large (a square of 0.25 for 0.025 m)"
        };
        format!(
            "{origin}: the target, {extent:.3} m across, is seen {d:.2} m from the camera, {ratio:.0} times the reach of this {reach:.3} m robot (at most {PLACEMENT_REACHES}): {likely} (or the camera's focal lengths as many times too large)"
        )
    })
}

/// Why a fit that did not converge is refused.
fn unconverged(cal: &CameraCalibration) -> Option<String> {
    let fit = &cal.fit;
    (!fit.converged).then(|| {
        format!(
            "the camera fit did not converge ({:?} after {} iterations)",
            fit.stop, fit.iterations
        )
    })
}

/// A pixel σ̂ (the RMS without one) above [`SIGMA_LIMIT_PX`].
fn sigma(cal: &CameraCalibration) -> Option<String> {
    let fit = &cal.fit;
    let s = fit.sigma_px.unwrap_or(fit.rms_px);
    (s > SIGMA_LIMIT_PX || !s.is_finite()).then(|| {
        format!(
            "the camera fit's pixel σ̂ is {s:.2} px, above {SIGMA_LIMIT_PX} px (a corner detector's is 0.1–0.5 px): these pixels are not of this camera, target and robot (the distortion model, the intrinsics, the target's layout, or a joint that moved?)"
        )
    })
}

/// The object on the end beyond the reach from the tip link, or the fixed
/// one beyond [`PLACEMENT_REACHES`] reaches from the base.
fn placements(cal: &CameraCalibration) -> Option<String> {
    let fit = &cal.fit;
    let reach = crate::units::reach(&fit.robot);
    let (fixed, moving, fixed_name, moving_name) = match fit.sensor.mounting() {
        Mounting::EyeToHand => (&fit.camera, &fit.target, "camera", "target"),
        Mounting::EyeInHand => (&fit.target, &fit.camera, "target", "camera"),
    };
    let on_end = moving.translation.vector.norm();
    let in_base = fixed.translation.vector.norm();
    if on_end > reach {
        return Some(format!(
            "the fit put the {moving_name} {on_end:.3} m from the tip link, beyond the robot's reach of {reach:.3} m: not a calibration of this robot (the target's unit or the robot?)"
        ));
    }
    (in_base > PLACEMENT_REACHES * reach).then(|| {
        format!(
            "the fit put the {fixed_name} {in_base:.3} m from the base, beyond {PLACEMENT_REACHES} times the robot's reach of {reach:.3} m: not a calibration of this robot (the target's unit or the robot?)"
        )
    })
}
