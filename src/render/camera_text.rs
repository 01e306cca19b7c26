//! A camera calibration as text (`calibrate --observations|--images`): the
//! pixels fitted, the unknowns, the start computed from the pixels, pixel
//! error RMS and σ (px), the camera's and target's placements with σ (m,
//! mm, deg), refined intrinsics, the robot unknowns' changes, the corners
//! relabelled, the gross-error test's notes and the verdict; and the
//! images' detection, one line per image.

use crate::frames::report::FramesReport;
use crate::identify::camera::CameraFit;
use crate::identify::camera::start::CameraStart;
use crate::identify::camera::start::labels::Labels;
use nalgebra::Isometry3;
use std::fmt::Write as _;

/// What the text of a camera calibration shows.
#[derive(Clone, Copy, Debug)]
pub struct CameraText<'a> {
    /// The fit.
    pub fit: &'a CameraFit,
    /// The mounting, or the link the camera is on, in words.
    pub label: &'a str,
    /// Where the pixels came from (a file, a folder of images).
    pub source: &'a str,
    /// Poses fitted.
    pub poses: usize,
    /// The calibrated frames (URDF robots).
    pub frames: Option<&'a FramesReport>,
    /// The files written.
    pub written: &'a [String],
    /// The start computed from the pixels, if one was.
    pub start: Option<&'a CameraStart>,
    /// Corners relabelled and poses dropped.
    pub labels: &'a Labels,
    /// What the gross-error test did, in words.
    pub notes: &'a [String],
    /// σ̂ tested against the stated pixel noise.
    pub noise_test: Option<&'a crate::identify::variance::BlockNoiseTest>,
    /// Why the fit is refused, if it is.
    pub refusal: Option<&'a str>,
}

/// The whole text of a camera calibration.
#[must_use]
pub fn text(t: &CameraText<'_>) -> String {
    fit_text(t)
        + &labels_text(t.labels)
        + &notes_text(t)
        + &t.refusal.map_or_else(String::new, |why| {
            format!("REFUSED: {why}: nothing written\n")
        })
}

/// What a computed start computed, in words.
fn start_phrase(st: &CameraStart) -> &'static str {
    match (st.camera_computed, st.target_computed) {
        (true, true) => "computed from the pixels (PnP + closed-form hand-eye)",
        (true, false) => {
            "the camera's placement computed from the pixels (PnP, the target's as given)"
        }
        _ => "the target's placement computed from the pixels (PnP, the camera's as given)",
    }
}

/// The gross-error test's notes and the stated noise's warning, one line
/// each.
fn notes_text(t: &CameraText<'_>) -> String {
    let mut s = String::new();
    for n in t.notes {
        let _ = writeln!(s, "note: {n}");
    }
    if let Some(t) = t.noise_test {
        let _ = writeln!(
            s,
            "pixel noise: σ̂ {:.3} px per coordinate against the stated {:.3} px ({:.2}×, χ² on {} degrees of freedom)",
            t.estimated, t.stated, t.ratio, t.dof
        );
        if let Some(w) = t.warning() {
            let _ = writeln!(s, "WARNING: {w}");
        }
    }
    s
}

