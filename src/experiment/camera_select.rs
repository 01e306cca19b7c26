//! The camera design pipeline, owned by the library: the chain the camera
//! sees (the robot's, or the one from the camera's own link), the
//! candidates (listed or sampled), the collision filters and line of sight
//! built on that chain, the D-optimal choice on the pixel Jacobian, its gap
//! to the visible pool's certified bound when asked for, and the report.
//! The command line and the Python package both call [`select_camera`];
//! neither assembles these steps.

use super::ExperimentError;
use crate::bound::{BoundSettings, DesignGap};
use crate::error::Error;
use crate::how_many::{CurveSettings, PoseCountCurve};
use crate::io::atomic::Output;
use crate::io::collision_choice::CollisionChoice;
use crate::io::{UrdfChain, urdf_branch};
use crate::model::Robot;
use crate::model::robot_ref::ChainChoice;
use crate::pool::PoolFilter;
use crate::pool::camera_view::CameraView;
use crate::pool::line_of_sight::{LineOfSight, SightLines};
use crate::report::{CameraDesignReport, CameraPoolInfo};
use crate::select::Settings;
use crate::select::camera::{CameraDesign, camera_design_filtered};
use std::fmt::Write as _;

/// Joint-space samples of a camera design when no count is given.
pub const DEFAULT_SAMPLES: usize = 20_000;

/// The pixel noise σ of a camera design's "how many poses" curve when none
/// is given, px: a corner detector's typical sub-pixel error (OpenCV's
/// `cornerSubPix` on a sharp checkerboard gives 0.1–0.5 px), and the σ of
/// the project's camera examples.
pub const DEFAULT_PIXEL_NOISE: f64 = 0.3;

/// Where a camera design's candidate configurations come from.
#[derive(Clone, Debug)]
pub enum Candidates {
    /// Configurations given (a pool file's rows, radians and metres).
    Listed(Vec<Vec<f64>>),
    /// `count` uniform samples within the joint limits, drawn with `seed`.
    Sampled {
        /// How many.
        count: usize,
        /// Their seed.
        seed: u64,
    },
}

/// Everything a camera design is chosen from, resolved by the caller.
#[derive(Clone, Debug)]
pub struct CameraSelectPlan {
    /// How the camera must see the target (intrinsics, placements, limits).
    pub view: CameraView,
    /// The robot's link the camera is on (a head), if any: the design is
    /// then chosen on the chain from that link ([`urdf_branch::camera_branch`]).
    pub camera_link: Option<String>,
    /// The collision checks asked for (none by default).
    pub collision: CollisionChoice,
    /// Keep only configurations whose rays to the points the robot's
    /// collision geometry does not block (on with any collision check).
    pub line_of_sight: bool,
    /// The candidates.
    pub candidates: Candidates,
    /// The selection's settings (poses, seed).
    pub settings: Settings,
    /// Score the design against its visible pool's certified bound.
    pub gap: Option<BoundSettings>,
    /// The pixel noise σ the user gave, px (the report then predicts the
    /// true error at it).
    pub pixel_noise: Option<f64>,
    /// The robot's name or description path, for the report.
    pub robot_name: String,
    /// The chain of the robot's URDF tree, for the report.
    pub chain: ChainChoice,
}

/// A camera design with everything the caller renders or writes.
#[derive(Debug)]
pub struct CameraSelection {
    /// The chain the camera sees (the robot's, or from the camera's link).
    pub robot: Robot,
    /// The design.
    pub design: CameraDesign,
    /// Candidate configurations considered.
    pub candidates: usize,
    /// Candidates the collision filters removed; `None` without filters.
    pub collision_removed: Option<usize>,
    /// The gap to the visible pool's certified bound, when asked for.
    pub gap: Option<DesignGap>,
    /// The report (`--json`'s, the `.json` design's).
    pub report: CameraDesignReport,
    /// The chain's joint names.
    pub joint_names: Vec<String>,
    /// The selection's settings (the curve's selections reuse them).
    pub settings: Settings,
    /// The pixel noise σ the user gave, px.
    pub pixel_noise: Option<f64>,
    /// What the camera sees (its intrinsics, placements and target).
    pub view: CameraView,
    /// The line-of-sight check, when asked for.
    pub sight: Option<LineOfSight>,
}

