//! Calibration from measured data, as one pipeline: the measurement file
//! read and checked, the start mounted in the data's frame when the nominal
//! model is far from it, the unknowns the data cannot see fixed, the fit
//! (with a loss, compliances if asked), residuals, parameter significance
//! and held-out splits, in one typed report ([`MeasuredReport`]). The
//! command line parses its options into [`MeasuredSettings`] and renders
//! the report.

use super::paper::ExperimentError;
use crate::data::Measurements;
use crate::identify::compliance::{ComplianceComparison, compare, with_compliance};
use crate::identify::evaluation::ModelErrors;
use crate::identify::{
    Fit, HoldoutSettings, LmSettings, LossChoice, SplitResult, for_measurements, holdout,
    prepare_for_data, residuals, trust,
};
use crate::lsq::outliers::OutlierChoice;
use crate::model::gravity::GravityModel;
use crate::model::{ParamTable, Robot};
pub use crate::report::measured::{
    HoldoutReport, MeasuredReport, NoiseReport, OutlierReport, PREDICTION_CONFIGURATIONS,
    PrunedReport, Stat,
};
use holdout::holdout_report;
use nalgebra::Vector3;
use screen::screen;

pub mod evaluate;
pub mod full_model;
mod holdout;
mod screen;
pub mod summary;
pub mod verdict;
use std::path::Path;
use std::sync::Arc;

/// What a calibration from measurements does beyond the plain fit.
#[derive(Clone, Debug)]
pub struct MeasuredSettings {
    /// Levenberg–Marquardt settings.
    pub lm: LmSettings,
    /// The loss.
    pub loss: LossChoice,
    /// Unknowns to fix at their nominal values (the user's).
    pub fix: Vec<String>,
    /// Which unknowns are fitted: all, or a model that holds some (the
    /// links' offsets only, or the axis relations kept); with a restriction
    /// the full model is fitted to the same data beside it
    /// ([`full_model::FullModelGain`], in the report).
    pub restriction: crate::identify::restriction::Restriction,
    /// Parameters to add to the unknowns.
    pub free: Vec<String>,
    /// Held-out validation, if asked.
    pub holdout: Option<HoldoutSettings>,
    /// Units of the measurement file.
    pub units: crate::units::Units,
    /// The gravity model, when compliances are fitted or compared.
    pub gravity: Option<Arc<GravityModel>>,
    /// Fit a compliance per joint whose gravity torque varies.
    pub fit_compliance: bool,
    /// With held-out splits: fit with and without compliances, side by side.
    pub compare_compliance: bool,
    /// How the fit weighs its residual blocks.
    pub weights: crate::identify::Weights,
    /// What happens to poses the gross-error test flags (with least
    /// squares; a robust loss keeps every pose).
    pub outliers: OutlierChoice,
    /// The sensor's stated σ per position coordinate (metres), tested
    /// against the fit's σ̂ ([`crate::identify::variance::NoiseTest`]).
    pub stated_noise: Option<f64>,
    /// The stated σ per orientation axis (radians, full poses), tested
    /// against the orientation block's σ.
    pub stated_orientation_noise: Option<f64>,
}

/// A calibration from measurements: the robot as fitted, the fit, its
/// calibrated frames (URDF robots), its report and the verdict on it.
pub struct MeasuredCalibration {
    /// The robot the data were fitted as (mounted, with fixed and freed
    /// unknowns).
    pub robot: Robot,
    /// The fit.
    pub fit: Fit,
    /// The calibrated frames of a URDF robot at the estimate, with σ.
    pub frames: Option<(
        crate::frames::CalibratedFrames,
        crate::frames::report::FramesReport,
    )>,
    /// The report.
    pub report: MeasuredReport,
    /// Whether the calibrated robot may be written.
    pub verdict: verdict::Verdict,
}

