//! `activecal.calibrate`: identification from measured poses held in
//! memory, as `activecal calibrate --measurements FILE` does from a file,
//! and the `Calibration` it returns.

use crate::convert::{
    aligned, arg_err, count, detached, float_array, json_to_py, named_columns, rows,
};
use crate::fit_args::{holdout_of, restriction_of, weights_of};
pub(crate) use crate::fit_args::{loss_of, outliers_of, refuse_unused};
use crate::robot::Robot;
use activecal::data::Measurements;
use activecal::experiment::CalibratedFrames;
use activecal::experiment::Identification;
use activecal::experiment::acts_on::{self as lib_acts, Sensor};
use activecal::experiment::measured::{MeasuredSettings, calibrate_measurements};
use activecal::options::LmSettings;
use activecal::report::FramesReport;
use activecal::write::calibrated::Format;
use pyo3::prelude::*;
use std::sync::Arc;

/// A calibration: the estimate, its σ, the residuals, and the calibrated
/// robot to write.
#[pyclass(module = "activecal", name = "Calibration", frozen)]
pub struct Calibration {
    robot: Arc<activecal::model::Robot>,
    id: Identification,
    frames: Option<(CalibratedFrames, FramesReport)>,
    report: serde_json::Value,
    /// The library's verdict: whether the calibrated robot may be written.
    verdict: activecal::experiment::measured::verdict::Verdict,
    /// What its report folder shows.
    summary: crate::page::KeptSummary,
    /// How it was made, for pickling.
    recipe: crate::pickling::Recipe,
}

/// What `calibrate` reads from its array arguments.
struct Data {
    qs: Vec<Vec<f64>>,
    points: Vec<[f64; 3]>,
    orientations: Vec<[[f64; 3]; 3]>,
}

/// A DataFrame of measured points as an array: columns x, y, z for one
/// point a pose, x1, y1, z1 … xK, yK, zK for K markers (then (n, K, 3)).
fn points_frame<'py>(points: &Bound<'py, PyAny>, k: usize) -> PyResult<Bound<'py, PyAny>> {
    let columns: Vec<String> = if k == 1 {
        ["x", "y", "z"].map(String::from).to_vec()
    } else {
        (1..=k)
            .flat_map(|i| ["x", "y", "z"].map(|c| format!("{c}{i}")))
            .collect()
    };
    let a = named_columns(points, "points", &columns, "coordinate")?;
    if k > 1 && !a.is(points) {
        return a.call_method1("reshape", ((-1i64, k, 3usize),));
    }
    Ok(a)
}

/// The arrays checked against the robot: q (n, dof), points (n, 3) or
/// (n, K, 3) for K markers, orientations (n, 3, 3) for a full-pose robot.
fn data(
    py: Python<'_>,
    wrapper: &Robot,
    q: &Bound<'_, PyAny>,
    points: &Bound<'_, PyAny>,
    orientations: Option<&Bound<'_, PyAny>>,
) -> PyResult<Data> {
    let robot: &activecal::model::Robot = &wrapper.inner;
    let dof = robot.dof();
    let joints = activecal::units::joint_names(robot);
    let points = &aligned(q, points, "points")?;
    let orientations = orientations
        .map(|o| aligned(q, o, "orientations"))
        .transpose()?;
    let orientations = orientations.as_ref();
    let q = &named_columns(q, "q", &joints, "joint")?;
    let (qv, qshape) = float_array(
        py,
        q,
        "q",
        &[None, Some(dof)],
        "one row of joint values per pose, radians or metres",
    )?;
    let n = qshape[0];
    let k = activecal::experiment::sensor_for(robot).points_per_pose();
    let points = &points_frame(points, k)?;
    let (pv, _) = if k == 1 {
        float_array(
            py,
            points,
            "points",
            &[Some(n), Some(3)],
            "one measured position x, y, z per pose of q, metres",
        )?
    } else {
        float_array(
            py,
            points,
            "points",
            &[Some(n), Some(k), Some(3)],
            "each pose's markers' positions x, y, z, metres",
        )?
    };
    let orientations = match (
        orientations,
        activecal::experiment::sensor_for(robot).measures_orientation(),
    ) {
        (Some(o), true) => {
            let (ov, _) = float_array(
                py,
                o,
                "orientations",
                &[Some(n), Some(3), Some(3)],
                "one measured rotation matrix per pose of q, base frame",
            )?;
            ov.chunks(9)
                .map(|m| [[m[0], m[1], m[2]], [m[3], m[4], m[5]], [m[6], m[7], m[8]]])
                .collect()
        }
        (Some(_), false) => {
            return Err(arg_err(
                "orientations",
                format!(
                    "robot '{}' measures points, not orientations (load it with pose=True, or \"NAME:pose\", for full poses)",
                    robot.name
                ),
            ));
        }
        (None, true) => {
            return Err(arg_err(
                "orientations",
                format!(
                    "robot '{}' measures full poses: give one rotation matrix per pose",
                    robot.name
                ),
            ));
        }
        (None, false) => Vec::new(),
    };
    let mut qs = rows(&qv, dof);
    wrapper.check_joint_values("q", &mut qs)?;
    Ok(Data {
        qs,
        points: pv.chunks(3).map(|c| [c[0], c[1], c[2]]).collect(),
        orientations,
    })
}

