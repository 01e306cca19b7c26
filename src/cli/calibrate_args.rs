//! The arguments of `calibrate`, parsed once.

use activecal::options::LossKind;
use activecal::options::Restriction;
use clap::Args;
use std::path::PathBuf;

/// Arguments of the command. The options of measured data conflict with
/// `--design` (clap's `requires = "measurements"` is not checked when an
/// argument that conflicts with `--measurements`, such as `--design`, is
/// given: they were silently ignored); those of measured data from a file
/// or a bag are refused with other data by the acts-on tables
/// (`acts_on.rs`), naming the data given.
#[derive(Args)]
#[command(group(clap::ArgGroup::new("camera_data").args(["observations", "images"])))]
#[command(group(clap::ArgGroup::new("with_joints").args(["images", "bag"]).multiple(true)))]
pub struct CalibrateArgs {
    /// Robot: a built-in name, or a .toml description or .urdf file; append
    /// `:pose` for full-pose measurements (`:NAME` for a sensor registered
    /// by that name).
    #[arg(long, default_value = "puma560", value_parser = super::parse_robot)]
    pub robot: activecal::io::RobotRef,
    /// Design file (JSON with robot, levels, poses), as written by `select`:
    /// measurements are simulated there.
    #[arg(long, required_unless_present_any = ["measurements", "observations", "images", "bag"])]
    pub design: Option<PathBuf>,
    /// Measurement file: identify from these real measurements instead of
    /// simulating a design. CSV (`x1,y1,z1`, `x2,y2,z2`… for several
    /// markers, optional `phix1,phiy1,phiz1` roll-pitch-yaw or
    /// `qw1,qx1,qy1,qz1`, one column per joint named as in the URDF; metres
    /// and radians) or JSON (`qs`, `points`, optional `orientations` or
    /// `quaternions`, `markers`). Several markers per pose calibrate a
    /// marker sensor with one offset per marker; orientations a full pose.
    /// The simulation's options (`--validation`, `--trials`,
    /// `--save-measurements`) do not apply to measured data: refused.
    /// `--noise` is then the sensor's stated σ, tested against the
    /// residuals' σ̂.
    #[arg(
        long,
        conflicts_with_all = ["design", "trials", "save_measurements", "validation"]
    )]
    pub measurements: Option<PathBuf>,
    /// Write the simulated measurements (trial 0 of the seed) to this file,
    /// in a format `--measurements` reads: a .csv as a tracker exports it
    /// (a column per joint, x1,y1,z1 …, qw1,qx1,qy1,qz1 for full poses),
    /// anything else JSON.
    #[arg(long)]
    pub save_measurements: Option<PathBuf>,
    /// Write the calibrated robot, by extension (repeatable): .urdf — your
    /// URDF with only the chain's joint origins changed (a built-in or TOML
    /// robot: its chain as URDF); .yaml — the frames file (measurement
    /// frame, tool or markers, joint origins with σ); .toml — activecal's
    /// description whose tables are the estimate. Written only when the fit
    /// converged.
    #[arg(long)]
    pub out: Vec<PathBuf>,
    /// Replace existing output files.
    #[arg(long)]
    pub force: bool,
    /// Measurement noise σ per coordinate, metres. With --design, the
    /// simulated noise (default 0.01, 1 cm; a full-pose robot's orientation
    /// noise is σ / orientation_scale radians per axis); with
    /// --measurements, the sensor's stated σ: the residuals' σ̂ is tested
    /// against it (χ²) and a warning names the likely causes when they
    /// disagree.
    #[arg(long, allow_negative_numbers = true)]
    pub noise: Option<f64>,
    /// With --measurements of full poses, the tracker's stated orientation
    /// σ per axis, radians: the orientation residuals' σ̂ is tested against
    /// it (χ²) and a warning names the likely causes when they disagree.
    #[arg(long, allow_negative_numbers = true)]
    pub orientation_noise: Option<f64>,
    /// With --observations, the detector's stated σ per pixel coordinate,
    /// px: the pixels' σ̂ is tested against it (χ²), with a warning naming
    /// the likely causes when they disagree, and the gross-error test
    /// is against it.
    #[arg(long, allow_negative_numbers = true)]
    pub pixel_noise: Option<f64>,
    /// Seed of the noise and of the validation poses (default 0); with
    /// --measurements, of the --holdout splits only.
    #[arg(long, value_parser = super::parse_seed, allow_negative_numbers = true)]
    pub seed: Option<u64>,
    /// Noise realisations; more than 1 adds a Monte-Carlo summary.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub trials: usize,
    /// Held-out lattice poses (not in the design) for the validation RMS.
    #[arg(long, default_value_t = 500, allow_negative_numbers = true)]
    pub validation: usize,
    /// Levenberg–Marquardt iteration limit.
    #[arg(long, default_value_t = 200, allow_negative_numbers = true)]
    pub max_iterations: usize,
    /// Plain Levenberg–Marquardt steps, without geodesic acceleration.
    #[arg(long)]
    pub no_geodesic: bool,
    /// Loss of the fit (with --measurements): l2, or huber / cauchy with
    /// --loss-scale; poses the robust loss down-weights are named.
    #[arg(long, value_parser = super::choice::<LossKind>(), default_value_t = LossKind::L2, conflicts_with = "design")]
    pub loss: LossKind,
    /// Scale of a robust loss: a pose's residual norm (metres) where it
    /// turns robust.
    #[arg(long, conflicts_with = "design")]
    pub loss_scale: Option<f64>,
    /// Poses with a gross error (a tracker glitch, a contact seated off its
    /// socket, a misdetected corner or shifted board), found by Baarda's
    /// data snooping on each pose's (contact row's, camera pose's or
    /// point's) residuals at the least-squares fit: `drop` leaves the
    /// flagged one out and refits, one at a time, and lists each with its
    /// test value; `keep` keeps every one.
    #[arg(long, value_enum)]
    pub outliers: Option<OutliersKind>,
    /// The gross-error test's family-wise false-alarm rate: clean data have
    /// a pose flagged this often (in (0, 1); default 0.01).
    #[arg(long)]
    pub outlier_rate: Option<f64>,
    /// Which unknowns to estimate, with --measurements: `all` (the chain's
    /// complete, minimal set) or `offsets` (only the joints' zero offsets,
    /// the measurement frame and the tool; every link length and twist
    /// held at the model's value: what a driver's joint offsets and the
    /// frames file can hold).
    #[arg(long, value_enum)]
    pub unknowns: Option<UnknownsKind>,
    /// Keep closed-form inverse kinematics working on the calibrated model
    /// (with --measurements): hold the parameters that would change the
    /// nominal model's parallel, perpendicular or intersecting joint axes
    /// (listed in the report), fit the rest, and report the full model's
    /// fit of the same data beside it.
    #[arg(long, conflicts_with = "unknowns")]
    pub keep_axis_relations: bool,
    /// The unit of the joint offsets written to `--out *joint_offsets.yaml`
    /// (revolute joints; prismatic ones are in metres).
    #[arg(long, value_enum)]
    pub offset_unit: Option<OffsetUnit>,
    /// How the driver applies the offsets written to `--out
    /// *joint_offsets.yaml`: `add` (q = q_encoder + offset) or `subtract`
    /// (q = q_encoder − offset), q being the description's joint value.
    #[arg(long, value_enum)]
    pub offset_sign: Option<OffsetSign>,
    /// Unknowns to fix at their nominal values (comma-separated names, as
    /// in the estimate), with --measurements.
    #[arg(long, value_delimiter = ',', conflicts_with = "design")]
    pub fix: Vec<String>,
    /// Parameters to estimate besides the chosen unknowns (names such as
    /// `d_arm_3_joint`), with --measurements.
    #[arg(long, value_delimiter = ',', conflicts_with = "design")]
    pub free: Vec<String>,
    /// Held-out validation: fit on a random 1 − F of the poses, evaluate on
    /// the rest (with --measurements; --splits times, seeded by --seed).
    #[arg(long, value_name = "F", conflicts_with = "design")]
    pub holdout: Option<f64>,
    /// Random splits of --holdout.
    #[arg(long, default_value_t = 4, requires = "holdout")]
    pub splits: usize,
    /// With --holdout: also fit a model pruned to the parameters with
    /// |t| >= 2 and compare held-out errors.
    #[arg(long, requires = "holdout")]
    pub compare_pruned: bool,
    /// How a full-pose fit weighs orientations against positions (with
    /// --measurements): `estimated` (the default) estimates each block's σ
    /// from its own residuals and reweights until they agree (variance
    /// components; the σ's are printed with their degrees of freedom);
    /// `fixed` keeps the robot's orientation scale (1 m per rad unless
    /// --orientation-scale).
    #[arg(long, value_enum, default_value = "estimated")]
    pub weights: WeightsKind,
    /// Metres of position error a radian of orientation error counts as
    /// (a full-pose fit's fixed weight); implies --weights fixed.
    #[arg(long, value_name = "M_PER_RAD", conflicts_with = "weights")]
    pub orientation_scale: Option<f64>,
    /// A distance known between two contact points (a file with a `point`
    /// column): `A,B=METRES`, repeatable.
    #[arg(long, value_name = "A,B=METRES", conflicts_with = "design")]
    pub point_distance: Vec<String>,
    /// A known contact plane (a file with a `plane` column): `NAME=nx,ny,nz,d`
    /// (base frame, `n · x = d` in metres; the normal is normalised),
    /// repeatable. Planes not given are unknown and estimated.
    #[arg(long, value_name = "NAME=nx,ny,nz,d", conflicts_with = "design")]
    pub plane: Vec<String>,
    /// Contacts held out by placement (the part of a point's name before
    /// '/'): fit on all placements but one, judge on that one, for each.
    #[arg(
        long,
        value_enum,
        conflicts_with = "design",
        conflicts_with_all = ["train_on", "holdout"]
    )]
    pub holdout_by: Option<HoldoutBy>,
    /// Contacts: fit on this placement alone, judge on each other one.
    #[arg(
        long,
        value_name = "PLACEMENT",
        conflicts_with = "design",
        conflicts_with = "holdout"
    )]
    pub train_on: Option<String>,
    /// Also fit a compliance per revolute joint whose gravity torque (from
    /// the URDF's inertials) varies over the data: the joint deflects by
    /// c·τ(q); reports c, σ, t, k = −1/c and the largest deflection.
    #[arg(long, conflicts_with = "design")]
    pub compliance: bool,
    /// With --holdout: fit with and without compliances on the same splits
    /// and compare held-out errors.
    #[arg(long, requires = "holdout")]
    pub compare_compliance: bool,
    /// Take the links' masses and centres of mass from this URDF (same link
    /// names) instead of the robot's own.
    #[arg(long, value_name = "FILE", conflicts_with = "design")]
    pub inertia: Option<PathBuf>,
    /// A payload on the tip link: KG, or KG@X,Y,Z (metres, tip link frame).
    #[arg(long, value_name = "KG[@X,Y,Z]", value_parser = super::compliance::parse_payload, allow_hyphen_values = true, conflicts_with = "design")]
    pub payload: Option<activecal::io::inertia::Payload>,
    /// Write a report directory: report.md, report.json and figures (PNG
    /// and SVG) of the errors before and after, the held-out splits, the
    /// parameter changes with ±σ and their correlations. An existing
    /// non-empty directory needs --force.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Calibrate from a camera's pixels: a CSV with one row per detected
    /// target point, `pose, <joints as in the URDF>, feature, u, v`
    /// (pixels). Needs --camera-info, --target and --mounting (or
    /// --camera-link); --camera-pose and --target-pose are optional (the
    /// start computed from the pixels when not given).
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with_all = ["design", "measurements", "trials", "save_measurements", "noise", "validation"],
        requires_all = ["camera_info", "target"]
    )]
    pub observations: Option<PathBuf>,
    /// Calibrate from a camera's images: a directory of PNG or JPEG images, a
    /// pattern (`shots/pose_*.png`) or one image. The target's points are
    /// detected in each image (a checkerboard's inner corners, seen whole),
    /// refined with a window under half a square, and fitted as
    /// --observations' pixels are; an image that cannot be used is listed
    /// with its reason. Needs --joints, --camera-info, --target and
    /// --mounting (or --camera-link). With --bag: the bag's
    /// sensor_msgs/msg/Image or CompressedImage topic (raw mono8, rgb8,
    /// bgr8, rgba8, bgra8, PNG or JPEG), of each rest the image nearest its
    /// middle, and --camera-info the bag's CameraInfo topic.
    #[arg(
        long,
        value_name = "DIR|GLOB|TOPIC",
        conflicts_with_all = ["design", "measurements", "observations", "trials", "save_measurements", "noise", "validation"],
        requires_all = ["camera_info", "target"]
    )]
    pub images: Option<PathBuf>,
    /// With --images: the joint values of each image, a CSV `image,<joints
    /// as in the URDF>` with one row per image (its file name). With
    /// --bag: the bag's sensor_msgs/msg/JointState topic (default
    /// /joint_states).
    #[arg(long, value_name = "FILE|TOPIC", requires = "with_joints")]
    pub joints: Option<PathBuf>,
    /// Calibrate from a ROS 2 bag (a rosbag2 folder, or one .mcap or .db3
    /// file): the joints of --joints' topic, the measurement of --points,
    /// --poses or --tf, one pose per rest period (as `extract` finds and
    /// averages them), the clock offset estimated from the moves unless
    /// --time-offset gives it, and estimated again with the calibrated
    /// model (the fit repeated once when it moved by more than its
    /// uncertainty).
    #[arg(
        long,
        value_name = "BAG",
        conflicts_with_all = ["design", "measurements", "observations", "trials", "save_measurements", "validation"],
    )]
    pub bag: Option<PathBuf>,
    /// What to read from --bag and how.
    #[command(flatten)]
    pub from_bag: super::extract::BagOpts,
    /// With --bag: the design the run followed (`select --out`'s file):
    /// each rest is matched to the pose it reached, a rest that reached
    /// none is left out, a pose no rest gives is named.
    #[arg(long, value_name = "FILE", requires = "bag")]
    pub bag_design: Option<PathBuf>,
    /// With --bag-design: a rest reached a design pose when no joint is
    /// further from it than this (rad, m for prismatic joints).
    #[arg(
        long,
        value_name = "RAD",
        default_value_t = 0.01,
        requires = "bag_design"
    )]
    pub design_tolerance: f64,
    /// With --images (files or a bag's topic): write the pixels detected as an observations CSV
    /// (what --observations reads; joint values in radians and metres), to
    /// inspect or edit them. An existing file only with --force.
    #[arg(long, value_name = "FILE.csv", requires = "images")]
    pub save_observations: Option<PathBuf>,
    /// The camera's intrinsics: a ROS camera_info YAML or an OpenCV
    /// calibration YAML (plumb_bob or equidistant fisheye distortion).
    /// With --bag --images: the bag's sensor_msgs/msg/CameraInfo topic.
    #[arg(long, value_name = "FILE|TOPIC", requires = "camera_data")]
    pub camera_info: Option<PathBuf>,
    /// The target's points: a YAML `checkerboard: {rows, cols, square}`
    /// (inner corners, metres), `charuco: {rows, cols, square, marker}`,
    /// `aprilgrid: {rows, cols, tag_size, tag_spacing}` or `points: [{id,
    /// xyz}, …]`.
    #[arg(long, value_name = "FILE", requires = "camera_data")]
    pub target: Option<PathBuf>,
    /// Where the camera is: eye-to-hand (fixed camera, target on the
    /// flange) or eye-in-hand (camera on the flange, fixed target).
    #[arg(long, value_parser = super::choice::<activecal::options::Mounting>(), requires = "camera_data")]
    pub mounting: Option<activecal::options::Mounting>,
    /// A camera on the robot's own link LINK (a head camera) seeing a
    /// target on the tip: the chain from LINK down to where the two
    /// branches of the URDF tree meet and up to the tip is calibrated,
    /// --camera-pose is in LINK, --target-pose in the tip link.
    #[arg(
        long,
        value_name = "LINK",
        requires = "camera_data",
        conflicts_with = "mounting"
    )]
    pub camera_link: Option<String>,
    /// The camera's optical frame (z forward, x right, y down), roughly:
    /// in the base link (eye-to-hand), the tip link (eye-in-hand) or the
    /// camera's link (--camera-link),
    /// metres and radians (rpy as in URDF). The start of the fit: a rough
    /// guess, with every seen point in front of the camera. Optional: when
    /// not given it is computed from the pixels (each pose's target placed
    /// by PnP, then the closed-form hand-eye solution, or from
    /// --target-pose when that is given).
    #[arg(
        long,
        value_name = "X,Y,Z,ROLL,PITCH,YAW",
        allow_hyphen_values = true,
        requires = "camera_data"
    )]
    pub camera_pose: Option<String>,
    /// The target's frame (its points' frame), roughly: in the tip link
    /// (eye-to-hand) or the base link (eye-in-hand), metres and radians.
    /// Optional, as --camera-pose.
    #[arg(
        long,
        value_name = "X,Y,Z,ROLL,PITCH,YAW",
        allow_hyphen_values = true,
        requires = "camera_data"
    )]
    pub target_pose: Option<String>,
    /// With --observations: fit the camera's intrinsics too (fx, fy, cx,
    /// cy and the distortion's coefficients: plumb_bob's k1, k2, p1, p2,
    /// k3 or equidistant's k1 … k4; started from --camera-info),
    /// each reported with its σ.
    #[arg(long, requires = "camera_data")]
    pub refine_intrinsics: bool,
    /// With --refine-intrinsics: write the refined intrinsics as a ROS
    /// camera_info YAML (written only when the fit converged; an existing
    /// file only with --force).
    #[arg(long, value_name = "FILE.yaml", requires = "refine_intrinsics")]
    pub out_camera_info: Option<PathBuf>,
    /// Units of the --measurements file.
    #[command(flatten)]
    pub units: super::units::UnitOpts,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// The options typed on the command line (set after parsing).
    #[arg(skip)]
    pub given: super::acts_on::Given,
}

