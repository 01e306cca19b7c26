//! The time series a calibration run records, gathered from a bag in one
//! pass: the joints (from `sensor_msgs/msg/JointState`, in the robot's
//! joint order) and the measurement (points, poses, or a transform of the
//! `/tf` tree), each sorted by its header stamp.

use super::messages::{self, Stamped};
pub use super::timeseries::{JointSeries, MeasSeries};
use super::{Bag, BagError, RawMessage, tf};

/// Where the measurement is in the bag.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A `geometry_msgs/msg/PointStamped` topic (a tracker's point).
    Points(String),
    /// A `geometry_msgs/msg/PoseStamped` or `TransformStamped` topic (a
    /// motion-capture body).
    Poses(String),
    /// The transform from `parent` to `child` of the `/tf` and
    /// `/tf_static` trees.
    Tf {
        /// The frame the measurement is in (the tracker's).
        parent: String,
        /// The measured frame.
        child: String,
    },
}

impl Source {
    /// What the source is, for messages (`topic '/tracker'`, `/tf
    /// world → marker`).
    #[must_use]
    pub fn label(&self) -> String {
        match self {
            Source::Points(t) | Source::Poses(t) => format!("topic '{t}'"),
            Source::Tf { parent, child } => format!("/tf {parent} → {child}"),
        }
    }

    /// Whether the measurement has an orientation.
    #[must_use]
    pub fn is_pose(&self) -> bool {
        !matches!(self, Source::Points(_))
    }

    /// The source of one of a points topic, a poses topic or a transform
    /// `PARENT:CHILD` of /tf (the one given; refused, naming the settings
    /// by their keys, when none or two are given or the transform is not
    /// two frame names).
    pub fn one_of(
        points: Option<&str>,
        poses: Option<&str>,
        tf: Option<&str>,
    ) -> Result<Self, crate::error::SettingError> {
        use crate::error::SettingError;
        match (points, poses, tf) {
            (Some(t), None, None) => Ok(Source::Points(t.to_string())),
            (None, Some(t), None) => Ok(Source::Poses(t.to_string())),
            (None, None, Some(pc)) => match pc.split_once(':') {
                Some((p, c)) if !p.is_empty() && !c.is_empty() => Ok(Source::Tf {
                    parent: p.to_string(),
                    child: c.to_string(),
                }),
                _ => Err(SettingError::new(
                    "tf",
                    pc,
                    "give PARENT:CHILD, two frame names",
                )),
            },
            (None, None, None) => Err(SettingError::because(
                "points",
                "give the bag's measurement: `points` TOPIC, `poses` TOPIC or `tf` PARENT:CHILD",
            )),
            _ => Err(SettingError::because(
                "points",
                "give one measurement of `points`, `poses` and `tf`",
            )),
        }
    }
}

/// The two streams of a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Streams {
    /// The joints.
    pub joints: JointSeries,
    /// The measurement.
    pub meas: MeasSeries,
    /// `JointState` messages that carry none of the robot's joints (another
    /// group's, skipped).
    pub other_joint_messages: u64,
}

/// Reads the joint stream of `joints_topic` (the values of `joint_names`,
/// the robot's joints in order) and the measurement of `source`, in one
/// pass over the bag.
pub fn read(
    bag: &Bag,
    joints_topic: &str,
    joint_names: &[String],
    source: &Source,
) -> Result<Streams, BagError> {
    bag.topic(joints_topic, &[messages::JOINT_STATE])?;
    let mut wanted = vec![joints_topic.to_string()];
    match source {
        Source::Points(t) => {
            bag.topic(t, &[messages::POINT_STAMPED])?;
            wanted.push(t.clone());
        }
        Source::Poses(t) => {
            bag.topic(t, &[messages::POSE_STAMPED, messages::TRANSFORM_STAMPED])?;
            wanted.push(t.clone());
        }
        Source::Tf { .. } => wanted.extend(tf::topics(bag)?),
    }
    let wanted_refs: Vec<&str> = wanted.iter().map(String::as_str).collect();
    let mut out = Streams::default();
    let mut tree = tf::Tree::default();
    let mut seen = vec![false; joint_names.len()];
    bag.for_each(&wanted_refs, |m| {
        if m.topic == joints_topic {
            joint_message(bag, &m, joint_names, &mut seen, &mut out)
        } else {
            match source {
                Source::Points(_) | Source::Poses(_) => {
                    let s = stamped(bag, &m)?;
                    push(&mut out.meas, &s, source.is_pose());
                    Ok(())
                }
                Source::Tf { .. } => tree.add(bag, &m),
            }
        }
    })?;
    if let Some(j) = seen.iter().position(|s| !s) {
        return Err(bag.content_error(format!(
            "joint '{}' of the robot is in no message of '{joints_topic}'",
            joint_names[j]
        )));
    }
    if let Source::Tf { parent, child } = source {
        out.meas = tree.chain(bag, parent, child)?;
    }
    if out.meas.t.is_empty() {
        return Err(bag.content_error(format!("{}: no message", source.label())));
    }
    sort_joints(&mut out.joints);
    sort_meas(&mut out.meas);
    Ok(out)
}