/// Calibrates the robot from measured poses, as `activecal calibrate
/// --measurements FILE --json` does with a file holding the same values.
///
/// q: (n, dof) joint values, radians or metres. points: (n, 3) measured
/// positions, metres, in the sensor's frame (or (n, K, 3) for K markers).
/// orientations: (n, 3, 3) measured rotation matrices, for a full-pose robot
/// only. fix: unknowns held at their nominal values; free: parameters
/// estimated besides the unknowns (names as in `estimate`).
/// max_iterations: Levenberg–Marquardt's limit. loss: "l2", or "huber" /
/// "cauchy" with loss_scale (metres, a pose's residual norm where the loss
/// turns robust). weights: "estimated" (default: each residual block's σ —
/// position, orientation, each marker — from its own residuals) or
/// "fixed" (a radian of orientation weighs orientation_scale metres,
/// default the robot's, 1 m/rad; giving orientation_scale implies
/// "fixed"). holdout: a fraction of the poses held out in each of `splits`
/// random splits (seeded by `seed`), the fit judged on them (`holdout`).
/// compliance: also estimate a torsional compliance per joint (rad/(N·m)),
/// the joints deflected by the gravity torques of the robot's URDF
/// <inertial> elements (`report["compliances"]`), as `--compliance` does.
/// outliers: "drop" (default: poses with a gross error, found by Baarda's
/// data snooping at the family-wise rate outlier_rate, are left out one at
/// a time and listed in `report["outliers"]`) or "keep", as `--outliers`.
/// noise: the sensor's stated σ per coordinate (metres), as `--noise`: σ̂
/// is tested against it (`report["noise_test"]`), a rejection warns
/// (`UserWarning`, as the command line's warning), and the outlier test
/// uses it.
/// orientation_noise: with orientations, the tracker's stated σ per
/// orientation axis (radians), as `--orientation-noise`: the orientation
/// block's σ is tested against it (`report["orientation_noise_test"]`), a
/// rejection warns (`UserWarning`).
/// progress: a callable `progress(task, done, total, note)`, as `select`
/// takes it. unknowns: "all" (the chain's complete set) or "offsets" (only
/// the joints' zero offsets, the measurement frame and the tool), as
/// `--unknowns`. keep_axis_relations: hold the unknowns that would change
/// the nominal model's parallel, perpendicular or intersecting joint axes,
/// so closed-form inverse kinematics still apply, as
/// `--keep-axis-relations`. With either restriction the same data are
/// also fitted with every unknown: `report["full_model_gain"]` gives both
/// models' predicted (and held-out) errors and the relations held.
/// bag: a ROS 2 bag instead of q and points, as `--bag` (`points` its
/// PointStamped topic; poses, tf, joints, time_offset, max_offset,
/// rest_speed, rest_min, settle, design, design_tolerance as `extract`
/// takes them): the same pipeline, the extraction in `report["bag"]`.
#[pyfunction]
#[pyo3(signature = (robot, q=None, points=None, orientations=None, fix=None, free=None, max_iterations=200, loss="l2", loss_scale=None, weights=None, orientation_scale=None, holdout=None, splits=4, seed=0, compliance=false, outliers="drop", outlier_rate=0.01, noise=None, orientation_noise=None, progress=None, unknowns="all", keep_axis_relations=false, bag=None, joints="/joint_states", poses=None, tf=None, time_offset=None, max_offset=10.0, rest_speed=0.005, rest_min=0.5, settle=0.2, design=None, design_tolerance=0.01))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate(
    py: Python<'_>,
    robot: &Bound<'_, Robot>,
    q: Option<&Bound<'_, PyAny>>,
    points: Option<&Bound<'_, PyAny>>,
    orientations: Option<&Bound<'_, PyAny>>,
    fix: Option<Vec<String>>,
    free: Option<Vec<String>>,
    max_iterations: i64,
    loss: &str,
    loss_scale: Option<f64>,
    weights: Option<&str>,
    orientation_scale: Option<f64>,
    holdout: Option<f64>,
    splits: i64,
    seed: i128,
    compliance: bool,
    outliers: &str,
    outlier_rate: f64,
    noise: Option<f64>,
    orientation_noise: Option<f64>,
    progress: Option<&Bound<'_, PyAny>>,
    unknowns: &str,
    keep_axis_relations: bool,
    bag: Option<std::path::PathBuf>,
    joints: &str,
    poses: Option<&str>,
    tf: Option<&str>,
    time_offset: Option<f64>,
    max_offset: f64,
    rest_speed: f64,
    rest_min: f64,
    settle: f64,
    design: Option<std::path::PathBuf>,
    design_tolerance: f64,
) -> PyResult<Calibration> {
    let topic = crate::bag::points_topic(bag.is_some(), q, points, orientations)?;
    let bag_args = crate::bag::BagArgs {
        joints,
        points: topic.as_deref(),
        poses,
        tf,
        time_offset,
        max_offset,
        rest_speed,
        rest_min,
        settle,
        design_tolerance,
    };
    // Each keyword argument given acts on the data's sensor or is refused
    // (the command line's table).
    let given: Vec<&str> = [
        ("fix", fix.is_some()),
        ("free", free.is_some()),
        ("max_iterations", max_iterations != 200),
        ("loss", loss != "l2"),
        ("loss_scale", loss_scale.is_some()),
        ("weights", weights.is_some()),
        ("orientation_scale", orientation_scale.is_some()),
        ("holdout", holdout.is_some()),
        ("splits", splits != 4),
        ("seed", seed != 0),
        ("compliance", compliance),
        ("outliers", outliers != "drop"),
        ("outlier_rate", outlier_rate != 0.01),
        ("noise", noise.is_some()),
        ("orientation_noise", orientation_noise.is_some()),
        ("unknowns", unknowns != "all"),
        ("keep_axis_relations", keep_axis_relations),
    ]
    .into_iter()
    .filter_map(|(k, g)| g.then_some(k))
    .chain(bag_args.given(bag.is_some(), design.is_some()))
    .collect();
    let sensor = match (&bag, orientations) {
        (Some(_), _) if poses.is_some() || tf.is_some() => Sensor::BagPoses,
        (Some(_), _) => Sensor::BagPoints,
        (None, Some(_)) => Sensor::Poses,
        (None, None) => Sensor::Points,
    };
    refuse_unused(lib_acts::CALIBRATE, &given, sensor)?;
    use crate::pickling::kept;
    let recipe = crate::recipe!(py, "calibrate";
        robot = robot, q = kept(q)?, points = kept(points)?,
        orientations = kept(orientations)?, fix = &fix, free = &free,
        max_iterations = max_iterations, loss = loss, loss_scale = loss_scale, weights = weights,
        orientation_scale = orientation_scale, holdout = holdout, splits = splits, seed = seed,
        compliance = compliance, outliers = outliers, outlier_rate = outlier_rate, noise = noise,
        orientation_noise = orientation_noise, unknowns = unknowns,
        keep_axis_relations = keep_axis_relations, bag = &bag, joints = joints, poses = poses,
        tf = tf, time_offset = time_offset, max_offset = max_offset, rest_speed = rest_speed,
        rest_min = rest_min, settle = settle, design = &design,
        design_tolerance = design_tolerance);
    let robot = robot.get();
    let restriction = restriction_of(unknowns, keep_axis_relations)?;
    let fix = fix.unwrap_or_default();
    let weights = weights_of(weights, orientation_scale)?;
    let outliers = outliers_of(outliers, outlier_rate)?;
    let gravity = crate::fit_args::gravity_of(compliance, &robot.inner)?;
    let mut scaled = (*robot.inner).clone();
    if let Some(w) = orientation_scale {
        scaled.orientation_scale = w;
    }
    let inner = Arc::new(scaled);
    let holdout = holdout_of(holdout, splits, seed, weights)?;
    let input = match (crate::bag::input(bag, &bag_args, design)?, q, points) {
        (Some(b), _, _) => Input::Bag(b),
        (None, Some(q), Some(p)) => Input::Arrays(data(py, robot, q, p, orientations)?),
        // Refused by `points_topic`.
        (None, _, _) => return Err(arg_err("q", "give q and points, or bag")),
    };
    let max_iterations = count("max_iterations", max_iterations, 1)?;
    let loss = loss_of(loss, loss_scale)?;
    let settings = MeasuredSettings {
        lm: LmSettings::builder()
            .max_iterations(max_iterations)
            .geodesic(true)
            .build()
            .map_err(|e| crate::convert::Fail::from(e).into_py())?,
        loss,
        fix,
        restriction,
        free: free.unwrap_or_default(),
        holdout,
        units: activecal::units::Units::default(),
        gravity,
        fit_compliance: compliance,
        compare_compliance: false,
        weights,
        outliers,
        stated_noise: noise,
        stated_orientation_noise: orientation_noise,
    };
    settings
        .validate()
        .map_err(|e| crate::convert::Fail::from(e).into_py())?;
    let r = inner.clone();
    let (fitted, id, frames, (report, summary), verdict, warnings) =
        crate::progress::with_callback(progress, || {
            detached(py, move || {
                let t0 = std::time::Instant::now();
                let (meas, c, source) = fitted_input(input, &r, &settings)?;
                let mut report = c.report;
                report.base.elapsed_seconds = t0.elapsed().as_secs_f64();
                let v = serde_json::to_value(&report)?;
                let summary = crate::page::KeptSummary::keep(
                    activecal::experiment::measured::summary::measured(
                        &c.robot,
                        &c.fit.id,
                        format!("{}, {} poses", source.1, report.base.poses),
                        &report,
                        &v,
                        &meas,
                    ),
                );
                Ok((
                    c.robot,
                    c.fit.id,
                    c.frames,
                    (v, summary),
                    c.verdict,
                    report.warnings,
                ))
            })
        })?;
    crate::errors::warn_all(py, &warnings)?;
    Ok(Calibration {
        robot: Arc::new(fitted),
        id,
        frames,
        report,
        verdict,
        summary,
        recipe,
    })
}

