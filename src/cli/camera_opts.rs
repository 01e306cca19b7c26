//! The camera options of `select` (`camera_select.rs` runs them).

use activecal::options::DEFAULT_MAX_VIEW_ANGLE_DEG;
use clap::Args;
use std::path::PathBuf;

/// The camera options of `select`.
#[derive(Args, Debug, Default)]
pub struct CameraOpts {
    /// Choose poses for a camera (see --target, --mounting, --camera-link): its
    /// intrinsics, a ROS camera_info or OpenCV calibration YAML.
    #[arg(long, value_name = "FILE", requires_all = ["target", "camera_pose", "target_pose"])]
    pub camera_info: Option<PathBuf>,
    /// The camera's target: a YAML checkerboard {rows, cols, square} or
    /// points [{id, xyz}].
    #[arg(long, value_name = "FILE", requires = "camera_info")]
    pub target: Option<PathBuf>,
    /// eye-to-hand or eye-in-hand.
    #[arg(long, value_parser = super::choice::<activecal::options::Mounting>(), requires = "camera_info")]
    pub mounting: Option<activecal::options::Mounting>,
    /// A camera on the robot's own link LINK (a head camera) seeing a
    /// target on the tip (see `calibrate --camera-link`): the poses move
    /// the joints from LINK to the tip; --camera-pose is in LINK.
    #[arg(
        long,
        value_name = "LINK",
        requires = "camera_info",
        conflicts_with = "mounting"
    )]
    pub camera_link: Option<String>,
    /// The camera's optical frame in the base link (eye-to-hand) or the
    /// tip link (eye-in-hand): X,Y,Z,ROLL,PITCH,YAW (metres, radians).
    #[arg(
        long,
        value_name = "X,Y,Z,ROLL,PITCH,YAW",
        allow_hyphen_values = true,
        requires = "camera_info"
    )]
    pub camera_pose: Option<String>,
    /// The target's frame in the tip link (eye-to-hand) or the base link
    /// (eye-in-hand): X,Y,Z,ROLL,PITCH,YAW.
    #[arg(
        long,
        value_name = "X,Y,Z,ROLL,PITCH,YAW",
        allow_hyphen_values = true,
        requires = "camera_info"
    )]
    pub target_pose: Option<String>,
    /// The fraction of the target's points a pose must see.
    #[arg(long, default_value_t = 1.0, requires = "camera_info")]
    pub min_visible: f64,
    /// How far inside the image a seen point must be, pixels.
    #[arg(long, default_value_t = 10.0, requires = "camera_info")]
    pub image_margin: f64,
    /// The largest angle between the target's normal and the line of
    /// sight, degrees.
    #[arg(long, default_value_t = DEFAULT_MAX_VIEW_ANGLE_DEG, requires = "camera_info")]
    pub max_view_angle: f64,
    /// The range of the target's distance from the camera: LO,HI metres.
    #[arg(
        long,
        value_name = "LO,HI",
        default_value = "0.2,3.0",
        requires = "camera_info"
    )]
    pub distance: String,
    /// Keep only configurations whose rays from the camera's centre to the
    /// target's points (stopped 1 mm short) cross none of the URDF's
    /// collision geometry (nor an --obstacle); on whenever --self-collision,
    /// --obstacle or --floor is given. Meshes found as --package-dir says.
    #[arg(long, requires = "camera_info")]
    pub line_of_sight: bool,
    /// The pixel noise σ of the detected points, px: the true error the
    /// design predicts is printed at it (and in --json,
    /// `predicted_error_mm`), and --report's curve uses it [default
    /// there: 0.3 px].
    #[arg(
        long,
        value_name = "PX",
        requires = "camera_info",
        allow_negative_numbers = true
    )]
    pub pixel_noise: Option<f64>,
}
