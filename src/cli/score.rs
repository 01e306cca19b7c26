//! `score`: the observability indices of a design (ln OI_D, OI, O1–O5,
//! A-trace, rank), from pool pose ids or a design file.

use super::{PoolOpts, emit_report, load_description, parse_list};
use activecal::io::design::DesignFile;
use activecal::report::{PoolInfo, ScoreReport};
use anyhow::{Result, bail};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `score`.
#[derive(Args)]
pub struct ScoreArgs {
    #[command(flatten)]
    pub pool: PoolOpts,
    /// Pose ids (lattice indices) of the design, comma separated. Without
    /// it (and --design), a --pool file: is scored whole: a design written
    /// by `select --out d.csv` scores as `score --pool file:d.csv`.
    #[arg(long)]
    pub poses: Option<String>,
    /// A design file (as `select --out` writes) instead of --poses: its
    /// stored joint values are scored.
    #[arg(long, conflicts_with = "poses")]
    pub design: Option<PathBuf>,
    /// Position noise σ per axis of the measurements, metres: with
    /// --orientation-noise, sets the weight of a full pose's orientation
    /// rows (as `select --noise` does) [default: 0.01, as `select`].
    #[arg(long, value_name = "M", requires = "orientation_noise")]
    pub noise: Option<f64>,
    /// Orientation noise σ per axis of a full-pose sensor, radians: the
    /// design is scored with a radian of orientation weighed as
    /// `--noise`/RAD metres, as `select --orientation-noise` chooses it
    /// (and as `calibrate` weighs data by their estimated σ's). Default:
    /// the robot's orientation scale (1 m/rad).
    #[arg(long, value_name = "RAD", allow_negative_numbers = true)]
    pub orientation_noise: Option<f64>,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// `--robot`, `--levels` and `--visibility` given beside `--design` (the
/// option names in `given`) must agree with the design's own robot and pool,
/// which are what `score` uses: a conflict is refused naming both, never
/// silently ignored.
fn check_design_options(
    a: &ScoreArgs,
    given: &[&str],
    d: &DesignFile,
    path: &std::path::Path,
) -> Result<()> {
    let spec = d.spec()?;
    if given.contains(&"robot") {
        let robot = super::load_robot(&a.pool.robot)?;
        if let Err(e) = d.check_robot(&robot) {
            bail!(
                "--robot {} conflicts with {}: {e}; a design is scored on the robot it names: drop --robot",
                a.pool.robot,
                path.display()
            );
        }
    }
    let pool = match spec.levels() {
        Some(l) => format!("the {l}-level lattice"),
        None => "not a lattice".to_string(),
    };
    let levels = a.pool.levels.unwrap_or(super::DEFAULT_LEVELS);
    if given.contains(&"levels") && spec.levels() != Some(levels) {
        bail!(
            "--levels {levels} conflicts with {}: its pool is {pool}; a design is scored on its own pool: drop --levels",
            path.display()
        );
    }
    for (id, opt) in [
        ("pool", "--pool"),
        ("count", "--count"),
        ("pool_seed", "--pool-seed"),
        // The filters a design's pool was built with are its own; a margin
        // or a collision filter given beside it would otherwise be ignored.
        ("margin", "--margin"),
        ("clearance", "--clearance"),
        ("self_collision", "--self-collision"),
        ("obstacles", "--obstacle"),
        ("floor", "--floor"),
    ] {
        if given.contains(&id) {
            bail!(
                "{opt} given with {}: its pool is {pool} ({}); a design is scored on its own pool: drop {opt}",
                path.display(),
                serde_json::to_string(&spec.source)?
            );
        }
    }
    if given.contains(&"visibility") {
        let mine = super::filters(a.pool.visibility.as_deref(), None)?;
        if serde_json::to_value(&mine)? != serde_json::to_value(&spec.filters)? {
            let theirs = if spec.filters.is_empty() {
                "no filter".to_string()
            } else {
                format!("the filters {}", serde_json::to_string(&spec.filters)?)
            };
            bail!(
                "--visibility conflicts with {}: its pool ({pool}) has {theirs}; a design is scored on its own pool: drop --visibility",
                path.display()
            );
        }
    }
    Ok(())
}

/// The description with its orientation rows weighed as
/// `--noise`/`--orientation-noise` say (unchanged without them).
fn weighted(
    a: &ScoreArgs,
    mut d: activecal::io::Description,
) -> Result<activecal::io::Description> {
    if let Some(so) = a.orientation_noise {
        d.robot.orientation_scale =
            activecal::experiment::pool::orientation_scale(&d.robot, a.noise, so)?;
    }
    Ok(d)
}

/// Runs `score`; `given` names the pool options given on the command line
/// (not defaulted), which must agree with a `--design`.
pub fn cmd_score(a: ScoreArgs, given: &[&str]) -> Result<()> {
    let report = match (&a.poses, &a.design) {
        (Some(p), None) => {
            let ids: Vec<usize> = parse_list(p, "--poses")?;
            activecal::io::design::check_unique(&ids)?;
            let ctx = a
                .pool
                .load_for(weighted(&a, load_description(&a.pool.robot)?)?)?;
            let positions = ctx.pool.positions_of(&ids)?;
            ScoreReport::new(
                PoolInfo::new(&ctx.robot, &ctx.pool),
                ids,
                &ctx.x.select(&positions),
            )
        }
        (None, Some(path)) => {
            let d = DesignFile::read(path)?;
            check_design_options(&a, given, &d, path)?;
            let desc = weighted(&a, load_description(&d.robot_ref()?)?)?;
            activecal::experiment::gap::score_design_file(path, &d, desc, a.pool.params)?
        }
        (None, None) if matches!(a.pool.pool, super::PoolKind::File(_)) => {
            // Every pose of the file: a design written as .csv or .json.
            let ctx = a
                .pool
                .load_for(weighted(&a, load_description(&a.pool.robot)?)?)?;
            let all: Vec<usize> = (0..ctx.pool.len()).collect();
            ScoreReport::new(
                PoolInfo::new(&ctx.robot, &ctx.pool),
                ctx.pool.ids.clone(),
                &ctx.x.select(&all),
            )
        }
        _ => bail!(
            "give the design with --poses I1,I2,..., --design FILE, or --pool file:FILE alone (every pose of the file)"
        ),
    };
    emit_report(a.json, &report, || {
        activecal::render::design_text::score_text(&report)
    })
}