/// Where `calibrate`'s measurements come from: arrays, or a ROS 2 bag.
enum Input {
    /// The arrays q, points (and orientations), checked.
    Arrays(Data),
    /// A bag, its measurement and how to read it.
    Bag(crate::bag::BagInput),
}

/// What `calibrate` fitted.
type Fitted = (
    Measurements,
    activecal::experiment::measured::MeasuredCalibration,
    (String, String),
);

/// The fit of `input` with `s`: the measurements fitted, the calibration,
/// and their source (its name, as the report folder describes it).
fn fitted_input(
    input: Input,
    robot: &activecal::model::Robot,
    s: &MeasuredSettings,
) -> Result<Fitted, crate::convert::Fail> {
    const ARRAYS: &str = "the arrays given";
    match input {
        Input::Arrays(d) => {
            let meas = Measurements::with_orientations(robot, d.qs, d.points, d.orientations)?;
            let c = calibrate_measurements(robot, &meas, ARRAYS, Vec::new(), s, &mut |_| {})?;
            Ok((meas, c, (ARRAYS.into(), ARRAYS.into())))
        }
        Input::Bag(b) => {
            let name = b.path.display().to_string();
            let described = format!("ROS 2 bag `{name}`");
            let g = crate::bag::calibrate_from(b, robot, s)?;
            Ok((g.measurements, g.calibration, (name, described)))
        }
    }
}