/// Reads a measurement file (CSV or JSON) for `robot` in `units`; positions
/// beyond the robot's reach are refused
/// ([`crate::identify::evaluation::check_in_reach`]), a marker that repeats
/// another in every row is counted once. Returns the measurements and
/// notes on what was read.
pub fn read_measurement_file(
    path: &Path,
    robot: &Robot,
    units: crate::units::Units,
) -> Result<(Measurements, Vec<String>), crate::identify::IdentifyError> {
    let f = crate::io::measurements::read_in(path, robot, units)?;
    crate::identify::evaluation::check_in_reach(
        robot,
        &f.measurements,
        &path.display().to_string(),
        units.length,
    )?;
    let mut notes = f.notes;
    let (meas, repeats) = f.measurements.without_repeated_markers();
    for (copy, of) in repeats {
        notes.push(format!(
            "marker {} repeats marker {} in every row: counted once ({} markers per pose)",
            copy + 1,
            of + 1,
            meas.markers()
        ));
    }
    Ok((meas, notes))
}

/// The calibrated model's predicted error at random configurations, from
/// the covariance `σ̂² (XᵀX)⁻¹` of the fit `id` of `robot` to `meas`: the
/// same propagation as `select`'s prediction
/// ([`crate::how_many::predicted_errors`]) with the information of the
/// poses measured, at the estimate, and σ̂ for σ.
fn predicted_after_fit(
    robot: &Robot,
    id: &crate::identify::Identification,
    meas: &Measurements,
) -> Option<crate::how_many::PredictedErrors> {
    let sigma = id.sigma_hat.filter(|s| s.is_finite() && *s > 0.0)?;
    id.covariance.as_ref()?;
    let qs = meas.qs();
    let x = crate::blocks::jacobian_of(robot, &id.table, qs.len(), |k, q| {
        q.copy_from_slice(&qs[k]);
    });
    let info = x.information(&(0..qs.len()).collect::<Vec<_>>());
    let eval_qs = crate::how_many::random_configurations(robot, PREDICTION_CONFIGURATIONS, 0);
    let eval = crate::blocks::jacobian_of(robot, &id.table, eval_qs.len(), |k, q| {
        q.copy_from_slice(&eval_qs[k]);
    });
    crate::how_many::predicted_errors(robot, &eval, info.as_ref(), sigma)
}

/// How much better the rigid fit of the nominal points must fit the data
/// than the nominal model does before identification starts from it: a
/// tracker metres away and turned by tens of degrees gains 450–4,000×
/// (`tests/frames.rs`), where Levenberg–Marquardt from the nominal model
/// ends in a false minimum; FIGAROH's real TIAGo and UR10 data gain 125×
/// and 38× and converge from the nominal model, as before.
const MOUNT_GAIN: f64 = 200.0;

/// A URDF robot mounted in the data's frame ([`crate::frames::align`]) when
/// the nominal model is far from it, or when single measured points come
/// with no tool point given (a point sensor, no marker): then it is measured
/// as a one-marker sensor whose offset is an unknown from the start, started
/// at the point the rigid placement implies; with a note saying so, and
/// when far, the rigid fit's RMS position error (mm).
fn mounted_start(
    robot: &Robot,
    meas: &Measurements,
) -> Result<Option<(Robot, String, Option<f64>)>, crate::Error> {
    let Some(src) = robot.source.as_ref() else {
        return Ok(None);
    };
    let Some(a) = crate::frames::align::measurement_frame(robot, meas) else {
        return Ok(None);
    };
    let far = a.rms_after * MOUNT_GAIN < a.rms_before;
    let tool_unknown = single_point(robot, meas);
    if !far && !tool_unknown {
        return Ok(None);
    }
    let tool: [f64; 3] = a.tool.translation.vector.into();
    // The tool point the data imply is that of the rigid placement: start
    // from both (a placement near the nominal one changes little).
    let mount = a.motion * src.mount;
    let after = if tool_unknown {
        src.tool
    } else {
        src.tool * a.tool
    };
    let mut r = crate::io::urdf::remount(robot, mount, after)?;
    let mut notes = Vec::new();
    if far {
        let t = mount.translation.vector;
        notes.push(format!(
            "the data are far from the nominal model (RMS {:.1} mm): identification starts from the measurement frame that fits them best (RMS {:.1} mm), {:.3} m away and turned {:.1}°",
            a.rms_before * 1e3,
            a.rms_after * 1e3,
            t.norm(),
            mount.rotation.angle().to_degrees()
        ));
    }
    if tool_unknown {
        // One marker at the data's point: its three coordinates are unknowns
        // chosen before the joint origins (`Robot::with_markers`), so no
        // joint origin absorbs a tool off the last axis, where the polar
        // `a`, `γ` of the last frames are singular. Nominal and start alike
        // hold the point the data imply: no other was given.
        r = r.with_markers(&[tool])?;
        notes.push(format!(
            "single points and {}: the measured point on '{}' is an unknown (3 coordinates, chosen before the joint origins), started where the data put it, [{:.1}, {:.1}, {:.1}] mm (rigid fit RMS {:.3} mm); {} unknowns",
            crate::names::phrase::NO_TOOL_POINT,
            src.tip,
            tool[0] * 1e3,
            tool[1] * 1e3,
            tool[2] * 1e3,
            a.rms_after * 1e3,
            r.n_params()
        ));
    }
    Ok(Some((
        r,
        notes.join("; "),
        far.then_some(a.rms_after * 1e3),
    )))
}

