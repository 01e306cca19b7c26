//! What the relaxation bound returns: [`Bound`] (the certified bound, its
//! point, the stages' summaries and status), serialised as reports print it.

use super::conic::ConicStatus;
use super::settings::RelaxationSolver;
use serde::{Deserialize, Serialize};

/// Weight above which a pose counts as carrying relaxation weight in
/// [`Bound::support_size`].
pub const SUPPORT_TOL: f64 = 1e-6;

/// How the bound ended. Every status carries a valid bound; only the gap to
/// the best feasible point differs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundStatus {
    /// `certificate_gap ≤ gap_tol`.
    Certified,
    /// `N` equals the pool size: the only feasible point is `w = 1`, and the
    /// bound is `ln det` of the whole pool, exactly.
    Exact,
    /// The bound is valid but its gap is above `gap_tol` (Clarabel did not
    /// converge, or the round or time limits were hit).
    GapAboveTolerance,
}

/// What the candidate-set stage (Clarabel or Newton) did.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ConicSummary {
    /// Which solver ran.
    pub solver: RelaxationSolver,
    /// Status of the last Clarabel solve (`None` if Clarabel did not run).
    pub status: Option<ConicStatus>,
    /// Interior-point iterations of the last solve.
    pub iterations: u32,
    /// Interior-point iterations of all solves.
    pub total_iterations: u32,
    /// Clarabel solves (screening rounds).
    pub rounds: usize,
    /// Candidates in the last solve.
    pub candidates: usize,
    /// Whether the last solve was repeated without equilibration.
    #[serde(rename = "retried_without_equilibration")]
    pub retried: bool,
    /// Seconds in Clarabel, all rounds.
    pub seconds: f64,
    /// Clarabel's primal objective of the last solve, unscaled (an estimate,
    /// not a bound).
    pub ln_det_primal: Option<f64>,
    /// Clarabel's dual objective of the last solve, unscaled (uncertified:
    /// it bounds only the candidate subproblem, and only up to the solver's
    /// residuals).
    pub ln_det_dual: Option<f64>,
    /// Pairwise steps of the first-order polish after Clarabel.
    pub polish_steps: usize,
}

/// The certified upper bound on `ln OI_D` of every `N`-pose design of a
/// pool. It serialises as every report prints it (see its `Serialize`).
#[derive(Clone, Debug)]
pub struct Bound {
    /// Upper bound on `ln det M` of every `N`-pose design (and on the
    /// relaxation's optimum): the smallest certificate (eq. C) seen.
    pub ln_bound: f64,
    /// `ln det M(w)` at the feasible `weights`: a lower bound on the
    /// relaxation's optimum.
    pub ln_primal: f64,
    /// `ln_bound − ln_primal ≥ 0`.
    pub certificate_gap: f64,
    /// How it ended.
    pub status: BoundStatus,
    /// Poses per design.
    pub n: usize,
    /// Unknowns.
    pub p: usize,
    /// Pool size.
    pub pool_size: usize,
    /// Feasible relaxation weights, one per pool pose.
    pub weights: Vec<f64>,
    /// Poses with weight above [`SUPPORT_TOL`].
    pub support_size: usize,
    /// First-order stage (screening, or the whole solve without Clarabel).
    pub first_order: ExchangeSummary,
    /// Clarabel stage.
    pub conic: ConicSummary,
    /// Wall-clock seconds, all stages.
    pub seconds: f64,
    /// Whether the relaxation included prior information `M0`.
    pub with_prior: bool,
}

impl Serialize for Bound {
    /// The summary every report prints: the bound, its `log10_bound`, its
    /// status in snake case (`certified`), the sizes, the candidate-set
    /// stage as `solver` and the first-order stage; the weights stay out
    /// (a report lists the ones it needs).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("Bound", 13)?;
        st.serialize_field("ln_bound", &self.ln_bound)?;
        st.serialize_field("log10_bound", &self.log10_bound())?;
        st.serialize_field("ln_primal", &self.ln_primal)?;
        st.serialize_field("certificate_gap", &self.certificate_gap)?;
        st.serialize_field("status", &self.status)?;
        st.serialize_field("n", &self.n)?;
        st.serialize_field("p", &self.p)?;
        st.serialize_field("pool_size", &self.pool_size)?;
        st.serialize_field("support_size", &self.support_size)?;
        st.serialize_field("seconds", &self.seconds)?;
        st.serialize_field("solver", &self.conic)?;
        st.serialize_field("first_order", &self.first_order)?;
        st.serialize_field("with_prior", &self.with_prior)?;
        st.end()
    }
}

/// What the first-order stage did.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ExchangeSummary {
    /// Rounds (full-pool variance evaluations).
    pub rounds: usize,
    /// Pairwise exchange steps.
    pub steps: usize,
    /// Its certificate gap when it stopped.
    pub gap: f64,
    /// Seconds.
    pub seconds: f64,
}

impl Bound {
    /// `log10` of the bound on OI_D.
    #[must_use]
    pub fn log10_bound(&self) -> f64 {
        self.ln_bound / std::f64::consts::LN_10
    }

    /// Pool positions with weight above `tol`, ascending.
    #[must_use]
    pub fn support(&self, tol: f64) -> Vec<usize> {
        (0..self.weights.len())
            .filter(|&i| self.weights[i] > tol)
            .collect()
    }
}
