//! Which sensors each option of a command acts on (`calibrate`, `select`,
//! `evaluate`): one table per command, by the option's name (the command
//! line's option id, the Python keyword argument's name). An option given
//! with a sensor it does not act on is refused — by the command line naming
//! its flag, by the Python package naming the keyword — so no option is
//! accepted and ignored. The tables name no flag; what to say instead is
//! the caller's.

use serde::Serialize;

/// What a command works for: the sensor of its data or of its design.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Sensor {
    /// Calibration from measurements simulated at a design.
    Simulated,
    /// Calibration from measured points (no orientations).
    Points,
    /// Calibration from measured full poses (with orientations).
    Poses,
    /// Calibration from contacts (a point or plane per row).
    Contacts,
    /// Calibration from a camera's pixels.
    Pixels,
    /// Calibration from a camera's images (its pixels detected by
    /// activecal).
    Images,
    /// Calibration from points read from a ROS 2 bag (a tracker's
    /// topic): measured points whose source is a bag, not a file.
    BagPoints,
    /// Calibration from full poses read from a ROS 2 bag (a
    /// motion-capture topic or a transform of /tf).
    BagPoses,
    /// Calibration from a camera's images read from a ROS 2 bag (an image
    /// topic and its CameraInfo; the target detected by activecal).
    BagImages,
    /// Selection from a pool of poses (points, markers or full poses).
    Pool,
    /// Selection of configurations touching sockets.
    Sockets,
    /// Selection of poses for a camera.
    Camera,
}

impl Sensor {
    /// The sensor in a few words (no flag), for messages.
    #[must_use]
    pub fn words(self) -> &'static str {
        match self {
            Sensor::Simulated => "simulated measurements",
            Sensor::Points => "measured points (no orientations)",
            Sensor::Poses => "measured full poses (with orientations)",
            Sensor::Contacts => "contacts",
            Sensor::Pixels => "a camera's pixels",
            Sensor::Images => "a camera's images",
            Sensor::BagPoints => "points read from a ROS 2 bag",
            Sensor::BagPoses => "full poses read from a ROS 2 bag",
            Sensor::BagImages => "a camera's images read from a ROS 2 bag",
            Sensor::Pool => "a pool of poses",
            Sensor::Sockets => "configurations touching sockets",
            Sensor::Camera => "poses chosen for a camera",
        }
    }
}

/// One option's row: its name and the sensors it acts on.
#[derive(Clone, Copy, Debug)]
pub struct ActsOn {
    /// The option's name (the command line's id, the Python keyword's).
    pub id: &'static str,
    /// The sensors it acts on.
    pub sensors: &'static [Sensor],
}

use Sensor::{
    BagImages, BagPoints, BagPoses, Camera, Contacts, Images, Pixels, Points, Pool, Poses,
    Simulated, Sockets,
};

const fn a(id: &'static str, sensors: &'static [Sensor]) -> ActsOn {
    ActsOn { id, sensors }
}

const CAL_ALL: &[Sensor] = &[
    Simulated, Points, Poses, Contacts, Pixels, Images, BagPoints, BagPoses, BagImages,
];
/// A camera's pixels, given or detected in its images (files or a bag's).
const CAMERA_DATA: &[Sensor] = &[Pixels, Images, BagImages];
/// Anything read from a ROS 2 bag.
const BAG_ANY: &[Sensor] = &[BagPoints, BagPoses, BagImages];
/// Measured points or full poses: told apart once the data are read.
pub const MEASURED: &[Sensor] = &[Points, Poses];
/// Points or full poses read from a ROS 2 bag.
pub const BAG: &[Sensor] = &[BagPoints, BagPoses];
/// Points or full poses, from a file or a bag.
const MEASURED_ANY: &[Sensor] = &[Points, Poses, BagPoints, BagPoses];
/// Full poses, from a file or a bag.
const POSES_ANY: &[Sensor] = &[Poses, BagPoses];
/// Points or full poses (from a file or a bag) and simulated ones.
const POINTS_FITS: &[Sensor] = &[Simulated, Points, Poses, BagPoints, BagPoses];
const FITTED: &[Sensor] = &[Points, Poses, Contacts, BagPoints, BagPoses];
const READ: &[Sensor] = &[Points, Poses, Contacts, Pixels, Images];
/// Data read and fitted with a robust loss or screened for gross errors:
/// files, images and bags.
const FITTED_READ: &[Sensor] = &[
    Points, Poses, Contacts, Pixels, Images, BagPoints, BagPoses, BagImages,
];
const SEL_ALL: &[Sensor] = &[Pool, Sockets, Camera];
const EVAL_ALL: &[Sensor] = &[Points, Poses, Contacts];