impl Calibration {
    /// Writes the calibrated robot in `format` to `path`, refused when the
    /// library's verdict refuses it (a fit that did not converge, or that
    /// made another robot of this one), as the command line does.
    fn write_as(&self, format: Format, path: &std::path::Path, overwrite: bool) -> PyResult<()> {
        // The command line's verdict, from the library: the same refusals
        // with the same message.
        if let Some(why) = self.verdict.refusal() {
            return Err(crate::errors::new_err(
                crate::errors::Kind::Computation,
                format!("{}: not written: {why}", path.display()),
            ));
        }
        write_robot(
            format,
            &self.robot,
            &self.id.table,
            self.frames.as_ref().map(|(f, r)| (f, r)),
            "# Calibrated by activecal (Python).\n",
            path,
            overwrite,
            &[],
        )
    }
}

/// Writes a calibrated robot (`table`, with its frames when it has them) as
/// `format` to `path` after `header`, atomically; an existing file only with
/// `overwrite`, and never an input of the call that made it (`inputs`, and
/// the robot's own URDF), even with `overwrite`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn write_robot(
    format: Format,
    robot: &activecal::model::Robot,
    table: &activecal::model::ParamTable,
    frames: Option<(&CalibratedFrames, &FramesReport)>,
    header: &str,
    path: &std::path::Path,
    overwrite: bool,
    inputs: &[&std::path::Path],
) -> PyResult<()> {
    let calibrated = activecal::write::calibrated::CalibratedRobot {
        robot,
        table,
        frames,
        header,
    };
    calibrated
        .write(
            format,
            activecal::io::atomic::Output {
                label: "path",
                path,
            },
            overwrite,
            inputs,
        )
        .map_err(|e| crate::convert::Fail::from(e).into_py())
}

