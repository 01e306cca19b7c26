//! `bound` and `gap`: the certified D-optimal relaxation bound on OI_D, and a
//! design's D-efficiency against it.

use super::{PoolOpts, emit};
use activecal::bound::{Bound, BoundSettings, RelaxationSolver, design_gap, relaxation_bound};
use activecal::io::design::DesignFile;
use anyhow::Result;
use clap::Args;
use serde_json::{Value, json};
use std::path::PathBuf;

/// Options of the relaxation solve shared by `bound` and `gap`.
#[derive(Args, Clone, Debug)]
pub struct SolveOpts {
    /// Target certified gap in ln det (bound − best feasible relaxation value).
    #[arg(long, default_value_t = 1e-6)]
    pub gap_tol: f64,
    /// Solve with the first-order solver alone (no Clarabel).
    #[arg(long)]
    pub first_order: bool,
    /// Solver of the candidate subproblems: clarabel (conic form) or newton
    /// (log-barrier Newton on ln det itself). Both are certified by eq. (C).
    #[arg(long, default_value = "clarabel")]
    pub solver: String,
    /// Poses outside the first-order support given to Clarabel, by largest
    /// variance.
    #[arg(long, default_value_t = 100)]
    pub screen_extra: usize,
    /// Most candidate-set solves (screening rounds); large pools may need
    /// more than the default to certify.
    #[arg(long, default_value_t = 10)]
    pub max_rounds: usize,
}