/// The options of `calibrate` (and the global ones) and the sensors each acts
/// on.
pub const CALIBRATE: &[ActsOn] = &[
    a("base", CAL_ALL),
    a("tip", CAL_ALL),
    a("lock", CAL_ALL),
    a("frames", CAL_ALL),
    a("kinematics", CAL_ALL),
    a("markers", &[Simulated, Points, Poses, Contacts]),
    a("progress", CAL_ALL),
    a("robot", CAL_ALL),
    a("design", &[Simulated]),
    a("measurements", &[Points, Poses, Contacts]),
    a("save_measurements", &[Simulated]),
    a("out", CAL_ALL),
    a("force", CAL_ALL),
    a("noise", POINTS_FITS),
    a("outliers", FITTED_READ),
    a("outlier_rate", FITTED_READ),
    a("orientation_noise", POSES_ANY),
    a("pixel_noise", CAMERA_DATA),
    a("seed", POINTS_FITS),
    a("trials", &[Simulated]),
    a("validation", &[Simulated]),
    a("max_iterations", CAL_ALL),
    a("no_geodesic", CAL_ALL),
    a("loss", FITTED),
    a("loss_scale", FITTED),
    a("fix", MEASURED_ANY),
    a("unknowns", MEASURED_ANY),
    a("keep_axis_relations", MEASURED_ANY),
    a("offset_unit", POINTS_FITS),
    a("offset_sign", POINTS_FITS),
    a("free", FITTED),
    a("holdout", MEASURED_ANY),
    a("splits", MEASURED_ANY),
    a("compare_pruned", MEASURED_ANY),
    a("weights", POSES_ANY),
    a("orientation_scale", POSES_ANY),
    a("point_distance", &[Contacts]),
    a("plane", &[Contacts]),
    a("holdout_by", &[Contacts]),
    a("train_on", &[Contacts]),
    a("compliance", MEASURED_ANY),
    a("compare_compliance", MEASURED_ANY),
    a("inertia", MEASURED_ANY),
    a("payload", MEASURED_ANY),
    a(
        "report",
        &[
            Simulated, Points, Poses, Contacts, Images, BagPoints, BagPoses,
        ],
    ),
    a("observations", &[Pixels]),
    a("images", &[Images, BagImages]),
    a("joints", &[Images, BagPoints, BagPoses, BagImages]),
    a("save_observations", &[Images, BagImages]),
    a("camera_info", CAMERA_DATA),
    a("target", CAMERA_DATA),
    a("mounting", CAMERA_DATA),
    a("camera_link", CAMERA_DATA),
    a("camera_pose", CAMERA_DATA),
    a("target_pose", CAMERA_DATA),
    a("refine_intrinsics", CAMERA_DATA),
    a("out_camera_info", CAMERA_DATA),
    a("angle_unit", READ),
    a("length_unit", READ),
    a("bag", BAG_ANY),
    a("points", &[BagPoints]),
    a("poses", &[BagPoses]),
    a("tf", &[BagPoses]),
    a("time_offset", BAG_ANY),
    a("max_offset", BAG),
    a("rest_speed", BAG_ANY),
    a("rest_min", BAG_ANY),
    a("settle", BAG_ANY),
    a("bag_design", BAG),
    a("design_tolerance", BAG),
    a("json", CAL_ALL),
];

