//! Shared helpers of the command-line subcommands; one file per command group.

pub mod basic;
pub mod bench;
pub mod bound;
pub mod calibrate;
pub mod figures;
pub mod reproduce;
pub mod select;

use activecal::measure::Visibility;
use activecal::model::{ParamSet, Robot};
use activecal::pool::{Pool, PoolFilter, PoolSource, PoolSpec};
use anyhow::Result;
use serde_json::Value;

/// Parses a comma-separated list, naming the option in the error.
pub fn parse_list<T: std::str::FromStr>(s: &str, what: &str) -> Result<Vec<T>>
where
    T::Err: std::fmt::Display,
{
    s.split(',')
        .map(|x| {
            let x = x.trim();
            x.parse::<T>()
                .map_err(|e| anyhow::anyhow!("{what}: cannot parse '{x}': {e}"))
        })
        .collect()
}

/// Parses `--seed`: a non-negative integer. With `allow_negative_numbers`
/// (on every numeric option), `--seed -1` and `--seed=-1` both reach this
/// parser and get the same message (clap would otherwise take `-1` for an
/// unknown option).
pub fn parse_seed(s: &str) -> std::result::Result<u64, String> {
    s.trim().parse::<u64>().map_err(|_| {
        format!(
            "the seed must be a non-negative integer (0 to {}), got '{s}'",
            u64::MAX
        )
    })
}

/// The chain chosen by `--base`, `--tip` and `--lock` (global options).
static CHAIN: std::sync::OnceLock<activecal::io::ChainChoice> = std::sync::OnceLock::new();

/// Records the global chain options (once, before the command runs).
pub fn set_chain_choice(
    base: Option<String>,
    tip: Option<String>,
    lock: Option<&str>,
) -> Result<()> {
    let lock = match lock {
        Some(l) => activecal::io::ChainChoice::parse_lock(l)?,
        None => Vec::new(),
    };
    let _ = CHAIN.set(activecal::io::ChainChoice { base, tip, lock });
    Ok(())
}

/// A `--robot` name with the chain options appended as its `#…` fragment
/// (unless it names a chain already, as a design file's robot does), so
/// that reports and design files record the chain.
pub fn with_chain(name: &str) -> String {
    match CHAIN.get() {
        Some(c) if !c.is_empty() && !name.contains('#') => format!("{name}{}", c.fragment()),
        _ => name.to_string(),
    }
}

/// Loads and validates a robot: a built-in name, or a `.toml` description or
/// `.urdf` file ([`activecal::io::load_robot`]), with the chain options.
pub fn load_robot(name: &str) -> Result<Robot> {
    let r = activecal::io::load_robot(&with_chain(name))?;
    r.validate()?;
    Ok(r)
}

/// Errors if `path` exists and `force` is not set: nothing the user has is
/// replaced without asking. Checked before any work is done.
pub fn refuse_overwrite(path: &std::path::Path, force: bool) -> Result<()> {
    check_outputs(&[("--out", path)], &[], force)
}

/// Checks a command's outputs before any work (see
/// [`activecal::io::atomic::check_outputs`]): each is a file in an existing
/// directory, not an input, not another output, and new unless `force`.
pub fn check_outputs(
    outputs: &[(&str, &std::path::Path)],
    inputs: &[&std::path::Path],
    force: bool,
) -> Result<()> {
    let outs: Vec<activecal::io::atomic::Output<'_>> = outputs
        .iter()
        .map(|&(option, path)| activecal::io::atomic::Output { option, path })
        .collect();
    activecal::io::atomic::check_outputs(&outs, inputs, force)?;
    Ok(())
}