/// For a one-marker robot and single-point data whose given offset is far
/// from where the data put it (more than [`MARKER_FAR`] times the rigid
/// fit's RMS, and over a millimetre): the data's offset, to start from,
/// with a note; `None` otherwise (the given offset is the start). The
/// nominal (the user's offset) is kept for the report.
fn marker_start(robot: &Robot, meas: &Measurements) -> Option<([f64; 3], String)> {
    let sensor = crate::measure::sensor_for(robot);
    let one = sensor.tool_record() == crate::measure::ToolRecord::Markers
        && sensor.points_per_pose() == 1
        && meas.markers() == 1
        && meas.orientations().is_empty();
    if !one {
        return None;
    }
    let a = crate::frames::align::measurement_frame(robot, meas)?;
    let given = Vector3::from(*robot.nominal.markers.first()?);
    let implied = a.tool.translation.vector;
    let off = (implied - given).norm();
    if !(off > MARKER_FAR * a.rms_after && off > 1e-3) {
        return None;
    }
    let note = format!(
        "the marker given, [{:.1}, {:.1}, {:.1}] mm, is {:.1} mm from where the data put it: identification starts from [{:.1}, {:.1}, {:.1}] mm (rigid fit RMS {:.3} mm)",
        given[0] * 1e3,
        given[1] * 1e3,
        given[2] * 1e3,
        off * 1e3,
        implied[0] * 1e3,
        implied[1] * 1e3,
        implied[2] * 1e3,
        a.rms_after * 1e3
    );
    Some((implied.into(), note))
}

/// A given marker is far from the data's when it is this many times the
/// rigid fit's RMS residual away.
const MARKER_FAR: f64 = 10.0;

/// Whether the robot measures one point per pose and the data hold only
/// that (no orientation, one marker): the tool point was not given.
fn single_point(robot: &Robot, meas: &Measurements) -> bool {
    crate::measure::sensor_for(robot).follows_tool_point()
        && meas.markers() == 1
        && meas.orientations().is_empty()
}

/// Identification from the measurement file `path`: each note is passed
/// to `on_note` as it is found (what was read, the mount, the start) and
/// kept in the report.
pub fn calibrate_measured(
    robot: &Robot,
    path: &Path,
    s: &MeasuredSettings,
    on_note: &mut dyn FnMut(&str),
) -> Result<MeasuredCalibration, ExperimentError> {
    let (meas, read_notes) = read_measurement_file(path, robot, s.units)?;
    let source = path.display().to_string();
    calibrate_read(robot, &meas, &source, read_notes, s, on_note)
}

