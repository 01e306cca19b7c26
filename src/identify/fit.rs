//! Calibrating from measured data as one call: a loss chosen at run time,
//! the samples it down-weighted, each parameter's significance, and
//! held-out validation over random splits (optionally against a model
//! pruned to its significant parameters).

use super::evaluation::{ModelErrors, residuals};
use super::start::for_measurements;
use super::{
    Calibration, Cauchy, Huber, Identification, IdentifyError, LmSettings, Loss, Result, Robust,
    identify, identify_robust,
};
use crate::data::Measurements;
use crate::error::SettingError;
use crate::model::{ParamTable, Robot};
use rand::SeedableRng;
use rand::seq::SliceRandom;
use serde::Serialize;

/// The loss of a fit, chosen at run time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum LossChoice {
    /// Least squares.
    L2,
    /// Huber with this scale (metres of a pose's weighted residual norm).
    Huber {
        /// The scale.
        scale: f64,
    },
    /// Cauchy with this scale (metres).
    Cauchy {
        /// The scale.
        scale: f64,
    },
}

/// A loss by its name, before its scale is given: the choice a front end
/// offers ([`LossChoice::of`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LossKind {
    /// Least squares.
    L2,
    /// Huber: quadratic up to the scale, linear beyond.
    Huber,
    /// Cauchy: down-weights gross outliers towards zero.
    Cauchy,
}

crate::choice!(LossKind { L2 => "l2", Huber => "huber", Cauchy => "cauchy" });

impl LossChoice {
    /// The loss `kind` at `scale` (metres: the residual norm of one pose
    /// where a robust loss turns robust), checked: a robust loss needs a
    /// finite scale > 0, least squares takes none.
    pub fn of(kind: LossKind, scale: Option<f64>) -> std::result::Result<Self, SettingError> {
        let scale = match (kind, scale) {
            (LossKind::L2, None) => return Ok(LossChoice::L2),
            (LossKind::L2, Some(_)) => {
                return Err(SettingError::because(
                    "loss_scale",
                    "is for `loss` huber or cauchy",
                ));
            }
            (_, None) => {
                return Err(SettingError::because(
                    "loss_scale",
                    format!(
                        "`loss` {kind} needs it (metres: the residual norm of one pose where the loss turns robust, e.g. 3 times the sensor noise)"
                    ),
                ));
            }
            (_, Some(s)) => crate::error::positive("loss_scale", s, "metres")?,
        };
        Ok(match kind {
            LossKind::Huber => LossChoice::Huber { scale },
            _ => LossChoice::Cauchy { scale },
        })
    }
}

/// A weight below this marks a sample as down-weighted in reports (Huber:
/// its residual beyond the scale).
pub const DOWNWEIGHTED: f64 = 0.999;

impl LossChoice {
    /// The loss weight below which a pose counts as down-weighted: its
    /// residual norm beyond the loss's scale (Huber's weight `c/r` is below
    /// 1 there, Cauchy's `1/(1 + r²/c²)` below ½); `None` for least squares.
    /// Cauchy weighs every pose below 1, so `DOWNWEIGHTED` would list them
    /// all.
    #[must_use]
    pub fn downweighted_below(self) -> Option<f64> {
        match self {
            LossChoice::L2 => None,
            LossChoice::Huber { .. } => Some(DOWNWEIGHTED),
            LossChoice::Cauchy { .. } => Some(0.5),
        }
    }
}

/// A fit: the identification and each pose's final loss weight (all 1 for
/// least squares).
#[derive(Clone, Debug)]
pub struct Fit {
    /// The identification.
    pub id: Identification,
    /// The loss weight `ρ'(‖r_i‖²)` of each pose at the estimate.
    pub weights: Vec<f64>,
    /// The loss.
    pub loss: LossChoice,
}

impl Fit {
    /// Poses (0-based) the loss really down-weights (their residual beyond
    /// its scale, [`LossChoice::downweighted_below`]), with their weight.
    #[must_use]
    pub fn downweighted(&self) -> Vec<(usize, f64)> {
        let below = self.loss.downweighted_below().unwrap_or(0.0);
        self.weights
            .iter()
            .enumerate()
            .filter(|(_, w)| **w < below)
            .map(|(i, &w)| (i, w))
            .collect()
    }
}

