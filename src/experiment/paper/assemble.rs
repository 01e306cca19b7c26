//! The report assembled from what the stages computed.

use super::report::{
    BoundSummary, DesignRow, EaeOiSummary, EaeSummary, FigureData, Log10Oid, MonteCarloRow,
    MultistartSummary, NewtonCheck, PaperReport, RandomSummary, SettingsSummary, TablesSummary,
};
use super::{PaperSettings, RandomBaseline, Selections};
use crate::bound::DesignGap;
use crate::identify::PaperTables;
use crate::model::Robot;
use crate::select::oi_from_ln_oid;

/// A natural logarithm as a base-10 one.
fn l10(ln: f64) -> f64 {
    ln / std::f64::consts::LN_10
}

/// Everything the experiment computed, for the report.
pub(super) struct Parts<'a> {
    pub(super) pool: &'a crate::pool::Pool,
    pub(super) robot: &'a Robot,
    pub(super) p: usize,
    pub(super) random: &'a RandomBaseline,
    pub(super) sel: &'a Selections,
    pub(super) bound: &'a crate::bound::Bound,
    pub(super) newton: &'a crate::bound::Bound,
    pub(super) named: &'a [(&'a str, Vec<usize>)],
    pub(super) gaps: &'a [DesignGap],
    pub(super) tables: &'a PaperTables,
}

impl Parts<'_> {
    /// The design of `d` as pool ids.
    fn ids(&self, d: &[usize]) -> Vec<usize> {
        self.pool.ids_of(d)
    }

    /// The typed report of the run.
    pub(super) fn report(
        &self,
        a: &PaperSettings,
        mc: crate::identify::montecarlo::Comparison,
        figures: FigureData,
        seconds: f64,
    ) -> PaperReport {
        let (pool, robot, p) = (self.pool, self.robot, self.p);
        let rs = &self.random.search;
        let sel = self.sel;
        let (e_det, best, fed, det) = (&sel.e_det, &sel.best, &sel.fed, &sel.det);
        PaperReport {
            settings: SettingsSummary {
                levels: a.levels,
                n: a.n,
                initial: a.initial,
                designs: a.designs,
                starts: a.starts,
                trials: a.trials,
                noise: a.noise,
                seed: a.seed,
                pool: pool.len(),
                p,
            },
            pool: pool.spec.clone(),
            chain: crate::report::chain(robot),
            random: RandomSummary {
                best_log10_oid: l10(rs.best_ln_oid),
                best_oi: oi_from_ln_oid(rs.best_ln_oid, p),
                median_log10_oid: l10(rs.ln_oid[self.random.median_j]),
                best_poses: self.ids(&rs.best),
            },
            eae: EaeSummary {
                log10_oid: l10(e_det.ln_oid),
                oi: e_det.oi,
                seconds: sel.eae_seconds,
                poses: self.ids(&e_det.poses),
                trace_log10_oid: e_det.trace.iter().map(|r| l10(r.ln_oid)).collect(),
            },
            eae_oi: sel.e_oi.as_ref().map(|o| EaeOiSummary {
                log10_oid: l10(o.ln_oid),
                oi: o.oi,
                same_design: same_poses(&o.poses, &e_det.poses),
                poses: self.ids(&o.poses),
            }),
            multistart: MultistartSummary {
                log10_oid: l10(best.ln_oid),
                oi: best.oi,
                seconds: sel.best_seconds,
                best_start: best.start,
            },
            fedorov: Log10Oid {
                log10_oid: l10(fed.ln_oid),
            },
            detmax: Log10Oid {
                log10_oid: l10(det.ln_oid),
            },
            bound: self.bound_summary(),
            designs: self
                .named
                .iter()
                .zip(self.gaps)
                .map(|((name, d), g)| DesignRow {
                    name: (*name).to_string(),
                    poses: self.ids(d),
                    log10_oid: g.log10_oid,
                    d_efficiency: g.d_efficiency,
                })
                .collect(),
            tables: TablesSummary {
                estimate: self.tables.estimate.clone(),
                residual: self.tables.residual.clone(),
                std: self.tables.std.clone(),
                iterations: self.tables.identification.iterations,
                status: self.tables.identification.status,
            },
            monte_carlo: mc.designs.iter().map(monte_carlo_row).collect(),
            seconds,
            monte_carlo_full: mc.designs,
            figures,
        }
    }

    /// The bound and its Newton cross-check.
    fn bound_summary(&self) -> BoundSummary {
        let (bound, newton) = (self.bound, self.newton);
        BoundSummary {
            log10_bound: bound.log10_bound(),
            ln_bound: bound.ln_bound,
            ln_primal: bound.ln_primal,
            certificate_gap: bound.certificate_gap,
            support_size: bound.support_size,
            seconds: bound.seconds,
            status: bound.status,
            newton: NewtonCheck {
                log10_bound: newton.log10_bound(),
                ln_bound: newton.ln_bound,
                ln_primal: newton.ln_primal,
                certificate_gap: newton.certificate_gap,
                seconds: newton.seconds,
                status: newton.status,
            },
        }
    }
}

/// Whether two designs hold the same poses, in any order.
fn same_poses(a: &[usize], b: &[usize]) -> bool {
    let mut a1 = a.to_vec();
    let mut b1 = b.to_vec();
    a1.sort_unstable();
    b1.sort_unstable();
    a1 == b1
}

/// One design's Monte-Carlo row of the report.
fn monte_carlo_row(d: &crate::identify::montecarlo::MonteCarloSummary) -> MonteCarloRow {
    MonteCarloRow {
        design: d.design.clone(),
        trials: d.trials,
        converged: d.converged,
        rmse_median_over_predicted: d.rmse_over_predicted.as_ref().map(|s| s.median),
        param_rmse: d
            .parameters
            .iter()
            .map(|q| (q.name.clone(), q.rmse))
            .collect(),
        ln_generalized_variance_ratio: d.generalized_variance.as_ref().map(|g| g.ln_ratio),
        validation_rms_before: d.validation_rms_before,
        validation_rms_after_median: d.validation_rms_after.as_ref().map(|s| s.median),
    }
}
