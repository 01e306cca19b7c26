//! The units a file gives joint values and positions in, and the one rule
//! every reader of joint values applies (measurement files, pool and
//! `--existing` files, design files, a joint vector typed by hand).
//!
//! Inside the library every angle is in radians and every length in
//! metres. A reader takes a typed [`Units`] (what the file holds), converts
//! with [`joint_values_to_model_units`] and gets every value checked
//! against its joint's limits there, once, with one tolerance
//! ([`limit_tolerance`]). A value beyond it is an
//! [`Error::JointOutOfLimits`] naming the file, the row, the column, the
//! joint, the value and the limits — and, when the whole column would fit
//! after a degree→radian (or millimetre→metre) conversion, saying that it
//! looks like degrees (millimetres): a [`UnitHint`] the command line turns
//! into the option to give.

use crate::error::{Error, Result, UnitHint};
use crate::model::Robot;
use serde::{Deserialize, Serialize};

/// The unit of a file's revolute joint values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AngleUnit {
    /// Radians (the library's unit).
    #[default]
    Rad,
    /// Degrees.
    Deg,
}

/// The unit of a file's lengths: measured positions and prismatic joint
/// values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    /// Metres (the library's unit).
    #[default]
    M,
    /// Millimetres.
    Mm,
}

crate::choice!(AngleUnit { Rad => "rad", Deg => "deg" });
crate::choice!(LengthUnit { M => "m", Mm => "mm" });

impl AngleUnit {
    /// Radians per unit.
    #[must_use]
    pub fn to_rad(self) -> f64 {
        match self {
            AngleUnit::Rad => 1.0,
            AngleUnit::Deg => std::f64::consts::PI / 180.0,
        }
    }

    /// The symbol, for messages: `rad` or `deg`.
    #[must_use]
    pub fn symbol(self) -> &'static str {
        match self {
            AngleUnit::Rad => "rad",
            AngleUnit::Deg => "deg",
        }
    }
}

impl LengthUnit {
    /// Metres per unit.
    #[must_use]
    pub fn to_m(self) -> f64 {
        match self {
            LengthUnit::M => 1.0,
            LengthUnit::Mm => 1e-3,
        }
    }

    /// The symbol, for messages: `m` or `mm`.
    #[must_use]
    pub fn symbol(self) -> &'static str {
        match self {
            LengthUnit::M => "m",
            LengthUnit::Mm => "mm",
        }
    }
}

/// The units of a file: revolute joint values in `angle`, measured
/// positions and prismatic joint values in `length`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Units {
    /// Unit of revolute joint values.
    pub angle: AngleUnit,
    /// Unit of positions and prismatic joint values.
    pub length: LengthUnit,
}

/// Absolute slack on a joint limit, radians or metres: a value printed with
/// six decimals (`%.6f`, a common export) is within 5e-7 of what was meant,
/// and a limit of 2π written as `6.283185` in a URDF is 3.1e-7 below the
/// 2π a controller reports; 1e-6 lets both pass (it matters for joints of
/// zero or tiny range).
pub const LIMIT_ABS_TOL: f64 = 1e-6;

/// Slack on a joint limit relative to the joint's range `hi − lo`. Joint
/// values that are right can lie past a model's limits: real readings
/// overshoot a URDF's limits (FIGAROH's TIAGo torso reads 0.35018 m against
/// an upper limit of 0.35 m, 0.05 % of its range), and the built-in arms'
/// limits are working ranges chosen for pose pools, narrower than the
/// hardware's (the UR5's q2 ∈ [−180°, 0] against the datasheet's ±360°;
/// `tests/real_data.rs` round-trips measurements with q2 = 0.5 rad, 16 %
/// of the range past its limit). A unit error misses by a factor instead:
/// degrees read as radians are 57.3 times too large, millimetres read as
/// metres 1000 times, which puts a column past its limits by far more than
/// a fifth of the range unless every angle in it is within a few degrees of
/// zero (FIGAROH's UR10 in degrees: 143 against ±6.28, 11 ranges past).
pub const LIMIT_REL_TOL: f64 = 0.2;

/// How far past a joint's limits `[lo, hi]` a value may lie and still be
/// accepted: [`LIMIT_ABS_TOL`] + [`LIMIT_REL_TOL`] · (hi − lo).
#[must_use]
pub fn limit_tolerance(lo: f64, hi: f64) -> f64 {
    LIMIT_ABS_TOL + LIMIT_REL_TOL * (hi - lo).abs()
}

