//! A bag to [`Measurements`]: the streams read ([`super::series`]), the
//! rests found ([`super::rest`]), the clocks aligned ([`super::clock`]),
//! each measurement averaged over its rest, and a report of every rest with
//! the reason it was left out, if it was.

use super::clock::{self, Offset};
use super::rest::{self, Averaged, RestSettings};
use super::series::{self, Source, Streams};
use super::{Bag, BagError};
use crate::data::Measurements;
use crate::error::{Error, Result};
use crate::model::Robot;
use nalgebra::{Quaternion, UnitQuaternion};
use serde::Serialize;
use std::path::Path;

/// What to read from a bag and how.
#[derive(Clone, Debug, PartialEq)]
pub struct ExtractSettings {
    /// The `sensor_msgs/msg/JointState` topic.
    pub joints: String,
    /// The measurement.
    pub source: Source,
    /// Rest detection and averaging.
    pub rest: RestSettings,
    /// The clock offset (measurement stamp minus joint stamp, s) when
    /// known; estimated from the moves otherwise.
    pub time_offset: Option<f64>,
    /// The largest offset searched for (s).
    pub max_offset: f64,
    /// The design's joint values, when the run followed one: each rest is
    /// matched to the pose it reached.
    pub design: Option<Vec<Vec<f64>>>,
    /// A rest reached a design pose when no joint is further from it than
    /// this (rad, m).
    pub design_tolerance: f64,
}

impl ExtractSettings {
    /// Settings for `joints` and `source` with the default rest detection,
    /// the offset estimated within ±10 s.
    #[must_use]
    pub fn new(joints: &str, source: Source) -> Self {
        Self {
            joints: joints.to_string(),
            source,
            rest: RestSettings::default(),
            time_offset: None,
            max_offset: 10.0,
            design: None,
            design_tolerance: 0.01,
        }
    }
}

impl ExtractSettings {
    /// Refuses a largest clock offset that is no number of seconds ≥ 0, a
    /// design tolerance that is not > 0 and a clock offset given that is
    /// not finite.
    pub fn validate(&self) -> std::result::Result<(), crate::error::SettingError> {
        use crate::error::SettingError;
        if !(self.max_offset.is_finite() && self.max_offset >= 0.0) {
            return Err(SettingError::new(
                "max_offset",
                self.max_offset,
                "give seconds, 0 or more",
            ));
        }
        let tolerance = self.design_tolerance;
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(SettingError::new(
                "design_tolerance",
                tolerance,
                "give a positive number (rad, m)",
            ));
        }
        match self.time_offset {
            Some(o) if !o.is_finite() => Err(SettingError::new(
                "time_offset",
                o,
                "not a number of seconds",
            )),
            _ => Ok(()),
        }
    }
}

/// How the clock offset was settled.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClockReport {
    /// The offset applied (measurement stamp minus joint stamp, s).
    pub applied: f64,
    /// Whether it was given rather than estimated.
    pub given: bool,
    /// The estimate from the moves, when made.
    pub estimate: Option<Offset>,
    /// Why the estimate was or was not applied.
    pub note: String,
}

/// One rest of the run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RestRecord {
    /// Its period on the joint clock (s).
    pub rest: rest::Rest,
    /// The averages, when the measurement was seen.
    pub averaged: Option<Averaged>,
    /// Why it was left out (`None`: kept).
    pub left_out: Option<String>,
    /// The design pose it reached (0-based), with a design.
    pub design_pose: Option<usize>,
}

/// A design pose that no kept rest gives.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MissingPose {
    /// The design pose (0-based).
    pub pose: usize,
    /// Why: no rest reached it, or its rest was left out (and why).
    pub reason: String,
}

/// What an extraction found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ExtractReport {
    /// The bag.
    pub bag: String,
    /// The joint topic.
    pub joints: String,
    /// The measurement's source.
    pub source: String,
    /// Joint samples read and their median rate (Hz).
    pub joint_samples: usize,
    /// The joints' median rate (Hz).
    pub joint_rate: f64,
    /// Measurement samples read.
    pub measurement_samples: usize,
    /// The measurement's median rate (Hz).
    pub measurement_rate: f64,
    /// The clocks.
    pub clock: ClockReport,
    /// Every rest, in time order.
    pub rests: Vec<RestRecord>,
    /// Median scatter of the kept rests' samples, per coordinate (m): the
    /// measured noise of one sample.
    pub scatter: f64,
    /// Median standard error of the kept rests' averages, per coordinate
    /// (m): the noise the fit should see (scatter / √samples).
    pub averaged_noise: f64,
    /// Median orientation scatter of one sample, per axis (rad; poses).
    pub orientation_scatter: Option<f64>,
    /// The design's poses that no kept rest gives (with a design).
    pub missing_design_poses: Vec<MissingPose>,
    /// The settings used.
    pub settings: RestSettings,
}