/// The options of `select` (and the global ones) and the sensors each acts
/// on.
pub const SELECT: &[ActsOn] = &[
    a("base", SEL_ALL),
    a("tip", SEL_ALL),
    a("lock", SEL_ALL),
    a("frames", SEL_ALL),
    a("kinematics", SEL_ALL),
    a("markers", &[Pool, Sockets]),
    a("keep_axis_relations", &[Pool]),
    a("progress", SEL_ALL),
    a("robot", SEL_ALL),
    a("pool", &[Pool, Camera]),
    a("levels", &[Pool]),
    a("count", SEL_ALL),
    a("pool_seed", SEL_ALL),
    a("params", &[Pool, Sockets]),
    a("visibility", &[Pool]),
    a("self_collision", SEL_ALL),
    a("srdf", SEL_ALL),
    a("skip_always_touching", SEL_ALL),
    a("package_dirs", SEL_ALL),
    a("obstacles", SEL_ALL),
    a("floor", SEL_ALL),
    a("angle_unit", &[Pool, Camera]),
    a("length_unit", &[Pool, Camera]),
    a("compliance", &[Pool]),
    a("margin", &[Pool, Sockets]),
    a("clearance", SEL_ALL),
    a("n", SEL_ALL),
    a("algorithm", &[Pool]),
    a("initial", &[Pool]),
    a("starts", &[Pool]),
    a("ils", &[Pool]),
    a("kick", &[Pool]),
    a("designs", &[Pool]),
    a("polish", &[Pool]),
    a("seed", SEL_ALL),
    a("fixed", &[Pool]),
    a("criterion", &[Pool]),
    a("out", SEL_ALL),
    a("force", SEL_ALL),
    a("gap", &[Pool, Camera]),
    a("gap_solver", &[Pool, Camera]),
    a("existing", &[Pool]),
    a("refine", &[Pool]),
    a("refine_sweeps", &[Pool]),
    a("order", &[Pool]),
    a("home", &[Pool]),
    a("report", &[Pool, Camera]),
    a("target_error", &[Pool, Camera]),
    a("noise", &[Pool]),
    a("orientation_noise", &[Pool]),
    a("points", &[Sockets]),
    a("point_distance", &[Sockets]),
    a("camera_info", &[Camera]),
    a("target", &[Camera]),
    a("mounting", &[Camera]),
    a("camera_link", &[Camera]),
    a("camera_pose", &[Camera]),
    a("target_pose", &[Camera]),
    a("min_visible", &[Camera]),
    a("image_margin", &[Camera]),
    a("max_view_angle", &[Camera]),
    a("distance", &[Camera]),
    a("line_of_sight", &[Camera]),
    a("pixel_noise", &[Camera]),
    a("json", SEL_ALL),
];

/// The options of `evaluate` (and the global ones) and the sensors each acts
/// on.
pub const EVALUATE: &[ActsOn] = &[
    a("base", EVAL_ALL),
    a("tip", EVAL_ALL),
    a("lock", EVAL_ALL),
    a("frames", EVAL_ALL),
    a("kinematics", EVAL_ALL),
    a("markers", EVAL_ALL),
    a("progress", EVAL_ALL),
    a("robot", EVAL_ALL),
    a("measurements", EVAL_ALL),
    a("angle_unit", EVAL_ALL),
    a("length_unit", EVAL_ALL),
    a("point_distance", &[Contacts]),
    a("plane", &[Contacts]),
    a("json", EVAL_ALL),
];

/// The sensors option `id` of `table` acts on; `None` for an option the
/// table does not decide.
#[must_use]
pub fn sensors_of(table: &[ActsOn], id: &str) -> Option<&'static [Sensor]> {
    table.iter().find(|r| r.id == id).map(|r| r.sensors)
}

/// The options of `given` that act on none of `sensors` by `table` (an
/// option without a row too), in order.
#[must_use]
pub fn not_acting<'a>(table: &[ActsOn], given: &[&'a str], sensors: &[Sensor]) -> Vec<&'a str> {
    given
        .iter()
        .copied()
        .filter(|id| sensors_of(table, id).is_none_or(|s| !s.iter().any(|x| sensors.contains(x))))
        .collect()
}

/// What the table's sentences below are: why an option does not act on the
/// sensors its row leaves out, or what to use instead (options and
/// settings named by their keys in backticks, spelled by each front end:
/// the command line `--pixel-noise`, Python `pixel_noise`); an option not
/// listed names the sensors it is for.
pub type WhyNot = &'static [(&'static str, &'static str)];

const LS: &str = "the camera fit is least squares on the pixels";

