//! The reports of a camera: what a calibration from a camera's pixels
//! (built by [`crate::experiment::camera::CameraCalibration::report`]) and a design chosen for a camera
//! ([`crate::select::camera`]) found, as the command line prints them as
//! JSON (and writes a design's JSON file) and the Python package returns
//! them. Built here once, so that both give the same values.

use crate::bound::DesignGap;
use crate::identify::FixedParameter;
use crate::identify::camera::start::CameraStart;
use crate::measure::camera::Mounting;
use crate::measure::pinhole::Intrinsics;
use crate::model::robot_ref::ChainChoice;
use crate::select::camera::CameraDesign;
use serde::Serialize;

/// A calibration from a camera's pixels: the unknowns' estimate with its
/// σ, the pixel errors, the placements found and the files written.
#[derive(Clone, Debug, Serialize)]
pub struct CameraCalibrationReport {
    /// The name of the robot fitted (the chain from the camera's link for
    /// a camera on the robot's own link).
    pub robot: String,
    /// Where the observations came from (a file's path).
    pub observations: String,
    /// `eye-to-hand` or `eye-in-hand`.
    pub mounting: Mounting,
    /// The robot's link the camera is on, for a camera on the robot's own
    /// link (a head); `None` (null) otherwise.
    pub camera_link: Option<String>,
    /// Configurations observed.
    pub poses: usize,
    /// Target points seen over all of them.
    pub points_seen: usize,
    /// Names of the unknowns: the robot's, `camera_x … target_rz`, then
    /// the refined intrinsics.
    pub names: Vec<String>,
    /// The estimate (metres, radians, pixels), in the order of `names`.
    pub estimate: Vec<f64>,
    /// Its standard deviations, when the estimate has a covariance.
    pub std: Option<Vec<f64>>,
    /// Where the fit started: each placement given or computed from the
    /// pixels, and how.
    pub start: CameraStartReport,
    /// RMS pixel error at the start placements (nominal robot), px.
    pub start_rms_px: f64,
    /// RMS pixel error after fitting the placements alone, px.
    pub rigid_rms_px: f64,
    /// RMS pixel error calibrated, px.
    pub rms_px: f64,
    /// The pixel noise σ estimated from the residuals, px.
    pub sigma_px: Option<f64>,
    /// Degrees of freedom of `sigma_px`.
    pub redundancy: usize,
    /// Whether the fit converged (only then is anything written).
    pub converged: bool,
    /// Intrinsics asked to be refined that the data do not determine, held
    /// at their given values with the reason.
    pub fixed_intrinsics: Vec<FixedParameter>,
    /// Why the fit stopped.
    pub stop: String,
    /// The camera's and the target's placements in the URDF's links
    /// (robots imported from a URDF).
    pub camera: Option<crate::frames::report::CameraBlock>,
    /// The intrinsics at the estimate, when they were refined.
    pub intrinsics: Option<Intrinsics>,
    /// The poses whose checkerboard corners were relabelled (the detector
    /// returned them turned or mirrored), with the labelling applied.
    pub relabelled: Vec<crate::identify::camera::start::labels::Relabelled>,
    /// The poses left out because their corners' order could not be told.
    pub dropped_poses: Vec<crate::identify::camera::start::labels::DroppedPose>,
    /// Why the calibration may not be written (nothing was), when it
    /// may not ([`crate::experiment::camera::verdict`]).
    pub refused: Option<String>,
    /// The gross-error test: its choice and the poses and points it left
    /// out ([`crate::identify::camera::screen`]).
    pub outliers: CameraOutliers,
    /// What the gross-error test did, in words.
    pub notes: Vec<String>,
    /// σ̂ tested against the stated pixel noise, when one was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_test: Option<crate::identify::variance::BlockNoiseTest>,
    /// What the user should look at: the fit is written, but the pixels
    /// are not as stated.
    pub warnings: Vec<String>,
    /// 0, or 3 when refused.
    pub exit_status: i32,
    /// The files written.
    pub out: Vec<String>,
    /// What became of each image, when the pixels were detected in images
    /// (files or a bag's image topic).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub images: Option<Vec<crate::io::images::ImageReport>>,
    /// What was read from the ROS 2 bag, when the images came from one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bag: Option<crate::io::bag::camera::BagImagesReport>,
}

/// The camera's gross-error test in a report.
#[derive(Clone, Debug, Serialize)]
pub struct CameraOutliers {
    /// Drop (at a rate) or keep.
    pub choice: crate::lsq::outliers::OutlierChoice,
    /// What was left out, in the order the test found it.
    pub left_out: Vec<crate::identify::camera::screen::CameraOutlier>,
}

/// Where a camera fit started: each placement `given` or `computed` from
/// the pixels ([`crate::identify::camera::start`]) and, when one was
/// computed, the method, the poses whose target PnP placed, their pixel
/// RMS and both start placements as `X, Y, Z, ROLL, PITCH, YAW` (metres,
/// radians: what the options that give them read).
#[derive(Clone, Debug, Serialize)]
pub struct CameraStartReport {
    /// `given` or `computed`.
    pub camera: &'static str,
    /// `given` or `computed`.
    pub target: &'static str,
    /// `PnP + closed-form hand-eye` (both computed) or `PnP` (one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub method: Option<&'static str>,
    /// Poses whose target was placed from its pixels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub poses_placed: Option<usize>,
    /// Their PnP pixel RMS, px.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pnp_rms_px: Option<f64>,
    /// The camera's start placement.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera_pose: Option<[f64; 6]>,
    /// The target's start placement.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target_pose: Option<[f64; 6]>,
}

