//! A ROS 2 bag's extraction as text (`extract`, and `calibrate --bag`
//! before its fit): the topics read, the rests found and kept, the clock
//! offset and the noise of a rest, every figure with its unit; for a
//! camera's topics the images used at each rest.

use crate::io::bag::camera::BagImagesReport;
use crate::io::bag::extract::ExtractReport;
use crate::report::bag::{BagSection, ClockRefit};
use std::path::Path;

/// The text form of a camera's extraction (`out`: the CSV written).
#[must_use]
pub fn bag_images_text(r: &BagImagesReport, out: Option<&Path>) -> String {
    let c = &r.intrinsics;
    let mut s = format!(
        "{}: '{}' {} samples; '{}' {} image(s){}; camera from '{}': {} × {} px, fx {:.1} px, {}\n",
        r.bag,
        r.joints,
        r.joint_samples,
        r.images,
        r.image_count,
        if r.image_rate > 0.0 {
            format!(" at {:.1} Hz", r.image_rate)
        } else {
            String::new()
        },
        r.camera_info,
        c.width,
        c.height,
        c.fx,
        c.distortion.model()
    );
    s += &format!(
        "rests: {} found (speed under {} rad/s for at least {} s, the first {} s left out, clock offset {} s), {} with the target\n",
        r.rests.len(),
        r.settings.speed,
        r.settings.min_duration,
        r.settings.settle,
        r.time_offset,
        r.kept()
    );
    for line in super::camera_text::image_lines(&r.images()) {
        s += &line;
        s += "\n";
    }
    if let Some(out) = out {
        s += &format!("wrote {} ({} poses)\n", out.display(), r.kept());
    }
    s
}

/// The text form of an extraction's report (`out`: the CSV written).
#[must_use]
pub fn extract_text(r: &ExtractReport, out: Option<&Path>) -> String {
    let mut s = format!(
        "{}: '{}' {} samples at {:.1} Hz; {} {} samples at {:.1} Hz\n",
        r.bag,
        r.joints,
        r.joint_samples,
        r.joint_rate,
        r.source,
        r.measurement_samples,
        r.measurement_rate
    );
    let c = &r.clock;
    s += &match &c.estimate {
        Some(e) => format!(
            "clock offset: estimated {:.4} s ± {:.4} s from {} moves; applied {:.4} s ({})\n",
            e.seconds, e.uncertainty, e.moves, c.applied, c.note
        ),
        None => format!("clock offset: {:.4} s ({})\n", c.applied, c.note),
    };
    s += &format!(
        "rests: {} found (speed under {} rad/s for at least {} s, the first {} s left out), {} kept\n",
        r.rests.len(),
        r.settings.speed,
        r.settings.min_duration,
        r.settings.settle,
        r.kept()
    );
    let design =
        r.rests.iter().any(|x| x.design_pose.is_some()) || !r.missing_design_poses.is_empty();
    s += if design {
        "rest  start s  length s  samples  scatter mm  design pose  left out\n"
    } else {
        "rest  start s  length s  samples  scatter mm  left out\n"
    };
    let t0 = r.rests.first().map_or(0.0, |x| x.rest.start);
    for (k, x) in r.rests.iter().enumerate() {
        let (n, sc) = x.averaged.as_ref().map_or(("-".into(), "-".into()), |a| {
            (a.samples.to_string(), format!("{:.4}", a.scatter * 1e3))
        });
        let pose = if design {
            format!(
                "  {:>11}",
                x.design_pose.map_or("-".into(), |p| (p + 1).to_string())
            )
        } else {
            String::new()
        };
        s += &format!(
            "{:>4}  {:>7.2}  {:>8.2}  {:>7}  {:>10}{pose}  {}\n",
            k + 1,
            x.rest.start - t0,
            x.rest.end - x.rest.start,
            n,
            sc,
            x.left_out.as_deref().unwrap_or("")
        );
    }
    for m in &r.missing_design_poses {
        s += &format!("design pose {} not measured: {}\n", m.pose + 1, m.reason);
    }
    s += &format!(
        "noise: one sample's scatter {:.4} mm per coordinate (median rest), an averaged pose's {:.5} mm",
        r.scatter * 1e3,
        r.averaged_noise * 1e3
    );
    if let Some(o) = r.orientation_scatter {
        s += &format!("; orientation {:.4}° per axis", o.to_degrees());
    }
    s += "\n";
    if let Some(out) = out {
        s += &format!("wrote {} ({} poses)\n", out.display(), r.kept());
    }
    s
}

/// The two estimates of the clock offset, as a note.
#[must_use]
pub fn clock_note(c: &ClockRefit) -> String {
    let n = &c.nominal;
    match &c.calibrated {
        Some(k) => format!(
            "clock offset with the calibrated model {:.4} s ± {:.4} s (nominal model {:.4} s ± {:.4} s): {}",
            k.seconds,
            k.uncertainty,
            n.seconds,
            n.uncertainty,
            if c.refitted {
                "moved by more than its uncertainty, extracted and fitted again"
            } else {
                "within the nominal estimate's uncertainty, kept"
            }
        ),
        None => format!(
            "clock offset {:.4} s ± {:.4} s with the nominal model, not estimated again",
            n.seconds, n.uncertainty
        ),
    }
}

/// What `calibrate --bag` prints before its fit: the extraction and, when
/// the clock offset was estimated again, both estimates.
#[must_use]
pub fn bag_section_text(b: &BagSection) -> String {
    let mut text = extract_text(&b.extraction, None);
    if let Some(c) = &b.clock_refit {
        text += &format!("{}\n", clock_note(c));
    }
    text + "\n"
}
