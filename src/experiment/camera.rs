//! Calibration from a camera's pixels as one step: the sensor the setup
//! describes, the fit ([`crate::identify::camera::fit_camera`]), the
//! calibrated frames with the camera's and the target's placements in the
//! URDF's links, and the report
//! ([`crate::report::CameraCalibrationReport`]). The command line
//! and the Python package both call it; reading the files and writing the
//! results are theirs.

use crate::data::CameraObservations;
use crate::experiment::measured::verdict::Verdict;
use crate::frames::camera::camera_frames;
use crate::frames::report::FramesReport;
use crate::frames::{CalibratedFrames, FramesError};
use crate::identify::LmSettings;
use crate::identify::camera::screen::{CameraOutlier, screen_camera};
use crate::identify::camera::start::labels::{Labels, relabel};
use crate::identify::camera::start::{CameraStart, StartError, start_placements};
use crate::identify::camera::{CameraFit, CameraFitError};
use crate::identify::variance::{BlockNoiseTest, NoiseOf};
use crate::io::camera_target::Target;
use crate::lsq::outliers::OutlierChoice;
use crate::measure::camera::{CameraSensor, Mounting};
use crate::measure::pinhole::Intrinsics;
use crate::model::Robot;
use crate::report::{CameraCalibrationReport, CameraStartReport};
use nalgebra::Isometry3;

pub mod files;
pub mod images;
pub mod verdict;

/// What a camera calibration is given besides the robot and the
/// observations: the camera, the target, how they are mounted and where
/// they roughly are.
#[derive(Clone, Debug)]
pub struct CameraSetup {
    /// The camera's intrinsics (the start, when refined).
    pub intrinsics: Intrinsics,
    /// The target's points.
    pub target: Target,
    /// Where the target came from (its file), for messages.
    pub target_origin: String,
    /// Which of the two rides on the tip link.
    pub mounting: Mounting,
    /// The robot's link the camera is on (a head), when the robot given
    /// is the chain from it ([`crate::io::urdf_branch::camera_branch`]).
    pub camera_link: Option<String>,
    /// The camera's rough placement (the start of the fit); `None`:
    /// computed from the pixels ([`crate::identify::camera::start`]).
    pub camera: Option<Isometry3<f64>>,
    /// The target's rough placement (the start of the fit); `None`:
    /// computed from the pixels.
    pub target_pose: Option<Isometry3<f64>>,
    /// Whether the intrinsics are unknowns of the fit too.
    pub refine_intrinsics: bool,
    /// What happens to poses and points the gross-error test flags
    /// ([`crate::identify::camera::screen`]).
    pub outliers: OutlierChoice,
    /// The detector's stated σ per pixel coordinate (px): σ̂ is tested
    /// against it and the gross-error test uses it; `None`: σ̂ alone.
    pub pixel_noise: Option<f64>,
}

/// Why a camera calibration could not be made.
#[derive(Debug, thiserror::Error)]
pub enum CameraCalibrationError {
    /// The fit could not be made (bad input, a start that does not see
    /// what the observations say).
    #[error(transparent)]
    Fit(Box<CameraFitError>),
    /// The calibrated robot could not be split into frames.
    #[error(transparent)]
    Frames(#[from] FramesError),
    /// The start computed from the pixels puts seen points behind the
    /// camera: the poses' PnP disagree with the robot's motion.
    #[error(
        "{origin}: the start computed from the pixels (each pose's PnP and the closed-form hand-eye) puts {behind} seen point(s) behind the camera (first: pose {pose}): the poses' own PnP disagree with the robot's motion; the farthest from the start's prediction: {}; check those poses' joint values and their points' ids",
        worst(disagree)
    )]
    StartDisagrees {
        /// Where the observations came from.
        origin: String,
        /// Seen points behind the camera.
        behind: usize,
        /// The first pose with one.
        pose: i64,
        /// Each pose's PnP distance from the start's prediction (pose,
        /// metres, degrees), the worst first
        /// ([`crate::identify::camera::start::disagreeing_poses`]).
        disagree: Vec<(i64, f64, f64)>,
    },
    /// A placement not given could not be computed from the pixels.
    #[error("{origin}: no start computed from the pixels ({error}); give both rough placements")]
    Start {
        /// Where the observations came from.
        origin: String,
        /// Why.
        error: StartError,
    },
}