/// Identifies `robot` from `meas` starting at `start` with `loss`.
pub fn fit(
    robot: &Robot,
    start: &ParamTable,
    meas: &Measurements,
    lm: &LmSettings,
    loss: LossChoice,
) -> Result<Fit> {
    fn weights<L: Loss>(
        robot: &Robot,
        start: &ParamTable,
        meas: &Measurements,
        theta: &[f64],
        loss: L,
    ) -> Result<Vec<f64>> {
        let mut p = Robust::new(Calibration::new(robot, start, meas)?, loss);
        p.reweight(theta);
        Ok(p.weights())
    }
    let (id, w) = match loss {
        LossChoice::L2 => {
            let id = identify(robot, start, meas, lm)?;
            let w = vec![1.0; meas.len()];
            (id, w)
        }
        LossChoice::Huber { scale } => {
            let l = Huber::new(scale)?;
            let id = identify_robust(robot, start, meas, lm, l)?;
            let w = weights(robot, start, meas, &id.estimate, l)?;
            (id, w)
        }
        LossChoice::Cauchy { scale } => {
            let l = Cauchy::new(scale)?;
            let id = identify_robust(robot, start, meas, lm, l)?;
            let w = weights(robot, start, meas, &id.estimate, l)?;
            (id, w)
        }
    };
    Ok(Fit {
        id,
        weights: w,
        loss,
    })
}

/// How a fit weighs its residual blocks (positions, orientations) against
/// each other.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Weights {
    /// Each block's σ estimated from its own residuals, the weights
    /// iterated to agree ([`fit_weighted`]).
    #[default]
    Estimated,
    /// The robot's [`Robot::orientation_scale`] as given.
    Fixed,
}

/// A fit with the weights it ended with and its blocks' σ's.
#[derive(Clone, Debug)]
pub struct WeightedFit {
    /// The robot as fitted: its `orientation_scale` the final weight.
    pub robot: Robot,
    /// The table the fit started from (the last round's start).
    pub start: ParamTable,
    /// The fit.
    pub fit: Fit,
    /// Each residual block's σ at the fit.
    pub sigmas: Vec<super::variance::BlockSigma>,
    /// Reweighting rounds (0 with fixed weights or one block).
    pub rounds: usize,
}

/// Reweighting rounds at most, and the relative change of the weight below
/// which they stop (the σ's then agree with the weights to 0.1 %).
const VCE_ROUNDS: usize = 20;
const VCE_TOL: f64 = 1e-3;

/// Fits as [`fit`], and with [`Weights::Estimated`] and a sensor that
/// measures orientations, re-weighs the orientation rows by the ratio of
/// the position and orientation σ's estimated from the residuals
/// ([`super::variance`]: `w = σ_p / σ_o`, metres per radian) and refits
/// from the last estimate until the weight settles. Noise-free data (a σ
/// below 1e-12) keep the given weight.
pub fn fit_weighted(
    robot: &Robot,
    start: &ParamTable,
    meas: &Measurements,
    lm: &LmSettings,
    loss: LossChoice,
    weights: Weights,
) -> Result<WeightedFit> {
    let mut r = robot.clone();
    let mut from = start.clone();
    let mut f = fit(&r, &from, meas, lm, loss)?;
    let mut sigmas = super::variance::block_sigmas(&r, &from, meas, &f.id, &f.weights)?;
    let mut rounds = 0;
    let reweigh = weights == Weights::Estimated && !meas.orientations().is_empty();
    while reweigh && rounds < VCE_ROUNDS {
        let Some(w) = position_per_orientation(&sigmas) else {
            break;
        };
        if (w / r.orientation_scale).ln().abs() < VCE_TOL {
            break;
        }
        r.orientation_scale = w;
        from = f.id.table.clone();
        f = fit(&r, &from, meas, lm, loss)?;
        sigmas = super::variance::block_sigmas(&r, &from, meas, &f.id, &f.weights)?;
        rounds += 1;
    }
    Ok(WeightedFit {
        robot: r,
        start: from,
        fit: f,
        sigmas,
        rounds,
    })
}

