//! `score` and `select`: observability of a design, and pose selection.

use super::{PoolOpts, emit, parse_list};
use activecal::criterion::{DCriterion, Indices, OiCriterion};
use activecal::io::design::DesignFile;
use activecal::select::{Algorithm, Selection, Settings, multistart};
use anyhow::{Result, bail};
use clap::Args;
use serde_json::{Value, json};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `score`.
#[derive(Args)]
pub struct ScoreArgs {
    #[command(flatten)]
    pub pool: PoolOpts,
    /// Lattice indices of the design, comma separated.
    #[arg(long)]
    pub poses: Option<String>,
    /// A design file (JSON with robot, levels, poses) instead of --poses.
    #[arg(long, conflicts_with = "poses")]
    pub design: Option<PathBuf>,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Runs `score`.
pub fn cmd_score(a: ScoreArgs) -> Result<()> {
    let mut opts = a.pool.clone();
    let lattice_poses: Vec<usize> = match (&a.poses, &a.design) {
        (Some(p), None) => parse_list(p, "--poses")?,
        (None, Some(path)) => {
            let d = DesignFile::read(path)?;
            opts.robot = d.robot.clone();
            opts.levels = d.levels;
            d.poses
        }
        _ => bail!("give the design with --poses I1,I2,... or --design FILE"),
    };
    let ctx = opts.load()?;
    activecal::io::design::check_unique(&lattice_poses)?;
    let positions = ctx.pool.positions_of(&lattice_poses)?;
    let ind = Indices::from_design(&ctx.x, &positions);
    let v = json!({
        "robot": ctx.robot.name, "levels": opts.levels, "poses": lattice_poses,
        "ln_oid": ind.ln_oid, "log10_oid": ind.log10_oid, "oi": ind.oi, "o1": ind.o1, "o2": ind.o2,
        "o3": ind.o3, "o4": ind.o4, "o5": ind.o5, "a_trace": ind.a_trace, "rank": ind.rank,
        "p": ctx.x.p(), "singular": ind.rank < ctx.x.p(),
    });
    emit(a.json, &v, || {
        format!(
            "{} poses, rank {} of {}\nln OI_D {:.6}  log10 OI_D {:.6}\nOI {:.6}  O1 {:.6e}  O2 {:.6e}  O3 {:.6e}  O4 {:.6e}  O5 {:.6e}  tr(M^-1) {:.6e}\n",
            lattice_poses.len(),
            ind.rank,
            ctx.x.p(),
            ind.ln_oid,
            ind.log10_oid,
            ind.oi,
            ind.o1,
            ind.o2,
            ind.o3,
            ind.o4,
            ind.o5,
            ind.a_trace
        )
    });
    Ok(())
}

/// Arguments of `select`.
#[derive(Args)]
pub struct SelectArgs {
    #[command(flatten)]
    pub pool: PoolOpts,
    /// Poses in the design.
    #[arg(long, default_value_t = 30)]
    pub n: usize,
    /// eae, fedorov, detmax or random.
    #[arg(long, default_value = "eae")]
    pub algorithm: String,
    /// Initial random poses of EAE (fixed poses included).
    #[arg(long, default_value_t = 12)]
    pub initial: usize,
    /// Independent random starts; the best is kept.
    #[arg(long, default_value_t = 1)]
    pub starts: usize,
    /// Random designs drawn by --algorithm random.
    #[arg(long, default_value_t = 5000)]
    pub designs: usize,
    /// Polish the best start with Fedorov exchange.
    #[arg(long)]
    pub polish: bool,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Lattice indices of poses every design must contain.
    #[arg(long)]
    pub fixed: Option<String>,
    /// det (ln OI_D, with O(p²) updates) or oi (the paper's eigenvalue OI, recomputed).
    #[arg(long, default_value = "det")]
    pub criterion: String,
    /// Write the design file here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Overwrite --out if it exists.
    #[arg(long)]
    pub force: bool,
    /// Also compute the relaxation bound and report the design's D-efficiency.
    #[arg(long)]
    pub gap: bool,
    /// Solver of the bound for `--gap`: clarabel or newton (see `bound`).
    #[arg(long, default_value = "clarabel", requires = "gap")]
    pub gap_solver: String,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Runs a selection with the named criterion.
pub fn run_selection(
    x: &activecal::blocks::Blocks,
    criterion: &str,
    alg: Algorithm,
    s: &Settings,
) -> Result<Selection> {
    Ok(match criterion {
        "det" => multistart(x, DCriterion::new, alg, s)?,
        "oi" => multistart(x, OiCriterion::new, alg, s)?,
        other => bail!("unknown criterion '{other}' (expected det or oi)"),
    })
}

/// Runs `select`.
pub fn cmd_select(a: SelectArgs) -> Result<()> {
    if let Some(out) = &a.out {
        super::refuse_overwrite(out, a.force)?;
    }
    let alg = Algorithm::parse(&a.algorithm)?;
    let gap_solver = activecal::bound::RelaxationSolver::parse(&a.gap_solver)?;
    let ctx = a.pool.load()?;
    let fixed_lattice: Vec<usize> = match &a.fixed {
        Some(f) => parse_list(f, "--fixed")?,
        None => vec![],
    };
    activecal::io::design::check_unique(&fixed_lattice)?;
    let fixed = ctx.pool.positions_of(&fixed_lattice)?;
    let s = Settings {
        n: a.n,
        initial: a.initial.max(fixed.len()).min(a.n),
        starts: a.starts,
        designs: a.designs,
        polish: a.polish,
        seed: a.seed,
        fixed,
        ..Settings::default()
    };
    let t0 = Instant::now();
    let sel = run_selection(&ctx.x, &a.criterion, alg, &s)?;
    let seconds = t0.elapsed().as_secs_f64();
    let lat = |k: usize| ctx.pool.indices[k];
    let poses: Vec<usize> = sel.poses.iter().map(|&k| lat(k)).collect();
    let trace: Vec<Value> = sel
        .trace
        .iter()
        .map(|r| {
            json!({"step": r.step, "kind": r.kind, "added": r.added.map(lat), "removed": r.removed.map(lat),
                   "size": r.size, "ln_oid": r.ln_oid, "log10_oid": r.ln_oid / std::f64::consts::LN_10,
                   "oi": r.oi, "ridge": r.ridge})
        })
        .collect();
    let log10 = sel.ln_oid / std::f64::consts::LN_10;
    let v = json!({
        "robot": ctx.robot.name, "levels": a.pool.levels, "poses": poses,
        "ln_oid": sel.ln_oid, "log10_oid": log10, "oi": sel.oi, "trace": trace,
        "seconds": seconds, "algorithm": alg, "criterion": a.criterion, "seed": a.seed,
        "starts": a.starts, "polish": a.polish, "best_start": sel.start,
        "fixed": fixed_lattice,
    });
    let mut v = v;
    if a.gap {
        let settings = activecal::bound::BoundSettings::builder()
            .solver(gap_solver)
            .build()?;
        let bound = activecal::bound::relaxation_bound(&ctx.x, a.n, &settings)?;
        let g = activecal::bound::design_gap(&ctx.x, &sel.poses, &bound)?;
        v["log10_bound"] = json!(g.log10_bound);
        v["d_efficiency"] = json!(g.d_efficiency);
        v["bound_status"] = json!(format!("{:?}", g.bound_status));
    }
    if let Some(out) = &a.out {
        let mut d = DesignFile::new(&ctx.robot.name, a.pool.levels, poses.clone());
        for k in [
            "ln_oid",
            "log10_oid",
            "oi",
            "algorithm",
            "criterion",
            "seed",
            "starts",
            "polish",
            "fixed",
        ] {
            d.extra.insert(k.into(), v[k].clone());
        }
        d.write(out, a.force)?;
    }
    emit(a.json, &v, || {
        format!(
            "{alg:?} ({} criterion, seed {}, {} start(s){}): {} poses in {:.3} s\nlog10 OI_D {:.4}  OI {:.6}\nposes: {}\n",
            a.criterion,
            a.seed,
            a.starts,
            if a.polish { ", Fedorov polish" } else { "" },
            poses.len(),
            seconds,
            log10,
            sel.oi,
            poses
                .iter()
                .map(|p| p.to_string())
                .collect::<Vec<_>>()
                .join(",")
        )
    });
    Ok(())
}
