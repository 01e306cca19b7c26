//! The held-out figures of a calibration from measured data: each split's
//! held-out, nominal and fitted position RMS, their means, and the pruned
//! model's.

use crate::identify::{HoldoutSettings, SplitResult};
use crate::report::measured::{HoldoutReport, PrunedReport, Stat};

/// The held-out figures over `splits`.
pub(super) fn holdout_report(settings: HoldoutSettings, splits: Vec<SplitResult>) -> HoldoutReport {
    let mean = |v: &mut dyn Iterator<Item = f64>| {
        let x: Vec<f64> = v.collect();
        x.iter().sum::<f64>() / x.len().max(1) as f64
    };
    let ori = |f: &dyn Fn(&SplitResult) -> Option<f64>| -> Option<Stat> {
        splits
            .iter()
            .map(f)
            .collect::<Option<Vec<f64>>>()
            .map(Stat::of)
    };
    let pruned = settings.prune.then(|| PrunedReport {
        n_params: splits
            .iter()
            .filter_map(|s| s.pruned.as_ref().map(|p| p.0))
            .collect(),
        position_rms_mm: Stat::of(
            splits
                .iter()
                .filter_map(|s| s.pruned.as_ref().map(|p| p.1.position_rms_mm))
                .collect(),
        ),
        orientation_rms_deg: ori(&|s| s.pruned.as_ref().and_then(|p| p.1.orientation_rms_deg)),
    });
    HoldoutReport {
        settings,
        position_rms_mm: Stat::of(splits.iter().map(|s| s.held_out.position_rms_mm).collect()),
        orientation_rms_deg: ori(&|s| s.held_out.orientation_rms_deg),
        nominal_position_rms_mm: mean(&mut splits.iter().map(|s| s.nominal.position_rms_mm)),
        fitted_position_rms_mm: mean(&mut splits.iter().map(|s| s.fitted.position_rms_mm)),
        pruned,
        splits,
    }
}
