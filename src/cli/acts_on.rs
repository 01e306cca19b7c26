//! Which sensors each option of `calibrate`, `select` and `evaluate` acts
//! on: one table per command ([`CALIBRATE`], [`SELECT`], [`EVALUATE`]),
//! checked against the
//! options typed on the command line before any work. An option typed with
//! a sensor it does not act on is refused, naming the option and the
//! sensor: no option is accepted and ignored.

use anyhow::{Result, bail};
use clap::ArgMatches;
use clap::parser::ValueSource;

/// What a command works for: the sensor of its data or of its design.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sensor {
    /// `calibrate --design`: measurements simulated at a design.
    Simulated,
    /// `calibrate --measurements` of points (no orientation columns).
    Points,
    /// `calibrate --measurements` of full poses (orientation columns).
    Poses,
    /// `calibrate --measurements` of contacts (a `point` or `plane` column).
    Contacts,
    /// `calibrate --observations`: a camera's pixels.
    Pixels,
    /// `select` from a pool of poses (points, markers or full poses).
    Pool,
    /// `select --point`: configurations touching sockets.
    Sockets,
    /// `select --camera-info`: poses for a camera.
    Camera,
}

impl Sensor {
    /// The sensor in a few words, for the list of those an option acts on.
    #[must_use]
    pub fn short(self) -> &'static str {
        match self {
            Sensor::Simulated => "--design",
            Sensor::Points => "point measurements",
            Sensor::Poses => "full-pose measurements",
            Sensor::Contacts => "contacts",
            Sensor::Pixels => "--observations",
            Sensor::Pool => "a pose pool",
            Sensor::Sockets => "--point",
            Sensor::Camera => "--camera-info",
        }
    }

    /// The sensor as the command line gives it, for messages.
    #[must_use]
    pub fn given_as(self) -> &'static str {
        match self {
            Sensor::Simulated => "--design (measurements simulated at a design)",
            Sensor::Points => "--measurements of points (a file without orientations)",
            Sensor::Poses => "--measurements of full poses (a file with orientations)",
            Sensor::Contacts => "--measurements of contacts (a 'point' or 'plane' column)",
            Sensor::Pixels => "--observations (a camera's pixels)",
            Sensor::Pool => "a pool of poses (select without --point or --camera-info)",
            Sensor::Sockets => "--point (configurations touching sockets)",
            Sensor::Camera => "--camera-info (poses chosen for a camera)",
        }
    }
}

/// One option's row: its clap id, the sensors it acts on, and what to say
/// when it is given with another (empty: the sensors it is for are named).
pub struct Rule {
    /// The option's clap id (its field's name).
    pub id: &'static str,
    /// The sensors the option acts on.
    pub acts_on: &'static [Sensor],
    /// Why it acts on no other sensor, or what to use instead.
    pub why: &'static str,
}

use Sensor::{Camera, Contacts, Pixels, Points, Pool, Poses, Simulated, Sockets};

const fn r(id: &'static str, acts_on: &'static [Sensor], why: &'static str) -> Rule {
    Rule { id, acts_on, why }
}

const CAL_ALL: &[Sensor] = &[Simulated, Points, Poses, Contacts, Pixels];
/// Measured points or full poses: told apart once the file is read.
pub const MEASURED: &[Sensor] = &[Points, Poses];
const FITTED: &[Sensor] = &[Points, Poses, Contacts];
const READ: &[Sensor] = &[Points, Poses, Contacts, Pixels];
const LS: &str = "the camera fit is least squares on the pixels";

