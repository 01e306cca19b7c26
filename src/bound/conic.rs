//! The relaxation as a conic program for Clarabel: ln det through the PSD and
//! exponential cones.
//!
//! For weights `w` of `m` candidate poses, with `Z` lower triangular `p × p`
//! and `t ∈ ℝᵖ`:
//!
//! `maximise Σ_j t_j  s.t.  Σ w = N,  0 ≤ w ≤ 1,`
//! `[[M(w), Z], [Zᵀ, Diag(Z)]] ⪰ 0,  (t_j, 1, Z_jj) ∈ K_exp`   (R)
//!
//! whose optimum is `max ln det M(w)`: the PSD block forces
//! `Π Z_jj ≤ det M(w)`, and `t_j ≤ ln Z_jj` is the exponential cone
//! `1·exp(t_j/1) ≤ Z_jj`. Clarabel minimises `qᵀx` subject to
//! `A x + s = b, s ∈ K`, so the cone coefficients enter `A` negated and
//! `ln det = −obj_val`. The PSD cone's vector is the upper triangle column by
//! column, entry `(r, c)` at `c(c+1)/2 + r`, off-diagonal entries times √2.
//! The off-diagonal entries of the bottom-right block have no entries in `A`
//! at all, so chordal decomposition can split the cone.

use super::BoundError;
use super::variance::{Scaled, check_problem, scale_columns};
use crate::blocks::Blocks;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Settings of the Clarabel solve: [`ConicSettings::builder`] (validated)
/// or the defaults in [`Default`].
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(default)]
#[non_exhaustive]
pub struct ConicSettings {
    /// Interior-point iteration limit. Default 200.
    pub max_iter: u32,
    /// Time limit in seconds for one solve. Default 120.
    pub time_limit: f64,
    /// Absolute and relative duality-gap tolerance. Default 1e-10.
    pub tol_gap: f64,
    /// Primal and dual feasibility tolerance. Default 1e-10.
    pub tol_feas: f64,
    /// Clarabel's data equilibration. Default true.
    pub equilibrate: bool,
    /// Re-solve once with equilibration off when the first solve does not
    /// end `Solved` (known to help on these problems). Default true.
    pub retry_without_equilibration: bool,
    /// Chordal decomposition of the PSD cone. Default true.
    pub chordal: bool,
    /// Clarabel's clique merging after chordal decomposition: `"none"`,
    /// `"parent_child"` or `"clique_graph"`. Default `"clique_graph"`.
    pub chordal_merge: String,
    /// Clarabel's progress printing. Default false.
    pub verbose: bool,
}

impl Default for ConicSettings {
    fn default() -> Self {
        Self {
            max_iter: 200,
            time_limit: 120.0,
            tol_gap: 1e-10,
            tol_feas: 1e-10,
            equilibrate: true,
            retry_without_equilibration: true,
            chordal: true,
            chordal_merge: "clique_graph".into(),
            verbose: false,
        }
    }
}

crate::settings::settings_builder! {
    /// Validated construction of [`ConicSettings`].
    ConicSettingsBuilder for ConicSettings, error BoundError {
        /// Interior-point iteration limit (default 200).
        max_iter: u32,
        /// Seconds per solve (default 120).
        time_limit: f64,
        /// Duality-gap tolerance (default 1e-10).
        tol_gap: f64,
        /// Feasibility tolerance (default 1e-10).
        tol_feas: f64,
        /// Data equilibration (default true).
        equilibrate: bool,
        /// One re-solve without equilibration (default true).
        retry_without_equilibration: bool,
        /// Chordal decomposition (default true).
        chordal: bool,
        /// Clique merging: "none", "parent_child" or "clique_graph" (default).
        chordal_merge: String,
        /// Clarabel's progress printing (default false).
        verbose: bool,
    }
}