/// As [`calibrate_measured`], from measurements already in memory (checked
/// as a file's are, [`Measurements::check`] and
/// [`crate::identify::evaluation::check_in_reach`], in metres and radians):
/// `source` names them in errors and in the report (a file's path), `notes`
/// are what their reading found. [`MeasuredSettings::units`] is not used.
pub fn calibrate_measurements(
    robot: &Robot,
    meas: &Measurements,
    source: &str,
    read_notes: Vec<String>,
    s: &MeasuredSettings,
    on_note: &mut dyn FnMut(&str),
) -> Result<MeasuredCalibration, ExperimentError> {
    let in_file = in_source(source);
    meas.check(robot).map_err(|e| in_file(e.into()))?;
    crate::identify::evaluation::check_in_reach(robot, meas, source, crate::units::LengthUnit::M)
        .map_err(in_file)?;
    calibrate_read(robot, meas, source, read_notes, s, on_note)
}

/// An identification error of the measurements named `source`.
fn in_source(
    source: &str,
) -> impl Fn(crate::identify::IdentifyError) -> ExperimentError + Copy + '_ {
    move |error| ExperimentError::InFile {
        path: source.to_string(),
        error,
    }
}

/// The calibration of measurements read by [`read_measurement_file`] (and
/// not checked against `robot`'s sensor: a point robot's data with
/// orientations are fitted as full poses, several markers as markers), as
/// [`calibrate_measured`] does after reading: for a caller that looks at
/// the data before fitting them. `source` names them in errors and in the
/// report, `notes` are what their reading found.
pub fn calibrate_read(
    robot: &Robot,
    meas: &Measurements,
    source: &str,
    read_notes: Vec<String>,
    s: &MeasuredSettings,
    on_note: &mut dyn FnMut(&str),
) -> Result<MeasuredCalibration, ExperimentError> {
    s.validate().map_err(crate::Error::from)?;
    let held = s.with_held(robot)?;
    let fitted = fit_read(robot, meas, source, read_notes, &held, on_note)?;
    beside_full(robot, meas, source, s, &held, fitted)
}

/// The full model's fit beside a restricted one ([`MeasuredSettings::restriction`]),
/// in the report, and the report's exit status.
fn beside_full(
    robot: &Robot,
    meas: &Measurements,
    source: &str,
    user: &MeasuredSettings,
    held: &MeasuredSettings,
    mut c: MeasuredCalibration,
) -> Result<MeasuredCalibration, ExperimentError> {
    c.report.full_model_gain = full_model::beside_full_model(
        robot,
        meas,
        source,
        held,
        &user.fix,
        user.restriction,
        (&c.robot, &c.fit.id.table),
    )?;
    c.report.exit_status = c.verdict.exit_status();
    Ok(c)
}

impl MeasuredSettings {
    /// Refuses a stated noise that is no σ (`noise`, metres per
    /// coordinate; `orientation_noise`, radians per axis: each a finite
    /// number > 0) and an outlier test's rate outside (0, 1); run by
    /// [`calibrate_read`], and by a front end before it reads any data.
    pub fn validate(&self) -> Result<(), crate::error::SettingError> {
        let stated =
            "the sensor's stated σ, tested against the residuals: give a finite number > 0";
        if let Some(v) = self.stated_noise.filter(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(crate::error::SettingError::new(
                "noise",
                v,
                format!("{stated} (metres per coordinate)"),
            ));
        }
        if let Some(v) = self
            .stated_orientation_noise
            .filter(|v| !(v.is_finite() && *v > 0.0))
        {
            return Err(crate::error::SettingError::new(
                "orientation_noise",
                v,
                format!("{stated} (radians per axis)"),
            ));
        }
        Ok(())
    }

    /// These settings with the unknowns [`MeasuredSettings::restriction`]
    /// holds added to those fixed.
    fn with_held(&self, robot: &Robot) -> Result<Self, ExperimentError> {
        let mut held = self.clone();
        held.fix = crate::identify::restriction::with_held(&self.fix, self.restriction, robot)?;
        Ok(held)
    }
}

