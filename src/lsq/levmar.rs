//! The Levenberg–Marquardt solver, generic over [`Residuals`]: column
//! scaling, Nielsen damping updates and optional geodesic acceleration.
//!
//! Each step minimises the damped, scaled linear model
//! `‖J δ + r‖² + λ ‖D δ‖²` by solving the augmented least-squares system
//! `[J D⁻¹; √λ I] u = [−r; 0]`, `δ = D⁻¹ u`, with faer's Householder QR.
//!
//! Why not a crate: `levenberg-marquardt` (the MINPACK port) is written
//! against its own nalgebra version and would put a second nalgebra in the
//! build; our Jacobians live in faer matrices anyway. Why the augmented
//! system and not the normal equations `(JᵀJ + λD²) δ = −Jᵀr`: forming `JᵀJ`
//! squares the condition number, and a 20 m lever arm (frame `a`) beside
//! millimetre offsets makes that matter for the 1e-9 recovery we require.
//!
//! `D` is MINPACK's scaling, `d_j = max over iterations of ‖J_{:,j}‖`, so the
//! damping is invariant to the units of the unknowns (radians vs. metres).
//! [`levenberg_marquardt`] reads as its phases: `begin_outer` (scaling and
//! the gradient test), `damped_trials` (trial steps at rising damping,
//! MINPACK's tolerances), `finish`.

use super::{LsqError, Residuals, Result};
use crate::linalg::qr::SeqQr;
use faer::Mat;
use serde::{Deserialize, Serialize};

/// Settings of the solver, with documented defaults: build with
/// [`LmSettings::builder`] (validated) or take [`LmSettings::default`];
/// [`LmSettings::validate`] is also called by [`super::identify`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
#[non_exhaustive]
pub struct LmSettings {
    /// Most outer iterations (Jacobian evaluations after the first). Default 200.
    pub max_iterations: usize,
    /// Step tolerance: stop when `‖D δ‖ ≤ xtol (‖D θ‖ + xtol)`. Default 1e-10.
    pub xtol: f64,
    /// Cost tolerance: stop when the actual and the predicted relative
    /// reductions of the cost are both at most `ftol`. Default 1e-12.
    pub ftol: f64,
    /// Gradient tolerance: stop when every column of `J` is within `gtol` of
    /// orthogonal to the residual (cosine). Default 1e-10.
    pub gtol: f64,
    /// Initial damping `λ₀` relative to the largest diagonal entry of the
    /// scaled `JᵀJ`. Default 1e-3.
    pub initial_damping: f64,
    /// Add Transtrum's geodesic acceleration (one extra residual evaluation
    /// per trial step) to follow curved valleys from a far start. Default true.
    pub geodesic: bool,
}

impl Default for LmSettings {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            xtol: 1e-10,
            ftol: 1e-12,
            gtol: 1e-10,
            initial_damping: 1e-3,
            geodesic: true,
        }
    }
}

crate::settings::settings_builder! {
    /// Validated construction of [`LmSettings`]: `LmSettings::builder()`,
    /// setters, `build()`.
    LmSettingsBuilder for LmSettings, error LsqError {
        /// Most outer iterations (default 200).
        max_iterations: usize,
        /// Step tolerance (default 1e-10).
        xtol: f64,
        /// Cost tolerance (default 1e-12).
        ftol: f64,
        /// Gradient tolerance (default 1e-10).
        gtol: f64,
        /// Initial relative damping (default 1e-3).
        initial_damping: f64,
        /// Geodesic acceleration (default true).
        geodesic: bool,
    }
}

