//! The fit of a contact calibration: the robot's identifiable unknowns,
//! the tool offset and the points, by Levenberg–Marquardt (a robust loss by
//! iteratively reweighted least squares on the poses' rows only: a known
//! distance is never down-weighted).
//!
//! **The gauge.** Moving the whole setup rigidly (in particular turning it
//! about the base's vertical and translating it) changes no residual: the
//! unknown points follow. Unknowns whose column lies in the span of the
//! points' columns are fixed and reported as such (unknown planes follow
//! such a motion too; a known plane pins the setup, and then no unknown is
//! fixed as the gauge); the rest of what the
//! contacts cannot see is fixed by the shared rule
//! ([`crate::identify::undetermined`]: column-pivoted QR on the
//! column-scaled Jacobian, the sensor's own unknowns pivoted first).

use super::{start_own, start_planes};
use crate::data::ContactFile;
use crate::identify::lm::{Solution, StopReason, levenberg_marquardt};
use crate::identify::undetermined::{FixedParameter, fix_undetermined_below};
use crate::identify::{Calibration, LmSettings, LossChoice, Residuals, Result};
use crate::lsq::loss::{Cauchy, Huber, Loss};
use crate::lsq::outliers::{OutlierChoice, Tester};
use crate::measure::contact::{ContactSensor, KnownDistance, Plane, PlaneKind};
use crate::model::{ParamTable, Robot};
use faer::Mat;
use serde::Serialize;

/// Most reweighting rounds of a robust fit.
pub const IRLS_ROUNDS: usize = 50;
/// A robust fit stops when no `√w` of a row changes by more than this.
pub const IRLS_TOLERANCE: f64 = 1e-9;
/// An unknown whose twist (rad/s and m/s per unit of it, O(1)) differs by
/// no more than this between rows is a rigid motion of the whole setup:
/// rounding of the chain walk is ~1e-15, a joint's motion varies by O(0.1).
pub const GAUGE_TOL: f64 = 1e-8;

/// The pivot (of a unit column, after the columns kept before it) at or
/// below which a contact fit calls an unknown weakly determined, and
/// estimates it only when the data's noise makes it worth it
/// ([`super::worth`]): stricter than the shared
/// [`crate::identify::undetermined::PIVOT_TOL`] (3.2e-5, which separates
/// exact dependences from rounding). Contacts carry σ ≈ 0.2 mm on points
/// ~0.5 m from the base (4e-4 relative), so an unknown with less than 1e-3
/// of its column outside the others is moved by noise far beyond its real
/// size: on one MUKCa placement joint 6's γ went to 0.56 ± 0.22 rad and
/// predicted the other placements worse; with 1e-3 joint 6's γ and d are
/// fixed (their motion at the ball is nearly the tool offset's), on one
/// placement as on nine (held out: 0.569 → 0.554 mm trained on one
/// placement, 0.421 → 0.420 mm leaving one out).
pub const CONTACT_PIVOT_TOL: f64 = 1e-3;

/// The reason given for an unknown that moves every point together.
pub const GAUGE_REASON: &str = "moves every contact point together (a rigid motion of the whole setup, e.g. about the base's vertical): the unknown points absorb it";

/// How to fit: [`ContactSettings::builder`] (validated) or the defaults.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct ContactSettings {
    /// The solver's settings. Default [`LmSettings::default`].
    pub lm: LmSettings,
    /// The loss. Default least squares.
    pub loss: LossChoice,
    /// Parameters never fixed (nor counted as the gauge). Default none.
    pub keep: Vec<String>,
    /// What happens to rows the gross-error test flags (with least
    /// squares; a robust loss keeps every row). Default: dropped at
    /// [`crate::lsq::outliers::ALPHA`]. [`fit_contacts`] fits every
    /// row; the pipeline ([`crate::experiment::contacts`]) tests them.
    pub outliers: OutlierChoice,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            lm: LmSettings::default(),
            loss: LossChoice::L2,
            keep: Vec::new(),
            outliers: OutlierChoice::default(),
        }
    }
}