/// Writes `text` to `path` (see [`refuse_overwrite`]), naming the file in
/// any error.
pub fn write_new(path: &std::path::Path, text: &str, force: bool) -> Result<()> {
    refuse_overwrite(path, force)?;
    activecal::io::atomic::write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// Prints `value` as one JSON line, or the human-readable `text`.
pub fn emit(json_out: bool, value: &Value, text: impl FnOnce() -> String) {
    use std::io::Write;
    let s = if json_out {
        format!("{value}\n")
    } else {
        text()
    };
    // A closed pipe (`activecal ... | head`) is not an error worth a panic.
    let _ = std::io::stdout().lock().write_all(s.as_bytes());
}

/// Prints a typed report as one JSON line, or the human-readable `text`.
pub fn emit_report<T: serde::Serialize>(
    json_out: bool,
    report: &T,
    text: impl FnOnce() -> String,
) -> Result<()> {
    let v = serde_json::to_value(report)?;
    emit(json_out, &v, text);
    Ok(())
}

/// Options that define a pose pool, shared by the commands that need one.
#[derive(clap::Args, Clone, Debug)]
pub struct PoolOpts {
    /// Robot: a built-in name (puma560, ur5, stanford), or a .toml
    /// description or .urdf file; append `:pose` for full-pose measurements.
    #[arg(long, default_value = "puma560")]
    pub robot: String,
    /// Lattice values per joint.
    #[arg(long, default_value_t = 5, allow_negative_numbers = true)]
    pub levels: usize,
    /// Parameter set the Jacobian is computed with.
    #[arg(long, value_enum, default_value_t = ParamSet::Nominal)]
    pub params: ParamSet,
    /// Sensor visibility region as JSON, e.g.
    /// '{"kind":"box","min":[-30,-30,-30],"max":[30,30,30]}' or
    /// '{"kind":"cone","apex":[0,0,0],"axis":[0,1,0],"half_angle":0.1,"max_range":40}'.
    #[arg(long)]
    pub visibility: Option<String>,
}

/// A robot, its pose pool and the pool's identification Jacobian.
pub struct PoolCtx {
    /// The robot.
    pub robot: Robot,
    /// The pool.
    pub pool: Pool,
    /// Identification Jacobian of every pool pose.
    pub x: activecal::blocks::Blocks,
}

/// The filters of a pool: `--visibility`, else the robot description's
/// region, else none.
pub fn filters(
    visibility: Option<&str>,
    described: Option<&Visibility>,
) -> Result<Vec<PoolFilter>> {
    Ok(match (visibility, described) {
        (Some(v), _) => {
            let vis: Visibility =
                serde_json::from_str(v).map_err(|e| anyhow::anyhow!("--visibility: {e}"))?;
            vis.validate()
                .map_err(|e| anyhow::anyhow!("--visibility: {e}"))?;
            vec![PoolFilter::Visibility(vis)]
        }
        (None, Some(vis)) => vec![PoolFilter::Visibility(vis.clone())],
        (None, None) => vec![],
    })
}

/// Loads a robot with its description's visibility region (validated).
pub fn load_description(name: &str) -> Result<activecal::io::Description> {
    let d = activecal::io::load_description(&with_chain(name))?;
    d.robot.validate()?;
    Ok(d)
}

/// Builds the pool of `spec` for `robot` ([`PoolSpec::build`], filters at the
/// nominal model) and its Jacobian at `params`.
pub fn build_pool(robot: Robot, spec: &PoolSpec, params: ParamSet) -> Result<PoolCtx> {
    let pool = spec.build(&robot, &robot.nominal)?;
    let x = pool.jacobian(&robot, robot.params(params));
    Ok(PoolCtx { robot, pool, x })
}

impl PoolOpts {
    /// The pool these options describe, for a robot description.
    pub fn spec(&self, described: Option<&Visibility>) -> Result<PoolSpec> {
        Ok(PoolSpec {
            source: PoolSource::Lattice {
                levels: self.levels,
            },
            filters: filters(self.visibility.as_deref(), described)?,
        })
    }

    /// Loads the robot, builds the pool and its Jacobian.
    pub fn load(&self) -> Result<PoolCtx> {
        let d = load_description(&self.robot)?;
        let spec = self.spec(d.visibility.as_ref())?;
        build_pool(d.robot, &spec, self.params)
    }
}