/// The worst of `disagree` (pose, metres, degrees) in words.
fn worst(disagree: &[(i64, f64, f64)]) -> String {
    disagree
        .iter()
        .take(5)
        .map(|(p, m, d)| format!("pose {p} {:.0} mm, {d:.1}°", m * 1e3))
        .collect::<Vec<_>>()
        .join("; ")
}

impl From<CameraFitError> for CameraCalibrationError {
    fn from(e: CameraFitError) -> Self {
        Self::Fit(Box::new(e))
    }
}

/// A calibration from a camera's pixels.
#[derive(Clone, Debug)]
pub struct CameraCalibration {
    /// The name of the robot fitted.
    pub robot_name: String,
    /// The observations fitted.
    pub observations: CameraObservations,
    /// The fit.
    pub fit: CameraFit,
    /// The calibrated frames and their report with the `camera` block
    /// (robots imported from a URDF).
    pub frames: Option<(CalibratedFrames, FramesReport)>,
    /// The robot's link the camera is on, if any.
    pub camera_link: Option<String>,
    /// Whether the intrinsics were refined.
    pub refine_intrinsics: bool,
    /// The start computed from the pixels, when a placement was not
    /// given.
    pub start: Option<CameraStart>,
    /// Whether it may be written ([`verdict::camera_verdict`]).
    pub verdict: Verdict,
    /// The poses of a checkerboard whose corners were relabelled, and
    /// those dropped as ambiguous
    /// ([`crate::identify::camera::start::labels`]).
    pub labels: Labels,
    /// The poses and points the gross-error test left out, in the order it
    /// found them ([`crate::identify::camera::screen`]).
    pub outliers: Vec<CameraOutlier>,
    /// The gross-error test's choice.
    pub outlier_choice: OutlierChoice,
    /// What the gross-error test did, in words.
    pub notes: Vec<String>,
    /// σ̂ tested against the stated pixel noise, when one was given.
    pub noise_test: Option<BlockNoiseTest>,
    /// Where the pixels came from, as the report shows it
    /// ([`Self::with_source`]; a pixels file unless said).
    pub source: CameraSource,
}

/// Where a camera calibration's pixels came from, as its report shows it.
#[derive(Clone, Debug, Default)]
pub enum CameraSource {
    /// Pixels given (a file, arrays).
    #[default]
    Pixels,
    /// Detected in image files: what became of each image.
    Images(Vec<crate::io::images::ImageReport>),
    /// Detected in a ROS 2 bag's image topic: what was read from it.
    Bag(crate::io::bag::camera::BagImagesReport),
}

/// Calibrates `robot` (the chain from the camera's link for a camera on
/// the robot's own link) from `observations` of `setup`'s target.
pub fn calibrate_camera(
    robot: &Robot,
    mut observations: CameraObservations,
    setup: &CameraSetup,
    lm: &LmSettings,
) -> Result<CameraCalibration, CameraCalibrationError> {
    let labels = relabel(
        robot,
        &setup.intrinsics,
        setup.mounting,
        &setup.target.points,
        setup.target.grid,
        &mut observations,
    );
    let start = match (setup.camera, setup.target_pose) {
        (Some(_), Some(_)) => None,
        (cam, tgt) => Some(
            start_placements(
                robot,
                &setup.intrinsics,
                setup.mounting,
                &setup.target.points,
                &observations,
                cam.as_ref(),
                tgt.as_ref(),
            )
            .map_err(|error| CameraCalibrationError::Start {
                origin: observations.origin.clone(),
                error,
            })?,
        ),
    };
    let (cam0, tgt0) = match &start {
        Some(st) => (&st.camera, &st.target),
        None => (
            setup.camera.as_ref().expect("given"),
            setup.target_pose.as_ref().expect("given"),
        ),
    };
    let sensor = CameraSensor::new(
        setup.intrinsics.clone(),
        setup.mounting,
        setup.target.points.clone(),
        cam0,
        tgt0,
    )
    .with_face(setup.target.face)
    .with_intrinsics_refined(setup.refine_intrinsics);
    let own0 = CameraSensor::start_own(cam0, tgt0);
    let screened = screen_camera(
        robot,
        &sensor,
        &own0,
        &observations,
        lm,
        setup.outliers,
        setup.pixel_noise,
    );
    let screened = match screened {
        Err(CameraFitError::BehindCamera { behind, pose }) if start.is_some() => {
            let st = start.as_ref().expect("computed");
            return Err(CameraCalibrationError::StartDisagrees {
                origin: observations.origin.clone(),
                behind,
                pose,
                disagree: crate::identify::camera::start::disagreeing_poses(
                    robot,
                    &setup.intrinsics,
                    setup.mounting,
                    &setup.target.points,
                    &observations,
                    st,
                ),
            });
        }
        r => r?,
    };
    let fit = screened.fit;
    let noise_test = setup
        .pixel_noise
        .and_then(|px| BlockNoiseTest::new(NoiseOf::Pixels, px, fit.sigma_px?, fit.redundancy));
    let mut frames = camera_frames(&fit)?;
    if let Some(c) = frames.as_mut().and_then(|f| f.1.camera.as_mut()) {
        c.camera_link.clone_from(&setup.camera_link);
    }
    let mut cal = CameraCalibration {
        robot_name: robot.name.clone(),
        observations,
        fit,
        frames,
        camera_link: setup.camera_link.clone(),
        refine_intrinsics: setup.refine_intrinsics,
        start,
        verdict: Verdict::Calibrated,
        labels,
        outliers: screened.outliers,
        outlier_choice: setup.outliers,
        notes: screened.notes,
        noise_test,
        source: CameraSource::Pixels,
    };
    cal.verdict = verdict::camera_verdict(&cal, &setup.target_origin, extent(&setup.target));
    Ok(cal)
}