/// Why an option of `calibrate` acts on no other sensor than its row's
/// ([`CALIBRATE`]).
pub const CALIBRATE_WHY: WhyNot = &[
    (
        "offset_unit",
        "the camera and contact fits write no joint offsets",
    ),
    (
        "offset_sign",
        "the camera and contact fits write no joint offsets",
    ),
    (
        "markers",
        "a camera sees the points of its `target`, not markers; a bag's `points` topic is one point",
    ),
    (
        "noise",
        "a contact fit's σ is estimated from its residuals; a camera's is `pixel_noise`",
    ),
    (
        "orientation_noise",
        "it is a tracker's orientation σ; only full poses carry orientations",
    ),
    (
        "pixel_noise",
        "it is a camera's σ in pixels; a tracker's is `noise`",
    ),
    ("seed", "the fit has no randomness"),
    ("loss", LS),
    ("loss_scale", LS),
    (
        "free",
        "the camera fit estimates every joint origin of the chain",
    ),
    (
        "holdout",
        "contacts are held out by placement (`holdout_by`, `train_on`); a camera fit has no held-out validation",
    ),
    ("splits", "`holdout`'s splits"),
    ("compare_pruned", "`holdout`'s comparison"),
    (
        "weights",
        "there are no orientations to weigh against positions",
    ),
    (
        "orientation_scale",
        "there are no orientations to weigh against positions",
    ),
    ("inertia", "it is for `compliance`"),
    ("payload", "it is for `compliance`"),
    (
        "report",
        "a camera fit's report is its text or `json` (with `images` DIR, `report` writes the contact sheet; not yet with a bag's images)",
    ),
    (
        "joints",
        "`observations` carry their joint values; `joints` gives the images' (a file) or a bag's joint topic",
    ),
    (
        "save_observations",
        "it writes the pixels detected in `images`",
    ),
    (
        "angle_unit",
        "no file of joint values is read (a bag's are in radians)",
    ),
    (
        "length_unit",
        "no file of joint values is read (a bag's are in metres)",
    ),
    (
        "max_offset",
        "a camera's clock offset is not estimated from a bag: give `time_offset` (0 when not given)",
    ),
    (
        "bag_design",
        "it matches a bag's rests to the design the run followed",
    ),
    (
        "design_tolerance",
        "it matches a bag's rests to the design the run followed",
    ),
];

const EAE: &str = "a camera design is chosen by exchange-add-exchange (EAE) on the determinant, a socket design D-optimally then exchanged for the predicted true error";
const SOCKET: &str = "the pool is configurations projected onto each socket from `count` joint-space samples, chosen D-optimally then exchanged for the predicted true error";

/// Why an option of `select` acts on no other sensor than its row's
/// ([`SELECT`]).
pub const SELECT_WHY: WhyNot = &[
    (
        "markers",
        "a camera sees the points of its `target`, not markers",
    ),
    ("pool", SOCKET),
    ("levels", "there is no lattice"),
    (
        "params",
        "the camera's Jacobian is at the nominal parameters",
    ),
    (
        "visibility",
        "the camera's view is `min_visible`, `image_margin`, `max_view_angle` and `distance`",
    ),
    ("angle_unit", "no file of joint values is read"),
    ("length_unit", "no file of joint values is read"),
    ("margin", "the samples are drawn within the joint limits"),
    ("algorithm", EAE),
    ("initial", EAE),
    ("starts", EAE),
    ("ils", EAE),
    ("kick", EAE),
    ("designs", EAE),
    ("polish", EAE),
    ("criterion", EAE),
    ("gap", SOCKET),
    ("gap_solver", SOCKET),
    ("report", SOCKET),
    ("target_error", SOCKET),
    (
        "noise",
        "it is a point's noise in metres; a camera's is `pixel_noise` PX (the detected points' σ in pixels), a socket design predicts its errors per unit noise",
    ),
];

/// Why `id` does not act beyond its row's sensors, by `why` (`None`: the
/// table says nothing, name the sensors it is for).
#[must_use]
pub fn why_not(why: WhyNot, id: &str) -> Option<&'static str> {
    why.iter().find(|(k, _)| *k == id).map(|(_, w)| *w)
}