impl LmSettings {
    /// Checks every setting is in range.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value: f64, reason| LsqError::Setting {
            name,
            value: value.to_string(),
            reason,
        };
        if self.max_iterations == 0 {
            return Err(LsqError::Setting {
                name: "max_iterations",
                value: "0".into(),
                reason: "at least one iteration is needed (0 would report the start as the estimate)",
            });
        }
        for (name, v) in [
            ("xtol", self.xtol),
            ("ftol", self.ftol),
            ("gtol", self.gtol),
        ] {
            if !(v.is_finite() && (0.0..1.0).contains(&v)) {
                return Err(bad(name, v, "a tolerance must be in [0, 1)"));
            }
        }
        if !(self.initial_damping.is_finite() && self.initial_damping > 0.0) {
            return Err(bad(
                "initial_damping",
                self.initial_damping,
                "must be finite and > 0",
            ));
        }
        Ok(())
    }
}

/// Why the iteration stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The residual is exactly zero.
    ZeroResidual,
    /// The step tolerance `xtol` was met.
    StepTolerance,
    /// The cost tolerance `ftol` was met.
    CostTolerance,
    /// The gradient tolerance `gtol` was met.
    GradientTolerance,
    /// `max_iterations` outer iterations were done.
    MaxIterations,
    /// The cost or the Jacobian was not finite at an accepted point.
    NonFinite,
    /// The damping reached its ceiling (1e32) without an acceptable step.
    DampingLimit,
}

fn sumsq(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum()
}

fn norm(v: &[f64]) -> f64 {
    sumsq(v).sqrt()
}
/// What [`levenberg_marquardt`] returns: the solver's state at the end.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Parameters at the end.
    pub theta: Vec<f64>,
    /// Jacobian at `theta` (`m × n`).
    pub jac: Mat<f64>,
    /// Whether the residual and the Jacobian at `theta` are finite.
    pub finite: bool,
    /// Which rule stopped the iteration.
    pub stop: StopReason,
    /// Outer iterations (Jacobian evaluations after the first).
    pub iterations: usize,
    /// Residual evaluations, including rejected and geodesic trial points.
    pub evaluations: usize,
    /// `‖r‖²` at the start.
    pub initial_rss: f64,
    /// `‖r‖²` at `theta`.
    pub rss: f64,
    /// `‖r‖²` after each accepted step (first entry: start).
    pub history: Vec<f64>,
    /// Final damping `λ` (scaled units).
    pub lambda: f64,
}

impl Solution {
    /// The estimate's covariance `σ² (JᵀJ)⁻¹` at the solution for a
    /// residual σ `sigma`, and its standard deviations (the roots of its
    /// diagonal): both `None` when σ is unknown or the Jacobian is not
    /// finite or not of full rank.
    #[must_use]
    pub fn covariance(&self, sigma: Option<f64>) -> (Option<Vec<Vec<f64>>>, Option<Vec<f64>>) {
        let p = self.theta.len();
        let inv = self
            .finite
            .then(|| crate::linalg::qr::inverse_information(self.jac.as_ref()))
            .flatten();
        let covariance: Option<Vec<Vec<f64>>> = match (inv, sigma) {
            (Some(inv), Some(s)) => Some(
                (0..p)
                    .map(|i| (0..p).map(|j| s * s * inv[(i, j)]).collect())
                    .collect(),
            ),
            _ => None,
        };
        let std = covariance
            .as_ref()
            .map(|c| (0..p).map(|j| c[j][j].max(0.0).sqrt()).collect());
        (covariance, std)
    }
}

/// Ceiling on the scaled damping: past it a step is ~1e-32 of a gradient step.
const MAX_DAMPING: f64 = 1e32;
/// Smallest gain ratio for accepting a step.
const ACCEPT: f64 = 1e-4;
/// Geodesic acceleration: finite-difference step along the velocity, and the
/// largest allowed ratio `2‖a‖/‖v‖` (Transtrum & Sethna 2012).
const GEO_H: f64 = 0.1;
const GEO_ALPHA: f64 = 0.75;

