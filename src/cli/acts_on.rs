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
            why: self
                .why
                .iter()
                .find(|(id, _)| *id == r.id)
                .map_or("", |(_, w)| w),
        })
    }
}

const LS: &str = "the camera fit is least squares on the pixels";

/// What to say when an option of `calibrate` is given with a sensor it does
/// not act on (the sensors are the library's table,
/// [`lib::CALIBRATE`]); an option not listed names the sensors it is for.
const CALIBRATE_WHY: &[(&str, &str)] = &[
    (
        "offset_unit",
        "the camera and contact fits write no joint offsets",
    ),
    (
        "offset_sign",
        "the camera and contact fits write no joint offsets",
    ),
    (
        "markers",
        "a camera sees the points of its --target, not markers; a bag's --points topic is one point",
    ),
    (
        "noise",
        "a contact fit's σ is estimated from its residuals; a camera's is --pixel-noise",
    ),
    (
        "orientation_noise",
        "it is a tracker's orientation σ; only full poses carry orientations",
    ),
    (
        "pixel_noise",
        "it is a camera's σ in pixels; a tracker's is --noise",
    ),
    ("seed", "the fit has no randomness"),
    ("loss", LS),
    ("loss_scale", LS),
    (
        "free",
        "the camera fit estimates every joint origin of the chain",
    ),
    (
        "holdout",
        "contacts are held out by placement (--holdout-by, --train-on); a camera fit has no held-out validation",
    ),
    ("splits", "--holdout's splits"),
    ("compare_pruned", "--holdout's comparison"),
    (
        "weights",
        "there are no orientations to weigh against positions",
    ),
    (
        "orientation_scale",
        "there are no orientations to weigh against positions",
    ),
    ("inertia", "it is for --compliance"),
    ("payload", "it is for --compliance"),
    (
        "report",
        "a camera fit's report is its text or --json (with --images DIR, --report writes the contact sheet; not yet with a bag's images)",
    ),
    (
        "joints",
        "--observations carry their joint values; --joints gives the images' (a file) or a bag's joint topic",
    ),
    (
        "save_observations",
        "it writes the pixels detected in --images",
    ),
    (
        "angle_unit",
        "no file of joint values is read (a bag's are in radians)",
    ),
    (
        "length_unit",
        "no file of joint values is read (a bag's are in metres)",
    ),
    (
        "max_offset",
        "a camera's clock offset is not estimated from a bag: give --time-offset (0 when not given)",
    ),
    (
        "bag_design",
        "it matches a bag's rests to the design the run followed",
    ),
    (
        "design_tolerance",
        "it matches a bag's rests to the design the run followed",
    ),
];

/// The options of `calibrate` (and the global ones): the sensors each acts on
/// and what to say otherwise.
pub const CALIBRATE: &Table = &Table {
    rows: lib::CALIBRATE,
    why: CALIBRATE_WHY,
};

const EAE: &str = "a camera design is chosen by exchange-add-exchange (EAE) on the determinant, a socket design D-optimally then exchanged for the predicted true error";
const SOCKET: &str = "the pool is configurations projected onto each socket from --count joint-space samples, chosen D-optimally then exchanged for the predicted true error";

/// What to say when an option of `select` is given with a sensor it does
/// not act on (the sensors are the library's table,
/// [`lib::SELECT`]); an option not listed names the sensors it is for.
const SELECT_WHY: &[(&str, &str)] = &[
    (
        "markers",
        "a camera sees the points of its --target, not markers",
    ),
    ("pool", SOCKET),
    ("levels", "there is no lattice"),
    (
        "params",
        "the camera's Jacobian is at the nominal parameters",
    ),
    (
        "visibility",
        "the camera's view is --min-visible, --image-margin, --max-view-angle and --distance",
    ),
    ("angle_unit", "no file of joint values is read"),
    ("length_unit", "no file of joint values is read"),
    ("margin", "the samples are drawn within the joint limits"),
    ("algorithm", EAE),
    ("initial", EAE),
    ("starts", EAE),
    ("ils", EAE),
    ("kick", EAE),
    ("designs", EAE),
    ("polish", EAE),
    ("criterion", EAE),
    ("gap", SOCKET),
    ("gap_solver", SOCKET),
    ("report", SOCKET),
    ("target_error", SOCKET),
    (
        "noise",
        "it is a point's noise in metres; a camera's is --pixel-noise PX (the detected points' σ in pixels), a socket design predicts its errors per unit noise",
    ),
];

/// The options of `select` (and the global ones): the sensors each acts on
/// and what to say otherwise.
pub const SELECT: &Table = &Table {
    rows: lib::SELECT,
    why: SELECT_WHY,
};

/// What to say when an option of `evaluate` is given with a sensor it does
/// not act on (the sensors are the library's table,
/// [`lib::EVALUATE`]); an option not listed names the sensors it is for.
const EVALUATE_WHY: &[(&str, &str)] = &[];

/// The options of `evaluate` (and the global ones): the sensors each acts on
/// and what to say otherwise.
pub const EVALUATE: &Table = &Table {
    rows: lib::EVALUATE,
    why: EVALUATE_WHY,
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
        bail!("{}", refused.join("\n"))
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