/// Chooses a camera design: the chain, the candidates, the filters and line
/// of sight, the choice, its gap and report.
///
/// # Errors
/// A camera link not in the robot's URDF tree, collision checks or a line
/// of sight on a robot not imported from a URDF, an invalid view, too many
/// candidates for memory, or a failing selection or bound.
pub fn select_camera(
    robot: &Robot,
    plan: CameraSelectPlan,
) -> Result<CameraSelection, ExperimentError> {
    plan.view
        .validate()
        .map_err(|e| Error::Invalid(format!("camera view: {e}")))?;
    let robot = match &plan.camera_link {
        Some(link) => urdf_branch::camera_branch(robot, link)
            .map_err(|e| Error::Invalid(format!("the camera's link {link}: {e}")))?,
        None => robot.clone(),
    };
    let (filters, sight) = sight(
        &robot,
        &plan.collision,
        plan.line_of_sight,
        plan.camera_link.as_deref(),
    )?;
    let pool_seed = match plan.candidates {
        Candidates::Sampled { seed, .. } => seed,
        Candidates::Listed(_) => 0,
    };
    let candidates = candidates(&robot, plan.candidates)?;
    let (design, collision_removed) = camera_design_filtered(
        &robot,
        &plan.view,
        &filters,
        sight.as_ref(),
        &candidates,
        &plan.settings,
    )?;
    let gap = plan.gap.as_ref().map(|b| design.gap(b)).transpose()?;
    let joint_names = crate::units::joint_names(&robot);
    let pool = CameraPoolInfo {
        robot: plan.robot_name,
        chain: plan.chain,
        camera_link: plan.camera_link,
        candidates: candidates.len(),
        pool_seed,
        collision_removed,
        pixel_noise: plan.pixel_noise,
    };
    let report = CameraDesignReport::new(
        &design,
        pool,
        plan.view.mounting,
        joint_names.clone(),
        gap.clone(),
    );
    Ok(CameraSelection {
        robot,
        design,
        candidates: candidates.len(),
        collision_removed,
        gap,
        report,
        joint_names,
        settings: plan.settings,
        pixel_noise: plan.pixel_noise,
        view: plan.view,
        sight,
    })
}

/// The collision filters and the line of sight of a camera pool on
/// `robot` (the chain from `camera_link` with one: its joints drive the
/// whole tree by name, obstacles and the floor are in the tree's root
/// link, and the rays leave from the camera's link). Nothing without a
/// check or a line of sight.
fn sight(
    robot: &Robot,
    collision: &CollisionChoice,
    line_of_sight: bool,
    camera_link: Option<&str>,
) -> Result<(Vec<PoolFilter>, Option<LineOfSight>), Error> {
    if !(collision.any() || line_of_sight) {
        return Ok((Vec::new(), None));
    }
    let root = match camera_link {
        Some(link) => Some((link, urdf_branch::tree_root(robot)?)),
        None => None,
    };
    let Some(mut chain) = UrdfChain::of(robot) else {
        return Err(Error::Invalid(format!(
            "checking collisions or the line of sight needs a URDF robot with collision geometry; '{}' has none",
            robot.name
        )));
    };
    if let Some((_, r)) = &root {
        chain.base.clone_from(r);
    }
    let filters = if collision.any() {
        collision.filters(chain.clone())
    } else {
        Vec::new()
    };
    Ok((filters, Some(collision.line_of_sight(chain, root))))
}

/// The candidate configurations: those listed, or the samples (their
/// memory checked first).
fn candidates(robot: &Robot, c: Candidates) -> Result<Vec<Vec<f64>>, Error> {
    Ok(match c {
        Candidates::Listed(qs) => qs,
        Candidates::Sampled { count, seed } => {
            crate::resources::check_alloc::<f64>(
                &format!("{count} sampled candidate configurations"),
                count.saturating_mul(robot.dof() + 3),
            )?;
            crate::observability::generic_configurations(robot, count, seed)
        }
    })
}

/// Whether `out` names a `.csv` (the design's table) rather than a `.json`
/// (the design and its figures); refused otherwise.
fn is_csv(out: &Output<'_>) -> Result<bool, Error> {
    let ext = |e: &str| {
        out.path
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case(e))
    };
    if ext("csv") || ext("json") {
        return Ok(ext("csv"));
    }
    Err(Error::Invalid(format!(
        "{} {}: a camera design is written as .csv (candidate, the joints, points_seen) or .json (the design and its figures, as --json prints them)",
        out.label,
        out.path.display()
    )))
}