/// [`calibrate_read`]'s fit with the unknowns held already fixed.
pub(super) fn fit_read(
    robot: &Robot,
    meas: &Measurements,
    source: &str,
    read_notes: Vec<String>,
    s: &MeasuredSettings,
    on_note: &mut dyn FnMut(&str),
) -> Result<MeasuredCalibration, ExperimentError> {
    let in_file = in_source(source);
    let mut notes = Vec::new();
    let mut note = |n: &str| {
        on_note(n);
        notes.push(n.to_string());
    };
    read_notes.iter().for_each(|n| note(n));
    let given = robot;
    let mounted = mounted_start(robot, meas)?;
    let robot = match &mounted {
        Some((r, n, _)) => {
            note(n);
            r
        }
        None => robot,
    };
    let mut start = for_measurements(robot, meas, &s.lm).map_err(in_file)?;
    start.notes.iter().for_each(|n| note(n));
    if let Some((offset, n)) = marker_start(&start.robot, meas) {
        note(&n);
        start.table.markers = vec![offset];
    }

    let (fitted_robot, without) = match (&s.gravity, s.fit_compliance) {
        (Some(g), true) => {
            let (r, w) = with_compliance(&start.robot, g, meas);
            (r, Some(w))
        }
        _ => (start.robot.clone(), None),
    };
    let det =
        prepare_for_data(&fitted_robot, &start.table, meas, &s.fix, &s.free).map_err(in_file)?;
    let screened = screen(&det.robot, &start.table, meas, s).map_err(in_file)?;
    screened.notes.iter().for_each(|n| note(n));
    let weighted = screened.fit;
    let kept_meas = meas.subset(&screened.kept);
    let meas = &kept_meas;
    let noise = NoiseReport {
        weights: s.weights,
        orientation_scale_m_per_rad: weighted.robot.orientation_scale,
        rounds: weighted.rounds,
        blocks: weighted.sigmas,
    };
    let (r, f) = (weighted.robot, weighted.fit);
    let res = residuals(&r, &f.id.table, meas)?;
    let nominal = nominal_residuals(given, mounted.is_some(), &r, meas, &s.lm)?;
    let params = trust(&r, &r.nominal, &f.id);
    let compliance = without.map(|w| crate::identify::compliance::report(&r, &f.id, meas, w));
    let splits = Splits {
        robot,
        given,
        meas,
        s,
    };
    let ho = s.holdout.map(|h| splits.holdout_report(h)).transpose()?;
    let comparison = match (&s.holdout, s.compare_compliance) {
        (Some(h), true) => Some(splits.compliance_comparison(h)?),
        _ => None,
    };
    let predicted = predicted_after_fit(&r, &f.id, meas);
    let noise_test = s.stated_noise.and_then(|sigma| {
        crate::identify::variance::NoiseTest::new(sigma, f.id.sigma_hat?, f.id.dof)
    });
    let orientation_noise_test =
        crate::identify::variance::orientation_test(s.stated_orientation_noise, &noise.blocks);
    let mut warnings: Vec<String> = noise_test.iter().filter_map(|t| t.warning()).collect();
    warnings.extend(orientation_noise_test.iter().filter_map(|t| t.warning()));
    let base =
        crate::report::MeasuredCalibrationReport::new(&r, &f.id, source.to_string(), meas.len());
    let report = MeasuredReport {
        base,
        loss: s.loss,
        residuals: res,
        nominal_residuals: nominal,
        nominal_placed_position_rms_mm: mounted.as_ref().and_then(|m| m.2),
        parameters: params,
        fixed: det.fixed,
        downweighted: f
            .downweighted()
            .into_iter()
            .map(|(i, w)| (screened.kept[i], w))
            .collect(),
        outliers: OutlierReport {
            choice: s.outliers,
            left_out: screened.outliers,
        },
        holdout: ho,
        notes,
        frames: None,
        compliance,
        compliance_comparison: comparison,
        noise,
        predicted,
        noise_test,
        orientation_noise_test,
        warnings,
        full_model_gain: None,
        exit_status: 0,
        bag: None,
    };
    finish(r, f, report)
}