#[pymethods]
impl Calibration {
    /// Pickling: made again by the same call with the same arguments
    /// (deterministic: the same result; the robot's files read again).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        self.recipe.reduce(py)
    }
    /// Whether the fit converged (only then is the estimate trustworthy and
    /// the robot written).
    #[getter]
    fn converged(&self) -> bool {
        self.id.converged()
    }

    /// The estimate: {parameter name: value} in metres and radians.
    #[getter]
    fn estimate<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report["estimate"])
    }

    /// Standard deviations of the estimate, {name: σ} in metres and
    /// radians; None for a rank-deficient fit.
    #[getter]
    fn sigma<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report["std"])
    }

    /// Errors of the fitted model on the data: position_rms_mm,
    /// position_max_mm, orientation_rms_deg (full poses), per pose, ….
    #[getter]
    fn residuals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report["residuals"])
    }

    /// Held-out evidence (with `holdout`): each split's errors of the fitted
    /// and the nominal model on the poses it did not see, and their means
    /// (mm, degrees); None without `holdout`.
    #[getter]
    fn holdout<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report["holdout"])
    }

    /// The residual blocks' σ's the fit weighed by (position in mm,
    /// orientation in degrees, each marker), with their degrees of freedom.
    #[getter]
    fn noise<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report["noise"])
    }

    /// The calibrated robot in the URDF's terms (URDF robots): the
    /// measurement frame, the tool or markers and each joint origin's
    /// change with σ — the dict the frames file holds; None otherwise.
    #[getter]
    fn frames<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report["frames"])
    }

    /// The whole report: the dict `activecal calibrate --measurements FILE
    /// --json` prints (here "measurements" names the arrays, not a file).
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.report)
    }

    /// Writes the calibrated robot as URDF: the robot's own URDF with only
    /// the chain's joint origins changed (a built-in robot: its chain as
    /// URDF). Refused when the fit did not converge.
    #[pyo3(signature = (path, overwrite=true))]
    fn write_urdf(&self, path: std::path::PathBuf, overwrite: bool) -> PyResult<()> {
        self.write_as(Format::Urdf, &path, overwrite)
    }

    /// Writes the frames file (YAML): measurement frame, tool or markers and
    /// joint-origin changes with σ, metres and degrees as the command line
    /// writes it. URDF robots only; refused when the fit did not converge.
    #[pyo3(signature = (path, overwrite=true))]
    fn write_frames(&self, path: std::path::PathBuf, overwrite: bool) -> PyResult<()> {
        self.write_as(Format::Yaml, &path, overwrite)
    }

    /// Writes the calibrated joint origins as Universal Robots'
    /// default_kinematics.yaml (per joint x y z in metres, roll pitch yaw in
    /// radians, and a hash), which ur_description's xacro reads. URDF
    /// robots with the six UR joints only; refused when the fit did not
    /// converge.
    #[pyo3(signature = (path, overwrite=true))]
    fn write_ur_kinematics(&self, path: std::path::PathBuf, overwrite: bool) -> PyResult<()> {
        self.write_as(Format::UrKinematics, &path, overwrite)
    }

    /// Writes the calibrated joint origins as the per-joint origins file
    /// (JOINT: {xyz: [m], rpy: [rad]}), for a xacro description to read
    /// with xacro.load_yaml. URDF robots only; refused when the fit did not
    /// converge.
    #[pyo3(signature = (path, overwrite=true))]
    fn write_joint_origins(&self, path: std::path::PathBuf, overwrite: bool) -> PyResult<()> {
        self.write_as(Format::JointOrigins, &path, overwrite)
    }

    /// Writes the joints' zero offsets as a driver takes them: unit "rad"
    /// or "deg" (revolute joints; prismatic ones in metres), sign "add" (q =
    /// q_encoder + offset) or "subtract" (q = q_encoder − offset), as
    /// `--out *joint_offsets.yaml --offset-unit --offset-sign`. URDF robots
    /// only; refused when the fit did not converge.
    #[pyo3(signature = (path, unit="rad", sign="add", overwrite=true))]
    fn write_joint_offsets(
        &self,
        path: std::path::PathBuf,
        unit: &str,
        sign: &str,
        overwrite: bool,
    ) -> PyResult<()> {
        let degrees = match unit {
            "rad" => false,
            "deg" => true,
            other => return Err(arg_err("unit", format!("'{other}': \"rad\" or \"deg\""))),
        };
        let subtract = match sign {
            "add" => false,
            "subtract" => true,
            other => {
                return Err(arg_err(
                    "sign",
                    format!("'{other}': \"add\" or \"subtract\""),
                ));
            }
        };
        let c = activecal::io::kinematics_yaml::OffsetConvention { degrees, subtract };
        self.write_as(Format::JointOffsets(c), &path, overwrite)
    }

    /// The report folder `activecal calibrate --measurements FILE --report
    /// DIR` writes for this fit, written into `path`: report.md,
    /// report.json, the figures (PNG and SVG) and `index.html`, the 3D
    /// page of the measured poses (the nominal and the calibrated robot
    /// overlaid, the measured and fitted points, the residuals magnified,
    /// flagged poses marked). An existing directory is replaced whole;
    /// overwrite=False refuses a non-empty one with `FileError`.
    #[pyo3(signature = (path, overwrite=true))]
    fn write_report(
        &self,
        py: Python<'_>,
        path: std::path::PathBuf,
        overwrite: bool,
    ) -> PyResult<()> {
        let inputs = crate::page::robot_inputs(&self.robot);
        crate::page::write_folder(py, &path, overwrite, &inputs, |dir| {
            self.summary.folder(dir, &self.robot, &self.id)
        })
    }

    /// The 3D page of `write_report`'s folder (`index.html`), shown inline
    /// by Jupyter (a `Page`; its `html` is the page's text, byte for byte
    /// the command line's for the same data).
    fn show(&self, py: Python<'_>) -> PyResult<crate::page::Page> {
        crate::page::page_of(py, |dir| self.summary.folder(dir, &self.robot, &self.id))
    }

    fn __repr__(&self) -> String {
        format!(
            "Calibration({:?}, {:?}, {} iterations)",
            self.robot.name, self.id.status, self.id.iterations
        )
    }
}

