//! Measurement files: JSON (the [`Measurements`] format) and CSV as users
//! export them from a tracker or a motion-capture system.
//!
//! # CSV
//! A header names the columns, in any order:
//! * `x1,y1,z1` — the measured point (metres, sensor frame); `x2,y2,z2`, …
//!   for more markers on the same pose (`x,y,z` is read as marker 1). `K`
//!   markers make a `K`-marker measurement ([`crate::measure::markers`]):
//!   never flattened into one point.
//! * optionally the orientation of a full pose (one marker only):
//!   `phix1,phiy1,phiz1` (roll, pitch, yaw in radians, `R = Rz(phiz) ·
//!   Ry(phiy) · Rx(phix)`) or `qw1,qx1,qy1,qz1` (a unit quaternion, scalar
//!   first).
//! * one column per joint, named as the robot's joint (the URDF joint name,
//!   the frame label of a description, or `q1`, `q2`, … by joint order):
//!   radians for revolute joints, metres for prismatic ones.
//!
//! A missing joint column is an error naming it; other columns are listed
//! in a note, never silently dropped. A non-numeric cell is an error naming
//! the line and column; a non-finite value one naming the row.
//!
//! # Units
//! Both formats are read in the [`Units`] the caller names (radians and
//! metres by default): revolute joint values in its angle unit, measured
//! positions and prismatic joint values in its length unit (roll, pitch
//! and yaw stay radians). Joint values are converted and checked against
//! the joint limits by the one rule of every joint-value reader
//! ([`crate::units::joint_values_to_model_units`]).

use super::table::{Table, parse_csv};
use crate::data::{Measurements, ROTATION_TOLERANCE};
use crate::error::{Error, Result};
use crate::model::Robot;
pub use crate::units::joint_names;
use crate::units::{JointSource, Units, joint_values_to_model_units};
use nalgebra::{Quaternion, Rotation3, UnitQuaternion};
use std::path::Path;

/// Largest magnitude of a roll, pitch or yaw angle read from a file:
/// angles are radians; a value beyond 2π is almost surely in degrees.
pub const MAX_ANGLE: f64 = 2.0 * std::f64::consts::PI;

/// Measurements read from a file, with notes about what was read.
#[derive(Clone, Debug)]
pub struct MeasurementFile {
    /// The measurements (not yet checked against a robot's sensor: see
    /// [`Measurements::check`]).
    pub measurements: Measurements,
    /// What the reader noticed (columns ignored, the sensor the file implies).
    pub notes: Vec<String>,
}

/// Reads a measurement file for `robot`: CSV when the name ends in `.csv`,
/// otherwise JSON ([`Measurements`]). The joint columns of a CSV are matched
/// to the robot's joints by name. Radians and metres.
pub fn read(path: &Path, robot: &Robot) -> Result<MeasurementFile> {
    read_in(path, robot, Units::default())
}

/// As [`read`], for a file in `units` (see the module documentation): the
/// result is in radians and metres.
pub fn read_in(path: &Path, robot: &Robot, units: Units) -> Result<MeasurementFile> {
    let origin = path.display().to_string();
    let text = crate::io::read::read_text(path)?;
    let is_csv = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if is_csv {
        parse_csv_measurements_in(&text, &origin, robot, units)
    } else {
        let mut measurements: Measurements =
            serde_json::from_str(&text).map_err(|e| Error::Parse {
                path: origin.clone(),
                message: e.to_string(),
            })?;
        if let Some(name) = measurements.robot().filter(|n| *n != robot.name) {
            return Err(Error::Parse {
                path: origin,
                message: format!(
                    "the measurements are of robot '{name}', not '{}'",
                    robot.name
                ),
            });
        }
        let rows: Vec<String> = (0..measurements.len())
            .map(|k| format!("qs[{k}] (row {})", k + 1))
            .collect();
        let columns = joint_names(robot);
        let source = JointSource {
            file: &origin,
            rows: &rows,
            columns: &columns,
        };
        let mut qs = measurements.qs().to_vec();
        // A joint vector of another length is the check's to report, with
        // its pose (`Measurements::check`); only whole rows are converted.
        if qs.iter().all(|q| q.len() == robot.dof()) {
            joint_values_to_model_units(robot, units, &source, &mut qs)?;
        }
        measurements.set_units(qs, units.length.to_m());
        Ok(MeasurementFile {
            measurements,
            notes: Vec::new(),
        })
    }
}