fn stamped(bag: &Bag, m: &RawMessage<'_>) -> Result<Stamped, BagError> {
    let t = bag
        .topics()
        .iter()
        .find(|t| t.name == m.topic)
        .map_or("", |t| t.msg_type.as_str());
    let r = match t {
        messages::POINT_STAMPED => messages::point_stamped(m.data),
        messages::POSE_STAMPED => messages::pose_stamped(m.data),
        _ => messages::transform_stamped(m.data),
    };
    r.map_err(|e| bag.decode_error(m, e))
}

fn push(meas: &mut MeasSeries, s: &Stamped, pose: bool) {
    meas.t.push(s.header.stamp);
    meas.p.push(s.position);
    if pose {
        meas.r.push(s.orientation.unwrap_or([1.0, 0.0, 0.0, 0.0]));
    }
}

/// One `JointState`: all the robot's joints, or none (another group's);
/// a message with some but not all is an error naming the joint missing.
pub(super) fn joint_message(
    bag: &Bag,
    m: &RawMessage<'_>,
    names: &[String],
    seen: &mut [bool],
    out: &mut Streams,
) -> Result<(), BagError> {
    let js = messages::joint_state(m.data).map_err(|e| bag.decode_error(m, e))?;
    let at: Vec<Option<usize>> = names
        .iter()
        .map(|n| js.name.iter().position(|k| k == n))
        .collect();
    if at.iter().all(Option::is_none) {
        out.other_joint_messages += 1;
        return Ok(());
    }
    let mut q = Vec::with_capacity(names.len());
    for (j, k) in at.iter().enumerate() {
        let Some(k) = k else {
            return Err(bag.decode_error(
                m,
                (
                    "name",
                    format!(
                        "joint '{}' of the robot is missing (the message has {})",
                        names[j],
                        js.name.join(", ")
                    ),
                ),
            ));
        };
        let v = js.position[*k];
        if !v.is_finite() {
            return Err(bag.decode_error(m, ("position", format!("joint '{}' is {v}", names[j]))));
        }
        seen[j] = true;
        q.push(v);
    }
    out.joints.t.push(js.header.stamp);
    out.joints.q.push(q);
    Ok(())
}

fn order(t: &[f64]) -> Option<Vec<usize>> {
    if t.windows(2).all(|w| w[0] <= w[1]) {
        return None;
    }
    let mut idx: Vec<usize> = (0..t.len()).collect();
    idx.sort_by(|&a, &b| t[a].total_cmp(&t[b]));
    Some(idx)
}

pub(super) fn sort_joints(j: &mut JointSeries) {
    if let Some(idx) = order(&j.t) {
        j.t = idx.iter().map(|&i| j.t[i]).collect();
        j.q = idx.iter().map(|&i| j.q[i].clone()).collect();
    }
}

fn sort_meas(m: &mut MeasSeries) {
    if let Some(idx) = order(&m.t) {
        m.t = idx.iter().map(|&i| m.t[i]).collect();
        m.p = idx.iter().map(|&i| m.p[i]).collect();
        if !m.r.is_empty() {
            m.r = idx.iter().map(|&i| m.r[i]).collect();
        }
    }
}
