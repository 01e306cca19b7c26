//! The settings of the relaxation bound: the candidate subproblems' solver
//! and [`BoundSettings`], with its builder and its one `validate`.

use super::conic::ConicSettings;
use super::error::BoundError;
use super::first_order::ExchangeSettings;
use super::newton::NewtonSettings;
use serde::{Deserialize, Serialize};

/// The solver of the candidate subproblems of (R).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum RelaxationSolver {
    /// Clarabel on the PSD + exponential-cone form ([`super::conic`]).
    Clarabel,
    /// The log-barrier Newton method on `ln det M(w)` itself ([`super::newton`]):
    /// the default, 5–15 times faster than Clarabel on every pool measured
    /// (PUMA, UR5 full pose, a four-marker TIAGo) with a tighter certificate.
    #[default]
    Newton,
}

crate::choice!(RelaxationSolver { Clarabel => "clarabel", Newton => "newton" });

/// Settings of [`super::relaxation_bound`]. Build with [`BoundSettings::builder`]
/// (validated) or take [`BoundSettings::default`].
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default)]
pub struct BoundSettings {
    /// Target certified gap `ln_bound − ln_primal`. Default 1e-6.
    pub gap_tol: f64,
    /// Solve (R) on candidate sets with `solver` (true) or with the
    /// first-order solver alone (false). Default true.
    pub use_conic: bool,
    /// The candidate-set solver: Newton (default) or Clarabel.
    pub solver: RelaxationSolver,
    /// First-order certificate gap at which screening stops and Clarabel
    /// takes over. Default 1e-2.
    pub screen_gap: f64,
    /// Poses outside the support added to Clarabel's candidate set, by
    /// largest `d_i`. Default 100.
    pub screen_extra: usize,
    /// Pools of at most this many poses go to Clarabel whole. Default 400.
    pub direct_limit: usize,
    /// Maximum candidate-set solves (screening rounds). Default 20: with
    /// the support reduction of large candidate sets a round is cheap, and
    /// the 10⁶-pose PUMA pool at N = 145 needs 11.
    pub max_rounds: usize,
    /// Most violators added to the candidates per round, by largest `d_i`.
    /// Default 300.
    pub max_add: usize,
    /// Clarabel's gap and feasibility tolerance in screening rounds: solves
    /// whose purpose is to find the poses that violate the optimality
    /// conditions outside the candidates. The last solve (no violator left,
    /// or the whole pool) uses `conic.tol_gap`. Default 1e-7.
    pub screen_tol: f64,
    /// When the last Clarabel solve leaves no violator outside its
    /// candidates but its certificate gap is still above `gap_tol` (solver
    /// accuracy), run the first-order solver from its point for at most
    /// `polish_rounds` rounds; when Clarabel fails, continue the first-order
    /// solver to `gap_tol` instead. Default true.
    pub polish: bool,
    /// Round limit of each polish. Default 20.
    pub polish_rounds: usize,
    /// The first-order solver's settings (its `gap_tol` is overridden by
    /// `screen_gap` or `gap_tol` as the stage needs).
    pub first_order: ExchangeSettings,
    /// Clarabel's settings.
    pub conic: ConicSettings,
    /// The Newton solver's settings.
    pub newton: NewtonSettings,
}

impl Default for BoundSettings {
    fn default() -> Self {
        Self {
            gap_tol: 1e-6,
            use_conic: true,
            solver: RelaxationSolver::Newton,
            screen_gap: 1e-2,
            screen_extra: 100,
            direct_limit: 400,
            max_rounds: 20,
            max_add: 300,
            screen_tol: 1e-7,
            polish: true,
            polish_rounds: 20,
            first_order: ExchangeSettings::default(),
            conic: ConicSettings::default(),
            newton: NewtonSettings::default(),
        }
    }
}