impl ConicSettings {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), BoundError> {
        let pos = super::error::positive;
        pos("conic.time_limit", self.time_limit)?;
        pos("conic.tol_gap", self.tol_gap)?;
        pos("conic.tol_feas", self.tol_feas)?;
        if !["none", "parent_child", "clique_graph"].contains(&self.chordal_merge.as_str()) {
            return Err(BoundError::InvalidSetting {
                name: "conic.chordal_merge",
                value: self.chordal_merge.clone(),
                reason: "must be none, parent_child or clique_graph",
            });
        }
        if self.max_iter == 0 {
            return Err(BoundError::InvalidSetting {
                name: "conic.max_iter",
                value: "0".into(),
                reason: "must be ≥ 1",
            });
        }
        Ok(())
    }

    fn clarabel(&self, equilibrate: bool) -> DefaultSettings<f64> {
        DefaultSettings {
            max_iter: self.max_iter,
            time_limit: self.time_limit,
            verbose: self.verbose,
            tol_gap_abs: self.tol_gap,
            tol_gap_rel: self.tol_gap,
            tol_feas: self.tol_feas,
            equilibrate_enable: equilibrate,
            chordal_decomposition_enable: self.chordal,
            chordal_decomposition_merge_method: self.chordal_merge.clone(),
            max_threads: 1,
            ..DefaultSettings::default()
        }
    }
}

/// Clarabel's termination status, serialisable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[allow(missing_docs)]
pub enum ConicStatus {
    Unsolved,
    Solved,
    AlmostSolved,
    PrimalInfeasible,
    DualInfeasible,
    AlmostPrimalInfeasible,
    AlmostDualInfeasible,
    MaxIterations,
    MaxTime,
    NumericalError,
    InsufficientProgress,
    CallbackTerminated,
}

impl From<SolverStatus> for ConicStatus {
    fn from(s: SolverStatus) -> Self {
        match s {
            SolverStatus::Unsolved => Self::Unsolved,
            SolverStatus::Solved => Self::Solved,
            SolverStatus::AlmostSolved => Self::AlmostSolved,
            SolverStatus::PrimalInfeasible => Self::PrimalInfeasible,
            SolverStatus::DualInfeasible => Self::DualInfeasible,
            SolverStatus::AlmostPrimalInfeasible => Self::AlmostPrimalInfeasible,
            SolverStatus::AlmostDualInfeasible => Self::AlmostDualInfeasible,
            SolverStatus::MaxIterations => Self::MaxIterations,
            SolverStatus::MaxTime => Self::MaxTime,
            SolverStatus::NumericalError => Self::NumericalError,
            SolverStatus::InsufficientProgress => Self::InsufficientProgress,
            SolverStatus::CallbackTerminated => Self::CallbackTerminated,
        }
    }
}

impl ConicStatus {
    /// Solved to full or reduced accuracy.
    #[must_use]
    pub fn is_solved(self) -> bool {
        matches!(self, Self::Solved | Self::AlmostSolved)
    }
}

/// One Clarabel solve of problem (R) on a candidate set.
#[derive(Clone, Debug, Serialize)]
pub struct ConicOutcome {
    /// Weights of the candidates as returned (not clamped: they sit slightly
    /// inside or outside `[0, 1]`).
    pub weights: Vec<f64>,
    /// Termination status of the last solve.
    pub status: ConicStatus,
    /// Interior-point iterations, summed over the solve and its retry.
    pub iterations: u32,
    /// Whether the solve was repeated with equilibration off.
    pub retried: bool,
    /// `−obj_val`, unscaled: the solver's primal estimate of the optimum.
    /// Not a bound.
    pub ln_det_primal: f64,
    /// `−obj_val_dual`, unscaled: the solver's dual estimate. Not certified.
    pub ln_det_dual: f64,
    /// Seconds in Clarabel (setup and solve).
    pub seconds: f64,
}