/// Where joint values come from, for messages.
#[derive(Clone, Copy, Debug)]
pub struct JointSource<'a> {
    /// The file (or the option) that gave them.
    pub file: &'a str,
    /// A label for each row, in the file's terms (`line 5`, `qs[3]`).
    pub rows: &'a [String],
    /// The column of each joint, in joint order (the header's name).
    pub columns: &'a [String],
}

/// The names a file may use for each joint, in joint order: the label of
/// the frame the joint drives (a URDF's joint name).
#[must_use]
pub fn joint_names(robot: &Robot) -> Vec<String> {
    let mut names = vec![String::new(); robot.dof()];
    for f in &robot.frames {
        if let Some(j) = f.joint
            && j < names.len()
        {
            names[j].clone_from(&f.label);
        }
    }
    names
}

/// Whether each joint (in configuration order) is prismatic.
#[must_use]
pub fn prismatic_joints(robot: &Robot) -> Vec<bool> {
    let mut p = vec![false; robot.dof()];
    for f in &robot.frames {
        if let Some(j) = f.joint
            && j < p.len()
        {
            p[j] = f.is_prismatic();
        }
    }
    p
}

/// Converts joint values given in `units` to radians and metres, in place,
/// and checks every value against its joint's limits (see the module
/// documentation): the one rule of every reader of joint values. `qs` has
/// one row per `source.rows` label and `robot.dof()` values a row.
pub fn joint_values_to_model_units(
    robot: &Robot,
    units: Units,
    source: &JointSource<'_>,
    qs: &mut [Vec<f64>],
) -> Result<()> {
    let prismatic = prismatic_joints(robot);
    let names = joint_names(robot);
    let factor = |j: usize| {
        if prismatic[j] {
            units.length.to_m()
        } else {
            units.angle.to_rad()
        }
    };
    for (k, q) in qs.iter_mut().enumerate() {
        if q.len() != robot.dof() {
            return Err(Error::Parse {
                path: source.file.to_string(),
                message: format!(
                    "{}: {} joint values, the robot has {} ({})",
                    row_label(source, k),
                    q.len(),
                    robot.dof(),
                    names.join(", ")
                ),
            });
        }
        for (j, v) in q.iter_mut().enumerate() {
            if !v.is_finite() {
                return Err(Error::Parse {
                    path: source.file.to_string(),
                    message: format!(
                        "{}, column '{}' (joint {} '{}'): {v} is not a finite number",
                        row_label(source, k),
                        column_label(source, &names, j),
                        j + 1,
                        names[j]
                    ),
                });
            }
            *v *= factor(j);
        }
    }
    for j in 0..robot.dof() {
        check_column(robot, units, source, qs, j, prismatic[j], &names)?;
    }
    Ok(())
}

fn row_label(source: &JointSource<'_>, k: usize) -> String {
    source
        .rows
        .get(k)
        .cloned()
        .unwrap_or_else(|| format!("row {}", k + 1))
}

fn column_label(source: &JointSource<'_>, names: &[String], j: usize) -> String {
    source
        .columns
        .get(j)
        .cloned()
        .unwrap_or_else(|| names[j].clone())
}

/// Checks joint `j`'s column (model units) against its limits.
fn check_column(
    robot: &Robot,
    units: Units,
    source: &JointSource<'_>,
    qs: &[Vec<f64>],
    j: usize,
    prismatic: bool,
    names: &[String],
) -> Result<()> {
    let [lo, hi] = robot.limits[j];
    let tol = limit_tolerance(lo, hi);
    let inside = |v: f64| v >= lo - tol && v <= hi + tol;
    let Some(k) = qs.iter().position(|q| !inside(q[j])) else {
        return Ok(());
    };
    // The values as the file gave them, and what each other unit would make
    // of them (in model units).
    let (given, unit) = if prismatic {
        (units.length.to_m(), units.length.symbol())
    } else {
        (units.angle.to_rad(), units.angle.symbol())
    };
    // Another unit is named only when at least half the column fails in
    // this one: one value typed wrong among radians is not a column of
    // degrees, though all of them, as degrees, would fit.
    let failing = qs.iter().filter(|q| !inside(q[j])).count();
    let fits_as =
        |factor: f64| failing * 2 >= qs.len() && qs.iter().all(|q| inside(q[j] / given * factor));
    let hint = match (prismatic, units.angle, units.length) {
        (false, AngleUnit::Rad, _) if fits_as(AngleUnit::Deg.to_rad()) => Some(UnitHint::Degrees),
        (false, AngleUnit::Deg, _) if fits_as(1.0) => Some(UnitHint::Radians),
        (true, _, LengthUnit::M) if fits_as(LengthUnit::Mm.to_m()) => Some(UnitHint::Millimetres),
        (true, _, LengthUnit::Mm) if fits_as(1.0) => Some(UnitHint::Metres),
        _ => None,
    };
    Err(Error::JointOutOfLimits {
        file: source.file.to_string(),
        row: row_label(source, k),
        column: column_label(source, names, j),
        joint: names[j].clone(),
        value: qs[k][j] / given,
        unit,
        lo: lo / given,
        hi: hi / given,
        tolerance: tol / given,
        hint,
    })
}