crate::settings::settings_builder! {
    /// Validated construction of [`ContactSettings`].
    ContactSettingsBuilder for ContactSettings, error crate::identify::IdentifyError {
        /// The solver's settings (default [`LmSettings::default`]).
        lm: LmSettings,
        /// The loss (default least squares).
        loss: LossChoice,
        /// Parameters never fixed (default none).
        keep: Vec<String>,
        /// What happens to rows the gross-error test flags (default:
        /// dropped at rate [`crate::lsq::outliers::ALPHA`]).
        outliers: OutlierChoice,
    }
}

impl ContactSettings {
    /// Checks the solver's settings, the loss's scale and the outlier
    /// test's rate.
    pub fn validate(&self) -> Result<()> {
        self.lm.validate()?;
        crate::lsq::outliers::check_choice(self.outliers)?;
        loss_of(self.loss).map(|_| ())
    }
}

/// A contact calibration.
#[derive(Clone, Debug, Serialize)]
pub struct ContactFit {
    /// The robot with the unknowns that were estimated.
    #[serde(skip)]
    pub robot: Robot,
    /// The calibrated parameter table.
    #[serde(skip)]
    pub table: ParamTable,
    /// The estimated tool offset (end frame, metres).
    pub tool_offset: [f64; 3],
    /// The points' names.
    pub points: Vec<String>,
    /// The estimated points (base frame, metres).
    pub point_positions: Vec<[f64; 3]>,
    /// The planes: estimated (unknown) or as given (known).
    pub planes: Vec<PlaneEstimate>,
    /// Names of the estimated unknowns (robot's, then own).
    pub names: Vec<String>,
    /// Their start values.
    pub start: Vec<f64>,
    /// Their estimates.
    pub estimate: Vec<f64>,
    /// Their standard deviations `√(σ̂² (XᵀX)⁻¹)_jj`, when determined.
    pub std: Option<Vec<f64>>,
    /// Their covariance `σ̂² (XᵀX)⁻¹` (row-major, in the order of
    /// [`ContactFit::names`]), when determined: what the calibrated frames'
    /// standard deviations are carried from.
    #[serde(skip)]
    pub covariance: Option<Vec<Vec<f64>>>,
    /// Unknowns fixed at their start values, with why.
    pub fixed: Vec<FixedParameter>,
    /// Whether a tolerance was met with a finite, full-rank Jacobian.
    pub converged: bool,
    /// Why the iteration stopped.
    pub stop: StopReason,
    /// Outer iterations, summed over reweighting rounds.
    pub iterations: usize,
    /// `σ̂` of a row (metres), weighted.
    pub sigma_hat: Option<f64>,
    /// Each row's final loss weight (1 for least squares).
    pub weights: Vec<f64>,
}

impl ContactFit {
    /// Rows (0-based) whose weight is below
    /// [`crate::identify::fit::DOWNWEIGHTED`], with it.
    #[must_use]
    pub fn downweighted(&self) -> Vec<(usize, f64)> {
        self.weights
            .iter()
            .enumerate()
            .filter(|(_, w)| **w < crate::identify::fit::DOWNWEIGHTED)
            .map(|(i, &w)| (i, w))
            .collect()
    }
}

/// A contact plane after the fit: `normal · x = offset_m` (base frame).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PlaneEstimate {
    /// Its name.
    pub name: String,
    /// Whether it was given (not estimated).
    pub known: bool,
    /// Its unit normal.
    pub normal: [f64; 3],
    /// Its offset, metres.
    pub offset_m: f64,
}

/// A calibration's rows scaled by a weight per pose (constraints unscaled).
struct Weighted<'a> {
    inner: Calibration<'a>,
    sqrt_w: Vec<f64>,
}

