//! Robust losses for identification, applied by iteratively reweighted least
//! squares (IRLS) around any [`Residuals`], so that the solver stays the
//! plain least-squares loop of [`crate::identify::lm`].
//!
//! A loss `ρ(s)` acts on the squared norm `s = ‖r_b‖²` of each residual block
//! (the rows of one measured pose, [`Residuals::block_rows`]); the estimate
//! minimises `½ Σ_b ρ(‖r_b(θ)‖²)` (Ceres' convention: `ρ(s) = s` is least
//! squares). Its gradient `Σ_b ρ'(s_b) J_bᵀ r_b` is that of least squares
//! with every block scaled by `√ρ'(s_b)`, weights frozen: [`Robust`] holds
//! such frozen weights, [`Robust::reweight`] recomputes them at an estimate,
//! and [`super::lm::irls`] alternates the two until the weights settle.

use super::{LsqError, Residuals, Result};
use faer::Mat;
use serde::{Deserialize, Serialize};

/// A loss `ρ(s)` of a block's squared residual norm `s ≥ 0`.
pub trait Loss {
    /// `ρ(s)`.
    fn rho(&self, s: f64) -> f64;
    /// The IRLS weight `ρ'(s)` (1 for least squares, in `(0, 1]` for the
    /// robust losses here).
    fn weight(&self, s: f64) -> f64;
}

/// Least squares: `ρ(s) = s`, weight 1 (the default).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct L2;

impl Loss for L2 {
    fn rho(&self, s: f64) -> f64 {
        s
    }
    fn weight(&self, _s: f64) -> f64 {
        1.0
    }
}

fn check_scale(scale: f64) -> Result<f64> {
    if scale.is_finite() && scale > 0.0 {
        Ok(scale)
    } else {
        Err(LsqError::Setting {
            name: "loss scale",
            value: scale.to_string(),
            reason: "must be finite and > 0 (metres: the residual norm where the loss turns robust)",
        })
    }
}

/// Huber's loss with scale `c`: `ρ(s) = s` for `s ≤ c²`, `2c√s − c²` beyond
/// (quadratic near zero, linear in the residual norm past `c`); weight
/// `min(1, c/√s)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Huber {
    scale: f64,
}

impl Huber {
    /// Huber's loss with scale `c` (metres; a few σ of the noise). Errors on
    /// a scale that is not finite and positive.
    pub fn new(scale: f64) -> Result<Self> {
        Ok(Self {
            scale: check_scale(scale)?,
        })
    }
}

impl Loss for Huber {
    fn rho(&self, s: f64) -> f64 {
        let c = self.scale;
        if s <= c * c {
            s
        } else {
            2.0 * c * s.sqrt() - c * c
        }
    }
    fn weight(&self, s: f64) -> f64 {
        let c = self.scale;
        if s <= c * c { 1.0 } else { c / s.sqrt() }
    }
}

/// The Cauchy (Lorentzian) loss with scale `c`: `ρ(s) = c² ln(1 + s/c²)`;
/// weight `1/(1 + s/c²)` (redescending: a gross outlier's weight goes to 0).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cauchy {
    scale: f64,
}

impl Cauchy {
    /// The Cauchy loss with scale `c` (metres). Errors on a scale that is not
    /// finite and positive.
    pub fn new(scale: f64) -> Result<Self> {
        Ok(Self {
            scale: check_scale(scale)?,
        })
    }
}

impl Loss for Cauchy {
    fn rho(&self, s: f64) -> f64 {
        let c2 = self.scale * self.scale;
        c2 * (s / c2).ln_1p()
    }
    fn weight(&self, s: f64) -> f64 {
        1.0 / (1.0 + s / (self.scale * self.scale))
    }
}

/// A [`Residuals`] with every block scaled by `√w_b`, the weights frozen at
/// the last [`Robust::reweight`] (all 1 at the start).
pub struct Robust<R, L> {
    inner: R,
    loss: L,
    sqrt_w: Vec<f64>,
    scratch: Vec<f64>,
}