/// The CSV form of `meas` for `robot`, as [`read`] reads it back: a column
/// per joint (named as a URDF robot's joints, else `q1`…`qN`; radians,
/// metres for prismatic joints), `x1,y1,z1` (… one triple per marker; metres;
/// of a sensor that reads fewer coordinates, those alone:
/// [`crate::measure::Sensor::point_coordinates`]) and, for full
/// poses, the orientation as a unit quaternion `qw1,qx1,qy1,qz1`; one row
/// a pose, every value at full precision.
#[must_use]
pub fn to_csv(meas: &Measurements, robot: &Robot) -> String {
    let k = meas.markers();
    let full = !meas.orientations().is_empty();
    let mut head: Vec<String> = if robot.source.is_some() {
        joint_names(robot)
    } else {
        (1..=robot.dof()).map(|j| format!("q{j}")).collect()
    };
    let coords = crate::measure::sensor_for(robot).point_coordinates();
    for m in 1..=k {
        head.extend(coords.iter().map(|&c| format!("{}{m}", AXES[c])));
    }
    if full {
        head.extend(["qw1", "qx1", "qy1", "qz1"].map(String::from));
    }
    let mut out = head.join(",") + "\n";
    for (i, q) in meas.qs().iter().enumerate() {
        let mut row: Vec<String> = q.iter().map(f64::to_string).collect();
        for p in &meas.points()[k * i..k * (i + 1)] {
            row.extend(coords.iter().map(|&c| p[c].to_string()));
        }
        if let Some(r) = meas.orientations().get(i) {
            let m = nalgebra::Matrix3::from_row_slice(&r.concat());
            let u = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
            row.extend([u.w, u.i, u.j, u.k].iter().map(f64::to_string));
        }
        out += &(row.join(",") + "\n");
    }
    out
}

/// Parses measurement CSV `text` (see the module documentation), radians
/// and metres.
pub fn parse_csv_measurements(text: &str, origin: &str, robot: &Robot) -> Result<MeasurementFile> {
    parse_csv_measurements_in(text, origin, robot, Units::default())
}

/// Parses measurement CSV `text` in `units` (see the module documentation).
pub fn parse_csv_measurements_in(
    text: &str,
    origin: &str,
    robot: &Robot,
    units: Units,
) -> Result<MeasurementFile> {
    let t = parse_csv(text, origin)?;
    let err = |message: String| Error::Parse {
        path: origin.to_string(),
        message,
    };
    let layout = Layout::of(&t, robot).map_err(err)?;
    let notes = layout.notes(&t, origin, robot);
    let m = units.length.to_m();
    let n = t.rows.len();
    let mut qs = Vec::with_capacity(n);
    let mut points = Vec::with_capacity(n * layout.markers.len());
    let mut orientations = Vec::new();
    for (row, &line) in t.rows.iter().zip(&t.lines) {
        let cell = Cells {
            table: &t,
            row,
            line,
        };
        qs.push(
            layout
                .joints
                .iter()
                .map(|&c| cell.at(c))
                .collect::<std::result::Result<Vec<f64>, String>>()
                .map_err(err)?,
        );
        for cols in &layout.markers {
            let mut p = [0.0; 3];
            for (v, c) in p.iter_mut().zip(cols) {
                if let Some(c) = *c {
                    *v = m * cell.at(c).map_err(err)?;
                }
            }
            points.push(p);
        }
        if let Some(r) = layout.orientation.read(&cell).map_err(err)? {
            orientations.push(r);
        }
    }
    let rows: Vec<String> = t.lines.iter().map(|l| format!("line {l}")).collect();
    let columns: Vec<String> = layout
        .joints
        .iter()
        .map(|&c| t.columns[c].clone())
        .collect();
    let source = JointSource {
        file: origin,
        rows: &rows,
        columns: &columns,
    };
    joint_values_to_model_units(robot, units, &source, &mut qs)?;
    Ok(MeasurementFile {
        measurements: Measurements::unchecked(qs, layout.markers.len(), points, orientations),
        notes,
    })
}