impl Residuals for Weighted<'_> {
    fn n_residuals(&self) -> usize {
        self.inner.n_residuals()
    }
    fn n_params(&self) -> usize {
        self.inner.n_params()
    }
    fn eval(&mut self, theta: &[f64], r: &mut [f64], mut jac: Option<&mut Mat<f64>>) -> bool {
        let ok = self.inner.eval(theta, r, jac.as_deref_mut());
        for (i, w) in self.sqrt_w.iter().enumerate() {
            for k in 3 * i..3 * i + 3 {
                r[k] *= w;
                if let Some(j) = jac.as_deref_mut() {
                    for c in 0..j.ncols() {
                        j[(k, c)] *= w;
                    }
                }
            }
        }
        ok
    }
}

/// The calibration problem of `robot` on `file`'s contacts.
fn problem<'a>(
    robot: &'a Robot,
    start: &'a ParamTable,
    file: &'a ContactFile,
    distances: &[KnownDistance],
    planes: &[Plane],
) -> Calibration<'a> {
    // The planes were checked when read or made known: a failure here is a
    // programming error, not an input's.
    let sensor = ContactSensor::new(file.points.clone(), distances.to_vec())
        .with_planes(planes.to_vec())
        .expect("checked planes");
    let measured: Vec<f64> = file
        .groups
        .iter()
        .flat_map(|&g| ContactSensor::value_of(g))
        .collect();
    Calibration::with_sensor(robot, start, &file.qs, Box::new(sensor), measured)
}

/// The gross-error test of `fit`'s rows ([`crate::lsq::outliers`]):
/// the least-squares problem `fit` solved (`file`'s rows with `distances`,
/// its robot's unknowns from `start`, the planes started as
/// [`fit_contacts`] starts them) at its estimate, ready to test each row's
/// three residuals (the distance rows are never tested); `None` when its
/// information is singular or nothing is left to test against.
#[must_use]
pub fn row_tester(
    fit: &ContactFit,
    start: &ParamTable,
    file: &ContactFile,
    distances: &[KnownDistance],
) -> Option<Tester> {
    let planes = start_planes(&fit.robot, start, file);
    let mut prob = problem(&fit.robot, start, file, distances, &planes);
    Tester::new(&mut prob, &fit.estimate, None)
}

/// The Jacobian of `prob` at `theta`.
fn jacobian(prob: &mut dyn Residuals, theta: &[f64]) -> Mat<f64> {
    let mut r = vec![0.0; prob.n_residuals()];
    let mut x = Mat::<f64>::zeros(prob.n_residuals(), prob.n_params());
    prob.eval(theta, &mut r, Some(&mut x));
    x
}

/// Fits `robot`'s determined unknowns, the tool offset and the points to
/// `file`'s contacts with the known `distances` (indices into
/// `file.points`), from `start`. Unknowns the data determine only weakly
/// (a pivot at or below [`CONTACT_PIVOT_TOL`]) are estimated when their σ
/// in a fit of every determined unknown is below the error a joint origin
/// is expected to carry, and fixed otherwise ([`super::worth`]).
pub fn fit_contacts(
    robot: &Robot,
    start: &ParamTable,
    file: &ContactFile,
    distances: &[KnownDistance],
    settings: &ContactSettings,
) -> Result<ContactFit> {
    settings.validate()?;
    let own0 = start_own(robot, start, file);
    let planes = start_planes(robot, start, file);
    let setup = Setup {
        start,
        file,
        distances,
        planes: &planes,
        own0: &own0,
        settings,
    };
    let at = |tol| {
        determined(
            robot,
            start,
            file,
            distances,
            &planes,
            &own0,
            &settings.keep,
            tol,
        )
    };
    let strict = at(crate::identify::undetermined::PIVOT_TOL)?;
    let weak_bar = at(CONTACT_PIVOT_TOL)?;
    let weak: Vec<String> = weak_bar
        .fixed
        .iter()
        .filter(|f| !strict.fixed.iter().any(|s| s.name == f.name))
        .map(|f| f.name.clone())
        .collect();
    if weak.is_empty() {
        return Ok(setup.fit(strict));
    }
    // Every determined unknown estimated, then the weak ones the noise
    // makes worthless fixed (`worth`).
    let all = setup.fit(strict.clone());
    if !all.converged {
        return Ok(setup.fit(weak_bar));
    }
    let to_fix = super::worth::weak_to_fix(
        &all.robot,
        &weak,
        &all.names,
        &all.start,
        all.std.as_deref(),
    );
    if to_fix.is_empty() {
        return Ok(all);
    }
    let mut reduced = strict;
    reduced.robot.unknowns.retain(|&u| {
        let n = robot.param_name(u);
        !to_fix.iter().any(|f| f.name == n)
    });
    reduced.fixed.extend(to_fix);
    Ok(setup.fit(reduced))
}

