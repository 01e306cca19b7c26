//! A camera's images in a bag (issue #52's camera topics): the
//! `sensor_msgs/msg/CameraInfo` message gives the intrinsics, the rests are
//! found on the joint stream ([`super::rest`]), and of each rest the image
//! nearest the middle of its settled part (after the settling time, before
//! its last half speed window, as [`super::rest::average`] averages) goes
//! through the image detection of [`crate::io::images`]; the joint values
//! are their mean over the middle half of that part ([`mean_q`]). The result is the camera's observations, one pose
//! per rest whose image shows the target, as the observations CSV gives
//! them, with a report of every rest.

use super::messages::{self, CameraInfo, ImageData};
use super::rest::{self, Rest, RestSettings};
use super::series::{self, Streams};
use super::{Bag, BagError, RawMessage};
use crate::data::CameraObservations;
use crate::error::{Error, Result};
use crate::io::camera_target::Target;
use crate::io::images::{Board, ImageOutcome, ImageReport, detect_in};
use crate::measure::pinhole::{Distortion, Intrinsics};
use crate::model::Robot;
use serde::Serialize;
use std::path::Path;

/// What to read from a bag for a camera, and how.
#[derive(Clone, Debug, PartialEq)]
pub struct BagImageSettings {
    /// The `sensor_msgs/msg/JointState` topic.
    pub joints: String,
    /// The `sensor_msgs/msg/Image` or `CompressedImage` topic.
    pub images: String,
    /// The `sensor_msgs/msg/CameraInfo` topic (its first message is read).
    pub camera_info: String,
    /// Rest detection (its settling time is skipped before an image is
    /// chosen).
    pub rest: RestSettings,
    /// The camera's clock offset: an image's stamp minus the joint stamp
    /// of the same instant (s).
    pub time_offset: f64,
}

impl BagImageSettings {
    /// Settings for the three topics, the default rest detection, no
    /// clock offset.
    #[must_use]
    pub fn new(joints: &str, images: &str, camera_info: &str) -> Self {
        Self {
            joints: joints.to_string(),
            images: images.to_string(),
            camera_info: camera_info.to_string(),
            rest: RestSettings::default(),
            time_offset: 0.0,
        }
    }
}

/// One rest and what became of its image.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RestImage {
    /// The rest (joint clock, s).
    pub rest: Rest,
    /// The image chosen: its 0-based index on the image topic, when one
    /// fell in the rest's settled part.
    pub image_index: Option<u64>,
    /// Its stamp moved onto the joint clock (s).
    pub image_time: Option<f64>,
    /// The image's detection (its `file` names the rest and the image).
    pub image: ImageReport,
}

/// What was read from the bag.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BagImagesReport {
    /// The bag.
    pub bag: String,
    /// The joint topic.
    pub joints: String,
    /// The image topic.
    pub images: String,
    /// The CameraInfo topic.
    pub camera_info: String,
    /// Joint samples read.
    pub joint_samples: usize,
    /// Images on the topic.
    pub image_count: usize,
    /// The images' median rate (Hz).
    pub image_rate: f64,
    /// The camera from the CameraInfo message.
    pub intrinsics: Intrinsics,
    /// Every rest, in time order.
    pub rests: Vec<RestImage>,
    /// The rest detection used.
    pub settings: RestSettings,
    /// The clock offset applied (s).
    pub time_offset: f64,
}

impl BagImagesReport {
    /// Rests whose image showed the target.
    #[must_use]
    pub fn kept(&self) -> usize {
        self.rests.iter().filter(|r| r.image.pose.is_some()).count()
    }

    /// Every rest's image as the image reader reports it.
    #[must_use]
    pub fn images(&self) -> Vec<ImageReport> {
        self.rests.iter().map(|r| r.image.clone()).collect()
    }
}

/// The camera's observations from a bag, with the intrinsics its
/// CameraInfo gives and the report.
#[derive(Clone, Debug)]
pub struct BagImages {
    /// One pose per rest whose image showed the target (pose id: the
    /// rest's 0-based index).
    pub observations: CameraObservations,
    /// The camera, from the CameraInfo message.
    pub intrinsics: Intrinsics,
    /// What was found.
    pub report: BagImagesReport,
}