/// `σ_p / σ_o` (metres per radian) from the blocks' σ's, the positions'
/// pooled; `None` without both, or when either is below 1e-12 (noise-free
/// data say nothing of the ratio).
fn position_per_orientation(sigmas: &[super::variance::BlockSigma]) -> Option<f64> {
    let pooled = |unit: &str| {
        let (ss, red) = sigmas
            .iter()
            .filter(|b| b.unit == unit && b.sigma.is_finite())
            .fold((0.0, 0.0), |(s, r), b| {
                (s + b.sigma * b.sigma * b.redundancy, r + b.redundancy)
            });
        (red > 0.0).then(|| (ss / red).sqrt())
    };
    let (p, o) = (pooled("m")?, pooled("rad")?);
    (p > 1e-12 && o > 1e-12).then(|| (p / o).clamp(1e-4, 1e4))
}

/// |t| at or above which a parameter's change from nominal is called
/// significant (about 95 % two-sided for a normal estimate).
pub const T_SIGNIFICANT: f64 = 2.0;

/// How far one parameter's estimate can be trusted.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ParameterTrust {
    /// Parameter name.
    pub name: String,
    /// Nominal value (metres or radians).
    pub nominal: f64,
    /// Estimate.
    pub estimate: f64,
    /// Estimate − nominal.
    pub change: f64,
    /// Standard deviation of the estimate, when the fit has a covariance.
    pub std: Option<f64>,
    /// `change / std`.
    pub t: Option<f64>,
    /// A plain verdict.
    pub verdict: &'static str,
}

/// Each identified parameter's estimate against `nominal`, with its
/// standard deviation, `t = change/σ` and a verdict.
#[must_use]
pub fn trust(robot: &Robot, nominal: &ParamTable, id: &Identification) -> Vec<ParameterTrust> {
    let nom = robot.unknown_values(nominal);
    let n_kin = robot.n_unknowns();
    id.names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let change = id.estimate[k] - nom[k];
            let std = id.covariance.as_ref().map(|c| c.std[k]);
            let t = std.filter(|s| *s > 0.0).map(|s| change / s);
            let verdict = if k >= n_kin {
                "marker offset: always estimated"
            } else {
                match t {
                    Some(t) if t.abs() >= T_SIGNIFICANT => {
                        "significant: the data move it from nominal"
                    }
                    Some(_) => "not significant: consistent with nominal (a candidate to fix)",
                    None => "no covariance (rank-deficient or no residual degrees of freedom)",
                }
            };
            ParameterTrust {
                name: name.clone(),
                nominal: nom[k],
                estimate: id.estimate[k],
                change,
                std,
                t,
                verdict,
            }
        })
        .collect()
}

/// The robot with its unknowns changed: `fix` removed (kept at their
/// values), `free` added (any structural parameter by name). Marker offsets
/// cannot be fixed. The result is checked to be identifiable.
pub fn with_fixed_and_free(robot: &Robot, fix: &[String], free: &[String]) -> Result<Robot> {
    if fix.is_empty() && free.is_empty() {
        return Ok(robot.clone());
    }
    let mut ids = robot.unknowns.clone();
    for name in fix {
        if name.starts_with("marker") {
            return Err(setting(
                "fixed parameter",
                name,
                "marker offsets are always estimated",
            ));
        }
        let unknowns: Vec<String> = robot
            .unknowns
            .iter()
            .map(|&u| robot.param_name(u))
            .collect();
        let id = robot
            .param_id(name)
            .map_err(|_| unknown_name("fixed parameter", name, &unknowns))?;
        let Some(pos) = ids.iter().position(|&u| u == id) else {
            return Err(setting(
                "fixed parameter",
                name,
                "not an unknown of this robot (see the estimate's names)",
            ));
        };
        ids.remove(pos);
    }
    for name in free {
        let id = robot.param_id(name).map_err(|_| {
            let all: Vec<String> = robot
                .candidate_unknowns()
                .into_iter()
                .map(|u| robot.param_name(u))
                .collect();
            unknown_name("freed parameter", name, &all)
        })?;
        if !ids.contains(&id) {
            ids.push(id);
        }
    }
    ids.sort();
    let mut r = robot.clone();
    r.unknowns = ids;
    r.validate()?;
    r.check_identifiable()?;
    Ok(r)
}

