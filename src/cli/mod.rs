//! Shared helpers of the command-line subcommands; one file per command group.

pub mod acts_on;
pub mod basic;
pub mod bench;
pub mod bound;
pub mod calibrate;
pub mod calibrate_args;
pub mod calibrated;
pub mod camera;
pub mod camera_images;
pub mod camera_opts;
pub mod camera_select;
pub mod compliance;
pub mod contact;
pub mod contact_evaluate;
pub mod contact_select;
pub mod existing;
pub mod extract;
pub mod hints;
pub mod measured;
pub mod pool_opts;
pub mod progress;
pub mod reproduce;
pub mod run_files;
pub mod score;
pub mod select;
pub mod simulated;
pub mod tour;
pub mod units;

use activecal::io::{ChainChoice, RobotRef};
use activecal::model::Robot;
use anyhow::Result;
use serde_json::Value;

pub use activecal::render::select_text::existing_text;
pub use existing::load_existing;
pub use pool_opts::{DEFAULT_LEVELS, PoolCtx, PoolKind, PoolOpts, filters, pool_stats_text};

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

/// Parses `X,Y,Z,ROLL,PITCH,YAW` (six finite numbers: metres, and radians
/// as URDF's rpy), naming the option in the error.
pub fn six(flag: &str, s: &str) -> Result<[f64; 6]> {
    match <[f64; 6]>::try_from(parse_list::<f64>(s, flag)?) {
        Ok(v) if v.iter().all(|x| x.is_finite()) => Ok(v),
        _ => anyhow::bail!(
            "{flag} {s}: expected six finite numbers X,Y,Z,ROLL,PITCH,YAW (metres and radians)"
        ),
    }
}

/// The value parser of an option that takes one of a library type's named
/// values ([`activecal::names::Choice`]): `--help` lists the names, and a
/// wrong one is refused with them.
pub fn choice<T: activecal::names::Choice + Send + Sync>()
-> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(T::ALL.iter().map(|v| v.name())).try_map(|s| {
        T::from_name(&s).ok_or_else(|| format!("'{s}' is not one of the offered names"))
    })
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

/// Parses `--robot` (and `robots --export`): a built-in name or a path,
/// with an optional `:pose` suffix and, as design files of old wrote it,
/// a `#…` chain ([`RobotRef::parse`]).
pub fn parse_robot(s: &str) -> std::result::Result<RobotRef, String> {
    RobotRef::parse(s).map_err(|e| e.to_string())
}

/// The chain options typed on the command line (`--base`, `--tip`,
/// `--lock`, `--frames`, `--marker`), checked: one value, resolved once and given to
/// the command's robot ([`apply_chain`]).
pub fn chain_choice(
    base: Option<String>,
    tip: Option<String>,
    lock: Option<&str>,
    frames: Option<std::path::PathBuf>,
    kinematics: Option<std::path::PathBuf>,
    markers: &[String],
) -> Result<ChainChoice> {
    let lock = match lock {
        Some(l) => ChainChoice::parse_lock(l).map_err(|e| anyhow::anyhow!("--{e}"))?,
        None => Vec::new(),
    };
    if let Some(f) = &frames
        && !f.is_file()
    {
        anyhow::bail!("--frames {}: no such file", f.display());
    }
    if let Some(f) = &kinematics
        && !f.is_file()
    {
        anyhow::bail!("--kinematics {}: no such file", f.display());
    }
    let markers = markers
        .iter()
        .map(|m| activecal::io::MarkerChoice::parse(m).map_err(|e| anyhow::anyhow!("--{e}")))
        .collect::<Result<Vec<_>>>()?;
    Ok(ChainChoice {
        base,
        tip,
        lock,
        frames: frames.map(|f| f.display().to_string()),
        kinematics: kinematics.map(|f| f.display().to_string()),
        markers,
    })
}

/// Gives the chain options to a command's robot. A robot that names a chain
/// already (`tiago.urdf#tip=…`, as design files of old did) keeps it; chain
/// options that differ from it are refused, naming both.
pub fn apply_chain(robot: &mut RobotRef, c: &ChainChoice) -> Result<()> {
    if c.is_empty() {
        return Ok(());
    }
    if !robot.chain.is_empty() && robot.chain != *c {
        anyhow::bail!(
            "{} conflicts with the robot '{robot}', which names its chain already ({}); give the chain once",
            chain_options(c),
            robot.chain.fragment()
        );
    }
    robot.chain = c.clone();
    Ok(())
}