/// Which columns of a measurement CSV hold what.
struct Layout {
    /// `x_k, y_k, z_k` of each marker (`None`: a coordinate the sensor
    /// does not read, 0).
    markers: Vec<[Option<usize>; 3]>,
    /// The orientation columns of a full pose, if any.
    orientation: OrientationColumns,
    /// One column per joint of the robot, in joint order.
    joints: Vec<usize>,
    /// Which columns are read (the others go into a note).
    used: Vec<bool>,
}

/// How a full pose's orientation is given.
enum OrientationColumns {
    /// No orientation: points only.
    None,
    /// `phix1, phiy1, phiz1` (roll, pitch, yaw).
    Rpy([usize; 3]),
    /// `qw1, qx1, qy1, qz1`.
    Quaternion([usize; 4]),
}

/// One row's cells, with what an error about them names.
struct Cells<'a> {
    table: &'a Table,
    row: &'a [f64],
    line: usize,
}

impl Cells<'_> {
    /// The finite value of column `c`.
    fn at(&self, c: usize) -> std::result::Result<f64, String> {
        let v = self.row[c];
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!(
                "line {}, column {} ('{}'): {v} is not a finite number",
                self.line,
                c + 1,
                self.table.columns[c]
            ))
        }
    }
}

impl Layout {
    /// Finds the marker, orientation and joint columns of `t`'s header.
    fn of(t: &Table, robot: &Robot) -> std::result::Result<Self, String> {
        let mut used = vec![false; t.columns.len()];
        let coords = crate::measure::sensor_for(robot).point_coordinates();
        let markers = marker_columns(t, &mut used, coords)?;
        let orientation = orientation_columns(t, &mut used, markers.len())?;
        let joints = joint_columns(t, &mut used, robot)?;
        Ok(Self {
            markers,
            orientation,
            joints,
            used,
        })
    }

    /// Notes on columns left unread and on a several-marker sensor.
    fn notes(&self, t: &Table, origin: &str, robot: &Robot) -> Vec<String> {
        let mut notes = Vec::new();
        let extra: Vec<&str> = t
            .columns
            .iter()
            .zip(&self.used)
            .filter(|(_, u)| !**u)
            .map(|(c, _)| c.as_str())
            .collect();
        if !extra.is_empty() {
            notes.push(format!(
                "{origin}: column(s) not used (not a marker, orientation or joint of robot '{}'): {}",
                robot.name,
                extra.join(", ")
            ));
        }
        if self.markers.len() > 1 {
            notes.push(format!(
                "{origin}: {} markers per pose: a {}-marker sensor with an offset of its own per marker",
                self.markers.len(),
                self.markers.len()
            ));
        }
        notes
    }
}

/// Marks column `name` as read and returns its index.
fn take(t: &Table, name: &str, used: &mut [bool]) -> Option<usize> {
    let c = t.column(name)?;
    used[c] = true;
    Some(c)
}

/// The coordinate names of a measured point, in order.
const AXES: [&str; 3] = ["x", "y", "z"];