/// The camera of a CameraInfo message: its size, camera matrix and
/// distortion (`plumb_bob` with 5 coefficients, or 4, 8, 12, 14 whose
/// rational terms are 0; `equidistant` with 4); an uncalibrated camera
/// (a zero camera matrix) or another model is an error naming it.
pub fn intrinsics(info: &CameraInfo) -> std::result::Result<Intrinsics, String> {
    let k = info.k;
    if k.iter().all(|v| *v == 0.0) {
        return Err("the camera matrix k is all zeros: the camera is not calibrated (calibrate its intrinsics first, or give --camera-info FILE)".into());
    }
    let pinhole = k[1].abs() <= 1e-9 * k[0].abs()
        && k[3] == 0.0
        && k[6] == 0.0
        && k[7] == 0.0
        && (k[8] - 1.0).abs() < 1e-12;
    if !pinhole {
        return Err(format!(
            "k = {k:?} is not a pinhole camera matrix [fx 0 cx; 0 fy cy; 0 0 1] (no skew)"
        ));
    }
    let d = &info.d;
    let distortion = match info.distortion_model.as_str() {
        "plumb_bob"
            if matches!(d.len(), 4 | 5 | 8 | 12 | 14) && d.iter().skip(5).all(|v| *v == 0.0) =>
        {
            Distortion::PlumbBob([d[0], d[1], d[2], d[3], d.get(4).copied().unwrap_or(0.0)])
        }
        "equidistant" if d.len() == 4 => Distortion::Equidistant([d[0], d[1], d[2], d[3]]),
        "plumb_bob" | "equidistant" => {
            return Err(format!(
                "distortion_model '{}' with {} coefficient(s) d = {d:?}: plumb_bob takes k1, k2, p1, p2, k3 (the rational terms 0), equidistant k1, k2, k3, k4",
                info.distortion_model,
                d.len()
            ));
        }
        other => {
            return Err(format!(
                "distortion_model '{other}' is not supported; this camera model reads plumb_bob (k1, k2, p1, p2, k3) and equidistant (k1, k2, k3, k4)"
            ));
        }
    };
    let c = Intrinsics {
        width: info.width,
        height: info.height,
        fx: k[0],
        fy: k[4],
        cx: k[2],
        cy: k[5],
        distortion,
    };
    c.check()?;
    Ok(c)
}

/// The first pass's findings: the joints, the first CameraInfo, and each
/// image's index and stamp.
#[derive(Default)]
struct Scan {
    streams: Streams,
    info: Option<CameraInfo>,
    stamps: Vec<(u64, f64)>,
}

fn decode_image<'a>(bag: &Bag, m: &RawMessage<'a>) -> std::result::Result<ImageData<'a>, BagError> {
    let t = bag
        .topics()
        .iter()
        .find(|t| t.name == m.topic)
        .map_or("", |t| t.msg_type.as_str());
    let r = if t == messages::COMPRESSED_IMAGE {
        messages::compressed_image(m.data)
    } else {
        messages::image(m.data)
    };
    r.map_err(|e| bag.decode_error(m, e))
}