/// The largest distance between two of `target`'s points, metres.
fn extent(target: &Target) -> f64 {
    let p = &target.points;
    p.iter()
        .flat_map(|a| p.iter().map(move |b| (a - b).norm()))
        .fold(0.0, f64::max)
}

impl CameraCalibration {
    /// The calibration, its pixels from `source`.
    #[must_use]
    pub fn with_source(mut self, source: CameraSource) -> Self {
        self.source = source;
        self
    }

    /// The report, with the files `out` written from it.
    #[must_use]
    pub fn report(&self, out: Vec<String>) -> CameraCalibrationReport {
        let fit = &self.fit;
        CameraCalibrationReport {
            robot: self.robot_name.clone(),
            observations: self.observations.origin.clone(),
            mounting: fit.sensor.mounting(),
            camera_link: self.camera_link.clone(),
            poses: self.observations.qs.len(),
            points_seen: self.observations.n_seen(),
            names: fit.names.clone(),
            estimate: fit.estimate.clone(),
            std: fit.std.clone(),
            start: CameraStartReport::of(self.start.as_ref()),
            start_rms_px: fit.given_rms_px,
            rigid_rms_px: fit.rigid_rms_px,
            rms_px: fit.rms_px,
            sigma_px: fit.sigma_px,
            redundancy: fit.redundancy,
            converged: fit.converged,
            fixed_intrinsics: fit.fixed_intrinsics.clone(),
            stop: format!("{:?}", fit.stop),
            camera: self.frames.as_ref().and_then(|f| f.1.camera.clone()),
            intrinsics: self.refine_intrinsics.then(|| fit.intrinsics()),
            relabelled: self.labels.relabelled.clone(),
            dropped_poses: self.labels.dropped.clone(),
            outliers: crate::report::CameraOutliers {
                choice: self.outlier_choice,
                left_out: self.outliers.clone(),
            },
            notes: self.notes.clone(),
            noise_test: self.noise_test.clone(),
            warnings: self
                .noise_test
                .iter()
                .filter_map(BlockNoiseTest::warning)
                .collect(),
            refused: self.verdict.refusal().map(str::to_string),
            exit_status: self.verdict.exit_status(),
            out,
            images: match &self.source {
                CameraSource::Pixels => None,
                CameraSource::Images(i) => Some(i.clone()),
                CameraSource::Bag(b) => Some(b.images()),
            },
            bag: match &self.source {
                CameraSource::Bag(b) => Some(b.clone()),
                _ => None,
            },
        }
    }

    /// The intrinsics at the estimate as a ROS `camera_info` YAML naming
    /// the camera `camera_name`, with `comment` at its top
    /// ([`crate::io::camera_info::render_camera_info`]).
    #[must_use]
    pub fn camera_info_text(&self, camera_name: &str, comment: &str) -> String {
        crate::io::camera_info::render_camera_info(&self.fit.intrinsics(), camera_name, comment)
    }
}