/// Markers: `x1,y1,z1`, `x2,…`; plain `x,y,z` count as marker 1. Only the
/// coordinates `coords` (indices into `x y z`) the sensor reads are
/// columns; the others stay `None`.
fn marker_columns(
    t: &Table,
    used: &mut [bool],
    coords: &[usize],
) -> std::result::Result<Vec<[Option<usize>; 3]>, String> {
    let mut marker_cols: Vec<[Option<usize>; 3]> = Vec::new();
    for k in 1.. {
        let names: Vec<String> = coords.iter().map(|&c| format!("{}{k}", AXES[c])).collect();
        let found: Vec<Option<usize>> = names.iter().map(|n| t.column(n)).collect();
        let found = if k == 1 && found.iter().all(Option::is_none) {
            coords.iter().map(|&c| t.column(AXES[c])).collect()
        } else {
            found
        };
        if found.iter().all(Option::is_none) {
            break;
        }
        if found.iter().any(Option::is_none) {
            let missing: Vec<&str> = names
                .iter()
                .zip(&found)
                .filter(|(_, f)| f.is_none())
                .map(|(n, _)| n.as_str())
                .collect();
            return Err(format!(
                "marker {k}: column(s) {} missing (a marker needs {})",
                missing.join(", "),
                and_list(&names)
            ));
        }
        let mut cols = [None; 3];
        for (&c, f) in coords.iter().zip(&found) {
            cols[c] = *f;
            f.iter().for_each(|&i| used[i] = true);
        }
        marker_cols.push(cols);
    }
    if marker_cols.is_empty() {
        let names: Vec<String> = coords.iter().map(|&c| format!("{}1", AXES[c])).collect();
        return Err(format!(
            "no measured point: expected column{} {} (metres); the header has {}",
            if names.len() == 1 { "" } else { "s" },
            names.join(", "),
            t.columns.join(", ")
        ));
    }
    Ok(marker_cols)
}