/// Reads the joints, the camera's first CameraInfo and the images' stamps.
fn scan(bag: &Bag, s: &BagImageSettings, names: &[String]) -> std::result::Result<Scan, BagError> {
    bag.topic(&s.joints, &[messages::JOINT_STATE])?;
    bag.topic(&s.images, &[messages::IMAGE, messages::COMPRESSED_IMAGE])?;
    bag.topic(&s.camera_info, &[messages::CAMERA_INFO])?;
    let mut out = Scan::default();
    let mut seen = vec![false; names.len()];
    let wanted = [s.joints.as_str(), s.images.as_str(), s.camera_info.as_str()];
    bag.for_each(&wanted, |m| {
        if m.topic == s.joints {
            series::joint_message(bag, &m, names, &mut seen, &mut out.streams)
        } else if m.topic == s.images {
            let img = decode_image(bag, &m)?;
            out.stamps.push((m.index, img.header.stamp));
            Ok(())
        } else {
            if out.info.is_none() {
                out.info =
                    Some(messages::camera_info(m.data).map_err(|e| bag.decode_error(&m, e))?);
            }
            Ok(())
        }
    })?;
    if let Some(j) = seen.iter().position(|s| !s) {
        return Err(bag.content_error(format!(
            "joint '{}' of the robot is in no message of '{}'",
            names[j], s.joints
        )));
    }
    series::sort_joints(&mut out.streams.joints);
    Ok(out)
}

/// A rest's settled part: after the settling time, and before its last
/// half speed window (a rest's last samples see the next move starting;
/// [`rest::average`]'s window).
fn settled(r: &Rest, s: &RestSettings) -> (f64, f64) {
    (r.start + s.settle, r.end - s.window / 2.0)
}

/// Of each rest, the image nearest the middle of its settled part: its
/// index on the topic and its time on the joint clock.
fn choose(rests: &[Rest], stamps: &[(u64, f64)], s: &BagImageSettings) -> Vec<Option<(u64, f64)>> {
    rests
        .iter()
        .map(|r| {
            let (t0, t1) = settled(r, &s.rest);
            let mid = 0.5 * (t0 + t1);
            stamps
                .iter()
                .map(|&(i, t)| (i, t - s.time_offset))
                .filter(|&(_, t)| (t0..=t1).contains(&t))
                .min_by(|a, b| (a.1 - mid).abs().total_cmp(&(b.1 - mid).abs()))
        })
        .collect()
}

/// The mean joint values over the middle half of a rest's settled part
/// ([`settled`]), around the image chosen. Not the whole part: a rest is
/// found where the joints' speed is under the threshold, and a smooth move
/// starts and ends under it: on the simulated runs of
/// `verify/tests/live_bag_images.rs` (quintic moves, 0.005 rad/s) the rests
/// found reach 0.07–0.5 s past the true rests' ends, where the next move
/// has begun (1e-6 to 1e-5 rad: as much as the detected corners' own
/// error at 0.5 m); the middle half keeps hundreds of samples at 500 Hz.
fn mean_q(st: &Streams, r: &Rest, s: &RestSettings) -> Vec<f64> {
    let j = &st.joints;
    let (t0, t1) = settled(r, s);
    let quarter = 0.25 * (t1 - t0);
    let (a, b) = (
        rest::lower_bound(&j.t, t0 + quarter),
        rest::lower_bound(&j.t, t1 - quarter + 1e-12),
    );
    let rows = &j.q[a.min(j.q.len() - 1)..b.max(a + 1).min(j.q.len())];
    let dof = rows.first().map_or(0, Vec::len);
    (0..dof)
        .map(|k| rows.iter().map(|q| q[k]).sum::<f64>() / rows.len() as f64)
        .collect()
}

