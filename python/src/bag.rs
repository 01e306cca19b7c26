//! `activecal.extract`: a ROS 2 bag's rests as the measurement table
//! `activecal extract --out` writes (the library's
//! [`activecal::io::bag::extract`] does the work; here the arguments are
//! converted and the table handed to pandas).

use crate::convert::{Fail, arg_err, detached, json_to_py};
use crate::robot::Robot;
use activecal::experiment::bag::BagCalibration;
use activecal::io::bag::extract::{ExtractSettings, extract as extract_bag};
use activecal::io::bag::series::Source;
use pyo3::prelude::*;
use std::path::PathBuf;

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
    let s = settings(&BagArgs {
        joints,
        points,
        poses,
        tf,
        time_offset,
        max_offset,
        rest_speed,
        rest_min,
        settle,
        design_tolerance,
    })?;
    let inner = robot.inner.clone();
    let (csv, report) = crate::progress::with_callback(progress, || {
        detached(py, move || {
            let mut s = s;
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

/// The keyword arguments that say what to read from a bag and how, as
/// `extract` and `calibrate` take them.
pub(crate) struct BagArgs<'a> {
    /// The sensor_msgs/msg/JointState topic.
    pub joints: &'a str,
    /// A PointStamped topic.
    pub points: Option<&'a str>,
    /// A PoseStamped or TransformStamped topic.
    pub poses: Option<&'a str>,
    /// "PARENT:CHILD" of /tf.
    pub tf: Option<&'a str>,
    /// The clock offset given (s), or None to estimate it.
    pub time_offset: Option<f64>,
    /// The largest clock offset searched for (s).
    pub max_offset: f64,
    /// A joint is at rest under this speed (rad/s, m/s).
    pub rest_speed: f64,
    /// The shortest rest (s).
    pub rest_min: f64,
    /// Seconds left out at the start of each rest.
    pub settle: f64,
    /// A rest reached a design pose within this (rad, m).
    pub design_tolerance: f64,
}

impl BagArgs<'_> {
    /// The keyword arguments given (not at their defaults), by the acts-on
    /// table's names (`design` is the table's `bag_design`), with `bag`
    /// and `design` when given.
    pub(crate) fn given(&self, bag: bool, design: bool) -> Vec<&'static str> {
        [
            ("bag", bag),
            ("points", self.points.is_some()),
            ("poses", self.poses.is_some()),
            ("tf", self.tf.is_some()),
            ("joints", self.joints != "/joint_states"),
            ("time_offset", self.time_offset.is_some()),
            ("max_offset", self.max_offset != 10.0),
            ("rest_speed", self.rest_speed != 0.005),
            ("rest_min", self.rest_min != 0.5),
            ("settle", self.settle != 0.2),
            ("bag_design", design),
            ("design_tolerance", self.design_tolerance != 0.01),
        ]
        .into_iter()
        .filter_map(|(k, g)| g.then_some(k))
        .collect()
    }
}

/// The library's extraction settings from the keyword arguments, checked
/// (a bad one named by its keyword).
pub(crate) fn settings(a: &BagArgs<'_>) -> PyResult<ExtractSettings> {
    let fail = |e| Fail::from(e).into_py();
    let source = Source::one_of(a.points, a.poses, a.tf).map_err(fail)?;
    let mut s = ExtractSettings::new(a.joints, source);
    s.rest.speed = a.rest_speed;
    s.rest.min_duration = a.rest_min;
    s.rest.settle = a.settle;
    s.max_offset = a.max_offset;
    s.design_tolerance = a.design_tolerance;
    s.time_offset = a.time_offset;
    s.validate().map_err(fail)?;
    Ok(s)
}

/// A bag to calibrate from: its path, what to read and how, and the
/// design file the run followed.
pub(crate) struct BagInput {
    /// The bag (a rosbag2 folder, or one .mcap or .db3 file).
    pub path: PathBuf,
    /// What to read from it and how.
    pub settings: ExtractSettings,
    /// The design the run followed, each rest matched to its pose.
    pub design: Option<PathBuf>,
}

/// The calibration of `robot` from the bag `b` with the fit's settings
/// `s`: the library's pipeline `calibrate --bag` runs
/// ([`activecal::experiment::bag::calibrate_bag`]), whose report says
/// what it found in the bag (`report["bag"]`, as the command line's JSON).
pub(crate) fn calibrate_from(
    b: BagInput,
    robot: &activecal::model::Robot,
    s: &activecal::experiment::measured::MeasuredSettings,
) -> Result<BagCalibration, Fail> {
    let mut x = b.settings;
    if let Some(d) = &b.design {
        x.design = Some(activecal::io::bag::design::read_design(d, robot)?);
    }
    Ok(activecal::experiment::bag::calibrate_bag(
        &b.path,
        robot,
        &x,
        s,
        &mut |_| {},
    )?)
}

/// `calibrate`'s `points` as a bag's topic: with `bag` given, `points` is
/// the PointStamped topic (a str) and q and orientations are not given
/// (the bag holds them); without, q and points are both given (arrays).
pub(crate) fn points_topic(
    bag: bool,
    q: Option<&Bound<'_, PyAny>>,
    points: Option<&Bound<'_, PyAny>>,
    orientations: Option<&Bound<'_, PyAny>>,
) -> PyResult<Option<String>> {
    let from_bag = "with bag, the joint values and measurements are read from the bag";
    match (bag, q, points, orientations) {
        (true, Some(_), _, _) => Err(arg_err("q", from_bag)),
        (true, _, _, Some(_)) => Err(arg_err(
            "orientations",
            format!("{from_bag} (full poses: poses= or tf=)"),
        )),
        (true, _, Some(p), _) => p.extract::<String>().map(Some).map_err(|_| {
            arg_err(
                "points",
                "with bag, the bag's geometry_msgs/msg/PointStamped topic (a str)",
            )
        }),
        (true, _, None, _) => Ok(None),
        (false, Some(_), Some(_), _) => Ok(None),
        (false, None, _, _) => Err(arg_err("q", "give q and points (arrays), or bag")),
        (false, _, None, _) => Err(arg_err("points", "give q and points (arrays), or bag")),
    }
}

/// The bag `calibrate` reads when `bag` is given: its path, the
/// extraction's settings from `a` and the design file.
pub(crate) fn input(
    bag: Option<PathBuf>,
    a: &BagArgs<'_>,
    design: Option<PathBuf>,
) -> PyResult<Option<BagInput>> {
    let Some(path) = bag else { return Ok(None) };
    Ok(Some(BagInput {
        path,
        settings: settings(a)?,
        design,
    }))
}
