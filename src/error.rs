//! Errors for bad input. Numerical outcomes (a singular design, a solver that
//! stalls) are statuses in results, not errors; see docs/contributing.md.

use thiserror::Error;

pub use crate::settings::{SettingError, positive};

/// Everything that can be wrong with what a user gave the library.
#[derive(Debug, Error)]
pub enum Error {
    /// The named robot is not built in and is not a readable file.
    #[error("unknown robot '{name}' (built-in robots: {known})")]
    UnknownRobot {
        /// The name given.
        name: String,
        /// Comma-separated list of the built-in robots.
        known: String,
    },
    /// A joint vector with the wrong length.
    #[error("expected {expected} joint angles, got {got}")]
    JointCount {
        /// Degrees of freedom of the robot.
        expected: usize,
        /// Length of the vector given.
        got: usize,
    },
    /// A NaN or infinite joint angle.
    #[error("joint angle q{joint} is not a finite number ({})", Compact(*.value))]
    NonFiniteAngle {
        /// 1-based joint number.
        joint: usize,
        /// The value given.
        value: f64,
    },
    /// Joint limits with lower > upper, or not finite.
    #[error(
        "joint q{joint}: invalid limits [{}, {}] (need finite lo <= hi)",
        Compact(*.lo),
        Compact(*.hi)
    )]
    InvalidLimits {
        /// 1-based joint number.
        joint: usize,
        /// Lower limit given.
        lo: f64,
        /// Upper limit given.
        hi: f64,
    },
    /// A lattice with fewer than 2 levels per joint.
    #[error("a pose lattice needs at least 2 levels per joint, got {0}")]
    TooFewLevels(usize),
    /// A pose lattice too large to index.
    #[error("a lattice of {levels}^{dof} poses is too large")]
    LatticeTooLarge {
        /// Levels per joint.
        levels: usize,
        /// Number of joints.
        dof: usize,
    },
    /// Lattice digits of the wrong length or out of range.
    #[error("invalid lattice digits {digits:?}: need {dof} digits, each in 0..{levels}")]
    InvalidDigits {
        /// Digits given.
        digits: Vec<usize>,
        /// Number of joints.
        dof: usize,
        /// Levels per joint.
        levels: usize,
    },
    /// A lattice index outside the lattice, or a pose not in the (filtered) pool.
    #[error("pose {index} is not in the pool ({reason})")]
    PoseNotInPool {
        /// The lattice index given.
        index: usize,
        /// Why: outside the lattice, or removed by the visibility filter.
        reason: String,
    },
    /// A parameter name that the robot does not have.
    #[error("unknown parameter '{0}'")]
    UnknownParameter(String),
    /// A parameter table entry that is not finite.
    #[error("parameter {name} is not finite ({})", Compact(*.value))]
    NonFiniteParameter {
        /// Parameter name, `<symbol>_<frame>`.
        name: String,
        /// The value.
        value: f64,
    },
    /// Unknowns that the measurements cannot determine.
    #[error("unidentifiable unknowns: {names:?} (numerical rank {rank} of {p})")]
    Unidentifiable {
        /// Names of the unknowns that are in the null space.
        names: Vec<String>,
        /// Numerical rank of the stacked Jacobian.
        rank: usize,
        /// Number of unknowns.
        p: usize,
    },
    /// An output file that exists, with overwriting not asked for: nothing
    /// the user has is lost without asking.
    #[error("{label} {path}: exists, and overwriting it was not asked for")]
    OutputExists {
        /// What the output is (its label, see [`crate::io::atomic::Output`]).
        label: String,
        /// The path given.
        path: String,
    },
    /// A setting given a value it cannot take.
    #[error(transparent)]
    Setting(#[from] SettingError),
    /// An output directory (replaced whole, as a report folder is) that
    /// exists and holds files, with replacing it not asked for.
    #[error("{label} {path}: exists and is not empty, and replacing it was not asked for")]
    OutputDirNotEmpty {
        /// What the directory is (its label, see [`crate::io::atomic::Output`]).
        label: String,
        /// The path given.
        path: String,
    },
    /// A structure whose estimated memory exceeds the budget
    /// ([`crate::resources::MemoryBudget`]), refused before allocating it.
    #[error(
        "{what} would need {needed} of memory, above the limit of {limit} ({source_of_limit})\n  use a smaller pool (fewer lattice levels or poses) or raise the limit"
    )]
    TooLarge {
        /// What was to be allocated.
        what: String,
        /// Its estimated size.
        needed: String,
        /// The budget.
        limit: String,
        /// Where the budget comes from.
        source_of_limit: String,
    },
    /// An allocation the system refused although the budget allowed it (a
    /// limit the budget cannot see, or memory taken by other processes).
    #[error(
        "{what}: allocating {needed} failed (the system refused the memory); use a smaller pool or free memory"
    )]
    OutOfMemory {
        /// What was to be allocated.
        what: String,
        /// Its size.
        needed: String,
    },
    /// A joint value outside its joint's limits by more than
    /// [`crate::units::limit_tolerance`] (see [`crate::units`]).
    #[error(
        "{file}: {row}, column '{column}'{}: {} {unit} is outside the joint's limits [{}, {}] {unit} (by more than the tolerance {:.1e} {unit}){}",
        if column == joint { String::new() } else { format!(" (joint '{joint}')") },
        Compact(*.value),
        Compact(*.lo),
        Compact(*.hi),
        tolerance,
        hint.map_or(String::new(), |h| format!("; {}", h.column_text()))
    )]
    JointOutOfLimits {
        /// The file (or option) that gave the value.
        file: String,
        /// The row, in the file's terms (`line 5`, `qs[3]`).
        row: String,
        /// The column's name.
        column: String,
        /// The joint's name.
        joint: String,
        /// The value, in the unit the file was read in.
        value: f64,
        /// That unit's symbol.
        unit: &'static str,
        /// Lower limit, in that unit.
        lo: f64,
        /// Upper limit, in that unit.
        hi: f64,
        /// The accepted slack, in that unit.
        tolerance: f64,
        /// The unit the whole column would fit in, if another.
        hint: Option<UnitHint>,
    },
    /// Measured positions that move far less than the robot does at their
    /// poses (`check_positions_in_reach` in [`crate::units`]).
    #[error(
        "{file}: the measured positions move {:.3} mm RMS about their mean, the nominal model's {:.1} mm at the same poses (read in {unit}){}",
        *.spread * 1e3,
        *.nominal * 1e3,
        hint.map_or(String::new(), |h| format!("; {}", h.spread_text(unit)))
    )]
    PositionsTooSmall {
        /// The measurement file.
        file: String,
        /// The measured positions' RMS about their mean, metres (after
        /// reading in `unit`).
        spread: f64,
        /// The nominal model's points' RMS about their mean, metres.
        nominal: f64,
        /// The length unit the positions were read in.
        unit: &'static str,
        /// The unit they would pass in, if another.
        hint: Option<UnitHint>,
    },
    /// Measured positions whose nominal residuals are far beyond the robot's
    /// reach ([`crate::units::check_positions_in_reach`]).
    #[error(
        "{file}: the measured positions are {} m (RMS) from where the nominal model puts them, more than {factor} times the robot's reach of {} m (positions read in {unit}){}",
        Compact(*.rms),
        Compact(*.reach),
        hint.map_or(String::new(), |h| format!("; {}", h.position_text(unit)))
    )]
    PositionsBeyondReach {
        /// The measurement file.
        file: String,
        /// The nominal RMS residual, metres (after reading in `unit`).
        rms: f64,
        /// The robot's reach, metres ([`crate::units::reach`]).
        reach: f64,
        /// The factor of the reach allowed.
        factor: f64,
        /// The length unit the positions were read in.
        unit: &'static str,
        /// The unit they would pass in, if another.
        hint: Option<UnitHint>,
    },
    /// Any other invalid argument, with a message saying what and why.
    #[error("{0}")]
    Invalid(String),

    /// Drawing a figure failed (plotters, the PNG encoder or the embedded
    /// fonts).
    #[error("drawing a figure: {0}")]
    Draw(String),

    /// File input/output.
    // Not a `#[source]`: the message already includes it, and the CLI prints
    // error chains, which would repeat it.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: String,
        /// The underlying error.
        cause: std::io::Error,
    },
    /// A malformed JSON or TOML file.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: String,
        /// What is wrong, with its place.
        message: String,
    },
}