/// The fit, its start, placements, intrinsics and robot unknowns as text.
fn fit_text(t: &CameraText<'_>) -> String {
    let (fit, label, poses, frames, written, start) =
        (t.fit, t.label, t.poses, t.frames, t.written, t.start);
    let mut s = String::new();
    let n_kin = fit.robot.n_unknowns();
    let _ = writeln!(
        s,
        "camera calibration ({label}) from {}: {poses} poses, {} pixel rows ({} points seen)",
        t.source,
        fit.rows,
        fit.rows / 2
    );
    let refined = fit.sensor.refines_intrinsics() || !fit.fixed_intrinsics.is_empty();
    let _ = writeln!(
        s,
        "unknowns: {} = {n_kin} of the robot + 6 of the camera + 6 of the target{}",
        fit.names.len(),
        if refined {
            format!(" + {} intrinsics", fit.names.len() - n_kin - 12)
        } else {
            String::new()
        }
    );
    if let Some(st) = start {
        let _ = writeln!(
            s,
            "start: {}: the target placed at {} of {poses} poses, their PnP pixel RMS {:.3} px",
            start_phrase(st),
            st.poses_placed,
            st.pnp_rms_px
        );
        let f = |m: &Isometry3<f64>| {
            crate::report::xyz_rpy(m)
                .map(|v| format!("{v:.4}"))
                .join(",")
        };
        let _ = writeln!(
            s,
            "start placements: --camera-pose={} --target-pose={}",
            f(&st.camera),
            f(&st.target)
        );
    }
    let _ = writeln!(
        s,
        "pixel error RMS: {:.3} px at the {} placements, {:.3} px after fitting them alone, {:.3} px calibrated",
        fit.given_rms_px,
        match start {
            None => "given",
            Some(st) if st.camera_computed && st.target_computed => "computed",
            Some(_) => "start",
        },
        fit.rigid_rms_px,
        fit.rms_px
    );
    match fit.sigma_px {
        Some(sg) => {
            let _ = writeln!(
                s,
                "pixel σ (variance component): {sg:.3} px, {} degrees of freedom",
                fit.redundancy
            );
        }
        None => s.push_str("pixel σ: not estimated\n"),
    }
    if let Some(c) = frames.and_then(|f| f.camera.as_ref()) {
        for (what, b) in [("camera (optical frame)", &c.camera), ("target", &c.target)] {
            let _ = write!(
                s,
                "{what} in {}: xyz [{:.5}, {:.5}, {:.5}] m, rpy [{:.4}, {:.4}, {:.4}] deg",
                b.parent, b.xyz[0], b.xyz[1], b.xyz[2], b.rpy_deg[0], b.rpy_deg[1], b.rpy_deg[2]
            );
            if let (Some(t), Some(r)) = (b.sigma_xyz_mm, b.sigma_rotation_deg) {
                let _ = write!(
                    s,
                    ", σ {} mm, {} deg",
                    crate::render::frames_text::s3(t, 3),
                    crate::render::frames_text::s3(r, 4)
                );
            }
            s.push('\n');
        }
    }
    if refined {
        intrinsics_text(fit, &mut s);
    }
    s.push_str("robot unknowns (change from nominal, σ):\n");
    for k in 0..n_kin {
        let unit = if fit.names[k].starts_with("a_") || fit.names[k].starts_with("d_") {
            (1e3, "mm")
        } else {
            (180.0 / std::f64::consts::PI, "deg")
        };
        let change = (fit.estimate[k] - fit.start[k]) * unit.0;
        let sd = fit.std.as_ref().map_or(f64::NAN, |sd| sd[k] * unit.0);
        let _ = writeln!(
            s,
            "  {:<28} {change:+.4} {u}  σ {sd:.4} {u}",
            fit.names[k],
            u = unit.1
        );
    }
    for w in written {
        let _ = writeln!(s, "wrote {w}");
    }
    s
}

/// The poses whose checkerboard corners were relabelled, and those
/// dropped as ambiguous, one line each kind (empty when none).
fn labels_text(l: &Labels) -> String {
    let mut s = String::new();
    if !l.relabelled.is_empty() {
        let each: Vec<String> = l
            .relabelled
            .iter()
            .map(|r| format!("pose {} {}", r.pose, r.labelling.name()))
            .collect();
        let _ = writeln!(
            s,
            "note: the checkerboard's corners were detected in another order at {} poses, relabelled by the robot's motion: {}",
            each.len(),
            each.join(", ")
        );
    }
    for d in &l.dropped {
        let _ = writeln!(s, "note: pose {} left out: {}", d.pose, d.reason);
    }
    s
}

/// The refined intrinsics with their change from the given ones and σ,
/// and those held at their given values with the reason.
fn intrinsics_text(fit: &CameraFit, s: &mut String) {
    let k0 = fit.robot.n_unknowns() + crate::measure::camera::OWN_PARAMS;
    s.push_str("intrinsics (refined, change from given, σ):\n");
    let mask = fit.sensor.free_intrinsics();
    let free = (0..mask.len()).filter(|&j| mask[j]);
    for (k, j) in (k0..).zip(free) {
        let name = fit.sensor.intrinsics().names()[j];
        let unit = if j < 4 { " px" } else { "" };
        let sd = fit.std.as_ref().map_or(f64::NAN, |sd| sd[k]);
        let _ = writeln!(
            s,
            "  {name:<3} {:.6}{unit}  ({:+.6})  σ {sd:.6}{unit}",
            fit.estimate[k],
            fit.estimate[k] - fit.start[k]
        );
    }
    for f in &fit.fixed_intrinsics {
        let _ = writeln!(s, "  {} held at {}: {}", f.name, f.value, f.reason);
    }
}

/// One line per image: the points found and the detection's figures, or
/// the reason it was left out.
#[must_use]
pub fn image_lines(images: &[crate::io::images::ImageReport]) -> Vec<String> {
    images
        .iter()
        .map(|r| match &r.outcome {
            crate::io::images::ImageOutcome::Found {
                points,
                square_px,
                window_px,
                shift_px,
                edge_width_px,
            } => format!(
                "{}: {points} points, squares ≥ {square_px:.1} px, window ±{}–{} px, refinement shift {:.3} px median ({:.3} px max), edge width {edge_width_px:.2} px",
                r.file, window_px[0], window_px[1], shift_px[0], shift_px[1]
            ),
            crate::io::images::ImageOutcome::LeftOut { reason } => format!("{}: left out: {reason}", r.file),
        })
        .collect()
}
