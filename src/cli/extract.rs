//! `activecal extract BAG`: a ROS 2 bag's rests into the measurement CSV
//! `calibrate --measurements` reads (the library's `io::bag::extract` does
//! the work; here the flags are parsed and the report rendered).

use super::emit_report;
use activecal::io::bag::camera::{BagImageSettings, read_bag_images};
use activecal::io::bag::extract::{ExtractSettings, extract};
use activecal::io::bag::series::Source;
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::PathBuf;

/// The options of `extract`.
#[derive(Args, Debug)]
pub struct ExtractArgs {
    /// The bag: a rosbag2 folder (with its metadata.yaml), or one .mcap or
    /// .db3 file.
    pub bag: PathBuf,
    /// The robot whose joints /joint_states gives (by name) and whose
    /// nominal model predicts the moves for the clock offset.
    #[arg(long, value_parser = super::parse_robot)]
    pub robot: activecal::io::RobotRef,
    /// The bag's sensor_msgs/msg/JointState topic.
    #[arg(long, value_name = "TOPIC", default_value = "/joint_states")]
    pub joints: String,
    /// What to read from the bag and how.
    #[command(flatten)]
    pub from: BagOpts,
    /// A camera's sensor_msgs/msg/Image or CompressedImage topic (raw
    /// mono8, rgb8, bgr8, rgba8, bgra8 or PNG): of each rest, the image
    /// nearest the middle of its settled part is searched for --target,
    /// and --out is the observations CSV `calibrate --observations` reads.
    #[arg(
        long,
        value_name = "TOPIC",
        requires_all = ["camera_info", "target"],
        conflicts_with_all = ["points", "poses", "tf", "max_offset", "design"]
    )]
    pub images: Option<String>,
    /// With --images: the camera's sensor_msgs/msg/CameraInfo topic (its
    /// first message gives the intrinsics).
    #[arg(long, value_name = "TOPIC", requires = "images")]
    pub camera_info: Option<String>,
    /// With --images: the target (the YAML `calibrate --target` reads; a
    /// checkerboard or a ChArUco board).
    #[arg(long, value_name = "FILE", requires = "images")]
    pub target: Option<PathBuf>,
    /// The design the run followed (`select --out`'s .json, .yaml or .csv):
    /// each rest is matched to the pose it reached, a rest that reached
    /// none is left out, a pose no rest gives is named.
    #[arg(long, value_name = "FILE")]
    pub design: Option<PathBuf>,
    /// A rest reached a design pose when no joint is further from it than
    /// this (rad, m for prismatic joints).
    #[arg(long, value_name = "RAD", default_value_t = 0.01, requires = "design")]
    pub design_tolerance: f64,
    /// The measurement CSV to write (what `calibrate --measurements` reads;
    /// with --images, the observations CSV `calibrate --observations`
    /// reads).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// Overwrite --out if it exists (never an input).
    #[arg(long)]
    pub force: bool,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// What to read from a bag and how: the options `extract` and `calibrate
/// --bag` share (each command names the joint topic and the design its
/// own way: `calibrate --design` is the simulation's).
#[derive(Args, Debug, Clone)]
pub struct BagOpts {
    /// A bag's geometry_msgs/msg/PointStamped topic: a tracker's point.
    #[arg(long, value_name = "TOPIC", conflicts_with_all = ["poses", "tf"], requires = "bag")]
    pub points: Option<String>,
    /// A bag's geometry_msgs/msg/PoseStamped or TransformStamped topic: a
    /// motion-capture body's pose.
    #[arg(long, value_name = "TOPIC", conflicts_with = "tf", requires = "bag")]
    pub poses: Option<String>,
    /// The transform PARENT → CHILD of a bag's /tf and /tf_static (static
    /// transforms composed with one moving transform).
    #[arg(long, value_name = "PARENT:CHILD", requires = "bag")]
    pub tf: Option<String>,
    /// The clock offset, seconds: the measurement's stamp minus the joint
    /// stamp of the same instant. Estimated from the moves when not given.
    #[arg(long, value_name = "S", allow_hyphen_values = true, requires = "bag")]
    pub time_offset: Option<f64>,
    /// The largest clock offset searched for, seconds.
    #[arg(long, value_name = "S", default_value_t = 10.0, requires = "bag")]
    pub max_offset: f64,
    /// A joint is at rest under this speed (rad/s, m/s for prismatic).
    #[arg(long, value_name = "SPEED", default_value_t = 0.005, requires = "bag")]
    pub rest_speed: f64,
    /// The shortest rest period, seconds.
    #[arg(long, value_name = "S", default_value_t = 0.5, requires = "bag")]
    pub rest_min: f64,
    /// Seconds left out at the start of each rest while the arm settles.
    #[arg(long, value_name = "S", default_value_t = 0.2, requires = "bag")]
    pub settle: f64,
}

