//! `bound` and `gap`: the certified D-optimal relaxation bound on OI_D, and a
//! design's D-efficiency against it.

use super::{PoolOpts, emit_report, filters, load_description};
use activecal::io::design::DesignFile;
use activecal::model::ParamSet;
use activecal::options::{BoundSettings, RelaxationSolver};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

/// Options of the relaxation solve shared by `bound` and `gap`.
#[derive(Args, Clone, Debug)]
pub struct SolveOpts {
    /// Target certified gap in ln det (bound − best feasible relaxation value).
    #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
    pub gap_tol: f64,
    /// Solve with the first-order solver alone (no Clarabel).
    #[arg(long)]
    pub first_order: bool,
    /// Solver of the candidate subproblems: clarabel (conic form) or newton
    /// (log-barrier Newton on ln det itself). Both are certified by eq. (C).
    #[arg(long, value_parser = super::choice::<RelaxationSolver>(), default_value_t = RelaxationSolver::Newton)]
    pub solver: RelaxationSolver,
    /// Poses outside the first-order support given to Clarabel, by largest
    /// variance.
    #[arg(long, default_value_t = 100, allow_negative_numbers = true)]
    pub screen_extra: usize,
    /// First-order certificate gap (ln det) at which screening stops and the
    /// candidate-set solver takes over.
    #[arg(long, default_value_t = 1e-2)]
    pub screen_gap: f64,
    /// Most candidate-set solves (screening rounds); large pools may need
    /// more than the default to certify.
    #[arg(long, default_value_t = 20, allow_negative_numbers = true)]
    pub max_rounds: usize,
}

impl SolveOpts {
    fn settings(&self) -> Result<BoundSettings> {
        Ok(BoundSettings::builder()
            .gap_tol(self.gap_tol)
            .use_conic(!self.first_order)
            .solver(self.solver)
            .screen_extra(self.screen_extra)
            .screen_gap(self.screen_gap)
            .max_rounds(self.max_rounds)
            .build()?)
    }
}

/// Arguments of `bound`.
#[derive(Args)]
pub struct BoundArgs {
    #[command(flatten)]
    pub pool: PoolOpts,
    /// Poses per design.
    #[arg(long, default_value_t = 30, allow_negative_numbers = true)]
    pub n: usize,
    #[command(flatten)]
    pub solve: SolveOpts,
    /// Also list the poses carrying relaxation weight (lattice index, weight).
    #[arg(long)]
    pub weights: bool,
    /// Poses already measured (see `select --existing`): the relaxation
    /// maximises ln det(M0 + Σ w_i X_iᵀX_i) with M0 their information.
    #[arg(long, value_name = "FILE")]
    pub existing: Option<PathBuf>,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `gap`.
#[derive(Args)]
pub struct GapArgs {
    /// The design file (JSON with robot, levels, poses).
    #[arg(long)]
    pub design: PathBuf,
    /// Parameter set the Jacobian is computed with.
    #[arg(long, value_parser = super::choice::<ParamSet>(), default_value_t = ParamSet::Nominal)]
    pub params: ParamSet,
    /// Sensor visibility region as JSON (see `bound --help`).
    #[arg(long)]
    pub visibility: Option<String>,
    #[command(flatten)]
    pub solve: SolveOpts,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Runs `bound`.
pub fn cmd_bound(a: BoundArgs) -> Result<()> {
    let settings = a.solve.settings()?;
    let ctx = a.pool.load()?;
    let existing = a
        .existing
        .as_deref()
        .map(|p| super::load_existing(p, &ctx.robot, a.pool.params, a.pool.units.units()))
        .transpose()?;
    let report = activecal::experiment::bound::bound_of_pool(
        ctx.scoring(),
        existing,
        a.n,
        settings,
        a.weights,
    )?;
    emit_report(a.json, &report, || {
        let mut s = super::pool_stats_text(&ctx.pool.stats);
        if let Some(e) = &report.existing {
            s += &super::existing_text(e);
        }
        s += &activecal::render::bound_text::bound_text(&report.bound);
        s + &report
            .support
            .as_deref()
            .map_or(String::new(), activecal::render::bound_text::support_text)
    })
}

/// Runs `gap`: the bound over the design's own pool (with `--visibility`
/// replacing its filters when given).
pub fn cmd_gap(a: GapArgs) -> Result<()> {
    let settings = a.solve.settings()?;
    let d = DesignFile::read(&a.design)?;
    let desc = load_description(&d.robot_ref()?)?;
    let replaced = (d.pool.is_none() || a.visibility.is_some())
        .then(|| filters(a.visibility.as_deref(), desc.visibility.as_ref()))
        .transpose()?;
    let report = activecal::experiment::gap::gap_of_design_file(
        &a.design, &d, desc, replaced, a.params, &settings,
    )?;
    emit_report(a.json, &report, || {
        activecal::render::design_text::gap_text(
            &a.design.display().to_string(),
            &report,
            activecal::options::SUPPORT_WEIGHT,
        )
    })
}
