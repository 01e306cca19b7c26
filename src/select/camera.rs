//! Poses chosen for a camera: the configurations of a pool in which the
//! camera sees its target well ([`CameraView`]), and a D-optimal choice
//! among them on the pixel Jacobian (the robot's unknowns a camera
//! identifies and the 12 placement unknowns; each pose's `2N` rows those of
//! the points predicted inside the image with the view's margin, zero for
//! the others, [`crate::measure::camera`]). Each chosen pose says how many
//! points it will see.

use super::{Algorithm, CriterionKind, Selection, Settings, select};
use crate::blocks::Blocks;
use crate::error::{Error, Result};
use crate::identify::camera::camera_robot;
use crate::identify::camera::predict::predicted_error_of_information;
use crate::measure::Sensor;
use crate::measure::camera::CameraSensor;
use crate::measure::camera::OWN_PARAMS;
use crate::model::Robot;
use crate::pool::PoolFilter;
use crate::pool::camera_view::CameraView;
use crate::pool::line_of_sight::LineOfSight;
use rayon::prelude::*;
use serde::Serialize;

/// A design for a camera.
#[derive(Clone, Debug, Serialize)]
pub struct CameraDesign {
    /// The chosen configurations (radians, metres), in the order chosen.
    pub qs: Vec<Vec<f64>>,
    /// Each one's index in the candidates given.
    pub candidates: Vec<usize>,
    /// The points each one will see (inside the image with the margin, and
    /// in sight with a line of sight).
    pub seen: Vec<usize>,
    /// The candidates the view kept (and, with a line of sight, that
    /// passed it).
    pub visible: usize,
    /// Of the candidates the view kept, those the line of sight removed
    /// ([`crate::pool::line_of_sight`]); `None` without one.
    pub out_of_sight: Option<usize>,
    /// Unknowns: the robot's, then the camera's and the target's 6 each.
    pub names: Vec<String>,
    /// `ln det(XᵀX)` of the design (pixels per metre or radian, unit
    /// noise).
    pub ln_det: f64,
    /// The true error the design predicts per pixel of noise σ (metres
    /// per px): the RMS error of the moving one's origin in the fixed
    /// one's frame at [`PREDICTION_CONFIGURATIONS`] generic configurations
    /// (seed 0), from `σ² (XᵀX)⁻¹` at σ = 1 px
    /// ([`crate::identify::camera::predict`]); linear in σ. `None` for a
    /// singular design.
    pub predicted_error_per_px: Option<f64>,
    /// The selection's own record.
    #[serde(skip)]
    pub selection: Selection,
    /// Each visible pose's index in the candidates given (the pool the
    /// selection's positions index).
    #[serde(skip)]
    pub pool: Vec<usize>,
    /// The robot as the camera sees it ([`camera_robot`]: its unknowns
    /// those a camera identifies).
    #[serde(skip)]
    pub robot: Robot,
    /// The camera and the target, at the view's placements.
    #[serde(skip)]
    pub sensor: CameraSensor,
    /// The placements' own unknowns' values.
    #[serde(skip)]
    pub own: Vec<f64>,
    /// The largest rank of a visible pose's pixel information `XᵢᵀXᵢ`
    /// (6 for a camera that sees a rigid target: the pixels move with the
    /// target's placement in the camera only); each pose's block is
    /// compressed to this many rows ([`Blocks::compressed`]).
    pub rank_per_pose: usize,
    /// The pixel Jacobian blocks of the visible pool (the candidates the
    /// view kept, in order), which the selection's positions index,
    /// compressed to [`Self::rank_per_pose`] rows a pose (the same
    /// information).
    #[serde(skip)]
    pub blocks: Blocks,
}

impl CameraDesign {
    /// The design against the certified bound of its visible pool: the
    /// relaxation bound on `ln det XᵀX` of every design of its size from
    /// the candidates the view kept ([`crate::bound::relaxation_bound`] on
    /// the pixel Jacobian blocks) and the design's D-efficiency against it
    /// ([`crate::bound::design_gap`]), as for any sensor's pool.
    pub fn gap(
        &self,
        settings: &crate::bound::BoundSettings,
    ) -> std::result::Result<crate::bound::DesignGap, crate::bound::BoundError> {
        let bound = crate::bound::relaxation_bound(&self.blocks, None, self.qs.len(), settings)?;
        crate::bound::design_gap(&self.blocks, None, &self.selection.poses, &bound)
    }
}

/// Configurations the predicted error is averaged over.
pub const PREDICTION_CONFIGURATIONS: usize = 1000;

/// The pixel Jacobian blocks (`2N × p` a pose) of `qs` for `robot` (its
/// unknowns those of [`camera_robot`]) seen as `view` says, nominal
/// parameters.
#[must_use]
pub fn camera_blocks(robot: &Robot, view: &CameraView, qs: &[Vec<f64>]) -> Blocks {
    let (sensor, own) = view.sensor();
    debug_assert_eq!(own.len(), OWN_PARAMS);
    crate::blocks::jacobian_with(robot, &robot.nominal, &sensor, &own, qs.len(), |k, q| {
        q.copy_from_slice(&qs[k]);
    })
}

/// Chooses `settings.n` of the `candidates` (joint vectors of `robot`)
/// for `view` by exchange-add-exchange on the D criterion: the candidates
/// the view keeps (at the nominal parameters) form the pool. Errors when
/// the view is malformed or keeps fewer candidates than the design needs.
pub fn camera_design(
    robot: &Robot,
    view: &CameraView,
    candidates: &[Vec<f64>],
    settings: &Settings,
) -> Result<CameraDesign> {
    camera_design_in_sight(robot, view, None, candidates, settings)
}