impl ExtractReport {
    /// Rests kept.
    #[must_use]
    pub fn kept(&self) -> usize {
        self.rests.iter().filter(|r| r.left_out.is_none()).count()
    }
}

/// The measurements and the report.
#[derive(Clone, Debug)]
pub struct Extracted {
    /// One pose per kept rest (radians, metres; orientations for poses).
    pub measurements: Measurements,
    /// What was found.
    pub report: ExtractReport,
}

fn rate(t: &[f64]) -> f64 {
    let dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let m = rest::median(&dt);
    if m > 0.0 { 1.0 / m } else { 0.0 }
}

/// Reads the bag at `path` for `robot` (its joints by name) and returns one
/// measurement per rest.
pub fn extract(path: &Path, robot: &Robot, s: &ExtractSettings) -> Result<Extracted> {
    s.rest.check().map_err(Error::Invalid)?;
    let bag = Bag::open(path)?;
    let names = crate::io::measurements::joint_names(robot);
    let streams = {
        let _task = crate::progress::Task::start("reading the bag", None);
        series::read(&bag, &s.joints, &names, &s.source)?
    };
    let rests = rest::find_rests(&streams.joints, &s.rest);
    if rests.is_empty() {
        return Err(BagError::Content {
            bag: bag.name().to_string(),
            message: format!(
                "no rest period on '{}': no {} s or longer where every joint's speed stays under {} rad/s (or m/s)",
                s.joints, s.rest.min_duration, s.rest.speed
            ),
        }
        .into());
    }
    let clock = settle_clock(robot, &streams, &rests, s);
    let mut records = judge(&streams, &rests, &s.rest, clock.applied);
    let missing = match &s.design {
        Some(d) => match_design(&mut records, d, s.design_tolerance),
        None => Vec::new(),
    };
    let mut got = assemble(&bag, &streams, records, clock, s, robot)?;
    got.report.missing_design_poses = missing;
    Ok(got)
}

/// Matches each rest to the design pose it reached; a kept rest that
/// reached none is left out. Returns the design poses no kept rest gives.
fn match_design(records: &mut [RestRecord], design: &[Vec<f64>], tol: f64) -> Vec<MissingPose> {
    use super::design::nearest;
    for r in records.iter_mut() {
        let Some(a) = &r.averaged else { continue };
        match nearest(&a.q, design) {
            Some((k, far)) if far <= tol => r.design_pose = Some(k),
            Some((k, far)) if r.left_out.is_none() => {
                r.left_out = Some(format!(
                    "reached no pose of the design (the nearest, pose {}, is {far:.4} rad or m away at one joint)",
                    k + 1
                ));
            }
            _ => {}
        }
    }
    (0..design.len())
        .filter(|&k| {
            !records
                .iter()
                .any(|r| r.design_pose == Some(k) && r.left_out.is_none())
        })
        .map(|k| {
            let left = records
                .iter()
                .enumerate()
                .find(|(_, r)| r.design_pose == Some(k));
            let reason = match left {
                Some((j, r)) => format!(
                    "its rest ({}) was left out: {}",
                    j + 1,
                    r.left_out.as_deref().unwrap_or("")
                ),
                None => "no rest reached it".to_string(),
            };
            MissingPose { pose: k, reason }
        })
        .collect()
}

/// The offset: the one given, else the estimate when it is significant
/// (more than twice its uncertainty and over 1 ms).
fn settle_clock(
    robot: &Robot,
    st: &Streams,
    rests: &[rest::Rest],
    s: &ExtractSettings,
) -> ClockReport {
    if let Some(o) = s.time_offset {
        return ClockReport {
            applied: o,
            given: true,
            estimate: None,
            note: "given".into(),
        };
    }
    let estimate = clock::estimate(robot, &st.joints, &st.meas, rests, s.max_offset);
    let (applied, note) = match &estimate {
        None => (
            0.0,
            "not estimated (fewer than two moves seen by both streams); none applied".to_string(),
        ),
        Some(e) if e.seconds.abs() > (2.0 * e.uncertainty).max(1e-3) => (
            e.seconds,
            "estimated from the moves and applied".to_string(),
        ),
        Some(_) => (
            0.0,
            "estimated from the moves; not significant, none applied".to_string(),
        ),
    };
    ClockReport {
        applied,
        given: false,
        estimate,
        note,
    }
}