/// What a contact fit is of: the data, the known distances and planes, the
/// start, the settings.
struct Setup<'a> {
    start: &'a ParamTable,
    file: &'a ContactFile,
    distances: &'a [KnownDistance],
    planes: &'a [Plane],
    own0: &'a [f64],
    settings: &'a ContactSettings,
}

impl Setup<'_> {
    /// Fits the unknowns of `reduced` (the rest fixed with their reasons).
    fn fit(&self, reduced: crate::identify::Determined) -> ContactFit {
        fit_reduced(self, reduced)
    }
}

/// The fit of [`fit_contacts`] with the unknowns of `reduced`.
fn fit_reduced(s: &Setup<'_>, reduced: crate::identify::Determined) -> ContactFit {
    let (start, file, distances, planes, own0) = (s.start, s.file, s.distances, s.planes, s.own0);
    let r = &reduced.robot;
    let mut theta0 = r.unknown_values(start);
    theta0.extend_from_slice(&own0);
    let mut prob = Weighted {
        inner: problem(r, start, file, distances, planes),
        sqrt_w: vec![1.0; file.qs.len()],
    };
    // The loss was checked when the settings were (`loss_of` in `fit_contacts`).
    let loss = loss_of(s.settings.loss).ok().flatten();
    let sol = solve(&mut prob, &theta0, &s.settings.lm, loss.as_deref());
    let weights: Vec<f64> = prob.sqrt_w.iter().map(|w| w * w).collect();
    finish(
        r,
        start,
        file,
        planes,
        &prob,
        theta0,
        sol,
        reduced.fixed,
        weights,
    )
}

/// The loss of a choice (`None` for least squares).
fn loss_of(choice: LossChoice) -> Result<Option<Box<dyn Loss>>> {
    Ok(match choice {
        LossChoice::L2 => None,
        LossChoice::Huber { scale } => Some(Box::new(Huber::new(scale)?)),
        LossChoice::Cauchy { scale } => Some(Box::new(Cauchy::new(scale)?)),
    })
}

/// Levenberg–Marquardt, reweighted until the weights settle for a loss.
fn solve(
    prob: &mut Weighted<'_>,
    theta0: &[f64],
    lm: &LmSettings,
    loss: Option<&dyn Loss>,
) -> Solution {
    let mut theta = theta0.to_vec();
    let mut iterations = 0;
    for round in 1.. {
        let mut sol = levenberg_marquardt(prob, &theta, lm);
        iterations += sol.iterations;
        sol.iterations = iterations;
        let Some(loss) = loss else { return sol };
        let mut r = vec![0.0; prob.n_residuals()];
        if !sol.finite || !prob.inner.eval(&sol.theta, &mut r, None) {
            return sol;
        }
        let mut change: f64 = 0.0;
        for (i, w) in prob.sqrt_w.iter_mut().enumerate() {
            let s: f64 = r[3 * i..3 * i + 3].iter().map(|v| v * v).sum();
            let new = loss.weight(s).sqrt();
            change = change.max((new - *w).abs());
            *w = new;
        }
        if change <= IRLS_TOLERANCE || round >= IRLS_ROUNDS {
            // The Jacobian and rss at the final weights.
            return levenberg_marquardt(prob, &sol.theta, lm);
        }
        theta.clone_from(&sol.theta);
    }
    unreachable!("the loop returns")
}