/// Levenberg–Marquardt on any [`Residuals`] from `theta0`: one outer
/// iteration per Jacobian, inner trials raising the damping until a step is
/// accepted or a tolerance is met (settings are not validated here; see
/// [`LmSettings::validate`]).
pub fn levenberg_marquardt<R: Residuals + ?Sized>(
    prob: &mut R,
    theta0: &[f64],
    s: &LmSettings,
) -> Solution {
    let mut lm = Iteration::start(prob, theta0, s);
    if !lm.finite_start {
        return lm.finish(StopReason::NonFinite);
    }
    let stop = loop {
        let gradient = match lm.begin_outer() {
            Ok(gradient) => gradient,
            Err(stop) => break stop,
        };
        if let Some(stop) = lm.damped_trials(&gradient) {
            break stop;
        }
    };
    lm.finish(stop)
}

/// The solver's state between phases: the point, its residual and Jacobian,
/// the scaling and damping, and the trial buffers (allocated once).
struct Iteration<'a, R: ?Sized> {
    prob: &'a mut R,
    s: &'a LmSettings,
    theta: Vec<f64>,
    r: Vec<f64>,
    jac: Mat<f64>,
    /// `½‖r‖²` at `theta`.
    cost: f64,
    /// MINPACK's column scaling `d_j`.
    d: Vec<f64>,
    /// Scaled damping `λ` (NaN until the first outer iteration sets it).
    lambda: f64,
    /// Nielsen's growth factor for `λ` after a rejected step.
    nu: f64,
    r_try: Vec<f64>,
    r_geo: Vec<f64>,
    theta_try: Vec<f64>,
    evaluations: usize,
    iterations: usize,
    initial_rss: f64,
    history: Vec<f64>,
    /// Whether the residual and the Jacobian at `theta0` are finite.
    finite_start: bool,
}

/// The gradient test's by-products an outer iteration's trials need.
struct Gradient {
    /// `Jᵀ r`.
    g: Vec<f64>,
    /// `‖D θ‖`, for the step tolerance.
    dtheta_norm: f64,
}

/// One damped trial step and what the model and the residual say of it.
struct Trial {
    /// Whether the step (and its geodesic correction) is finite and usable.
    ok: bool,
    /// Actual reduction of ½‖r‖² (−∞ when the trial point is not finite).
    actual: f64,
    /// Predicted reduction by the linear model.
    pred: f64,
    /// ½‖r‖² at the trial point.
    new_cost: f64,
    /// `‖D δ‖`.
    du_norm: f64,
}

impl<'a, R: Residuals + ?Sized> Iteration<'a, R> {
    /// Evaluates the residual and the Jacobian at `theta0`.
    fn start(prob: &'a mut R, theta0: &[f64], s: &'a LmSettings) -> Self {
        let p = theta0.len();
        debug_assert_eq!(p, prob.n_params());
        let m = prob.n_residuals();
        let theta = theta0.to_vec();
        let mut r = vec![0.0; m];
        // The Jacobian is held once (3n × p for n measured points): the
        // solution gets it at the end, and each trial builds only the
        // augmented system.
        let mut jac = Mat::<f64>::zeros(m, p);
        let finite = prob.eval(&theta, &mut r, Some(&mut jac));
        let rss0 = sumsq(&r);
        Self {
            prob,
            s,
            theta,
            r,
            jac,
            cost: 0.5 * rss0,
            d: vec![0.0; p],
            lambda: f64::NAN,
            nu: 2.0,
            r_try: vec![0.0; m],
            r_geo: vec![0.0; m],
            theta_try: vec![0.0; p],
            evaluations: 1,
            iterations: 0,
            initial_rss: rss0,
            history: vec![rss0],
            finite_start: finite && rss0.is_finite(),
        }
    }