impl CameraStartReport {
    /// The report of a computed start, or of two given placements.
    #[must_use]
    pub fn of(start: Option<&CameraStart>) -> Self {
        let word = |c: bool| if c { "computed" } else { "given" };
        match start {
            None => Self {
                camera: "given",
                target: "given",
                method: None,
                poses_placed: None,
                pnp_rms_px: None,
                camera_pose: None,
                target_pose: None,
            },
            Some(st) => Self {
                camera: word(st.camera_computed),
                target: word(st.target_computed),
                method: Some(if st.camera_computed && st.target_computed {
                    "PnP + closed-form hand-eye"
                } else {
                    "PnP"
                }),
                poses_placed: Some(st.poses_placed),
                pnp_rms_px: Some(st.pnp_rms_px),
                camera_pose: Some(xyz_rpy(&st.camera)),
                target_pose: Some(xyz_rpy(&st.target)),
            },
        }
    }
}

/// A placement as `X, Y, Z, ROLL, PITCH, YAW` (metres, radians; URDF's
/// rpy).
#[must_use]
pub fn xyz_rpy(m: &nalgebra::Isometry3<f64>) -> [f64; 6] {
    let t = m.translation.vector;
    let (r, p, y) = m.rotation.euler_angles();
    [t.x, t.y, t.z, r, p, y]
}

/// Where a camera design's candidates came from: the robot as its
/// reference names it, the camera's link, the samples and what the
/// collision filters removed.
#[derive(Clone, Debug)]
pub struct CameraPoolInfo {
    /// The robot's name or description path, without the chain.
    pub robot: String,
    /// The chain of the robot's URDF tree.
    pub chain: ChainChoice,
    /// The robot's link the camera is on (a head), if any.
    pub camera_link: Option<String>,
    /// Configurations sampled.
    pub candidates: usize,
    /// The samples' seed.
    pub pool_seed: u64,
    /// Samples the collision filters removed; `None` without filters.
    pub collision_removed: Option<usize>,
    /// The pixel noise σ the user gave, px (the design's true error is
    /// then also predicted at it).
    pub pixel_noise: Option<f64>,
}

/// A design chosen for a camera: the chosen configurations, the points
/// each will see, its figures and, when asked for, its gap to the visible
/// pool's certified bound.
#[derive(Clone, Debug, Serialize)]
pub struct CameraDesignReport {
    /// The robot's name or description path, without the chain.
    pub robot: String,
    /// The chain of the robot's URDF tree.
    pub chain: ChainChoice,
    /// The robot's link the camera is on (a head), if any.
    pub camera_link: Option<String>,
    /// `eye-to-hand` or `eye-in-hand`.
    pub mounting: Mounting,
    /// Configurations sampled.
    pub candidates: usize,
    /// The samples' seed.
    pub pool_seed: u64,
    /// Candidates the view kept (and in sight, with a line of sight).
    pub visible: usize,
    /// Samples the collision filters removed; `None` without filters.
    pub collision_removed: Option<usize>,
    /// Candidates seen well whose rays the robot blocks; `None` without a
    /// line of sight.
    pub out_of_sight: Option<usize>,
    /// Names of the unknowns.
    pub unknowns: Vec<String>,
    /// `ln det XᵀX` of the design (unit pixel noise).
    pub ln_det: f64,
    /// `log10` of the certified bound, with a gap.
    pub log10_bound: Option<f64>,
    /// The D-efficiency against the bound, with a gap.
    pub d_efficiency: Option<f64>,
    /// The true error predicted per pixel of noise σ, mm per px.
    pub predicted_error_mm_per_px: Option<f64>,
    /// The pixel noise σ given, px.
    pub pixel_noise_px: Option<f64>,
    /// The true error predicted at that noise, mm.
    pub predicted_error_mm: Option<f64>,
    /// The points each chosen configuration will see.
    pub points_seen: Vec<usize>,
    /// The joints' names, in the order of `poses`.
    pub joint_names: Vec<String>,
    /// Configurations chosen.
    pub n: usize,
    /// Each one's index in the samples.
    pub chosen_candidates: Vec<usize>,
    /// The chosen configurations (radians, metres).
    pub poses: Vec<Vec<f64>>,
    /// The gap to the visible pool's certified bound, when asked for.
    pub gap: Option<DesignGap>,
    /// The files written from the design (the caller's: set in what it
    /// prints, absent from the files it writes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub out: Option<Vec<String>>,
}

impl CameraDesignReport {
    /// The report of design `d` (its candidates indexed in the samples)
    /// chosen from `pool`, for a robot with joints `joint_names`, with its
    /// `gap` when one was computed.
    #[must_use]
    pub fn new(
        d: &CameraDesign,
        pool: CameraPoolInfo,
        mounting: Mounting,
        joint_names: Vec<String>,
        gap: Option<DesignGap>,
    ) -> Self {
        Self {
            robot: pool.robot,
            chain: pool.chain,
            camera_link: pool.camera_link,
            mounting,
            candidates: pool.candidates,
            pool_seed: pool.pool_seed,
            visible: d.visible,
            collision_removed: pool.collision_removed,
            out_of_sight: d.out_of_sight,
            unknowns: d.names.clone(),
            ln_det: d.ln_det,
            log10_bound: gap.as_ref().map(|g| g.log10_bound),
            d_efficiency: gap.as_ref().map(|g| g.d_efficiency),
            predicted_error_mm_per_px: d.predicted_error_per_px.map(|e| 1e3 * e),
            pixel_noise_px: pool.pixel_noise,
            predicted_error_mm: pool
                .pixel_noise
                .zip(d.predicted_error_per_px)
                .map(|(s, e)| 1e3 * e * s),
            points_seen: d.seen.clone(),
            joint_names,
            n: d.qs.len(),
            chosen_candidates: d.candidates.clone(),
            poses: d.qs.clone(),
            gap,
            out: None,
        }
    }
}