impl SolveOpts {
    fn settings(&self) -> Result<BoundSettings> {
        Ok(BoundSettings::builder()
            .gap_tol(self.gap_tol)
            .use_conic(!self.first_order)
            .solver(RelaxationSolver::parse(&self.solver)?)
            .screen_extra(self.screen_extra)
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
    #[arg(long, default_value_t = 30)]
    pub n: usize,
    #[command(flatten)]
    pub solve: SolveOpts,
    /// Also list the poses carrying relaxation weight (lattice index, weight).
    #[arg(long)]
    pub weights: bool,
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
    /// Parameter set the Jacobian is computed with: nominal or real.
    #[arg(long, default_value = "nominal")]
    pub params: String,
    /// Sensor visibility region as JSON (see `bound --help`).
    #[arg(long)]
    pub visibility: Option<String>,
    #[command(flatten)]
    pub solve: SolveOpts,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// The JSON summary of a bound.
fn bound_json(b: &Bound) -> Value {
    json!({
        "ln_bound": b.ln_bound,
        "log10_bound": b.log10_bound(),
        "ln_primal": b.ln_primal,
        "certificate_gap": b.certificate_gap,
        "status": b.status,
        "n": b.n,
        "p": b.p,
        "pool_size": b.pool_size,
        "support_size": b.support_size,
        "seconds": b.seconds,
        "solver": {
            "solver": b.conic.solver,
            "status": b.conic.status,
            "iterations": b.conic.iterations,
            "total_iterations": b.conic.total_iterations,
            "rounds": b.conic.rounds,
            "candidates": b.conic.candidates,
            "retried_without_equilibration": b.conic.retried,
            "seconds": b.conic.seconds,
            "ln_det_primal": b.conic.ln_det_primal,
            "ln_det_dual": b.conic.ln_det_dual,
            "polish_steps": b.conic.polish_steps,
        },
        "first_order": b.first_order,
    })
}

fn bound_text(b: &Bound) -> String {
    let mut s = format!(
        "relaxation bound, N = {} of {} poses, p = {}: {:?}\n\
         ln bound   {:.9}  (log10 OI_D <= {:.6})\n\
         ln primal  {:.9}\n\
         gap        {:.3e}\n\
         support    {} poses with weight\n",
        b.n,
        b.pool_size,
        b.p,
        b.status,
        b.ln_bound,
        b.log10_bound(),
        b.ln_primal,
        b.certificate_gap,
        b.support_size,
    );
    match b.conic.status {
        Some(st) => {
            s += &format!(
                "{:<10} {st:?}, {} iterations, {} round(s), {} candidates, {:.2} s\n",
                solver_name(b),
                b.conic.iterations,
                b.conic.rounds,
                b.conic.candidates,
                b.conic.seconds
            )
        }
        None => s += &format!("{:<10} not run\n", solver_name(b)),
    }
    s += &format!(
        "first order {} rounds, {} steps, {:.2} s\ntotal      {:.2} s\n",
        b.first_order.rounds, b.first_order.steps, b.first_order.seconds, b.seconds
    );
    s
}

fn solver_name(b: &Bound) -> &'static str {
    match b.conic.solver {
        RelaxationSolver::Clarabel => "clarabel",
        RelaxationSolver::Newton => "newton",
    }
}

/// Runs `bound`.
pub fn cmd_bound(a: BoundArgs) -> Result<()> {
    let settings = a.solve.settings()?;
    let ctx = a.pool.load()?;
    let b = relaxation_bound(&ctx.x, a.n, &settings)?;
    let mut v = bound_json(&b);
    v["robot"] = json!(ctx.robot.name);
    v["levels"] = json!(a.pool.levels);
    v["params"] = json!(a.pool.params);
    v["settings"] = json!(settings);
    let support: Vec<(usize, f64)> = b
        .support(activecal::bound::SUPPORT_TOL)
        .into_iter()
        .map(|k| (ctx.pool.indices[k], b.weights[k]))
        .collect();
    if a.weights {
        v["support"] = json!(
            support
                .iter()
                .map(|&(pose, w)| json!({"pose": pose, "w": w}))
                .collect::<Vec<_>>()
        );
    }
    emit(a.json, &v, || {
        let mut s = bound_text(&b);
        if a.weights {
            s += "pose      weight\n";
            for (pose, w) in &support {
                s += &format!("{pose:>6}  {w:.6}\n");
            }
        }
        s
    });
    Ok(())
}

/// Runs `gap`.
pub fn cmd_gap(a: GapArgs) -> Result<()> {
    let settings = a.solve.settings()?;
    let d = DesignFile::read(&a.design)?;
    let opts = PoolOpts {
        robot: d.robot.clone(),
        levels: d.levels,
        params: a.params.clone(),
        visibility: a.visibility.clone(),
    };
    let ctx = opts.load()?;
    let positions = d.positions_in(&ctx.robot, &ctx.pool)?;
    let b = relaxation_bound(&ctx.x, positions.len(), &settings)?;
    let g = design_gap(&ctx.x, &positions, &b)?;
    let weighted: Vec<usize> = g.weighted.iter().map(|&k| d.poses[k]).collect();
    let v = json!({
        "robot": ctx.robot.name,
        "levels": d.levels,
        "params": a.params,
        "poses": d.poses,
        "n": g.n,
        "p": g.p,
        "ln_oid": g.ln_oid,
        "log10_oid": g.log10_oid,
        "singular": g.ln_oid.is_none(),
        "ln_bound": g.ln_bound,
        "log10_bound": g.log10_bound,
        "d_efficiency": g.d_efficiency,
        "weighted_poses": weighted,
        "weights": g.weights,
        "bound": bound_json(&b),
    });
    emit(a.json, &v, || {
        let oid = g
            .log10_oid
            .map_or("singular (-inf)".to_string(), |l| format!("{l:.6}"));
        format!(
            "design {} ({} poses, p = {})\nlog10 OI_D     {oid}\nlog10 bound    {:.6}  ({:?}, gap {:.1e})\nD-efficiency  >= {:.6}\n\
             poses with relaxation weight > {}: {} of {}: {:?}\n",
            a.design.display(),
            g.n,
            g.p,
            g.log10_bound,
            b.status,
            b.certificate_gap,
            g.d_efficiency,
            activecal::bound::gap::WEIGHT_TOL,
            weighted.len(),
            g.n,
            weighted
        )
    });
    Ok(())
}