impl BoundSettings {
    /// A builder starting from the defaults.
    #[must_use]
    pub fn builder() -> BoundSettingsBuilder {
        BoundSettingsBuilder(Self::default())
    }

    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), BoundError> {
        let pos = super::error::positive;
        pos("gap_tol", self.gap_tol)?;
        pos("screen_gap", self.screen_gap)?;
        pos("screen_tol", self.screen_tol)?;
        if self.max_add == 0 {
            return Err(BoundError::InvalidSetting {
                name: "max_add",
                value: "0".into(),
                reason: "must be ≥ 1",
            });
        }
        if self.polish_rounds == 0 {
            return Err(BoundError::InvalidSetting {
                name: "polish_rounds",
                value: "0".into(),
                reason: "must be ≥ 1",
            });
        }
        if self.max_rounds == 0 {
            return Err(BoundError::InvalidSetting {
                name: "max_rounds",
                value: "0".into(),
                reason: "must be ≥ 1",
            });
        }
        self.first_order.validate()?;
        self.newton.validate()?;
        self.conic.validate()
    }
}

/// Validated construction of [`BoundSettings`].
#[derive(Clone, Debug)]
pub struct BoundSettingsBuilder(BoundSettings);

impl BoundSettingsBuilder {
    /// Target certified gap (default 1e-6).
    #[must_use]
    pub fn gap_tol(mut self, v: f64) -> Self {
        self.0.gap_tol = v;
        self
    }
    /// Clarabel (true, default) or the first-order solver alone.
    #[must_use]
    pub fn use_conic(mut self, v: bool) -> Self {
        self.0.use_conic = v;
        self
    }
    /// Screening gap of the first-order stage (default 1e-2).
    #[must_use]
    pub fn screen_gap(mut self, v: f64) -> Self {
        self.0.screen_gap = v;
        self
    }
    /// Extra candidates for Clarabel (default 100).
    #[must_use]
    pub fn screen_extra(mut self, v: usize) -> Self {
        self.0.screen_extra = v;
        self
    }
    /// Pool size up to which Clarabel gets the whole pool (default 400).
    #[must_use]
    pub fn direct_limit(mut self, v: usize) -> Self {
        self.0.direct_limit = v;
        self
    }
    /// Clarabel tolerance of screening rounds (default 1e-7).
    #[must_use]
    pub fn screen_tol(mut self, v: f64) -> Self {
        self.0.screen_tol = v;
        self
    }
    /// Most violators added per round (default 300).
    #[must_use]
    pub fn max_add(mut self, v: usize) -> Self {
        self.0.max_add = v;
        self
    }
    /// Maximum candidate-set solves (default 20).
    #[must_use]
    pub fn max_rounds(mut self, v: usize) -> Self {
        self.0.max_rounds = v;
        self
    }
    /// Round limit of each polish (default 20).
    #[must_use]
    pub fn polish_rounds(mut self, v: usize) -> Self {
        self.0.polish_rounds = v;
        self
    }
    /// First-order polishing after Clarabel (default true).
    #[must_use]
    pub fn polish(mut self, v: bool) -> Self {
        self.0.polish = v;
        self
    }
    /// First-order solver settings.
    #[must_use]
    pub fn first_order(mut self, v: ExchangeSettings) -> Self {
        self.0.first_order = v;
        self
    }
    /// Clarabel settings.
    #[must_use]
    pub fn conic(mut self, v: ConicSettings) -> Self {
        self.0.conic = v;
        self
    }
    /// The candidate-set solver (default Clarabel).
    #[must_use]
    pub fn solver(mut self, v: RelaxationSolver) -> Self {
        self.0.solver = v;
        self
    }
    /// Newton solver settings.
    #[must_use]
    pub fn newton(mut self, v: NewtonSettings) -> Self {
        self.0.newton = v;
        self
    }
    /// Validates and returns the settings.
    pub fn build(self) -> Result<BoundSettings, BoundError> {
        self.0.validate()?;
        Ok(self.0)
    }
}