/// The nominal model's errors on the data: with a mounted start, the
/// user's nominal model in the data's frame as given (with the best marker
/// offsets for it), not the start mounted for the fit.
fn nominal_residuals(
    given: &Robot,
    mounted: bool,
    fitted: &Robot,
    meas: &Measurements,
    lm: &LmSettings,
) -> Result<ModelErrors, crate::identify::IdentifyError> {
    if mounted && let Ok(s) = for_measurements(given, meas, lm) {
        return residuals(&s.robot, &s.robot.nominal, meas);
    }
    residuals(fitted, &fitted.nominal, meas)
}

/// Held-out splits of one data set, with the settings' fixed and freed
/// unknowns (and compliances) applied to every split's fit.
struct Splits<'a> {
    /// The robot the data are fitted as (mounted when far).
    robot: &'a Robot,
    /// The user's robot, for the nominal figures.
    given: &'a Robot,
    meas: &'a Measurements,
    s: &'a MeasuredSettings,
}

impl Splits<'_> {
    /// What a split's training fit is prepared as: compliances from `g` if
    /// any, the settings' fixed and freed unknowns (compliance names
    /// dropped when there is no gravity model), the undetermined fixed.
    fn prepare(
        &self,
        g: Option<Arc<GravityModel>>,
    ) -> impl Fn(&Robot, &ParamTable, &Measurements) -> crate::identify::Result<Robot> + use<> {
        // The geometric model has no compliance to fix or free.
        let geometric = |v: &[String]| -> Vec<String> {
            v.iter()
                .filter(|n| g.is_some() || !n.starts_with("c_"))
                .cloned()
                .collect()
        };
        let (fix, free) = (geometric(&self.s.fix), geometric(&self.s.free));
        move |x: &Robot, t: &ParamTable, m: &Measurements| {
            let x = match &g {
                Some(g) => with_compliance(x, g, m).0,
                None => x.clone(),
            };
            prepare_for_data(&x, t, m, &fix, &free).map(|d| d.robot)
        }
    }

    fn run(
        &self,
        h: &HoldoutSettings,
        g: Option<Arc<GravityModel>>,
    ) -> crate::identify::Result<Vec<SplitResult>> {
        let prep = self.prepare(g);
        holdout(
            self.robot,
            self.given,
            self.meas,
            &self.s.lm,
            self.s.loss,
            h,
            &prep,
        )
    }

    /// The held-out figures with the model as fitted.
    fn holdout_report(&self, h: HoldoutSettings) -> crate::identify::Result<HoldoutReport> {
        let g = self.s.gravity.clone().filter(|_| self.s.fit_compliance);
        Ok(holdout_report(h, self.run(&h, g)?))
    }

    /// Held-out errors with and without compliances on the same splits.
    fn compliance_comparison(
        &self,
        h: &HoldoutSettings,
    ) -> crate::identify::Result<ComplianceComparison> {
        let mut plain = *h;
        plain.prune = false;
        let geo = self.run(&plain, None)?;
        let com = self.run(&plain, self.s.gravity.clone())?;
        Ok(compare(&geo, &com))
    }
}

/// The calibration of `report`'s fit `f` of `r`: its calibrated frames
/// (URDF robots, in the report too) and the verdict on it.
fn finish(
    r: Robot,
    f: Fit,
    mut report: MeasuredReport,
) -> Result<MeasuredCalibration, ExperimentError> {
    let fit_block = crate::frames::report::FitBlock {
        poses: report.base.poses,
        position_rms_mm: report.residuals.position_rms_mm,
        orientation_rms_deg: report.residuals.orientation_rms_deg,
    };
    let cov = f.id.covariance.as_ref().map(|c| c.matrix.as_slice());
    let frames = crate::frames::calibrated(&r, &f.id.table, cov, Some(fit_block))?;
    report.frames = frames.as_ref().map(|(_, fr)| fr.clone());
    let verdict = verdict::verdict(
        &r,
        &f.id,
        frames.as_ref().map(|(c, _)| c),
        report.base.poses,
        report.parameters.len() + report.fixed.len(),
    );
    Ok(MeasuredCalibration {
        robot: r,
        fit: f,
        frames,
        report,
        verdict,
    })
}