/// The options of `calibrate` (and the global ones) and the sensors each
/// acts on.
pub const CALIBRATE: &[Rule] = &[
    r("base", CAL_ALL, ""),
    r("tip", CAL_ALL, ""),
    r("lock", CAL_ALL, ""),
    r("frames", CAL_ALL, ""),
    r(
        "markers",
        &[Simulated, Points, Poses, Contacts],
        "a camera sees the points of its --target, not markers",
    ),
    r("progress", CAL_ALL, ""),
    r("robot", CAL_ALL, ""),
    r("design", &[Simulated], ""),
    r("measurements", FITTED, ""),
    r("save_measurements", &[Simulated], ""),
    r("out", CAL_ALL, ""),
    r("force", CAL_ALL, ""),
    r(
        "noise",
        &[Simulated, Points, Poses],
        "a contact fit's σ is estimated from its residuals; a camera's is --pixel-noise",
    ),
    r("outliers", READ, ""),
    r("outlier_rate", READ, ""),
    r(
        "orientation_noise",
        &[Poses],
        "it is a tracker's orientation σ; only full poses carry orientations",
    ),
    r(
        "pixel_noise",
        &[Pixels],
        "it is a camera's σ in pixels; a tracker's is --noise",
    ),
    r(
        "seed",
        &[Simulated, Points, Poses],
        "the fit has no randomness",
    ),
    r("trials", &[Simulated], ""),
    r("validation", &[Simulated], ""),
    r("max_iterations", CAL_ALL, ""),
    r("no_geodesic", CAL_ALL, ""),
    r("loss", FITTED, LS),
    r("loss_scale", FITTED, LS),
    r("fix", MEASURED, ""),
    r(
        "free",
        FITTED,
        "the camera fit estimates every joint origin of the chain",
    ),
    r(
        "holdout",
        MEASURED,
        "contacts are held out by placement (--holdout-by, --train-on); a camera fit has no held-out validation",
    ),
    r("splits", MEASURED, "--holdout's splits"),
    r("compare_pruned", MEASURED, "--holdout's comparison"),
    r(
        "weights",
        &[Poses],
        "there are no orientations to weigh against positions",
    ),
    r(
        "orientation_scale",
        &[Poses],
        "there are no orientations to weigh against positions",
    ),
    r("point_distance", &[Contacts], ""),
    r("plane", &[Contacts], ""),
    r("holdout_by", &[Contacts], ""),
    r("train_on", &[Contacts], ""),
    r("compliance", MEASURED, ""),
    r("compare_compliance", MEASURED, ""),
    r("inertia", MEASURED, "it is for --compliance"),
    r("payload", MEASURED, "it is for --compliance"),
    r(
        "report",
        &[Simulated, Points, Poses, Contacts],
        "a camera fit's report is its text or --json",
    ),
    r("observations", &[Pixels], ""),
    r("camera_info", &[Pixels], ""),
    r("target", &[Pixels], ""),
    r("mounting", &[Pixels], ""),
    r("camera_link", &[Pixels], ""),
    r("camera_pose", &[Pixels], ""),
    r("target_pose", &[Pixels], ""),
    r("refine_intrinsics", &[Pixels], ""),
    r("out_camera_info", &[Pixels], ""),
    r("angle_unit", READ, "no file of joint values is read"),
    r("length_unit", READ, "no file of joint values is read"),
    r("json", CAL_ALL, ""),
];

const SEL_ALL: &[Sensor] = &[Pool, Sockets, Camera];
const EAE: &str = "a camera design is chosen by exchange-add-exchange (EAE) on the determinant, a socket design D-optimally then exchanged for the predicted true error";
const SOCKET: &str = "the pool is configurations projected onto each socket from --count joint-space samples, chosen D-optimally then exchanged for the predicted true error";