/// Solves problem (R) with Clarabel on a whole (small) pool Jacobian:
/// column-scales it, solves, and unscales the objective values.
///
/// The returned values are the solver's estimates, not certified bounds; see
/// [`super::relaxation_bound`] for the certified pipeline.
pub fn solve(x: &Blocks, n: usize, settings: &ConicSettings) -> Result<ConicOutcome, BoundError> {
    settings.validate()?;
    check_problem(x, n)?;
    let sc = scale_columns(x, n)?;
    Ok(solve_scaled(&sc, n, settings))
}

/// Solves problem (R) on the already scaled blocks `sc.x` (objective values
/// unscaled with `sc.ln_scale`).
pub(crate) fn solve_scaled(sc: &Scaled, n: usize, s: &ConicSettings) -> ConicOutcome {
    crate::linalg::blas::single_threaded();
    let clock = Instant::now();
    let (a, b, q, cones) = problem(sc, n);
    let p_mat = CscMatrix::zeros((q.len(), q.len()));
    let mut iterations = 0;
    let mut retried = false;
    let mut run = |equilibrate: bool| {
        let settings = s.clarabel(equilibrate);
        match DefaultSolver::new(&p_mat, &q, &a, &b, &cones, settings) {
            Ok(mut solver) => {
                solver.solve();
                let sol = &solver.solution;
                iterations += sol.iterations;
                Some((
                    ConicStatus::from(sol.status),
                    sol.x[..sc.x.n_poses()].to_vec(),
                    -sol.obj_val,
                    -sol.obj_val_dual,
                ))
            }
            Err(_) => None,
        }
    };
    let mut res = run(s.equilibrate);
    let ok = matches!(&res, Some((st, ..)) if *st == ConicStatus::Solved);
    if !ok && s.equilibrate && s.retry_without_equilibration {
        retried = true;
        let second = run(false);
        // Keep the better-terminated of the two.
        let rank = |r: &Option<(ConicStatus, Vec<f64>, f64, f64)>| match r {
            Some((ConicStatus::Solved, ..)) => 2,
            Some((ConicStatus::AlmostSolved, ..)) => 1,
            _ => 0,
        };
        if rank(&second) >= rank(&res) {
            res = second;
        }
    }
    let m = sc.x.n_poses();
    let (status, weights, pr, du) = res.unwrap_or((
        ConicStatus::NumericalError,
        vec![0.0; m],
        f64::NAN,
        f64::NAN,
    ));
    ConicOutcome {
        weights,
        status,
        iterations,
        retried,
        ln_det_primal: pr + sc.ln_scale,
        ln_det_dual: du + sc.ln_scale,
        seconds: clock.elapsed().as_secs_f64(),
    }
}

/// Index of the upper-triangle entry `(r, c)`, `r ≤ c`, in the PSD cone's
/// vector.
fn tri(r: usize, c: usize) -> usize {
    debug_assert!(r <= c);
    c * (c + 1) / 2 + r
}