/// The robot reduced to the unknowns the contacts determine: first the
/// gauge (unknowns whose motion is one rigid motion of the whole setup at
/// every row, see [`gauge_unknowns`]), then what the shared rule finds on
/// the Jacobian of the rest, with pivots at or below `pivot_tol` fixed.
#[allow(clippy::too_many_arguments)]
fn determined(
    robot: &Robot,
    start: &ParamTable,
    file: &ContactFile,
    distances: &[KnownDistance],
    planes: &[Plane],
    own0: &[f64],
    keep: &[String],
    pivot_tol: f64,
) -> Result<crate::identify::Determined> {
    let names = robot.parameter_names();
    // A known plane pins the setup: no rigid motion is free then.
    let pinned = planes
        .iter()
        .any(|p| matches!(p.kind, PlaneKind::Known { .. }));
    let free = if pinned {
        Vec::new()
    } else {
        gauge_unknowns(robot, start, &file.qs)
    };
    let gauge: Vec<usize> = free
        .into_iter()
        .filter(|&k| !keep.contains(&names[k]))
        .collect();
    let mut inner = robot.clone();
    inner.unknowns = (0..robot.n_unknowns())
        .filter(|k| !gauge.contains(k))
        .map(|k| robot.unknowns[k])
        .collect();
    let mut prob = problem(&inner, start, file, distances, planes);
    let mut theta = inner.unknown_values(start);
    theta.extend_from_slice(own0);
    let x = jacobian(&mut prob, &theta);
    let mut d = fix_undetermined_below(&inner, start, &file.qs, &x, keep, pivot_tol)?;
    let mut col_names = inner.parameter_names();
    col_names.truncate(inner.n_unknowns());
    col_names.extend(prob.sensor().own_param_names());
    let kept: Vec<usize> = (0..x.ncols())
        .filter(|&c| !d.fixed.iter().any(|f| f.name == col_names[c]))
        .collect();
    for f in &mut d.fixed {
        if let Some(k) = col_names.iter().position(|n| *n == f.name)
            && let Some(like) = nearest_combination(&x, k, &kept, &col_names)
        {
            f.reason = format!("{}; its motion is nearly a combination of {like}", f.reason);
        }
    }
    let mut fixed: Vec<FixedParameter> = gauge
        .iter()
        .map(|&k| FixedParameter {
            name: names[k].clone(),
            value: start.get(robot.unknowns[k]),
            reason: GAUGE_REASON.to_string(),
        })
        .collect();
    fixed.append(&mut d.fixed);
    d.fixed = fixed;
    Ok(d)
}

/// The (up to three) kept columns that carry most of unit column `k` of
/// `x` in its least-squares fit by the kept columns (each column scaled to
/// unit norm first): what an undetermined unknown's motion resembles.
fn nearest_combination(x: &Mat<f64>, k: usize, kept: &[usize], names: &[String]) -> Option<String> {
    use nalgebra::{DMatrix, DVector};
    let m = x.nrows();
    let unit = |c: usize| -> DVector<f64> {
        let v = DVector::from_fn(m, |i, _| x[(i, c)]);
        let n = v.norm();
        if n > 0.0 { v / n } else { v }
    };
    let a = DMatrix::from_columns(&kept.iter().map(|&c| unit(c)).collect::<Vec<_>>());
    let coef = (a.transpose() * &a)
        .cholesky()?
        .solve(&(a.transpose() * unit(k)));
    let mut order: Vec<usize> = (0..kept.len()).collect();
    order.sort_by(|&i, &j| coef[j].abs().total_cmp(&coef[i].abs()));
    let top: Vec<String> = order
        .iter()
        .take(3)
        .filter(|&&i| coef[i].abs() > 0.05)
        .map(|&i| format!("{} ({:+.2})", names[kept[i]], coef[i]))
        .collect();
    (!top.is_empty()).then(|| top.join(", "))
}