impl BagOpts {
    /// Whether the measurement is a full pose (`--poses`, `--tf`) rather
    /// than a point (`--points`).
    #[must_use]
    pub fn gives_poses(&self) -> bool {
        self.points.is_none()
    }

    /// The settings of a camera's images from the flags, with the joint,
    /// image and CameraInfo topics (the clock offset 0 unless
    /// --time-offset gives it: it is not estimated for a camera).
    pub fn image_settings(
        &self,
        joints: &str,
        images: &str,
        camera_info: &str,
    ) -> Result<BagImageSettings> {
        let mut s = BagImageSettings::new(joints, images, camera_info);
        s.rest.speed = self.rest_speed;
        s.rest.min_duration = self.rest_min;
        s.rest.settle = self.settle;
        if let Some(o) = self.time_offset {
            if !o.is_finite() {
                bail!("--time-offset {o}: not a number of seconds");
            }
            s.time_offset = o;
        }
        Ok(s)
    }

    /// The library's settings from the flags, with the joint topic and
    /// the design's tolerance (rad, m) as the command gives them, checked.
    pub fn settings(&self, joints: &str, design_tolerance: f64) -> Result<ExtractSettings> {
        let source = Source::one_of(
            self.points.as_deref(),
            self.poses.as_deref(),
            self.tf.as_deref(),
        )?;
        let mut s = ExtractSettings::new(joints, source);
        s.rest.speed = self.rest_speed;
        s.rest.min_duration = self.rest_min;
        s.rest.settle = self.settle;
        s.time_offset = self.time_offset;
        s.max_offset = self.max_offset;
        s.design_tolerance = design_tolerance;
        s.validate()?;
        Ok(s)
    }
}

/// Runs `extract`.
pub fn cmd_extract(a: ExtractArgs) -> Result<()> {
    check_out(&a)?;
    if a.images.is_some() {
        return extract_images(&a);
    }
    let mut settings = a.from.settings(&a.joints, a.design_tolerance)?;
    let robot = super::load_robot(&a.robot)?;
    if let Some(d) = &a.design {
        settings.design = Some(activecal::io::bag::design::read_design(d, &robot)?);
    }
    let got = extract(&a.bag, &robot, &settings)?;
    if let Some(out) = &a.out {
        let csv = activecal::io::measurements::to_csv(&got.measurements, &robot);
        activecal::io::atomic::write_atomic(out, csv.as_bytes())?;
    }
    let r = &got.report;
    emit_report(a.json, r, || {
        activecal::render::bag_text::extract_text(r, a.out.as_deref())
    })
}

/// `extract --images`: a camera's observations CSV.
fn extract_images(a: &ExtractArgs) -> Result<()> {
    let (Some(topic), Some(info), Some(target)) = (&a.images, &a.camera_info, &a.target) else {
        bail!("--images needs --camera-info TOPIC and --target FILE");
    };
    let robot = super::load_robot(&a.robot)?;
    let target = activecal::io::camera_target::read_target(target).context("--target")?;
    let s = a.from.image_settings(&a.joints, topic, info)?;
    let got = read_bag_images(&a.bag, &robot, &target, &s)?;
    if let Some(out) = &a.out {
        let csv = activecal::io::camera_observations::observations_csv(
            &got.observations,
            &robot,
            &target,
        );
        activecal::io::atomic::write_atomic(out, csv.as_bytes())?;
    }
    let r = &got.report;
    emit_report(a.json, r, || {
        activecal::render::bag_text::bag_images_text(r, a.out.as_deref())
    })
}

/// Refuses `--out` over an input or inside the bag, before any work.
fn check_out(a: &ExtractArgs) -> Result<()> {
    use activecal::io::atomic::{Output, check_outputs};
    if let Some(out) = &a.out {
        let mut inputs = vec![a.bag.as_path()];
        inputs.extend(a.design.as_deref());
        inputs.extend(a.target.as_deref());
        check_outputs(
            &[Output {
                label: "--out",
                path: out,
            }],
            &inputs,
            a.force,
        )?;
        if out.starts_with(&a.bag) {
            bail!(
                "--out {}: inside the bag {}; choose another place",
                out.display(),
                a.bag.display()
            );
        }
    }
    Ok(())
}