    /// The outer iteration's scaling update and stopping tests (zero
    /// residual, gradient, iteration count); sets the first damping.
    fn begin_outer(&mut self) -> std::result::Result<Gradient, StopReason> {
        let (m, p) = (self.jac.nrows(), self.jac.ncols());
        let col_norms: Vec<f64> = (0..p).map(|c| self.jac.col(c).norm_l2()).collect();
        for (dj, &cn) in self.d.iter_mut().zip(&col_norms) {
            *dj = (*dj).max(cn);
            if *dj == 0.0 {
                *dj = 1.0;
            }
        }
        if self.cost == 0.0 {
            return Err(StopReason::ZeroResidual);
        }
        let rnorm = norm(&self.r);
        let g: Vec<f64> = (0..p)
            .map(|c| (0..m).map(|i| self.jac[(i, c)] * self.r[i]).sum::<f64>())
            .collect();
        let gcos = (0..p)
            .filter(|&c| col_norms[c] > 0.0)
            .map(|c| g[c].abs() / (col_norms[c] * rnorm))
            .fold(0.0, f64::max);
        if gcos <= self.s.gtol {
            return Err(StopReason::GradientTolerance);
        }
        if self.iterations >= self.s.max_iterations {
            return Err(StopReason::MaxIterations);
        }
        if self.lambda.is_nan() {
            // The largest diagonal entry of the scaled JᵀJ, ‖J_{:,j}/d_j‖²
            // (one column at a time).
            let max_diag = (0..p)
                .map(|c| faer::Col::from_fn(m, |i| self.jac[(i, c)] / self.d[c]).squared_norm_l2())
                .fold(0.0, f64::max);
            self.lambda = self.s.initial_damping * max_diag.max(f64::MIN_POSITIVE);
        }
        let scaled: Vec<f64> = self.theta.iter().zip(&self.d).map(|(t, d)| t * d).collect();
        self.iterations += 1;
        Ok(Gradient {
            g,
            dtheta_norm: norm(&scaled),
        })
    }

    /// Trials at rising damping until one is accepted (`None`: go on with a
    /// new outer iteration) or a stopping rule is met.
    fn damped_trials(&mut self, gradient: &Gradient) -> Option<StopReason> {
        loop {
            let trial = self.trial(&gradient.g);
            let rho = if trial.pred > 0.0 {
                trial.actual / trial.pred
            } else {
                f64::NEG_INFINITY
            };
            let accepted = rho > ACCEPT;
            // ---- tolerances (MINPACK's tests, on this trial) ----------------
            let ftol_met = trial.ok
                && trial.actual.is_finite()
                && trial.actual.abs() <= self.s.ftol * self.cost
                && trial.pred <= self.s.ftol * self.cost
                && rho <= 2.0;
            let xtol_met = trial.du_norm <= self.s.xtol * (gradient.dtheta_norm + self.s.xtol);
            if accepted {
                if !self.accept(trial.new_cost, rho) {
                    return Some(StopReason::NonFinite);
                }
            } else {
                self.lambda *= self.nu;
                self.nu *= 2.0;
            }
            if ftol_met {
                return Some(StopReason::CostTolerance);
            }
            if xtol_met {
                return Some(StopReason::StepTolerance);
            }
            if self.lambda > MAX_DAMPING {
                return Some(StopReason::DampingLimit);
            }
            if accepted {
                return None;
            }
        }
    }

    /// One trial: the damped step `[Js; √λ I] u = [−r; 0]`, `Js = J D⁻¹`,
    /// `δ = D⁻¹ u`, its geodesic correction, and the residual at `θ + δ`.
    fn trial(&mut self, g: &[f64]) -> Trial {
        let (m, p) = (self.jac.nrows(), self.jac.ncols());
        let sl = self.lambda.sqrt();
        let aug = Mat::from_fn(m + p, p, |i, j| {
            if i < m {
                self.jac[(i, j)] / self.d[j]
            } else if i - m == j {
                sl
            } else {
                0.0
            }
        });
        let mut qr = SeqQr::new(aug);
        let mut u = Mat::from_fn(m + p, 1, |i, _| if i < m { -self.r[i] } else { 0.0 });
        qr.solve_lstsq_in_place(u.as_mut());
        let u: Vec<f64> = (0..p).map(|j| u[(j, 0)]).collect();
        let mut step: Vec<f64> = (0..p).map(|j| u[j] / self.d[j]).collect();
        let mut ok = u.iter().all(|v| v.is_finite());
        if ok && self.s.geodesic {
            ok = self.geodesic_correction(&mut qr, &u, &mut step);
        }
        let du: Vec<f64> = step.iter().zip(&self.d).map(|(x, d)| x * d).collect();
        // Predicted reduction of ½‖r‖² by the linear model: −gᵀδ − ½‖Jδ‖².
        let jd = self.jac_times(&step);
        let pred = -(0..p).map(|j| g[j] * step[j]).sum::<f64>() - 0.5 * sumsq(&jd);
        let mut actual = f64::NEG_INFINITY;
        let mut new_cost = f64::INFINITY;
        if ok {
            for j in 0..p {
                self.theta_try[j] = self.theta[j] + step[j];
            }
            self.evaluations += 1;
            if self.prob.eval(&self.theta_try, &mut self.r_try, None) {
                new_cost = 0.5 * sumsq(&self.r_try);
                if new_cost.is_finite() {
                    actual = self.cost - new_cost;
                }
            }
        }
        Trial {
            ok,
            actual,
            pred,
            new_cost,
            du_norm: norm(&du),
        }
    }