/// The robot a data set is fitted as: `fix` and `free` applied
/// ([`with_fixed_and_free`]), then the unknowns `meas` do not determine at
/// `start` fixed with a reason ([`super::fix_undetermined`]; never one
/// named in `free`).
pub fn prepare_for_data(
    robot: &Robot,
    start: &ParamTable,
    meas: &Measurements,
    fix: &[String],
    free: &[String],
) -> Result<super::Determined> {
    let r = with_fixed_and_free(robot, fix, free)?;
    super::fix_undetermined(&r, start, meas, free)
}

/// An unknown parameter name given as `what` (a fixed or a freed parameter): the closest valid names
/// (by edit distance) and the whole list.
fn unknown_name(what: &str, name: &str, valid: &[String]) -> IdentifyError {
    IdentifyError::Model(crate::Error::Invalid(format!(
        "{what} '{name}': not a parameter of this robot{}; the valid names are {}",
        crate::names::did_you_mean(name, valid),
        valid.join(", ")
    )))
}

fn setting(what: &'static str, name: &str, reason: &'static str) -> IdentifyError {
    IdentifyError::Setting {
        name: what,
        value: name.to_string(),
        reason,
    }
}

/// Held-out validation settings: build with [`HoldoutSettings::builder`]
/// (validated) or take [`HoldoutSettings::default`]. Whether a fraction
/// leaves a pose on each side depends on the data: [`holdout`] checks that.
#[derive(Clone, Copy, Debug, Serialize)]
#[non_exhaustive]
pub struct HoldoutSettings {
    /// Fraction of the poses held out per split, in (0, 1). Default 0.2.
    pub fraction: f64,
    /// Number of random splits, `≥ 1`. Default 4.
    pub splits: usize,
    /// Seed of the splits. Default 0.
    pub seed: u64,
    /// Also fit a model pruned to the significant parameters (|t| ≥ 2 on
    /// the split's training fit) and evaluate it on the same held-out poses.
    /// Default false.
    pub prune: bool,
    /// How each split's fit weighs its residual blocks (estimated on the
    /// split's training rows only). Default [`Weights::Estimated`].
    pub weights: Weights,
}

impl Default for HoldoutSettings {
    fn default() -> Self {
        Self {
            fraction: 0.2,
            splits: 4,
            seed: 0,
            prune: false,
            weights: Weights::Estimated,
        }
    }
}

crate::settings::settings_builder! {
    /// Validated construction of [`HoldoutSettings`].
    HoldoutSettingsBuilder for HoldoutSettings, error IdentifyError {
        /// Fraction held out per split, in (0, 1) (default 0.2).
        fraction: f64,
        /// Random splits (default 4).
        splits: usize,
        /// Seed of the splits (default 0).
        seed: u64,
        /// Also evaluate a pruned model (default false).
        prune: bool,
        /// Block weights of each split's fit (default estimated).
        weights: Weights,
    }
}

impl HoldoutSettings {
    /// Checks the fraction is in (0, 1) and there is at least one split.
    pub fn validate(&self) -> Result<()> {
        if !(self.fraction > 0.0 && self.fraction < 1.0) {
            return Err(IdentifyError::Setting {
                name: "held-out fraction",
                value: self.fraction.to_string(),
                reason: "the held-out fraction must be in (0, 1)",
            });
        }
        if self.splits == 0 {
            return Err(IdentifyError::Setting {
                name: "held-out splits",
                value: "0".into(),
                reason: "at least one split",
            });
        }
        Ok(())
    }
}

