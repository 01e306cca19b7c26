//! `robots`, `fk`, `pool`: the kinematic core on the command line.

use super::{emit_report, load_robot, parse_list};
use activecal::model::{ParamSet, Robot};
use activecal::report::{FkReport, LatticeReport, PoolSummary};
use activecal::write::poses::{PosesFormat, poses_text};
use anyhow::Result;
use clap::Args;

/// Arguments of the command.
#[derive(Args)]
pub struct RobotsArgs {
    /// Write this robot (a built-in name, a .toml description or a .urdf
    /// file) as a description file to start your own from: edit its tables,
    /// unknowns, limits or `orientation_scale`, then pass it as `--robot`.
    #[arg(long, value_name = "ROBOT", value_parser = super::parse_robot)]
    pub export: Option<activecal::io::RobotRef>,
    /// File for `--export` (default: standard output, as TOML), by
    /// extension: .toml (a description), .urdf (the URDF, or a built-in's
    /// chain as URDF), .yaml (a URDF robot's frames file); any other is
    /// refused. (Conflicting with --robot and --json as well: clap does not
    /// check `requires` when an option conflicting with the required one is
    /// given, and --out was silently ignored.)
    #[arg(long, requires = "export", conflicts_with_all = ["robot", "json"])]
    pub out: Option<std::path::PathBuf>,
    /// Replace an existing `--out` file.
    #[arg(long, requires = "out")]
    pub force: bool,
    /// Describe this robot (a built-in name, a .toml description or a
    /// .urdf file, with --base/--tip/--lock for a tree) instead of listing
    /// the built-in ones: its chain, joints with limits, parameter tables
    /// and unknowns.
    #[arg(long, value_name = "ROBOT", conflicts_with = "export", value_parser = super::parse_robot)]
    pub robot: Option<activecal::io::RobotRef>,
    /// Print one JSON object.
    #[arg(long, conflicts_with = "export")]
    pub json: bool,
}

/// Arguments of the command.
#[derive(Args)]
pub struct FkArgs {
    /// Robot: a built-in name, or a .toml description or .urdf file; append
    /// `:pose` for full-pose measurements (`:NAME` for a sensor registered
    /// by that name).
    #[arg(long, default_value = "puma560", value_parser = super::parse_robot)]
    pub robot: activecal::io::RobotRef,
    /// Parameter set.
    #[arg(long, value_parser = super::choice::<ParamSet>(), default_value_t = ParamSet::Nominal)]
    pub params: ParamSet,
    /// Joint values, comma separated, in joint order (radians and metres,
    /// or as --angle-unit and --length-unit say); checked against the
    /// joint limits.
    #[arg(long, allow_hyphen_values = true)]
    pub q: String,
    /// Angles are in degrees (the same as --angle-unit deg).
    #[arg(long)]
    pub deg: bool,
    /// Units of --q.
    #[command(flatten)]
    pub units: super::units::UnitOpts,
    /// Also print the identification Jacobian (t × p: 3 rows for a point, 6 for a pose).
    #[arg(long)]
    pub jacobian: bool,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of the command.
#[derive(Args)]
pub struct PoolArgs {
    #[command(flatten)]
    pub pool: super::PoolOpts,
    /// Lattice digits of one pose (joint 1 first), comma separated.
    #[arg(long)]
    pub digits: Option<String>,
    /// Write the kept poses here: .csv (a header of the joint names and
    /// `id`, one pose a row) or .json ({"joints", "ids", "qs"}), both
    /// readable by --pool file:.
    #[arg(long)]
    pub out: Option<std::path::PathBuf>,
    /// Replace an existing --out file.
    #[arg(long, requires = "out")]
    pub force: bool,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Runs `robots`.
pub fn cmd_robots(a: RobotsArgs) -> Result<()> {
    if let Some(name) = &a.export {
        use activecal::write::calibrated::Format;
        let format = match &a.out {
            Some(p) => {
                let mut files = super::run_files::RunFiles::new();
                files
                    .robot("--export", name, "--frames")
                    .output("--out", Some(p.as_path()));
                super::run_files::check(&files, a.force)?;
                Format::of(p).map_err(|e| anyhow::anyhow!("--out {e}"))?
            }
            None => Format::Toml,
        };
        let d = super::load_description(name)?;
        let text = activecal::write::robot::export(&d, format)?;
        match &a.out {
            Some(path) => super::write_new(path, &text, a.force)?,
            None => super::print_out(&text)?,
        }
        return Ok(());
    }
    let robots: Vec<Robot> = match &a.robot {
        Some(name) => {
            let d = super::load_description(name)?;
            d.robot.validate()?;
            vec![d.robot]
        }
        None => activecal::model::BUILTIN
            .iter()
            .map(|n| Robot::builtin(n).expect("built-in"))
            .collect(),
    };
    let report = activecal::report::RobotsReport {
        robots: robots
            .iter()
            .map(activecal::report::RobotReport::of)
            .collect(),
    };
    super::emit_report(a.json, &report, || {
        robots
            .iter()
            .map(activecal::render::robot_text::text)
            .collect()
    })
}

/// Runs `fk`.
pub fn cmd_fk(a: FkArgs) -> Result<()> {
    let robot = load_robot(&a.robot)?;
    let q: Vec<f64> = parse_list(&a.q, "--q")?;
    let mut units = a.units.units();
    if a.deg {
        units.angle = activecal::units::AngleUnit::Deg;
    }
    let r = FkReport::in_units(&robot, a.params, q, units, "--q", a.jacobian)?;
    emit_report(a.json, &r, || activecal::render::fk_text::text(&r))
}

/// Runs `pool`: one lattice pose (`--digits`), or the pool every source and
/// filter makes, with its counts, checked for repeated poses and written
/// with `--out`.
pub fn cmd_pool(a: PoolArgs) -> Result<()> {
    if let Some(out) = &a.out {
        let mut files = super::run_files::RunFiles::new();
        super::run_files::pool(&mut files, &a.pool).output("--out", Some(out));
        super::run_files::check(&files, a.force)?;
        PosesFormat::of("--out", out)?;
    }
    if let Some(d) = a.digits.as_deref() {
        let robot = load_robot(&a.pool.robot)?;
        if !matches!(a.pool.pool, super::PoolKind::Lattice) || a.out.is_some() {
            anyhow::bail!("--digits names one pose of --pool lattice, without --out");
        }
        let digits: Vec<usize> = parse_list(d, "--digits")?;
        let levels = a.pool.levels.unwrap_or(super::DEFAULT_LEVELS);
        let r = LatticeReport::new(&robot, levels, Some(digits))?;
        return emit_report(a.json, &r, || {
            activecal::render::pool_text::lattice_text(&r)
        });
    }
    let d = super::load_description(&a.pool.robot)?;
    let spec = a.pool.spec(&d)?;
    let pool = spec.build_poses(&d.robot, &d.robot.nominal)?;
    let r = PoolSummary::new(&d.robot, &pool)?;
    if let Some(out) = &a.out {
        let text = poses_text(PosesFormat::of("--out", out)?, &r, &pool);
        super::write_new(out, &text, a.force)?;
    }
    emit_report(a.json, &r, || {
        activecal::render::pool_text::pool_summary_text(
            &r,
            pool.lattice(),
            super::pool_opts::SRDF_HINT,
            a.out.as_deref(),
        )
    })
}
