//! The text of a camera design (what `select --camera-info` prints):
//! the candidates kept, the design's figures, its gap and predicted error,
//! and the files written (or the design's CSV when none was).

use crate::bound::DesignGap;
use crate::select::camera::CameraDesign;
use std::fmt::Write as _;

/// What a camera design's text says beside the design itself.
#[derive(Clone, Copy, Debug)]
pub struct CameraDesignFacts<'a> {
    /// Candidate configurations considered.
    pub candidates: usize,
    /// Candidates the collision filters removed, if filtered.
    pub collision_removed: Option<usize>,
    /// The gap to the visible pool's certified bound, if scored.
    pub gap: Option<&'a DesignGap>,
    /// The pixel noise σ the user gave, px.
    pub pixel_noise: Option<f64>,
    /// The design's CSV table, printed when no file was written.
    pub csv: &'a str,
}

/// The human-readable report of a camera design; `written` lists the
/// files written (the CSV table is printed when there are none).
#[must_use]
pub fn text(d: &CameraDesign, f: &CameraDesignFacts<'_>, written: &[String]) -> String {
    let predicted = d.predicted_error_per_px.map_or_else(
        || "not predicted (singular design)".to_string(),
        |e| {
            let at = f.pixel_noise.map_or(String::new(), |s| {
                format!(", {:.4} mm at σ = {s} px", 1e3 * e * s)
            });
            format!(
                "{:.4} mm per px of pixel noise σ (RMS over 1,000 configurations){at}",
                1e3 * e
            )
        },
    );
    let mut s = String::new();
    if let Some(c) = f.collision_removed {
        let _ = writeln!(
            s,
            "collision: removed {c} of {} sampled configurations",
            f.candidates
        );
    }
    let (well, blocked) = d.out_of_sight.map_or((String::new(), String::new()), |o| {
        (
            " and in sight".to_string(),
            format!(" ({o} more seen well, but the robot's collision geometry blocks a ray)"),
        )
    });
    let _ = write!(
        s,
        "camera: the target is seen well{well} at {} of {} sampled configurations{blocked}\nchose {} poses on the pixel Jacobian ({} unknowns): ln det XᵀX = {:.3} (unit pixel noise)\n",
        d.visible,
        f.candidates,
        d.qs.len(),
        d.names.len(),
        d.ln_det,
    );
    if let Some(g) = f.gap {
        let _ = writeln!(
            s,
            "log10 det XᵀX {:.4}  log10 bound {:.4}  D-efficiency >= {:.6} (the visible pool's certified bound)",
            g.log10_oid.unwrap_or(f64::NEG_INFINITY),
            g.log10_bound,
            g.d_efficiency
        );
    }
    let seen: Vec<String> = d.seen.iter().map(usize::to_string).collect();
    let _ = writeln!(
        s,
        "predicted true error: {predicted}\npoints seen per pose: {}",
        seen.join(", ")
    );
    if written.is_empty() {
        s += f.csv;
    }
    for w in written {
        let _ = writeln!(s, "wrote {w}");
    }
    s
}