/// `a`, `a and b`, `a, b and c`.
fn and_list(names: &[String]) -> String {
    match names {
        [] => String::new(),
        [a] => a.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// The orientation columns: all three angles, all four quaternion entries,
/// or none; only with one marker.
fn orientation_columns(
    t: &Table,
    used: &mut [bool],
    markers: usize,
) -> std::result::Result<OrientationColumns, String> {
    let rpy: Vec<Option<usize>> = ["phix1", "phiy1", "phiz1"]
        .iter()
        .map(|n| take(t, n, used))
        .collect();
    let quat: Vec<Option<usize>> = ["qw1", "qx1", "qy1", "qz1"]
        .iter()
        .map(|n| take(t, n, used))
        .collect();
    let has_rpy = rpy.iter().any(Option::is_some);
    let has_quat = quat.iter().any(Option::is_some);
    if has_rpy && has_quat {
        return Err(
            "both phix1/phiy1/phiz1 and qw1/qx1/qy1/qz1: give the orientation one way".into(),
        );
    }
    if (has_rpy && rpy.iter().any(Option::is_none))
        || (has_quat && quat.iter().any(Option::is_none))
    {
        return Err(
            "an incomplete orientation: give all of phix1, phiy1, phiz1 (roll, pitch, yaw) or all of qw1, qx1, qy1, qz1".into(),
        );
    }
    if (has_rpy || has_quat) && markers > 1 {
        return Err(format!(
            "an orientation with {markers} markers: a full pose has one measured point (orientations with several markers are not supported)"
        ));
    }
    Ok(match (&rpy[..], &quat[..]) {
        ([Some(a), Some(b), Some(c)], _) => OrientationColumns::Rpy([*a, *b, *c]),
        (_, [Some(w), Some(x), Some(y), Some(z)]) => {
            OrientationColumns::Quaternion([*w, *x, *y, *z])
        }
        _ => OrientationColumns::None,
    })
}

/// One column per joint, by name (or `q1…qN`).
fn joint_columns(
    t: &Table,
    used: &mut [bool],
    robot: &Robot,
) -> std::result::Result<Vec<usize>, String> {
    let names = joint_names(robot);
    let mut joint_cols = Vec::with_capacity(names.len());
    for (j, n) in names.iter().enumerate() {
        let alias = format!("q{}", j + 1);
        match take(t, n, used).or_else(|| take(t, &alias, used)) {
            Some(c) => joint_cols.push(c),
            None => {
                return Err(format!(
                    "no column for joint '{n}' (joint {} of robot '{}'; name the column '{n}' or '{alias}'); the header has {}",
                    j + 1,
                    robot.name,
                    t.columns.join(", ")
                ));
            }
        }
    }
    Ok(joint_cols)
}

impl OrientationColumns {
    /// The row's orientation as a row-major rotation, if the file has one.
    fn read(&self, cell: &Cells<'_>) -> std::result::Result<Option<[[f64; 3]; 3]>, String> {
        match self {
            Self::None => Ok(None),
            Self::Rpy(cols) => {
                let a = [cell.at(cols[0])?, cell.at(cols[1])?, cell.at(cols[2])?];
                if let Some((i, v)) = a.iter().enumerate().find(|(_, v)| v.abs() > MAX_ANGLE) {
                    let c = cols[i];
                    return Err(format!(
                        "line {}, column {} ('{}'): angle {v} is out of range (radians, |angle| <= 2π; degrees?)",
                        cell.line,
                        c + 1,
                        cell.table.columns[c]
                    ));
                }
                // R = Rz(phiz) Ry(phiy) Rx(phix): nalgebra's roll-pitch-yaw.
                let r = Rotation3::from_euler_angles(a[0], a[1], a[2]);
                Ok(Some(crate::data::rows(r.matrix())))
            }
            Self::Quaternion(cols) => {
                let v = [
                    cell.at(cols[0])?,
                    cell.at(cols[1])?,
                    cell.at(cols[2])?,
                    cell.at(cols[3])?,
                ];
                let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                if (norm - 1.0).abs() > ROTATION_TOLERANCE {
                    return Err(format!(
                        "line {}: quaternion (qw1, qx1, qy1, qz1) has norm {norm}, not 1 (to {ROTATION_TOLERANCE:e})",
                        cell.line
                    ));
                }
                let uq = UnitQuaternion::from_quaternion(Quaternion::new(v[0], v[1], v[2], v[3]));
                Ok(Some(crate::data::rows(uq.to_rotation_matrix().matrix())))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ur5() -> Robot {
        Robot::builtin("ur5:pose").unwrap()
    }

    #[test]
    fn rpy_is_rz_ry_rx_and_joints_match_by_name_in_any_order() {
        let text = "q6,q5,q4,q3,q2,q1,x1,y1,z1,phix1,phiy1,phiz1,temp\n0.6,0.5,0.4,0.3,-0.2,0.1,0.1,0.2,0.3,0.3,-0.2,1.1,20\n";
        let f = parse_csv_measurements(text, "m.csv", &ur5()).unwrap();
        let m = &f.measurements;
        assert_eq!(m.qs()[0], [0.1, -0.2, 0.3, 0.4, 0.5, 0.6]);
        assert_eq!(m.points()[0], [0.1, 0.2, 0.3]);
        let (x, y, z) = (0.3f64, -0.2f64, 1.1f64);
        let rz = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::z_axis(), z);
        let ry = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::y_axis(), y);
        let rx = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::x_axis(), x);
        let want = crate::data::rows((rz * ry * rx).matrix());
        for (got, want) in m.orientations()[0].iter().zip(&want) {
            for (g, w) in got.iter().zip(want) {
                assert!((g - w).abs() < 1e-15);
            }
        }
        assert!(f.notes[0].contains("temp"), "{:?}", f.notes);
        m.check(&ur5()).unwrap();
    }

    #[test]
    fn bad_files_name_the_place() {
        let r = ur5();
        let e = |t: &str| {
            parse_csv_measurements(t, "m.csv", &r)
                .unwrap_err()
                .to_string()
        };
        assert!(e("q1,q2,q3,q4,q5,x1,y1,z1\n1,2,3,4,5,0,0,0\n").contains("joint 6 of robot"));
        assert!(
            e("q1,q2,q3,q4,q5,q6,x1,y1,z1\n1,2,3,4,5,6,0,zero,0\n")
                .contains("line 2, column 8 ('y1'): cannot read 'zero'")
        );
        assert!(
            e("q1,q2,q3,q4,q5,q6,x1,y1,z1,phix1,phiy1,phiz1\n1,2,3,4,5,6,0,0,0,0,90,0\n")
                .contains("line 2, column 11 ('phiy1'): angle 90 is out of range")
        );
        assert!(e("q1,q2,q3,q4,q5,q6,x1,y1\n1,2,3,4,5,6,0,0\n").contains("z1 missing"));
        assert!(
            e("q1,q2,q3,q4,q5,q6,x1,y1,z1\n1,2,3,4,5,nan,0,0,0\n").contains("line 2, column 6")
        );
    }
}