/// The errors of a model on measured poses, as `activecal evaluate
/// --measurements FILE --json` prints them (`residuals`): `model` is a
/// `Robot` (for example the calibrated URDF and frames file loaded back) or
/// a `Calibration` (its fitted model). q, points and orientations are as
/// `calibrate` takes them: poses the fit did not see judge it.
#[pyfunction]
#[pyo3(signature = (model, q, points, orientations=None))]
pub fn evaluate<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    points: &Bound<'py, PyAny>,
    orientations: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (robot, table) = if let Ok(c) = model.cast::<Calibration>() {
        let c = c.get();
        (c.robot.clone(), c.id.table.clone())
    } else if let Ok(r) = model.cast::<Robot>() {
        let r = r.get();
        (r.inner.clone(), r.inner.nominal.clone())
    } else {
        return Err(arg_err("model", "a Robot or a Calibration"));
    };
    let wrapper = Robot {
        inner: robot.clone(),
        visibility: None,
        recipe: None,
    };
    let d = data(py, &wrapper, q, points, orientations)?;
    let v = detached(py, move || {
        let meas = Measurements::with_orientations(&robot, d.qs, d.points, d.orientations)?;
        let e = activecal::experiment::measured::evaluate::evaluate(
            &robot,
            &table,
            &meas,
            "the arrays given",
            Vec::new(),
        )?;
        Ok(serde_json::to_value(&e.residuals)?)
    })?;
    json_to_py(py, &v)
}