/// The unknowns whose elementary motion is the same rigid motion of the
/// base frame at every row (a constant twist: angular velocity `ω` and the
/// velocity `v − ω × p` of the base origin): moving the whole setup, they
/// change no residual once the points follow.
#[must_use]
pub fn gauge_unknowns(robot: &Robot, table: &ParamTable, qs: &[Vec<f64>]) -> Vec<usize> {
    let n = robot.n_unknowns();
    let mut ev = crate::kinematics::Evaluator::new(robot, table);
    let mut motions = vec![crate::kinematics::Motion::default(); n];
    let mut twists: Vec<Vec<[f64; 6]>> = vec![Vec::with_capacity(qs.len()); n];
    for q in qs {
        let end = ev.motions(q, &mut motions);
        for (k, m) in motions.iter().enumerate() {
            let v0 = m.lin - m.ang.cross(&end.position);
            twists[k].push([m.ang.x, m.ang.y, m.ang.z, v0.x, v0.y, v0.z]);
        }
    }
    (0..n)
        .filter(|&k| {
            let t = &twists[k];
            let Some(first) = t.first() else { return false };
            let scale = first.iter().map(|a| a.abs()).fold(0.0, f64::max).max(1.0);
            t.iter().all(|w| {
                w.iter()
                    .zip(first)
                    .all(|(a, b)| (a - b).abs() <= GAUGE_TOL * scale)
            })
        })
        .collect()
}

/// The fit's report from the solver's state.
#[allow(clippy::too_many_arguments)]
fn finish(
    robot: &Robot,
    start: &ParamTable,
    file: &ContactFile,
    planes: &[Plane],
    prob: &Weighted<'_>,
    theta0: Vec<f64>,
    sol: Solution,
    fixed: Vec<FixedParameter>,
    weights: Vec<f64>,
) -> ContactFit {
    let n_kin = robot.n_unknowns();
    let p = theta0.len();
    let m = prob.n_residuals();
    let dof = m.saturating_sub(p);
    let sigma_hat = (dof > 0 && sol.rss.is_finite()).then(|| (sol.rss / dof as f64).sqrt());
    let (covariance, std) = sol.covariance(sigma_hat);
    let own = &sol.theta[n_kin..];
    let sensor = ContactSensor::new(file.points.clone(), Vec::new())
        .with_planes(planes.to_vec())
        .expect("checked planes");
    let planes = planes
        .iter()
        .enumerate()
        .map(|(l, p)| {
            let (normal, offset_m) = sensor.plane_at(own, l);
            PlaneEstimate {
                name: p.name.clone(),
                known: matches!(p.kind, PlaneKind::Known { .. }),
                normal,
                offset_m,
            }
        })
        .collect();
    let mut names = robot.parameter_names();
    names.truncate(n_kin);
    names.extend(prob.inner.sensor().own_param_names());
    let converged = sol.finite
        && std.is_some()
        && !matches!(
            sol.stop,
            StopReason::MaxIterations | StopReason::NonFinite | StopReason::DampingLimit
        );
    ContactFit {
        robot: robot.clone(),
        table: robot.with_unknowns(start, &sol.theta[..n_kin]),
        tool_offset: [own[0], own[1], own[2]],
        points: file.points.clone(),
        point_positions: (0..file.points.len())
            .map(|g| ContactSensor::point(own, g).into())
            .collect(),
        planes,
        names,
        start: theta0,
        estimate: sol.theta,
        std,
        covariance,
        fixed,
        converged,
        stop: sol.stop,
        iterations: sol.iterations,
        sigma_hat,
        weights,
    }
}
