//! What a calibration report shows (figures, report.md and the 3D page
//! alike): the summary the command line and the Python package fill in.

use crate::identify::Identification;
use crate::model::{Robot, Symbol};

/// Whether a parameter name is an angle (γ, α, β: radians) rather than a
/// length (metres).
pub(super) fn is_angle(name: &str) -> bool {
    name.split('_')
        .next()
        .and_then(Symbol::parse)
        .is_some_and(|s| matches!(s, Symbol::Gamma | Symbol::Alpha | Symbol::Beta))
}

/// What a calibration report shows beside its figures.
pub struct CalibrationSummary<'a> {
    /// The robot.
    pub robot: &'a Robot,
    /// The fit.
    pub id: &'a Identification,
    /// Where the data came from (a file, or a simulated design).
    pub source: String,
    /// What one error is taken at ("pose", "held-out pose").
    pub what: &'static str,
    /// Position errors, mm: nominal and calibrated.
    pub position_mm: (Vec<f64>, Vec<f64>),
    /// Orientation errors, degrees, for full poses.
    pub orientation_deg: Option<(Vec<f64>, Vec<f64>)>,
    /// Each parameter: name, change from nominal and σ (metres or radians).
    pub params: Vec<(String, f64, Option<f64>)>,
    /// Held-out position RMS per split (mm): nominal and calibrated.
    pub splits: Option<(Vec<f64>, Vec<f64>)>,
    /// Further lines of the summary (markdown).
    pub notes: Vec<String>,
    /// The command's JSON report.
    pub json: serde_json::Value,
    /// The poses of the fit, for the 3D page (`None`: the page shows the
    /// tables and figures alone).
    pub poses: Option<FitPoses>,
}

/// The poses of a fit as the page shows them.
#[derive(Clone, Debug)]
pub struct FitPoses {
    /// Joint values of each pose.
    pub qs: Vec<Vec<f64>>,
    /// The point measured at each pose (measurement frame, metres), when
    /// one point per pose was measured.
    pub measured: Option<Vec<[f64; 3]>>,
    /// Poses the gross-error test left out.
    pub flagged: Vec<usize>,
}