    /// Geodesic acceleration `a = −(JᵀJ + λD²)⁻¹ Jᵀ r_vv` added to `step`
    /// as `½ a`; `false` (reject, damp more) when the residual at the probe
    /// is not finite or the path is too curved for this damping.
    fn geodesic_correction(&mut self, qr: &mut SeqQr, u: &[f64], step: &mut [f64]) -> bool {
        let (m, p) = (self.jac.nrows(), self.jac.ncols());
        for j in 0..p {
            self.theta_try[j] = self.theta[j] + GEO_H * step[j];
        }
        self.evaluations += 1;
        if !self.prob.eval(&self.theta_try, &mut self.r_geo, None) {
            return false;
        }
        // r_vv ≈ (2/h) [(r(θ + h v) − r(θ))/h − J v]
        let jv = self.jac_times(step);
        let mut a = Mat::from_fn(m + p, 1, |i, _| {
            if i < m {
                -(2.0 / GEO_H) * ((self.r_geo[i] - self.r[i]) / GEO_H - jv[i])
            } else {
                0.0
            }
        });
        qr.solve_lstsq_in_place(a.as_mut());
        let a_s: Vec<f64> = (0..p).map(|j| a[(j, 0)]).collect();
        if a_s.iter().all(|v| v.is_finite()) && 2.0 * norm(&a_s) <= GEO_ALPHA * norm(u) {
            for j in 0..p {
                step[j] += 0.5 * a_s[j] / self.d[j];
            }
            true
        } else {
            false
        }
    }

    /// Moves to the trial point, relaxes the damping (Nielsen) and evaluates
    /// the Jacobian there; `false` when it is not finite.
    fn accept(&mut self, new_cost: f64, rho: f64) -> bool {
        self.theta.copy_from_slice(&self.theta_try);
        self.cost = new_cost;
        std::mem::swap(&mut self.r, &mut self.r_try);
        self.history.push(2.0 * self.cost);
        self.lambda *= (1.0 / 3.0f64).max(1.0 - (2.0 * rho - 1.0).powi(3));
        self.nu = 2.0;
        self.prob
            .eval(&self.theta, &mut self.r, Some(&mut self.jac))
    }

    /// `J v`.
    fn jac_times(&self, v: &[f64]) -> Vec<f64> {
        let (m, p) = (self.jac.nrows(), self.jac.ncols());
        (0..m)
            .map(|i| (0..p).map(|j| self.jac[(i, j)] * v[j]).sum::<f64>())
            .collect()
    }

    /// The solution at the end (damping 0 when the start was not finite).
    fn finish(self, stop: StopReason) -> Solution {
        Solution {
            finite: self.finite_start && stop != StopReason::NonFinite,
            theta: self.theta,
            jac: self.jac,
            stop,
            iterations: self.iterations,
            evaluations: self.evaluations,
            initial_rss: self.initial_rss,
            rss: 2.0 * self.cost,
            history: self.history,
            lambda: if self.finite_start { self.lambda } else { 0.0 },
        }
    }
}