/// Reads the camera of the bag at `path` for `robot` (its joints by name)
/// and `target`: one pose per rest whose image shows the target.
pub fn read_bag_images(
    path: &Path,
    robot: &Robot,
    target: &Target,
    s: &BagImageSettings,
) -> Result<BagImages> {
    s.rest.check().map_err(Error::Invalid)?;
    let bag = Bag::open(path)?;
    let board = Board::of(target, &path.display().to_string())?;
    let names = crate::io::measurements::joint_names(robot);
    let found = {
        let _task = crate::progress::Task::start("reading the bag", None);
        scan(&bag, s, &names)?
    };
    let Some(info) = &found.info else {
        return Err(bag
            .content_error(format!(
                "no message on '{}': the camera's intrinsics are unknown",
                s.camera_info
            ))
            .into());
    };
    let intrinsics = intrinsics(info)
        .map_err(|e| bag.content_error(format!("'{}', message 0: {e}", s.camera_info)))?;
    let rests = rest::find_rests(&found.streams.joints, &s.rest);
    if rests.is_empty() {
        return Err(bag
            .content_error(format!(
                "no rest period on '{}': no {} s or longer where every joint's speed stays under {} rad/s (or m/s)",
                s.joints, s.rest.min_duration, s.rest.speed
            ))
            .into());
    }
    let chosen = choose(&rests, &found.stamps, s);
    let mut detected: Vec<Option<std::result::Result<_, String>>> = vec![None; rests.len()];
    let _task = crate::progress::Task::start("detecting the target", None);
    bag.for_each(&[s.images.as_str()], |m| {
        for (k, c) in chosen.iter().enumerate() {
            if c.is_some_and(|(i, _)| i == m.index) {
                let img = decode_image(&bag, &m)?;
                let got = super::image::decode_message(&img)
                    .and_then(|g| detect_in(&g, &board, target.ids.len(), &intrinsics));
                detected[k] = Some(got);
            }
        }
        Ok(())
    })?;
    assemble(&bag, &found, &rests, &chosen, detected, intrinsics, s)
}

type Detection = std::result::Result<(Vec<Option<[f64; 2]>>, ImageOutcome), String>;

fn assemble(
    bag: &Bag,
    found: &Scan,
    rests: &[Rest],
    chosen: &[Option<(u64, f64)>],
    detected: Vec<Option<Detection>>,
    intrinsics: Intrinsics,
    s: &BagImageSettings,
) -> Result<BagImages> {
    let mut obs = CameraObservations {
        origin: format!("{} '{}'", bag.name(), s.images),
        pose_ids: Vec::new(),
        qs: Vec::new(),
        seen: Vec::new(),
    };
    let mut records = Vec::new();
    for (k, (r, d)) in rests.iter().zip(detected).enumerate() {
        let c = chosen[k];
        let file = match c {
            Some((i, _)) => format!("rest {} (image {i})", k + 1),
            None => format!("rest {}", k + 1),
        };
        let outcome = match d {
            None => ImageOutcome::LeftOut {
                reason: format!(
                    "no image on '{}' in the rest after its {} s settling time",
                    s.images, s.rest.settle
                ),
            },
            Some(Err(reason)) => ImageOutcome::LeftOut { reason },
            Some(Ok((seen, outcome))) => {
                obs.pose_ids.push(k as i64);
                obs.qs.push(mean_q(&found.streams, r, &s.rest));
                obs.seen.push(seen);
                outcome
            }
        };
        let pose = matches!(outcome, ImageOutcome::Found { .. }).then_some(k as i64);
        records.push(RestImage {
            rest: *r,
            image_index: c.map(|(i, _)| i),
            image_time: c.map(|(_, t)| t),
            image: ImageReport {
                file,
                pose,
                outcome,
            },
        });
    }
    if obs.pose_ids.is_empty() {
        let why: Vec<String> = records
            .iter()
            .filter_map(|r| match &r.image.outcome {
                ImageOutcome::LeftOut { reason } => Some(format!("{}: {reason}", r.image.file)),
                ImageOutcome::Found { .. } => None,
            })
            .collect();
        return Err(bag
            .content_error(format!(
                "no rest's image could be used:\n  {}",
                why.join("\n  ")
            ))
            .into());
    }
    let t: Vec<f64> = found.stamps.iter().map(|x| x.1).collect();
    let dt: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .collect();
    let m = rest::median(&dt);
    let report = BagImagesReport {
        bag: bag.name().to_string(),
        joints: s.joints.clone(),
        images: s.images.clone(),
        camera_info: s.camera_info.clone(),
        joint_samples: found.streams.joints.t.len(),
        image_count: found.stamps.len(),
        image_rate: if m > 0.0 { 1.0 / m } else { 0.0 },
        intrinsics: intrinsics.clone(),
        rests: records,
        settings: s.rest.clone(),
        time_offset: s.time_offset,
    };
    Ok(BagImages {
        observations: obs,
        intrinsics,
        report,
    })
}