/// The options of `select` (and the global ones) and the sensors each acts
/// on.
pub const SELECT: &[Rule] = &[
    r("base", SEL_ALL, ""),
    r("tip", SEL_ALL, ""),
    r("lock", SEL_ALL, ""),
    r("frames", SEL_ALL, ""),
    r(
        "markers",
        &[Pool, Sockets],
        "a camera sees the points of its --target, not markers",
    ),
    r("progress", SEL_ALL, ""),
    r("robot", SEL_ALL, ""),
    r("pool", &[Pool, Camera], SOCKET),
    r("levels", &[Pool], "there is no lattice"),
    r("count", SEL_ALL, ""),
    r("pool_seed", SEL_ALL, ""),
    r(
        "params",
        &[Pool, Sockets],
        "the camera's Jacobian is at the nominal parameters",
    ),
    r(
        "visibility",
        &[Pool],
        "the camera's view is --min-visible, --image-margin, --max-view-angle and --distance",
    ),
    r("self_collision", SEL_ALL, ""),
    r("srdf", SEL_ALL, ""),
    r("skip_always_touching", SEL_ALL, ""),
    r("package_dirs", SEL_ALL, ""),
    r("obstacles", SEL_ALL, ""),
    r("floor", SEL_ALL, ""),
    r(
        "angle_unit",
        &[Pool, Camera],
        "no file of joint values is read",
    ),
    r(
        "length_unit",
        &[Pool, Camera],
        "no file of joint values is read",
    ),
    r("compliance", &[Pool], ""),
    r(
        "margin",
        &[Pool, Sockets],
        "the samples are drawn within the joint limits",
    ),
    r("clearance", SEL_ALL, ""),
    r("n", SEL_ALL, ""),
    r("algorithm", &[Pool], EAE),
    r("initial", &[Pool], EAE),
    r("starts", &[Pool], EAE),
    r("ils", &[Pool], EAE),
    r("kick", &[Pool], EAE),
    r("designs", &[Pool], EAE),
    r("polish", &[Pool], EAE),
    r("seed", SEL_ALL, ""),
    r("fixed", &[Pool], ""),
    r("criterion", &[Pool], EAE),
    r("out", SEL_ALL, ""),
    r("force", SEL_ALL, ""),
    r("gap", &[Pool, Camera], SOCKET),
    r("gap_solver", &[Pool, Camera], SOCKET),
    r("existing", &[Pool], ""),
    r("refine", &[Pool], ""),
    r("refine_sweeps", &[Pool], ""),
    r("order", &[Pool], ""),
    r("home", &[Pool], ""),
    r("report", &[Pool, Camera], SOCKET),
    r("target_error", &[Pool, Camera], SOCKET),
    r(
        "noise",
        &[Pool],
        "it is a point's noise in metres; a camera's is --pixel-noise PX (the detected points' σ in pixels), a socket design predicts its errors per unit noise",
    ),
    r("orientation_noise", &[Pool], ""),
    r("points", &[Sockets], ""),
    r("point_distance", &[Sockets], ""),
    r("camera_info", &[Camera], ""),
    r("target", &[Camera], ""),
    r("mounting", &[Camera], ""),
    r("camera_link", &[Camera], ""),
    r("camera_pose", &[Camera], ""),
    r("target_pose", &[Camera], ""),
    r("min_visible", &[Camera], ""),
    r("image_margin", &[Camera], ""),
    r("max_view_angle", &[Camera], ""),
    r("distance", &[Camera], ""),
    r("line_of_sight", &[Camera], ""),
    r("pixel_noise", &[Camera], ""),
    r("json", SEL_ALL, ""),
];

const EVAL_ALL: &[Sensor] = &[Points, Poses, Contacts];

/// The options of `evaluate` (and the global ones) and the sensors each
/// acts on.
pub const EVALUATE: &[Rule] = &[
    r("base", EVAL_ALL, ""),
    r("tip", EVAL_ALL, ""),
    r("lock", EVAL_ALL, ""),
    r("frames", EVAL_ALL, ""),
    r("markers", EVAL_ALL, ""),
    r("progress", EVAL_ALL, ""),
    r("robot", EVAL_ALL, ""),
    r("measurements", EVAL_ALL, ""),
    r("angle_unit", EVAL_ALL, ""),
    r("length_unit", EVAL_ALL, ""),
    r("point_distance", &[Contacts], ""),
    r("plane", &[Contacts], ""),
    r("json", EVAL_ALL, ""),
];

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
pub fn check(table: &[Rule], given: &Given, sensors: &[Sensor]) -> Result<()> {
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