/// Averages every rest and leaves out those with no measurement, a gap, or
/// a scatter far above the median's.
fn judge(st: &Streams, rests: &[rest::Rest], s: &RestSettings, offset: f64) -> Vec<RestRecord> {
    let dt = {
        let r = rate(&st.meas.t);
        if r > 0.0 { 1.0 / r } else { f64::INFINITY }
    };
    let mut out: Vec<RestRecord> = rests
        .iter()
        .map(|r| {
            let averaged =
                rest::average(&st.joints, &st.meas, r, [s.settle, s.window / 2.0], offset);
            let left_out = match &averaged {
                None => Some("no measurement during the rest".to_string()),
                Some(a) if a.longest_gap > s.max_gap_intervals * dt => Some(format!(
                    "a gap of {:.3} s in the measurement ({:.0} sample intervals)",
                    a.longest_gap,
                    a.longest_gap / dt
                )),
                Some(a) if a.samples < 3 => Some(format!("{} measurement sample(s)", a.samples)),
                Some(_) => None,
            };
            RestRecord {
                rest: *r,
                averaged,
                left_out,
                design_pose: None,
            }
        })
        .collect();
    let scatters: Vec<f64> = out
        .iter()
        .filter(|r| r.left_out.is_none())
        .filter_map(|r| r.averaged.as_ref().map(|a| a.scatter))
        .collect();
    let med = rest::median(&scatters);
    for r in out.iter_mut().filter(|r| r.left_out.is_none()) {
        let a = r.averaged.as_ref().expect("kept rests are averaged");
        if med > 0.0 && a.scatter > s.max_scatter_ratio * med {
            r.left_out = Some(format!(
                "scatter {:.4} mm, {:.1}× the median rest's {:.4} mm (a glitch or a vibration)",
                a.scatter * 1e3,
                a.scatter / med,
                med * 1e3
            ));
        }
    }
    out
}

fn rotation(q: [f64; 4]) -> [[f64; 3]; 3] {
    let u = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
    let m = u.to_rotation_matrix();
    std::array::from_fn(|i| std::array::from_fn(|k| m[(i, k)]))
}

fn assemble(
    bag: &Bag,
    st: &Streams,
    rests: Vec<RestRecord>,
    clock: ClockReport,
    s: &ExtractSettings,
    robot: &Robot,
) -> Result<Extracted> {
    let kept: Vec<&Averaged> = rests
        .iter()
        .filter(|r| r.left_out.is_none())
        .filter_map(|r| r.averaged.as_ref())
        .collect();
    if kept.is_empty() {
        return Err(bag
            .content_error(format!(
                "{} rest period(s) found, none with a usable measurement from {} (the first: {})",
                rests.len(),
                s.source.label(),
                rests[0].left_out.as_deref().unwrap_or("")
            ))
            .into());
    }
    let qs = kept.iter().map(|a| a.q.clone()).collect();
    let points = kept.iter().map(|a| a.position).collect();
    let orientations = kept
        .iter()
        .filter_map(|a| a.orientation.map(rotation))
        .collect();
    let markers = robot.measurement.markers().max(1);
    let measurements = Measurements::unchecked(qs, markers, points, orientations);
    let med = |f: &dyn Fn(&Averaged) -> Option<f64>| {
        rest::median(&kept.iter().filter_map(|a| f(a)).collect::<Vec<_>>())
    };
    let report = ExtractReport {
        bag: bag.name().to_string(),
        joints: s.joints.clone(),
        source: s.source.label(),
        joint_samples: st.joints.t.len(),
        joint_rate: rate(&st.joints.t),
        measurement_samples: st.meas.t.len(),
        measurement_rate: rate(&st.meas.t),
        clock,
        scatter: med(&|a| Some(a.scatter)),
        averaged_noise: med(&|a| Some(a.scatter / (a.samples as f64).sqrt())),
        orientation_scatter: s.source.is_pose().then(|| med(&|a| a.orientation_scatter)),
        rests,
        missing_design_poses: Vec::new(),
        settings: s.rest.clone(),
    };
    Ok(Extracted {
        measurements,
        report,
    })
}