/// A camera design's files checked before any work: each a `.csv` or a
/// `.json`, at most one of each; returned the `.csv` first.
pub fn design_outputs<'a>(outs: &[Output<'a>]) -> Result<Vec<Output<'a>>, Error> {
    let (mut csv, mut json) = (None, None);
    for o in outs {
        let slot = if is_csv(o)? { &mut csv } else { &mut json };
        if slot.replace(*o).is_some() {
            return Err(Error::Invalid(format!(
                "{} {}: one file of each kind (.csv, .json)",
                o.label,
                o.path.display()
            )));
        }
    }
    Ok(csv.into_iter().chain(json).collect())
}

impl CameraSelection {
    /// Writes the design to `out` as its name says: `.csv`, the design's
    /// table ([`Self::design_csv`]); `.json`, its report. Atomically; an
    /// existing file only with `overwrite`.
    pub fn write(&self, out: Output<'_>, overwrite: bool) -> Result<(), Error> {
        let text = if is_csv(&out)? {
            self.design_csv()
        } else {
            serde_json::to_string_pretty(&self.report)
                .map_err(|e| Error::Invalid(format!("{}: {e}", out.label)))?
                + "\n"
        };
        crate::io::atomic::check_outputs(&[out], &[], overwrite)?;
        crate::io::atomic::write_atomic(out.path, text.as_bytes())
    }

    /// The design as a CSV table: one row a pose, `candidate`, the joints
    /// (radians, metres, 17 significant digits) and `points_seen`.
    #[must_use]
    pub fn design_csv(&self) -> String {
        let d = &self.design;
        let mut csv = format!("candidate,{},points_seen\n", self.joint_names.join(","));
        for ((q, c), s) in d.qs.iter().zip(&d.candidates).zip(&d.seen) {
            let joints: Vec<String> = q.iter().map(|v| format!("{v:.17}")).collect();
            let _ = writeln!(csv, "{c},{},{s}", joints.join(","));
        }
        csv
    }

    /// The design as text (what `select --camera-info` prints): the
    /// candidates, the design's figures, the files `written` (the CSV table
    /// when none was) and, with a `curve`, the size it recommends.
    #[must_use]
    pub fn text(&self, written: &[String], curve: Option<&PoseCountCurve>) -> String {
        let csv = self.design_csv();
        let facts = crate::render::camera_design::CameraDesignFacts {
            candidates: self.candidates,
            collision_removed: self.collision_removed,
            gap: self.gap.as_ref(),
            pixel_noise: self.pixel_noise,
            csv: &csv,
        };
        let mut s = crate::render::camera_design::text(&self.design, &facts, written);
        if let Some(r) = curve.and_then(|c| c.recommended.as_ref()) {
            s += &crate::render::folder::recommendation_text(r);
        }
        s
    }

    /// Writes the report folder of this design into `dir` (`select
    /// --camera-info … --report DIR`): its text with the files `written`
    /// beside it, the report, the `curve` (`noise_is_default`: its noise
    /// was not given), the figures and the 3D page.
    ///
    /// # Errors
    /// The folder cannot be written.
    pub fn write_report(
        &self,
        dir: &std::path::Path,
        curve: &PoseCountCurve,
        written: &[String],
        noise_is_default: bool,
    ) -> Result<(), Error> {
        let json = serde_json::to_value(&self.report)
            .map_err(|e| Error::Invalid(format!("report.json: {e}")))?;
        let lines: Vec<SightLines> = match &self.sight {
            Some(s) => self
                .design
                .qs
                .iter()
                .filter_map(|q| s.sight_lines(&self.view, &self.robot, &self.robot.nominal, q))
                .collect(),
            None => Vec::new(),
        };
        crate::render::folder::camera_selection(
            dir,
            &self.robot,
            &self.joint_names,
            &crate::render::page_camera::CameraPage {
                design: &self.design,
                lines: &lines,
                package_dirs: self
                    .sight
                    .as_ref()
                    .map_or(&[], |s| s.collision.spec.package_dirs.as_slice()),
            },
            &self.text(written, Some(curve)),
            &json,
            curve,
            noise_is_default,
        )
    }

    /// The "how many poses" curve of this design's visible pool at pixel
    /// noise σ `noise_px` (px), with the design's own size among the
    /// sizes and `target_mm` the error to reach, if any.
    ///
    /// # Errors
    /// A failing selection or bound.
    pub fn curve(
        &self,
        bound: BoundSettings,
        noise_px: f64,
        target_mm: Option<f64>,
    ) -> Result<PoseCountCurve, crate::how_many::HowManyError> {
        let mut cs = CurveSettings::new(self.settings.clone(), noise_px);
        cs.bound = bound;
        cs.also = vec![self.design.qs.len()];
        cs.target_mm = target_mm;
        Ok(self.design.how_many(&cs)?)
    }
}