/// The simulated measurement noise σ when `--noise` is not given, metres.
pub const DEFAULT_NOISE: f64 = 0.01;

impl CalibrateArgs {
    /// `--seed`, 0 when not given.
    pub(super) fn seed(&self) -> u64 {
        self.seed.unwrap_or(0)
    }
}

/// The weights options of `calibrate`.
/// `--offset-unit`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetUnit {
    /// Radians.
    Rad,
    /// Degrees.
    Deg,
}

/// `--offset-sign`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetSign {
    /// q = q_encoder + offset.
    Add,
    /// q = q_encoder − offset.
    Subtract,
}

impl CalibrateArgs {
    /// The unknowns `--unknowns` and `--keep-axis-relations` restrict the
    /// fit to (every unknown by default).
    #[must_use]
    pub fn restriction(&self) -> Restriction {
        match (self.unknowns, self.keep_axis_relations) {
            (_, true) => Restriction::KeepAxisRelations,
            (Some(UnknownsKind::Offsets), false) => Restriction::Offsets,
            _ => Restriction::All,
        }
    }

    /// The joint-offset convention `--offset-unit` and `--offset-sign` name
    /// (radians, added, by default).
    #[must_use]
    pub fn offset_convention(&self) -> activecal::io::kinematics_yaml::OffsetConvention {
        activecal::io::kinematics_yaml::OffsetConvention {
            degrees: self.offset_unit == Some(OffsetUnit::Deg),
            subtract: self.offset_sign == Some(OffsetSign::Subtract),
        }
    }
}