/// An upper bound on the distance from the measurement frame's origin to
/// any measured point: the sum of every frame's |a| and |d|, the largest
/// travel of each prismatic joint, and the largest marker offset (metres).
#[must_use]
pub fn reach(robot: &Robot) -> f64 {
    let table = &robot.nominal;
    let links: f64 = table.rows.iter().map(|r| r[2].abs() + r[3].abs()).sum();
    let travel: f64 = prismatic_joints(robot)
        .iter()
        .zip(&robot.limits)
        .filter(|(p, _)| **p)
        .map(|(_, l)| l[0].abs().max(l[1].abs()))
        .sum();
    let marker = table
        .markers
        .iter()
        .map(|o| (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt())
        .fold(0.0, f64::max);
    links + travel + marker
}

/// How many times the robot's [`reach`] the nominal model's position RMS
/// residual may be before the positions are refused as being in another
/// unit or frame: a sensor frame placed anywhere near the robot leaves
/// residuals of the order of the reach (FIGAROH's TIAGo: 0.2–1 m against a
/// reach of about 2 m); millimetres read as metres leave a thousand times
/// the reach.
pub const REACH_FACTOR: f64 = 10.0;

/// Checks that measured positions (model units) are within reach of the
/// robot: the RMS of `‖y − p_nominal(q)‖` over every measured point must
/// stay below [`REACH_FACTOR`] × [`reach`]. `predicted` gives the nominal
/// model's position for each point's pose. Otherwise an
/// [`Error::PositionsBeyondReach`], with a [`UnitHint`] when the positions
/// would pass in the other length unit.
pub fn check_positions_in_reach(
    robot: &Robot,
    file: &str,
    length: LengthUnit,
    points: &[[f64; 3]],
    predicted: &[[f64; 3]],
) -> Result<()> {
    let rms_scaled = |s: f64| -> f64 {
        let n = points.len().max(1) as f64;
        let sum: f64 = points
            .iter()
            .zip(predicted)
            .map(|(y, p)| (0..3).map(|c| (y[c] * s - p[c]).powi(2)).sum::<f64>())
            .sum();
        (sum / n).sqrt()
    };
    let reach = reach(robot);
    let limit = REACH_FACTOR * reach;
    let rms = rms_scaled(1.0);
    if rms.is_nan() || rms <= limit {
        return check_positions_spread(file, length, points, predicted);
    }
    let hint = match length {
        LengthUnit::M if rms_scaled(1e-3) <= limit => Some(UnitHint::Millimetres),
        LengthUnit::Mm if rms_scaled(1e3) <= limit => Some(UnitHint::Metres),
        _ => None,
    };
    Err(Error::PositionsBeyondReach {
        file: file.to_string(),
        rms,
        reach,
        factor: REACH_FACTOR,
        unit: length.symbol(),
        hint,
    })
}

/// The RMS distance of `points` from their mean (metres).
fn spread(points: &[[f64; 3]]) -> f64 {
    let n = points.len().max(1) as f64;
    let mean: [f64; 3] = std::array::from_fn(|c| points.iter().map(|p| p[c]).sum::<f64>() / n);
    let sum: f64 = points
        .iter()
        .map(|p| (0..3).map(|c| (p[c] - mean[c]).powi(2)).sum::<f64>())
        .sum();
    (sum / n).sqrt()
}

/// How many times less than the nominal model's points the measured ones
/// may spread before positions read in millimetres are refused as metres:
/// a sensor sees the tool move about as far as the model's end frame does
/// (a tool changes that by its length, not a hundredfold), while metres
/// read as millimetres move a thousand times less.
pub const SPREAD_FACTOR: f64 = 100.0;

/// Checks that positions read in millimetres move as the robot does: their
/// spread (RMS about their mean, a measure no choice of sensor frame
/// changes) must not be [`SPREAD_FACTOR`] times less than the nominal
/// model's points' at the same poses when, read as metres, it would be
/// within that factor. Otherwise an [`Error::PositionsTooSmall`] with the
/// hint [`UnitHint::Metres`]. (Metres that spread too little have no other
/// unit to be in: a pivoting tool keeps its tip still.)
fn check_positions_spread(
    file: &str,
    length: LengthUnit,
    points: &[[f64; 3]],
    predicted: &[[f64; 3]],
) -> Result<()> {
    if length != LengthUnit::Mm {
        return Ok(());
    }
    let (measured, nominal) = (spread(points), spread(predicted));
    let ratio = measured / nominal;
    if !ratio.is_finite() || ratio * SPREAD_FACTOR >= 1.0 {
        return Ok(());
    }
    let as_metres = ratio * 1e3;
    if !(1.0 / SPREAD_FACTOR..=SPREAD_FACTOR).contains(&as_metres) {
        return Ok(());
    }
    Err(Error::PositionsTooSmall {
        file: file.to_string(),
        spread: measured,
        nominal,
        unit: length.symbol(),
        hint: Some(UnitHint::Metres),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(n: usize) -> Vec<String> {
        (0..n).map(|k| format!("line {}", k + 2)).collect()
    }

    #[test]
    fn degrees_are_converted_and_radians_pass() {
        let r = Robot::builtin("ur5").unwrap();
        let cols: Vec<String> = (1..=6).map(|j| format!("q{j}")).collect();
        let rows = rows(1);
        let src = JointSource {
            file: "m.csv",
            rows: &rows,
            columns: &cols,
        };
        let mut q = vec![vec![90.0, -45.0, 0.0, 10.0, 20.0, 30.0]];
        let deg = Units {
            angle: AngleUnit::Deg,
            ..Units::default()
        };
        joint_values_to_model_units(&r, deg, &src, &mut q).unwrap();
        assert!((q[0][0] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        let mut q = vec![vec![1.0, -1.0, 0.0, 0.5, 0.2, 0.3]];
        joint_values_to_model_units(&r, Units::default(), &src, &mut q).unwrap();
        assert_eq!(q[0][0], 1.0);
    }

    #[test]
    fn a_degree_column_is_refused_with_a_hint_naming_the_place() {
        let r = Robot::builtin("ur5").unwrap();
        let cols: Vec<String> = (1..=6).map(|j| format!("q{j}")).collect();
        let rows = rows(2);
        let src = JointSource {
            file: "m.csv",
            rows: &rows,
            columns: &cols,
        };
        let mut q = vec![
            vec![1.0, -1.0, 1.0, 1.0, 1.0, 1.0],
            vec![1.0, -1.0, 143.0, 1.0, 1.0, 1.0],
        ];
        let e = joint_values_to_model_units(&r, Units::default(), &src, &mut q).unwrap_err();
        assert!(matches!(
            e,
            Error::JointOutOfLimits {
                hint: Some(UnitHint::Degrees),
                ..
            }
        ));
        let s = e.to_string();
        assert!(
            s.contains("m.csv") && s.contains("line 3") && s.contains("'q3'") && s.contains("143"),
            "{s}"
        );
        assert!(s.contains("degrees"), "{s}");
        // 1000 fits no unit: no hint.
        let mut q = vec![vec![1.0, -1.0, 1000.0, 1.0, 1.0, 1.0]];
        let e = joint_values_to_model_units(&r, Units::default(), &src, &mut q).unwrap_err();
        assert!(matches!(e, Error::JointOutOfLimits { hint: None, .. }));
    }

    #[test]
    fn the_tolerance_is_a_fifth_of_the_range_and_not_more() {
        let r = Robot::builtin("ur5").unwrap();
        // Joint 2: [−π, 0], a working range.
        let [lo, hi] = r.limits[1];
        let tol = limit_tolerance(lo, hi);
        assert!(
            (tol - 1e-6 - 0.2 * std::f64::consts::PI).abs() < 1e-12,
            "{tol}"
        );
        let cols: Vec<String> = (1..=6).map(|j| format!("q{j}")).collect();
        let rows = rows(1);
        let src = JointSource {
            file: "m.csv",
            rows: &rows,
            columns: &cols,
        };
        let mut ok = vec![vec![0.0, hi + 0.99 * tol, 0.0, 0.0, 0.0, 0.0]];
        joint_values_to_model_units(&r, Units::default(), &src, &mut ok).unwrap();
        let mut bad = vec![vec![0.0, hi + 1.01 * tol, 0.0, 0.0, 0.0, 0.0]];
        assert!(joint_values_to_model_units(&r, Units::default(), &src, &mut bad).is_err());
        let mut bad = vec![vec![0.0, lo - 1.01 * tol, 0.0, 0.0, 0.0, 0.0]];
        assert!(joint_values_to_model_units(&r, Units::default(), &src, &mut bad).is_err());
    }
}