impl<R: Residuals, L: Loss> Robust<R, L> {
    /// Wraps `inner` with `loss`, all weights 1.
    pub fn new(inner: R, loss: L) -> Self {
        let m = inner.n_residuals();
        // Rows past the last whole block (a sensor's constraint rows) are
        // one block of their own.
        let nb = m.div_ceil(inner.block_rows().max(1));
        Self {
            inner,
            loss,
            sqrt_w: vec![1.0; nb],
            scratch: vec![0.0; m],
        }
    }

    /// Recomputes the weights `w_b = ρ'(‖r_b(θ)‖²)` at `θ`. Returns the
    /// largest change of a `√w_b`, or `None` if a residual is not finite.
    pub fn reweight(&mut self, theta: &[f64]) -> Option<f64> {
        if !self.inner.eval(theta, &mut self.scratch, None) {
            return None;
        }
        let b = self.inner.block_rows().max(1);
        let mut change: f64 = 0.0;
        for (w, rb) in self.sqrt_w.iter_mut().zip(self.scratch.chunks(b)) {
            let s: f64 = rb.iter().map(|v| v * v).sum();
            let new = self.loss.weight(s).sqrt();
            change = change.max((new - *w).abs());
            *w = new;
        }
        Some(change)
    }

    /// `Σ_b ρ(‖r_b(θ)‖²)` at `θ` (`None` if not finite).
    pub fn cost(&mut self, theta: &[f64]) -> Option<f64> {
        if !self.inner.eval(theta, &mut self.scratch, None) {
            return None;
        }
        let b = self.inner.block_rows().max(1);
        Some(
            self.scratch
                .chunks(b)
                .map(|rb| self.loss.rho(rb.iter().map(|v| v * v).sum()))
                .sum(),
        )
    }

    /// The current weights `w_b`, one per block.
    #[must_use]
    pub fn weights(&self) -> Vec<f64> {
        self.sqrt_w.iter().map(|w| w * w).collect()
    }

    /// The wrapped problem.
    pub fn inner(&self) -> &R {
        &self.inner
    }
}

impl<R: Residuals, L: Loss> Residuals for Robust<R, L> {
    fn n_residuals(&self) -> usize {
        self.inner.n_residuals()
    }

    fn n_params(&self) -> usize {
        self.inner.n_params()
    }

    fn block_rows(&self) -> usize {
        self.inner.block_rows()
    }

    fn eval(&mut self, theta: &[f64], r: &mut [f64], mut jac: Option<&mut Mat<f64>>) -> bool {
        let ok = self.inner.eval(theta, r, jac.as_deref_mut());
        let b = self.inner.block_rows().max(1);
        for (i, v) in r.iter_mut().enumerate() {
            *v *= self.sqrt_w[i / b];
        }
        if let Some(j) = jac {
            for c in 0..j.ncols() {
                for i in 0..j.nrows() {
                    j[(i, c)] *= self.sqrt_w[i / b];
                }
            }
        }
        ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ρ' is the weight: central differences of ρ against `weight` on both
    /// sides of the scale.
    #[test]
    fn weights_are_derivatives_of_rho() {
        let losses: [Box<dyn Loss>; 3] = [
            Box::new(L2),
            Box::new(Huber::new(0.5).unwrap()),
            Box::new(Cauchy::new(0.5).unwrap()),
        ];
        for l in &losses {
            for s in [0.01, 0.2, 0.3, 1.0, 7.0] {
                let h = 1e-6;
                let fd = (l.rho(s + h) - l.rho(s - h)) / (2.0 * h);
                // Smooth away from s = c² = 0.25: truncation h²|ρ'''| < 1e-9,
                // rounding ε|ρ|/h < 1e-9.
                assert!((fd - l.weight(s)).abs() < 1e-8, "s = {s}");
            }
        }
        assert!(Huber::new(0.0).is_err() && Cauchy::new(f64::NAN).is_err());
    }
}
