//! `activecal.extract`: a ROS 2 bag's rests as the measurement table
//! `activecal extract --out` writes (the library's
//! [`activecal::io::bag::extract`] does the work; here the arguments are
//! converted and the table handed to pandas).

use crate::convert::{Fail, arg_err, detached, json_to_py};
use crate::robot::Robot;
use activecal::io::bag::extract::{ExtractSettings, extract as extract_bag};
use activecal::io::bag::series::Source;
use pyo3::prelude::*;
use std::path::PathBuf;

/// A number argument that must be finite and at least `min`.
fn at_least(name: &str, v: f64, min: f64, what: &str) -> PyResult<f64> {
    if v.is_finite() && v >= min {
        Ok(v)
    } else {
        Err(arg_err(name, what))
    }
}

/// Reads the ROS 2 bag at `bag` (a rosbag2 folder, or one .mcap or .db3
/// file) as `activecal extract BAG --out FILE` does: one row per rest of
/// the joints (every joint slower than rest_speed rad/s for rest_min s or
/// longer), its joint values and measurement averaged after settle s.
/// The measurement is one of points (a PointStamped topic), poses (a
/// PoseStamped or TransformStamped topic) or tf ("PARENT:CHILD" of /tf).
/// time_offset: the clock offset (s, the measurement's stamp minus the
/// joints'), estimated from the moves within ±max_offset s when None.
/// design: the design file the run followed (each rest matched to its pose
/// within design_tolerance rad or m). Returns the table as a pandas
/// DataFrame with the CSV's columns (the joints, x1, y1, z1 and for poses
/// qw1, qx1, qy1, qz1; radians, metres), the extraction's report (rests,
/// reasons, clock offset, scatter) in its `attrs["report"]`.
#[pyfunction]
#[pyo3(signature = (bag, robot, *, joints="/joint_states", points=None, poses=None, tf=None, time_offset=None, max_offset=10.0, rest_speed=0.005, rest_min=0.5, settle=0.2, design=None, design_tolerance=0.01, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn extract<'py>(
    py: Python<'py>,
    bag: PathBuf,
    robot: &Robot,
    joints: &str,
    points: Option<&str>,
    poses: Option<&str>,
    tf: Option<&str>,
    time_offset: Option<f64>,
    max_offset: f64,
    rest_speed: f64,
    rest_min: f64,
    settle: f64,
    design: Option<PathBuf>,
    design_tolerance: f64,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let source = Source::one_of(points, poses, tf)
        .map_err(|e| crate::errors::new_err(crate::errors::Kind::Input, e))?;
    let mut s = ExtractSettings::new(joints, source);
    s.rest.speed = rest_speed;
    s.rest.min_duration = rest_min;
    s.rest.settle = settle;
    s.max_offset = at_least("max_offset", max_offset, 0.0, "seconds, 0 or more")?;
    s.design_tolerance = at_least(
        "design_tolerance",
        design_tolerance,
        f64::MIN_POSITIVE,
        "a positive number (rad, m)",
    )?;
    s.time_offset = time_offset
        .map(|o| at_least("time_offset", o, f64::MIN, "a number of seconds"))
        .transpose()?;
    let inner = robot.inner.clone();
    let (csv, report) = crate::progress::with_callback(progress, || {
        detached(py, move || {
            if let Some(d) = &design {
                s.design = Some(activecal::io::bag::design::read_design(d, &inner)?);
            }
            let got = extract_bag(&bag, &inner, &s)?;
            let csv = activecal::io::measurements::to_csv(&got.measurements, &inner);
            let report = serde_json::to_value(&got.report).map_err(Fail::input)?;
            Ok((csv, report))
        })
    })?;
    let io = py.import("io")?;
    let table = py
        .import("pandas")?
        .call_method1("read_csv", (io.call_method1("StringIO", (csv,))?,))?;
    table
        .getattr("attrs")?
        .set_item("report", json_to_py(py, &report)?)?;
    Ok(table)
}