/// As [`camera_design_in_sight`], the candidates first filtered by
/// `filters` (collision filters, [`PoolFilter`]), the design's candidate
/// indices (`candidates`, `pool`) those of `candidates` as given; with how
/// many the filters removed (`None` without filters).
pub fn camera_design_filtered(
    robot: &Robot,
    view: &CameraView,
    filters: &[PoolFilter],
    sight: Option<&LineOfSight>,
    candidates: &[Vec<f64>],
    settings: &Settings,
) -> Result<(CameraDesign, Option<usize>)> {
    let free: Vec<usize> = (0..candidates.len())
        .filter(|&i| {
            filters
                .iter()
                .all(|f| f.keeps(robot, &robot.nominal, &candidates[i]))
        })
        .collect();
    let removed = (!filters.is_empty()).then(|| candidates.len() - free.len());
    let free_qs: Vec<Vec<f64>> = free.iter().map(|&i| candidates[i].clone()).collect();
    let mut d = camera_design_in_sight(robot, view, sight, &free_qs, settings)?;
    for c in d.candidates.iter_mut().chain(d.pool.iter_mut()) {
        *c = free[*c];
    }
    Ok((d, removed))
}

/// As [`camera_design`], the pool also filtered by a line of sight
/// ([`LineOfSight`]: the candidates the view keeps whose rays to enough
/// target points the robot's collision geometry does not block); the
/// design says how many it removed. Errors when its model cannot be loaded.
pub fn camera_design_in_sight(
    robot: &Robot,
    view: &CameraView,
    sight: Option<&LineOfSight>,
    candidates: &[Vec<f64>],
    settings: &Settings,
) -> Result<CameraDesign> {
    view.validate()
        .map_err(|e| Error::Invalid(format!("camera view: {e}")))?;
    if let Some(s) = sight {
        s.load()
            .map_err(|e| Error::Invalid(format!("line of sight: {e}")))?;
    }
    let robot = camera_robot(robot)?;
    let viewed: Vec<usize> = (0..candidates.len())
        .filter(|&i| view.keeps(&robot, &robot.nominal, &candidates[i]))
        .collect();
    let kept: Vec<usize> = match sight {
        Some(s) => viewed
            .par_iter()
            .copied()
            .filter(|&i| s.keeps(view, &robot, &robot.nominal, &candidates[i]))
            .collect(),
        None => viewed.clone(),
    };
    let out_of_sight = sight.map(|_| viewed.len() - kept.len());
    if kept.len() < settings.n {
        return Err(Error::Invalid(format!(
            "the camera sees its target well at {} of {} candidate configurations{}, fewer than the {} poses asked for: a larger pool, a wider view (fraction of points, margin, viewing angle, distance) or fewer poses",
            kept.len(),
            candidates.len(),
            out_of_sight.map_or(String::new(), |b| format!(" ({b} more out of sight)")),
            settings.n
        )));
    }
    let qs: Vec<Vec<f64>> = kept.iter().map(|&i| candidates[i].clone()).collect();
    // The pixel Jacobian (its rows, the blocks made of them, and the
    // compressed blocks) refused with the figure when it would exceed the
    // memory budget: an error, not an abort.
    let (t, p) = (view.sensor().0.rows(), robot.n_unknowns() + OWN_PARAMS);
    crate::resources::MemoryBudget::from_env()?.check(
        &format!(
            "the pixel Jacobian of the {} candidate configurations the camera sees ({t} rows × {p} unknowns each)",
            qs.len()
        ),
        crate::resources::bytes_of(qs.len().saturating_mul(t).saturating_mul(p), 8)
            .saturating_mul(3),
    )?;
    let (blocks, rank_per_pose) = camera_blocks(&robot, view, &qs).compressed();
    let sel = select(&blocks, CriterionKind::Det, Algorithm::Eae, settings)?;
    let seen = sel
        .poses
        .iter()
        .map(|&k| match sight {
            Some(s) => s
                .seen_in_sight(view, &robot, &robot.nominal, &qs[k])
                .iter()
                .filter(|b| **b)
                .count(),
            None => view.view(&robot, &robot.nominal, &qs[k]).seen,
        })
        .collect();
    let (sensor, own) = view.sensor();
    let mut names = robot.parameter_names();
    names.extend(sensor.own_param_names());
    let mut d = CameraDesign {
        qs: sel.poses.iter().map(|&k| qs[k].clone()).collect(),
        candidates: sel.poses.iter().map(|&k| kept[k]).collect(),
        seen,
        visible: kept.len(),
        out_of_sight,
        names,
        ln_det: sel.ln_oid,
        predicted_error_per_px: None,
        selection: sel,
        pool: kept,
        robot,
        sensor,
        own,
        rank_per_pose,
        blocks,
    };
    let mut theta = d.robot.unknown_values(&d.robot.nominal);
    theta.extend_from_slice(&d.own);
    let qs = crate::observability::generic_configurations(&d.robot, PREDICTION_CONFIGURATIONS, 0);
    d.predicted_error_per_px = predicted_error_of_information(
        &d.robot,
        &d.sensor,
        &theta,
        d.blocks.information(&d.selection.poses).as_ref(),
        &qs,
    );
    Ok(d)
}