/// The unit a file's values look like when they fail in the unit they were
/// read in (see [`crate::units`]); the command line names the option.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnitHint {
    /// Angles in degrees, read as radians.
    Degrees,
    /// Angles in radians, read as degrees.
    Radians,
    /// Lengths in millimetres, read as metres.
    Millimetres,
    /// Lengths in metres, read as millimetres.
    Metres,
}

impl UnitHint {
    /// What a joint column that fits in this unit looks like.
    #[must_use]
    pub fn column_text(self) -> &'static str {
        match self {
            UnitHint::Degrees => {
                "every value of this column fits the limits after a degree→radian conversion: it looks like degrees"
            }
            UnitHint::Radians => {
                "every value of this column fits the limits as radians: it looks like radians, not degrees"
            }
            UnitHint::Millimetres => {
                "every value of this column fits the limits after a millimetre→metre conversion: it looks like millimetres"
            }
            UnitHint::Metres => {
                "every value of this column fits the limits as metres: it looks like metres, not millimetres"
            }
        }
    }

    /// What positions that spread as the robot moves in this unit look
    /// like.
    #[must_use]
    pub fn spread_text(self, read_as: &str) -> String {
        match self {
            UnitHint::Millimetres | UnitHint::Degrees => {
                format!("they look like millimetres (read as {read_as})")
            }
            UnitHint::Metres | UnitHint::Radians => {
                format!("they look like metres (read as {read_as})")
            }
        }
    }

    /// What positions that pass in this unit look like.
    #[must_use]
    pub fn position_text(self, read_as: &str) -> String {
        match self {
            UnitHint::Millimetres | UnitHint::Degrees => format!(
                "read as millimetres they are within reach: the positions look like millimetres (read as {read_as})"
            ),
            UnitHint::Metres | UnitHint::Radians => format!(
                "read as metres they are within reach: the positions look like metres (read as {read_as})"
            ),
        }
    }
}

/// Result with the crate's [`Error`](enum@Error).
pub type Result<T> = std::result::Result<T, Error>;

/// A number for messages: as Rust prints it when that is short (`0.5`,
/// `-250`, `1000000`), in scientific notation when it would be long
/// (`1e300`, not 301 digits; `1.5e-12`).
///
/// ```
/// use activecal::error::Compact;
/// assert_eq!(Compact(1e300).to_string(), "1e300");
/// assert_eq!(Compact(-0.25).to_string(), "-0.25");
/// assert_eq!(Compact(f64::NAN).to_string(), "NaN");
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compact(pub f64);

impl std::fmt::Display for Compact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        if v.is_finite() && v != 0.0 && !(1e-6..1e9).contains(&v.abs()) {
            write!(f, "{v:e}")
        } else {
            write!(f, "{v}")
        }
    }
}