/// One split's figures.
#[derive(Clone, Debug, Serialize)]
pub struct SplitResult {
    /// Poses fitted.
    pub train: usize,
    /// Poses held out.
    pub test: usize,
    /// Errors of the fitted model on the poses it was fitted to.
    pub fitted: ModelErrors,
    /// Errors of the fitted model on the held-out poses.
    pub held_out: ModelErrors,
    /// Errors of the nominal model on the held-out poses.
    pub nominal: ModelErrors,
    /// The pruned model's held-out errors and its unknowns' count.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pruned: Option<(usize, ModelErrors)>,
}

/// Fits on a random `1 − fraction` of the poses and evaluates on the rest,
/// `splits` times. `prepare` turns the robot adapted to the data
/// ([`for_measurements`]), its start table and the training poses into the
/// one fitted (e.g. [`prepare_for_data`]). The nominal figures are those of
/// `baseline` (the user's model, adapted to the data's sensor on the
/// training poses) when it differs from `robot` (a start mounted in the
/// data's frame).
#[allow(clippy::too_many_arguments)]
pub fn holdout(
    robot: &Robot,
    baseline: &Robot,
    meas: &Measurements,
    lm: &LmSettings,
    loss: LossChoice,
    settings: &HoldoutSettings,
    prepare: &dyn Fn(&Robot, &ParamTable, &Measurements) -> Result<Robot>,
) -> Result<Vec<SplitResult>> {
    settings.validate()?;
    let n = meas.len();
    let test = (settings.fraction * n as f64).round() as usize;
    if test == 0 || test >= n {
        return Err(IdentifyError::Setting {
            name: "held-out fraction",
            value: format!("{} of {n} poses", settings.fraction),
            reason: "the held-out fraction must be in (0, 1) and leave at least one pose on each side",
        });
    }
    let mut out = Vec::with_capacity(settings.splits);
    for s in 0..settings.splits {
        let mut idx: Vec<usize> = (0..n).collect();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(settings.seed.wrapping_add(s as u64));
        idx.shuffle(&mut rng);
        let (te, tr) = idx.split_at(test);
        let (mut tr, mut te) = (tr.to_vec(), te.to_vec());
        tr.sort_unstable();
        te.sort_unstable();
        let (mtr, mte) = (meas.subset(&tr), meas.subset(&te));
        let start = for_measurements(robot, &mtr, lm)?;
        let r = prepare(&start.robot, &start.table, &mtr)?;
        let WeightedFit {
            robot: r, fit: f, ..
        } = fit_weighted(&r, &start.table, &mtr, lm, loss, settings.weights)?;
        let fitted = residuals(&r, &f.id.table, &mtr)?;
        let held_out = residuals(&r, &f.id.table, &mte)?;
        let nominal = if std::ptr::eq(baseline, robot) {
            residuals(&r, &r.nominal, &mte)?
        } else {
            match for_measurements(baseline, &mtr, lm) {
                Ok(b) => residuals(&b.robot, &b.robot.nominal, &mte)?,
                Err(_) => residuals(&r, &r.nominal, &mte)?,
            }
        };
        let pruned = if settings.prune {
            let keep: Vec<String> = trust(&r, &r.nominal, &f.id)
                .into_iter()
                .filter(|p| {
                    p.name.starts_with("marker") || p.t.is_some_and(|t| t.abs() >= T_SIGNIFICANT)
                })
                .map(|p| p.name)
                .collect();
            let fix: Vec<String> = r
                .parameter_names()
                .into_iter()
                .filter(|n| !keep.contains(n))
                .collect();
            let rp = with_fixed_and_free(&r, &fix, &[])?;
            let fp = fit(&rp, &start.table, &mtr, lm, loss)?;
            Some((rp.n_params(), residuals(&rp, &fp.id.table, &mte)?))
        } else {
            None
        };
        out.push(SplitResult {
            train: tr.len(),
            test: te.len(),
            fitted,
            held_out,
            nominal,
            pruned,
        });
    }
    Ok(out)
}
