//! A start for the camera fit ([`super::fit_camera`]) computed from the
//! pixels, so that neither placement needs to be guessed:
//!
//! 1. at each pose, the target's pose `Pᵢ` in the camera's optical frame
//!    from its seen points ([`pnp::place_target`]); a pose whose target
//!    cannot be placed (too few points off a plane, say) is left out;
//! 2. with the nominal robot's end frame `Tᵢ` (base → tip; for a camera
//!    on the robot's own link, that link → tip), the two placements in
//!    closed form ([`hand_eye`]): eye-to-hand, the camera `C` in the base
//!    and the target `G` in the end frame satisfy `C Pᵢ = Tᵢ G`, i.e.
//!    `Tᵢ G = C Pᵢ` (`X = G`, `Z = C`, `Bᵢ = Pᵢ`); eye-in-hand, the camera
//!    `C` in the end frame and the target `G` in the base, `Tᵢ C Pᵢ = G`,
//!    i.e. `Tᵢ C = G Pᵢ⁻¹` (`X = C`, `Z = G`, `Bᵢ = Pᵢ⁻¹`). When one
//!    placement is known the other is the mean of its per-pose values.
//!
//! The fit's first step (the placements alone, the robot nominal) then
//! refines both jointly.

pub mod hand_eye;
pub mod labels;
pub mod pnp;

use crate::data::CameraObservations;
use crate::kinematics::Evaluator;
use crate::measure::camera::Mounting;
use crate::measure::pinhole::Intrinsics;
use crate::model::Robot;
use hand_eye::{HandEyeError, solve_ax_zb, solve_x_given_z, solve_z_given_x};
use nalgebra::{Isometry3, Rotation3, UnitQuaternion, Vector3};
use pnp::{PnpError, place_target};

/// The placements computed from the pixels, with what they came from.
#[derive(Clone, Debug)]
pub struct CameraStart {
    /// The camera's placement (in the base for eye-to-hand, in the end
    /// frame for eye-in-hand).
    pub camera: Isometry3<f64>,
    /// The target's placement (in the end frame for eye-to-hand, in the
    /// base for eye-in-hand).
    pub target: Isometry3<f64>,
    /// Whether the camera's placement was computed (else given).
    pub camera_computed: bool,
    /// Whether the target's placement was computed (else given).
    pub target_computed: bool,
    /// Poses whose target was placed from its pixels.
    pub poses_placed: usize,
    /// RMS over the placed poses' pixel coordinates of their own
    /// per-pose pose's reprojection error, pixels.
    pub pnp_rms_px: f64,
}

/// Why no start could be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StartError {
    /// Too few poses whose target could be placed.
    #[error(
        "the target could be placed from its pixels at {placed} of {poses} poses, 3 needed{}",
        first.as_ref().map_or(String::new(), |(p, e)| format!(" (pose {p}: {e})"))
    )]
    TooFewPlaced {
        /// Poses placed.
        placed: usize,
        /// Poses observed.
        poses: usize,
        /// The first pose not placed (its id) and why.
        first: Option<(i64, PnpError)>,
    },
    /// The closed form has no solution.
    #[error(transparent)]
    HandEye(#[from] HandEyeError),
}

/// Each pose's end frame of `robot` at its nominal parameters, as a rigid
/// motion.
pub(crate) fn end_frames(robot: &Robot, obs: &CameraObservations) -> Vec<Isometry3<f64>> {
    // The end frame the fit's first step sees: no unknowns, the nominal
    // table.
    let mut r = robot.clone();
    r.unknowns.clear();
    let mut ev = Evaluator::new(&r, &robot.nominal);
    obs.qs
        .iter()
        .map(|q| {
            let e = ev.end_frame(q);
            Isometry3::from_parts(
                e.position.into(),
                UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(e.rotation)),
            )
        })
        .collect()
}