/// Builds `A`, `b`, `q` and the cones of problem (R). Variables:
/// `[w (m), z (lower-triangular Z, p(p+1)/2, column-major), t (p)]`.
/// Rows: `Σw = N` (zero cone), `w ≥ 0` and `1 − w ≥ 0` (nonnegative cone),
/// `p` exponential cones, one PSD cone of side `2p`.
#[allow(clippy::type_complexity)]
fn problem(
    sc: &Scaled,
    n: usize,
) -> (CscMatrix<f64>, Vec<f64>, Vec<f64>, Vec<SupportedConeT<f64>>) {
    let x = &sc.x;
    let (m, t, p) = (x.n_poses(), x.t(), x.p());
    let nz = p * (p + 1) / 2;
    let nvar = m + nz + p;
    let exp0 = 1 + 2 * m;
    let psd0 = exp0 + 3 * p;
    let side = 2 * p;
    let nrows = psd0 + side * (side + 1) / 2;
    let sqrt2 = std::f64::consts::SQRT_2;
    // Index of Z_{r,k} (r ≥ k), column-major over the lower triangle.
    let zcol = |r: usize, k: usize| -> usize { k * p - k * (k.saturating_sub(1)) / 2 - k + r };
    // Check the packing once: column k starts after Σ_{l<k} (p − l) entries.
    debug_assert_eq!(zcol(p - 1, p - 1), nz - 1);

    let mut colptr = Vec::with_capacity(nvar + 1);
    let mut rowval = Vec::with_capacity(m * (3 + nz) + 4 * nz + p);
    let mut nzval = Vec::with_capacity(rowval.capacity());
    colptr.push(0);
    let xm = x.mat();
    // w_i columns.
    for i in 0..m {
        rowval.push(0);
        nzval.push(1.0);
        rowval.push(1 + i);
        nzval.push(-1.0);
        rowval.push(1 + m + i);
        nzval.push(1.0);
        for c in 0..p {
            for r in 0..=c {
                let mut v = 0.0;
                for l in i * t..i * t + t {
                    v += xm[(l, r)] * xm[(l, c)];
                }
                if v != 0.0 {
                    rowval.push(psd0 + tri(r, c));
                    nzval.push(if r == c { -v } else { -sqrt2 * v });
                }
            }
        }
        colptr.push(rowval.len());
    }
    // Z_{r,k} columns, r ≥ k, in the order of zcol.
    for k in 0..p {
        for r in k..p {
            debug_assert_eq!(colptr.len() - 1, m + zcol(r, k));
            if r == k {
                rowval.push(exp0 + 3 * k + 2);
                nzval.push(-1.0);
            }
            // Top-right block entry (r, p + k).
            rowval.push(psd0 + tri(r, p + k));
            nzval.push(-sqrt2);
            if r == k {
                // Bottom-right diagonal (p + k, p + k).
                rowval.push(psd0 + tri(p + k, p + k));
                nzval.push(-1.0);
            }
            colptr.push(rowval.len());
        }
    }
    // t_j columns.
    for j in 0..p {
        rowval.push(exp0 + 3 * j);
        nzval.push(-1.0);
        colptr.push(rowval.len());
    }
    let a = CscMatrix::new(nrows, nvar, colptr, rowval, nzval);
    let mut b = vec![0.0; nrows];
    b[0] = n as f64;
    for i in 0..m {
        b[1 + m + i] = 1.0;
    }
    for j in 0..p {
        b[exp0 + 3 * j + 1] = 1.0;
    }
    // A prior is the constant part of the PSD block: s = b − A x puts
    // M0 + Σ w_i X_iᵀX_i in its top-left corner.
    if let Some(m0) = &sc.m0 {
        for c in 0..p {
            for r in 0..=c {
                let v = 0.5 * (m0[(r, c)] + m0[(c, r)]);
                b[psd0 + tri(r, c)] = if r == c { v } else { sqrt2 * v };
            }
        }
    }
    let mut q = vec![0.0; nvar];
    q[m + nz..].iter_mut().for_each(|v| *v = -1.0);
    let mut cones = vec![
        SupportedConeT::ZeroConeT(1),
        SupportedConeT::NonnegativeConeT(2 * m),
    ];
    cones.extend((0..p).map(|_| SupportedConeT::ExponentialConeT()));
    cones.push(SupportedConeT::PSDTriangleConeT(side));
    (a, b, q, cones)
}

#[cfg(test)]
mod tests {
    #[test]
    fn z_packing_is_column_major_lower() {
        let p = 5;
        let zcol = |r: usize, k: usize| -> usize { k * p - k * (k.saturating_sub(1)) / 2 - k + r };
        let mut expect = 0;
        for k in 0..p {
            for r in k..p {
                assert_eq!(zcol(r, k), expect, "({r},{k})");
                expect += 1;
            }
        }
    }
}