/// `--unknowns`: which unknowns a fit estimates.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnknownsKind {
    /// The chain's complete, minimal set.
    All,
    /// Joint zero offsets, the measurement frame and the tool.
    Offsets,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum WeightsKind {
    /// Each residual block's σ estimated from the data.
    Estimated,
    /// The robot's orientation scale as given.
    Fixed,
}

/// How to hold contacts out.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum HoldoutBy {
    /// By placement: the part of a point's name before '/'.
    Placement,
}

/// What `calibrate --outliers` does with the poses the gross-error test
/// flags.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutliersKind {
    /// Leave each flagged pose out and refit.
    Drop,
    /// Keep every pose.
    Keep,
}

impl CalibrateArgs {
    /// The simulated noise σ (metres): `--noise`, or [`DEFAULT_NOISE`].
    #[must_use]
    pub fn noise(&self) -> f64 {
        self.noise.unwrap_or(DEFAULT_NOISE)
    }

    /// Refuses a stated `--orientation-noise` or `--pixel-noise` that is not
    /// a finite number > 0.
    pub fn check_stated_noises(&self) -> anyhow::Result<()> {
        for (flag, v, unit) in [("--pixel-noise", self.pixel_noise, "px per coordinate")] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0)
            {
                anyhow::bail!(
                    "{flag} {v}: it is the sensor's stated σ, tested against the residuals: give a finite number > 0 ({unit})"
                );
            }
        }
        Ok(())
    }

    /// The outlier choice of `--outliers` and `--outlier-rate`; the rate
    /// with `--outliers keep`, or either with a robust `--loss` (which keeps
    /// every pose), is refused.
    pub fn outlier_choice(&self) -> anyhow::Result<activecal::options::OutlierChoice> {
        use activecal::options::OutlierChoice;
        if let (Some(OutliersKind::Keep), Some(r)) = (self.outliers, self.outlier_rate) {
            anyhow::bail!(
                "--outlier-rate {r}: is the rate of the test that drops poses; with --outliers keep no pose is dropped"
            );
        }
        if self.loss != LossKind::L2 && (self.outliers.is_some() || self.outlier_rate.is_some()) {
            anyhow::bail!(
                "--outliers and --outlier-rate test the least-squares fit; --loss {} down-weights poses instead and keeps them all",
                self.loss
            );
        }
        Ok(match self.outliers.unwrap_or(OutliersKind::Drop) {
            OutliersKind::Drop => OutlierChoice::Drop {
                alpha: self
                    .outlier_rate
                    .unwrap_or(activecal::options::DEFAULT_OUTLIER_ALPHA),
            },
            OutliersKind::Keep => OutlierChoice::Keep,
        })
    }
}