/// The start placements of a camera fit of `robot` (its nominal
/// parameters) from `obs`, the camera with `intrinsics` mounted as
/// `mounting` seeing the target's `points`: the placements given are
/// kept, the others computed (see the module documentation).
pub fn start_placements(
    robot: &Robot,
    intrinsics: &Intrinsics,
    mounting: Mounting,
    points: &[Vector3<f64>],
    obs: &CameraObservations,
    camera: Option<&Isometry3<f64>>,
    target: Option<&Isometry3<f64>>,
) -> Result<CameraStart, StartError> {
    let frames = end_frames(robot, obs);
    let (mut a, mut p) = (Vec::new(), Vec::new());
    let (mut first, mut sq, mut rows) = (None, 0.0, 0usize);
    for (i, seen) in obs.seen.iter().enumerate() {
        let (pts, px): (Vec<Vector3<f64>>, Vec<[f64; 2]>) = seen
            .iter()
            .zip(points)
            .filter_map(|(s, pt)| s.map(|px| (*pt, px)))
            .unzip();
        match place_target(intrinsics, &pts, &px) {
            Ok(v) => {
                sq += v.rms_px.powi(2) * (2 * pts.len()) as f64;
                rows += 2 * pts.len();
                a.push(frames[i]);
                p.push(v.pose);
            }
            Err(e) => {
                first.get_or_insert((obs.pose_ids[i], e));
            }
        }
    }
    if a.len() < 3 {
        return Err(StartError::TooFewPlaced {
            placed: a.len(),
            poses: obs.seen.len(),
            first,
        });
    }
    // Bᵢ = Pᵢ (eye-to-hand) or Pᵢ⁻¹ (eye-in-hand).
    let b: Vec<Isometry3<f64>> = match mounting {
        Mounting::EyeToHand => p,
        Mounting::EyeInHand => p.iter().map(Isometry3::inverse).collect(),
    };
    // (given X, given Z) in the mounting's roles.
    let (gx, gz) = match mounting {
        Mounting::EyeToHand => (target, camera),
        Mounting::EyeInHand => (camera, target),
    };
    let (x, z) = match (gx, gz) {
        (Some(x), Some(z)) => (*x, *z),
        (Some(x), None) => (*x, solve_z_given_x(&a, &b, x)),
        (None, Some(z)) => (solve_x_given_z(&a, &b, z), *z),
        (None, None) => solve_ax_zb(&a, &b)?,
    };
    let (cam, tgt) = match mounting {
        Mounting::EyeToHand => (z, x),
        Mounting::EyeInHand => (x, z),
    };
    Ok(CameraStart {
        camera: cam,
        target: tgt,
        camera_computed: camera.is_none(),
        target_computed: target.is_none(),
        poses_placed: a.len(),
        pnp_rms_px: (sq / rows as f64).sqrt(),
    })
}

#[cfg(test)]
mod tests;

/// How far each placed pose's own PnP is from the target's pose the
/// start predicts there (eye-to-hand `C⁻¹ Tᵢ G`, eye-in-hand `(Tᵢ C)⁻¹
/// G`): `(pose id, metres, degrees)`, the worst first (by metres plus the
/// degrees' arc at 1 m). The poses at the top are those whose joint
/// values or points' labels disagree with the others'.
#[must_use]
pub fn disagreeing_poses(
    robot: &Robot,
    intrinsics: &Intrinsics,
    mounting: Mounting,
    points: &[Vector3<f64>],
    obs: &CameraObservations,
    start: &CameraStart,
) -> Vec<(i64, f64, f64)> {
    let frames = end_frames(robot, obs);
    let mut out: Vec<(i64, f64, f64)> = obs
        .seen
        .iter()
        .enumerate()
        .filter_map(|(i, seen)| {
            let (pts, px): (Vec<Vector3<f64>>, Vec<[f64; 2]>) = seen
                .iter()
                .zip(points)
                .filter_map(|(s, pt)| s.map(|px| (*pt, px)))
                .unzip();
            let own = place_target(intrinsics, &pts, &px).ok()?.pose;
            let predicted = match mounting {
                Mounting::EyeToHand => start.camera.inverse() * frames[i] * start.target,
                Mounting::EyeInHand => (frames[i] * start.camera).inverse() * start.target,
            };
            let d = predicted.inverse() * own;
            Some((
                obs.pose_ids[i],
                d.translation.vector.norm(),
                d.rotation.angle().to_degrees(),
            ))
        })
        .collect();
    let score = |x: &(i64, f64, f64)| x.1 + x.2.to_radians();
    out.sort_by(|a, b| score(b).total_cmp(&score(a)));
    out
}