/// The chain options as typed: `--base B --tip T --lock J=V --frames F`.
pub fn chain_options(c: &ChainChoice) -> String {
    let mut parts = Vec::new();
    if let Some(b) = &c.base {
        parts.push(format!("--base {b}"));
    }
    if let Some(t) = &c.tip {
        parts.push(format!("--tip {t}"));
    }
    if !c.lock.is_empty() {
        let l: Vec<String> = c.lock.iter().map(|(n, v)| format!("{n}={v}")).collect();
        parts.push(format!("--lock {}", l.join(",")));
    }
    if let Some(f) = &c.frames {
        parts.push(format!("--frames {f}"));
    }
    if let Some(k) = &c.kinematics {
        parts.push(format!("--kinematics {k}"));
    }
    parts.extend(c.markers.iter().map(|m| format!("--marker {m}")));
    parts.join(" ")
}

/// Loads and validates a robot: a built-in name, or a `.toml` description or
/// `.urdf` file ([`RobotRef::load`]), with its chain.
pub fn load_robot(r: &RobotRef) -> Result<Robot> {
    load_description(r).map(|d| d.robot)
}

/// Refuses a robot without a driven joint (a description whose frames are
/// all fixed, a chain whose joints are all locked): nothing to move.
fn has_joints(name: &str, r: &Robot) -> Result<()> {
    if r.dof() == 0 {
        anyhow::bail!(
            "{name}: this robot has no joints (every frame of its chain is fixed); a robot needs at least one revolute or prismatic joint"
        );
    }
    Ok(())
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
        .map(|&(label, path)| activecal::io::atomic::Output { label, path })
        .collect();
    activecal::io::atomic::check_outputs(&outs, inputs, force).map_err(|e| match e {
        activecal::Error::OutputExists { label, path } => {
            anyhow::anyhow!("{label} {path}: exists; pass --force to overwrite it")
        }
        e => e.into(),
    })
}

/// Writes `text` to `path` (see [`refuse_overwrite`]), naming the file in
/// any error.
pub fn write_new(path: &std::path::Path, text: &str, force: bool) -> Result<()> {
    refuse_overwrite(path, force)?;
    activecal::io::atomic::write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// An `--out` file, as the library's writers name it in messages.
pub fn out_file(path: &std::path::Path) -> activecal::io::atomic::Output<'_> {
    activecal::io::atomic::Output {
        label: "--out",
        path,
    }
}

/// Prints `value` as one JSON line (the library's words), or the
/// human-readable `text` with the library's phrases for settings spelled as
/// this command line's flags ([`hints::spell`]); a stdout
/// that cannot be written (a closed pipe) is an error naming stdout.
pub fn emit(json_out: bool, value: &Value, text: impl FnOnce() -> String) -> Result<()> {
    // JSON carries the library's own words; text is spelled with this
    // command line's flags ([`hints::spell`]).
    let s = if json_out {
        format!("{value}\n")
    } else {
        hints::spell(&text())
    };
    print_out(&s)
}

/// Writes `text` to stdout and flushes it: a write error (a closed pipe,
/// `activecal ... | head`) ends the command with a plain error, never a
/// panic.
pub fn print_out(text: &str) -> Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| anyhow::anyhow!("cannot write the output to stdout: {e}"))
}

/// Writes one diagnostic line to stderr; a closed stderr is ignored (a
/// diagnostic is never worth a panic or a failed command).
pub fn diag(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{}", hints::spell(line));
}

/// Prints a typed report as one JSON line, or the human-readable `text`.
pub fn emit_report<T: serde::Serialize>(
    json_out: bool,
    report: &T,
    text: impl FnOnce() -> String,
) -> Result<()> {
    let v = serde_json::to_value(report)?;
    emit(json_out, &v, text)
}

/// Loads a robot with its description's visibility region (validated).
pub fn load_description(r: &RobotRef) -> Result<activecal::io::Description> {
    let d = r.load()?;
    d.robot.validate()?;
    has_joints(&r.to_string(), &d.robot)?;
    Ok(d)
}
