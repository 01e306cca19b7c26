//! Which sensors each option of `calibrate`, `select` and `evaluate` acts
//! on: the library's tables ([`activecal::experiment::acts_on`], which the
//! Python package checks its keyword arguments against too), with what to
//! say here, naming flags, when an option typed on the command line does
//! not act on the sensor given ([`CALIBRATE`], [`SELECT`], [`EVALUATE`]).
//! Checked before any work: an option typed with a sensor it does not act
//! on is refused, naming the option and the sensor: no option is accepted
//! and ignored.

use activecal::experiment::acts_on as lib;
pub use activecal::experiment::acts_on::{MEASURED, Sensor};
use anyhow::{Result, bail};
use clap::ArgMatches;
use clap::parser::ValueSource;

/// How the command line names a sensor.
pub trait SensorText {
    /// The sensor in a few words, for the list of those an option acts on.
    fn short(self) -> &'static str;
    /// The sensor as the command line gives it, for messages.
    fn given_as(self) -> &'static str;
}

impl SensorText for Sensor {
    fn short(self) -> &'static str {
        match self {
            Sensor::Simulated => "--design",
            Sensor::Points => "point measurements",
            Sensor::Poses => "full-pose measurements",
            Sensor::Contacts => "contacts",
            Sensor::Pixels => "--observations",
            Sensor::Images => "--images",
            Sensor::Pool => "a pose pool",
            Sensor::Sockets => "--point",
            Sensor::Camera => "--camera-info",
            Sensor::BagPoints => "--bag --points",
            Sensor::BagPoses => "--bag --poses or --tf",
            Sensor::BagImages => "--bag --images",
        }
    }

    fn given_as(self) -> &'static str {
        match self {
            Sensor::Simulated => "--design (measurements simulated at a design)",
            Sensor::Points => "--measurements of points (a file without orientations)",
            Sensor::Poses => "--measurements of full poses (a file with orientations)",
            Sensor::Contacts => "--measurements of contacts (a 'point' or 'plane' column)",
            Sensor::Pixels => "--observations (a camera's pixels)",
            Sensor::Images => "--images (a camera's images)",
            Sensor::Pool => "a pool of poses (select without --point or --camera-info)",
            Sensor::Sockets => "--point (configurations touching sockets)",
            Sensor::Camera => "--camera-info (poses chosen for a camera)",
            Sensor::BagPoints => "--bag --points (a tracker's points from a ROS 2 bag)",
            Sensor::BagPoses => "--bag --poses or --tf (full poses from a ROS 2 bag)",
            Sensor::BagImages => "--bag --images (a camera's images from a ROS 2 bag)",
        }
    }
}

/// A command's table: the library's sensors per option, and what to say
/// when one is given with another sensor.
pub struct Table {
    /// The options and the sensors each acts on.
    pub rows: &'static [lib::ActsOn],
    /// Why an option acts on no other sensor, or what to use instead
    /// (an option not listed: the sensors it is for are named).
    pub why: &'static [(&'static str, &'static str)],
}

/// One option's row: its id, the sensors it acts on, and what to say when
/// it is given with another (empty: the sensors it is for are named).
pub struct Rule {
    /// The option's clap id (its field's name).
    pub id: &'static str,
    /// The sensors the option acts on.
    pub acts_on: &'static [Sensor],
    /// Why it acts on no other sensor, or what to use instead.
    pub why: &'static str,
}

impl Table {
    /// Every option's row.
    pub fn iter(&self) -> impl Iterator<Item = Rule> + '_ {
        self.rows.iter().map(|r| Rule {
            id: r.id,
            acts_on: r.sensors,
            why: lib::why_not(self.why, r.id).unwrap_or(""),
        })
    }
}

/// The options of `calibrate` (and the global ones): the sensors each acts on
/// and what to say otherwise.
pub const CALIBRATE: &Table = &Table {
    rows: lib::CALIBRATE,
    why: lib::CALIBRATE_WHY,
};

/// The options of `select` (and the global ones): the sensors each acts on
/// and what to say otherwise.
pub const SELECT: &Table = &Table {
    rows: lib::SELECT,
    why: lib::SELECT_WHY,
};

/// The options of `evaluate` (and the global ones): the sensors each acts on
/// (every option of `evaluate` names the sensors it is for).
pub const EVALUATE: &Table = &Table {
    rows: lib::EVALUATE,
    why: &[],
};

/// The options typed on a command's line (not defaulted): each as its
/// clap id and its flag (`--loss`).
#[derive(Clone, Debug, Default)]
pub struct Given(pub Vec<(String, String)>);

impl Given {
    /// The options of `sub` (a subcommand's matches, global options
    /// included) typed on the command line; `cmd` is the subcommand's
    /// built definition, whose long names the flags are.
    #[must_use]
    pub fn of(cmd: &clap::Command, sub: &ArgMatches) -> Self {
        // Groups (a flattened struct's) are ids too, but no options.
        let flag = |id: &str| {
            let arg = cmd.get_arguments().find(|a| a.get_id() == id)?;
            Some(arg.get_long().unwrap_or(id).to_string())
        };
        Given(
            sub.ids()
                .filter(|id| sub.value_source(id.as_str()) == Some(ValueSource::CommandLine))
                .filter_map(|id| {
                    Some((id.as_str().to_string(), format!("--{}", flag(id.as_str())?)))
                })
                .collect(),
        )
    }
}

/// Refuses each option of `given` that acts on none of `sensors` (by
/// `table`), naming the option and the sensor: one line each. An option
/// without a row in `table` is refused too (every option must be decided).
pub fn check(table: &Table, given: &Given, sensors: &[Sensor]) -> Result<()> {
    let refused: Vec<String> = given
        .0
        .iter()
        .filter_map(|(id, flag)| {
            let Some(rule) = table.iter().find(|r| r.id == id) else {
                return Some(format!("{flag}: not decided for {}", given_as(sensors)));
            };
            if rule.acts_on.iter().any(|s| sensors.contains(s)) {
                return None;
            }
            let why = if rule.why.is_empty() {
                let sens: Vec<&str> = rule.acts_on.iter().map(|s| s.short()).collect();
                format!("it acts on {}", sens.join(" or "))
            } else {
                rule.why.to_string()
            };
            Some(format!(
                "{flag}: not used with {}; {why}",
                given_as(sensors)
            ))
        })
        .collect();
    if refused.is_empty() {
        Ok(())
    } else {
        bail!("{}", super::hints::spell(&refused.join("\n")))
    }
}

/// `sensors` as the command line gives them: `--measurements` of either
/// kind before the file is read.
fn given_as(sensors: &[Sensor]) -> &'static str {
    match sensors {
        [s] => s.given_as(),
        _ => "--measurements (points or full poses)",
    }
}

#[cfg(test)]
#[path = "acts_on_tests.rs"]
mod tests;
