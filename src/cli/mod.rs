//! Shared helpers of the command-line subcommands; one file per command group.

pub mod basic;

use activecal::robot::Robot;
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

/// Loads and validates a robot by name.
pub fn load_robot(name: &str) -> Result<Robot> {
    let r = Robot::builtin(name)?;
    r.validate()?;
    Ok(r)
}

/// Prints `value` as one JSON line, or the human-readable `text`.
pub fn emit(json_out: bool, value: &Value, text: impl FnOnce() -> String) {
    if json_out {
        println!("{value}");
    } else {
        print!("{}", text());
    }
}
