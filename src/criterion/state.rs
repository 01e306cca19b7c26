//! The information state of a design over a pose pool: `M = XᵀX (+ δR)`,
//! `M⁻¹`, `ln det M`, updated by the paper's formulas (eq. (4)–(22)) in
//! block form.

use std::sync::atomic::{AtomicU64, Ordering};

use faer::MatRef;
use serde::{Deserialize, Serialize};

use super::CriterionError;
use super::lowrank::{LowRank, woodbury};
use super::prior::Prior;
use crate::blocks::Blocks;
use crate::linalg::chol::cholesky_inverse;
use crate::linalg::eigen::EigenScratch;
use crate::linalg::gram::{add_gram, gather_block, view};
use crate::linalg::rank::{
    MAX_CONDITION, eigenvalues_regular, equilibrated_cond1, equilibrated_eigenvalues,
    equilibrated_rank,
};

/// Settings of an [`InfoState`]; validated by [`InfoState::new`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct StateSettings {
    /// Relative ridge `δ ≥ 0`: `M = XᵀX + δR`, `R = diag(r_j)` with `r_j`
    /// the mean information of column `j` per pool pose
    /// ([`InfoState::ridge_scales`]), so that scaling a column (a unit
    /// change) scales its ridge with it. Lets a selection start from fewer
    /// than `p/t` poses. Default `0`.
    pub ridge: f64,
    /// Refactorize (recompute `M` from the design, Cholesky, `M⁻¹`,
    /// `ln det M`) after this many updates, `≥ 1`. Default `64`.
    pub refactor_every: usize,
    /// Largest accepted condition number of the equilibrated `M` (see the
    /// module docs' singularity rule), `> 1`. Default
    /// [`MAX_CONDITION`](crate::linalg::rank::MAX_CONDITION) `= 1e13`, the
    /// rule every command decides rank by.
    pub max_condition: f64,
}

impl Default for StateSettings {
    fn default() -> Self {
        Self {
            ridge: 0.0,
            refactor_every: 64,
            max_condition: MAX_CONDITION,
        }
    }
}

impl StateSettings {
    /// Sets [`ridge`](Self::ridge).
    #[must_use]
    pub fn with_ridge(mut self, ridge: f64) -> Self {
        self.ridge = ridge;
        self
    }

    /// Sets [`refactor_every`](Self::refactor_every).
    #[must_use]
    pub fn with_refactor_every(mut self, k: usize) -> Self {
        self.refactor_every = k;
        self
    }

    /// Sets [`max_condition`](Self::max_condition).
    #[must_use]
    pub fn with_max_condition(mut self, c: f64) -> Self {
        self.max_condition = c;
        self
    }

    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), CriterionError> {
        if !(self.ridge.is_finite() && self.ridge >= 0.0) {
            return Err(CriterionError::InvalidSetting {
                name: "ridge",
                value: self.ridge,
                reason: "need a finite ridge >= 0",
            });
        }
        if self.refactor_every == 0 {
            return Err(CriterionError::InvalidSetting {
                name: "refactor_every",
                value: 0.0,
                reason: "need at least 1",
            });
        }
        if !(self.max_condition.is_finite() && self.max_condition > 1.0) {
            return Err(CriterionError::InvalidSetting {
                name: "max_condition",
                value: self.max_condition,
                reason: "need a finite value > 1",
            });
        }
        Ok(())
    }
}

/// Outcome of pricing or applying a change (numerical, not an error).
#[must_use]
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Status {
    /// `M` stays positive definite; `ln det M` changes by `delta_ln_det`.
    /// For an update method, the change was applied.
    Regular {
        /// `ln det M' − ln det M`.
        delta_ln_det: f64,
        /// Smallest pivot `d` of the removal Schur complement (`+∞` when
        /// nothing is removed; in `(0, 1]` for a pure removal). The rounding
        /// error of the change is amplified by about `1/d`, and the singularity
        /// rule keeps `κ̂(M̃)/d < max_condition` (`M̃` the equilibrated `M`).
        min_pivot: f64,
    },
    /// The change would make `M` numerically singular: a pivot of the
    /// removal Schur complement was `≤ pivot_floor`
    /// (`= κ̂(M̃)/max_condition`). For an update method, nothing was changed.
    Singular {
        /// The offending pivot (may be `≤ 0`).
        pivot: f64,
        /// The floor it was compared with.
        pivot_floor: f64,
    },
}

impl Status {
    /// The change of `ln det M`, or `None` if singular.
    #[must_use]
    pub fn delta(&self) -> Option<f64> {
        match *self {
            Status::Regular { delta_ln_det, .. } => Some(delta_ln_det),
            Status::Singular { .. } => None,
        }
    }

    /// Whether the change keeps `M` positive definite.
    #[must_use]
    pub fn is_regular(&self) -> bool {
        matches!(self, Status::Regular { .. })
    }
}

/// Errors of the maintained quantities against a fresh recomputation from the
/// design (see the module docs on drift).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Drift {
    /// `|ln det M (maintained) − ln det M (fresh)|`; `+∞` if the fresh `M`
    /// cannot be factored.
    pub ln_det: f64,
    /// `max |M_fresh · M⁻¹ (maintained) − I|`.
    pub inverse: f64,
    /// `max |M (maintained) − M_fresh| / max |M_fresh|`.
    pub information: f64,
}

const NOT_IN_DESIGN: usize = usize::MAX;

/// Low-rank updates kept for [`InfoState::updates_since`] (between
/// `LOG_KEEP` and `2·LOG_KEEP` of the most recent ones).
const LOG_KEEP: usize = 64;

static NEXT_ID: AtomicU64 = AtomicU64::new(1);

fn fresh_id() -> u64 {
    NEXT_ID.fetch_add(1, Ordering::Relaxed)
}

/// The information state of a design over a pool: design pose list (pool
/// indices, no repeats), `M = XᵀX + δR` (`p×p`, see
/// [`StateSettings::ridge`]), `M⁻¹`, `ln det M`, and the number of updates
/// since the last refactorization.
///
/// Every method that needs the Jacobian blocks takes the pool the state was
/// built on; passing another pool of a different shape panics.
#[derive(Debug)]
pub struct InfoState {
    id: u64,
    t: usize,
    p: usize,
    n_pool: usize,
    design: Vec<usize>,
    position: Vec<usize>,
    settings: StateSettings,
    /// `r_j` of the ridge `δR` (see [`StateSettings::ridge`]).
    ridge_scale: Vec<f64>,
    /// `M`, `p×p` column-major (stride `p`), exactly symmetric.
    m: Vec<f64>,
    /// `M⁻¹`, same layout.
    m_inv: Vec<f64>,
    ln_det: f64,
    cond1: f64,
    since_refactor: usize,
    version: u64,
    epoch: u64,
    log_base: u64,
    log: Vec<LowRank>,
    /// Scratch for a gathered Jacobian block.
    block: Vec<f64>,
    /// Information measured before the design, `M0` (in `M` whenever `M`
    /// is recomputed from the design).
    prior: Option<Prior>,
}

impl Clone for InfoState {
    /// Clones with a fresh identity, so caches keyed on a state (such as
    /// [`PoolVariances`](super::PoolVariances)) never confuse two clones.
    fn clone(&self) -> Self {
        Self {
            id: fresh_id(),
            t: self.t,
            p: self.p,
            n_pool: self.n_pool,
            design: self.design.clone(),
            position: self.position.clone(),
            settings: self.settings,
            ridge_scale: self.ridge_scale.clone(),
            m: self.m.clone(),
            m_inv: self.m_inv.clone(),
            ln_det: self.ln_det,
            cond1: self.cond1,
            since_refactor: self.since_refactor,
            version: self.version,
            epoch: self.epoch,
            log_base: self.log_base,
            log: self.log.clone(),
            block: Vec::new(),
            prior: self.prior.clone(),
        }
    }
}

/// A fresh factorization of `M`.
struct Factored {
    m: Vec<f64>,
    m_inv: Vec<f64>,
    ln_det: f64,
    cond1: f64,
}

/// `r_j = ‖X_pool[:, j]‖² / n_pool`, the mean information of column `j` per
/// pool pose; `1` for a column that is zero (or overflows) on the whole
/// pool, which no ridge can make identifiable anyway.
fn ridge_scales(pool: &Blocks) -> Vec<f64> {
    let x = pool.mat();
    let n = pool.n_poses().max(1) as f64;
    (0..x.ncols())
        .map(|c| {
            let r = x.col(c).squared_norm_l2() / n;
            if r > 0.0 && r.is_finite() { r } else { 1.0 }
        })
        .collect()
}

/// The ridge's diagonal `δ·r_j`.
fn ridge_diagonal(scales: &[f64], ridge: f64) -> Vec<f64> {
    scales.iter().map(|r| ridge * r).collect()
}

impl InfoState {
    /// Builds the state of `design` (pool indices, no repeats, any order)
    /// from scratch: `M` from the blocks (plus the ridge), Cholesky (faer
    /// `llt`), `M⁻¹`, `ln det M = 2 Σ ln L_ii`.
    ///
    /// Errors: bad input ([`CriterionError::PoseOutOfRange`],
    /// [`DuplicatePose`](CriterionError::DuplicatePose),
    /// [`NonFinite`](CriterionError::NonFinite) anywhere in the pool,
    /// [`InvalidSetting`](CriterionError::InvalidSetting),
    /// [`UnsupportedShape`](CriterionError::UnsupportedShape) for `t > 6` or
    /// `p = 0`), or [`CriterionError::Singular`] when `M` is not positive
    /// definite or the condition number of its equilibrated form exceeds
    /// `max_condition`.
    pub fn new(
        pool: &Blocks,
        design: &[usize],
        settings: StateSettings,
    ) -> Result<Self, CriterionError> {
        Self::with_prior(pool, design, None, settings)
    }

    /// [`new`](Self::new) for a design added to prior information:
    /// `M = M0 + XᵀX (+ δI)`, so `ln det M` is `ln det(M0 + XᵀX)`. A prior
    /// of another size than the pool's `p` is
    /// [`CriterionError::UnsupportedShape`].
    pub fn with_prior(
        pool: &Blocks,
        design: &[usize],
        prior: Option<Prior>,
        settings: StateSettings,
    ) -> Result<Self, CriterionError> {
        settings.validate()?;
        if let Some(pr) = &prior
            && pr.p() != pool.p()
        {
            return Err(CriterionError::UnsupportedShape {
                reason: format!(
                    "the prior is for {} unknowns, the pool has {}",
                    pr.p(),
                    pool.p()
                ),
            });
        }
        let (t, p, n_pool) = (pool.t(), pool.p(), pool.n_poses());
        if t == 0 || p == 0 {
            return Err(CriterionError::UnsupportedShape {
                reason: format!("need t >= 1 rows per pose and p >= 1, got t={t}, p={p}"),
            });
        }
        let x = pool.mat();
        for c in 0..p {
            for r in 0..x.nrows() {
                let v = x[(r, c)];
                if !v.is_finite() {
                    return Err(CriterionError::NonFinite {
                        row: r,
                        col: c,
                        value: v,
                    });
                }
            }
        }
        let mut position = vec![NOT_IN_DESIGN; n_pool];
        for (k, &q) in design.iter().enumerate() {
            if q >= n_pool {
                return Err(CriterionError::PoseOutOfRange {
                    pose: q,
                    n_poses: n_pool,
                });
            }
            if position[q] != NOT_IN_DESIGN {
                return Err(CriterionError::DuplicatePose { pose: q });
            }
            position[q] = k;
        }
        let ridge_scale = ridge_scales(pool);
        let ridge = ridge_diagonal(&ridge_scale, settings.ridge);
        let f = Self::factor(
            pool,
            design,
            prior.as_ref(),
            &ridge,
            settings.max_condition,
            true,
        )?;
        Ok(Self {
            id: fresh_id(),
            t,
            p,
            n_pool,
            design: design.to_vec(),
            position,
            settings,
            ridge_scale,
            m: f.m,
            m_inv: f.m_inv,
            ln_det: f.ln_det,
            cond1: f.cond1,
            since_refactor: 0,
            version: 0,
            epoch: 0,
            log_base: 0,
            log: Vec::new(),
            block: Vec::new(),
            prior,
        })
    }

    /// `M = M0 + diag(ridge) + Σ_{i∈design} X_iᵀX_i`, factored; with
    /// `check_condition`, a condition number of the equilibrated `M` above
    /// `max_condition` (from its eigenvalues) is singular too.
    fn factor(
        pool: &Blocks,
        design: &[usize],
        prior: Option<&Prior>,
        ridge: &[f64],
        max_condition: f64,
        check_condition: bool,
    ) -> Result<Factored, CriterionError> {
        let p = pool.p();
        let m = Self::information(pool, design, prior, ridge);
        let singular = |m: &[f64]| CriterionError::Singular {
            rank_estimate: equilibrated_rank(view(m, p), max_condition).min(p - 1),
            p,
        };
        let Ok((m_inv, ln_det)) = cholesky_inverse(view(&m, p)) else {
            return Err(singular(&m));
        };
        if check_condition {
            let mut es = EigenScratch::new(p);
            if let Some(ev) = equilibrated_eigenvalues(view(&m, p), &mut Vec::new(), &mut es)
                && !eigenvalues_regular(&ev, max_condition)
            {
                return Err(singular(&m));
            }
        }
        let cond1 = equilibrated_cond1(&m, &m_inv, p);
        Ok(Factored {
            m,
            m_inv,
            ln_det,
            cond1,
        })
    }

    /// `M0 + diag(ridge) + Σ_{i∈design} X_iᵀX_i`, column-major, summed in
    /// design order after the prior.
    fn information(
        pool: &Blocks,
        design: &[usize],
        prior: Option<&Prior>,
        ridge: &[f64],
    ) -> Vec<f64> {
        let p = pool.p();
        let mut m = vec![0.0; p * p];
        if let Some(pr) = prior {
            pr.add_to(&mut m);
        }
        for i in 0..p {
            m[i * p + i] += ridge[i];
        }
        let mut xb = Vec::with_capacity(pool.t() * p);
        for &q in design {
            gather_block(pool.block(q), &mut xb);
            add_gram(&mut m, p, &xb, pool.t(), 1.0);
        }
        m
    }

    fn check_pool(&self, pool: &Blocks) {
        assert!(
            pool.t() == self.t && pool.p() == self.p && pool.n_poses() == self.n_pool,
            "InfoState used with a pool of another shape"
        );
    }

    fn check_in_range(&self, q: usize) -> Result<(), CriterionError> {
        if q >= self.n_pool {
            return Err(CriterionError::PoseOutOfRange {
                pose: q,
                n_poses: self.n_pool,
            });
        }
        Ok(())
    }

    fn check_addable(&self, q: usize) -> Result<(), CriterionError> {
        self.check_in_range(q)?;
        if self.position[q] != NOT_IN_DESIGN {
            return Err(CriterionError::AlreadyInDesign { pose: q });
        }
        Ok(())
    }

    fn check_removable(&self, q: usize) -> Result<(), CriterionError> {
        self.check_in_range(q)?;
        if self.position[q] == NOT_IN_DESIGN {
            return Err(CriterionError::NotInDesign { pose: q });
        }
        Ok(())
    }

    // ---------------------------------------------------------------- access

    /// Identity of this state (fresh for every construction and clone); with
    /// [`version`](Self::version) it keys caches.
    #[must_use]
    pub fn id(&self) -> u64 {
        self.id
    }

    /// Rows per pose.
    #[must_use]
    pub fn t(&self) -> usize {
        self.t
    }

    /// Number of parameters.
    #[must_use]
    pub fn p(&self) -> usize {
        self.p
    }

    /// Number of poses in the pool.
    #[must_use]
    pub fn n_pool(&self) -> usize {
        self.n_pool
    }

    /// Design poses (pool indices) in design order. Additions append,
    /// removals keep the order of the rest, exchanges replace in place.
    #[must_use]
    pub fn design(&self) -> &[usize] {
        &self.design
    }

    /// Position of pool pose `q` in [`design`](Self::design), if there.
    #[must_use]
    pub fn position_of(&self, q: usize) -> Option<usize> {
        self.position
            .get(q)
            .copied()
            .filter(|&k| k != NOT_IN_DESIGN)
    }

    /// Whether pool pose `q` is in the design.
    #[must_use]
    pub fn contains(&self, q: usize) -> bool {
        self.position_of(q).is_some()
    }

    /// The settings.
    #[must_use]
    pub fn settings(&self) -> &StateSettings {
        &self.settings
    }

    /// The prior information `M0`, if any.
    #[must_use]
    pub fn prior(&self) -> Option<&Prior> {
        self.prior.as_ref()
    }

    /// The relative ridge `δ`.
    #[must_use]
    pub fn ridge(&self) -> f64 {
        self.settings.ridge
    }

    /// `r_j`, the ridge's column scales: `M = XᵀX + δ·diag(r_j)` with
    /// `r_j = ‖X_pool[:, j]‖² / n_pool` (`1` for a column that is zero on the
    /// whole pool).
    #[must_use]
    pub fn ridge_scales(&self) -> &[f64] {
        &self.ridge_scale
    }

    /// `M = XᵀX + δR` (exactly symmetric).
    #[must_use]
    pub fn m(&self) -> MatRef<'_, f64> {
        view(&self.m, self.p)
    }

    /// `M⁻¹` (exactly symmetric).
    #[must_use]
    pub fn m_inv(&self) -> MatRef<'_, f64> {
        view(&self.m_inv, self.p)
    }

    /// `ln det M` (the log of the paper's `OI_D` when `δ = 0`).
    #[must_use]
    pub fn ln_det(&self) -> f64 {
        self.ln_det
    }

    /// `κ̂(M̃) = ‖M̃‖₁‖M̃⁻¹‖₁` of the equilibrated `M̃ = D^-½ M D^-½`
    /// (`D = diag M`): an upper bound of its 2-norm condition number, and
    /// unchanged when a column of the pool is scaled.
    #[must_use]
    pub fn condition_estimate(&self) -> f64 {
        self.cond1
    }

    /// Pivot floor of the singularity rule: `κ̂(M̃) / max_condition`.
    #[must_use]
    pub fn pivot_floor(&self) -> f64 {
        self.cond1 / self.settings.max_condition
    }

    /// Updates applied since the last refactorization.
    #[must_use]
    pub fn updates_since_refactor(&self) -> usize {
        self.since_refactor
    }

    /// Counter of changes (updates and refactorizations) since construction.
    #[must_use]
    pub fn version(&self) -> u64 {
        self.version
    }

    /// Counter of refactorizations since construction.
    #[must_use]
    pub fn epoch(&self) -> u64 {
        self.epoch
    }

    /// The low-rank updates applied since the last refactorization (at most
    /// the latest 128), oldest first, and the version before the first of
    /// them: update `k` took the state from version `base + k` to
    /// `base + k + 1`.
    #[must_use]
    pub fn updates_since(&self) -> (u64, &[LowRank]) {
        (self.log_base, &self.log)
    }

    // --------------------------------------------------------------- pricing

    fn low_rank(
        &self,
        pool: &Blocks,
        plus: Option<usize>,
        minus: Option<usize>,
    ) -> Result<LowRank, Status> {
        let empty = pool.mat().subrows(0, 0);
        let z_plus = plus.map_or(empty, |q| pool.block(q));
        let z_minus = minus.map_or(empty, |q| pool.block(q));
        woodbury(self.m_inv(), z_plus, z_minus, self.pivot_floor()).map_err(|s| Status::Singular {
            pivot: s.pivot,
            pivot_floor: s.pivot_floor,
        })
    }

    fn regular(lr: &LowRank) -> Status {
        Status::Regular {
            delta_ln_det: lr.ln_det_ratio(),
            min_pivot: lr.min_pivot(),
        }
    }

    fn status_of(r: &Result<LowRank, Status>) -> Status {
        match r {
            Ok(lr) => Self::regular(lr),
            Err(s) => *s,
        }
    }

    /// Gain of adding pool pose `q`: `ln det(I_t + X_q M⁻¹ X_qᵀ)` (matrix
    /// determinant lemma; the block form of eq. (17)/(20)). Never singular.
    pub fn price_add(&self, pool: &Blocks, q: usize) -> Result<Status, CriterionError> {
        self.check_pool(pool);
        self.check_addable(q)?;
        Ok(Self::status_of(&self.low_rank(pool, Some(q), None)))
    }

    /// Loss of removing design pose `q`: `ln det(I_t − X_q M⁻¹ X_qᵀ)`
    /// (block form of eq. (21)/(22)); [`Status::Singular`] when the result
    /// would be numerically singular.
    pub fn price_remove(&self, pool: &Blocks, q: usize) -> Result<Status, CriterionError> {
        self.check_pool(pool);
        self.check_removable(q)?;
        Ok(Self::status_of(&self.low_rank(pool, None, Some(q))))
    }

    /// Change of `ln det M` when design pose `out` is replaced by pool pose
    /// `inn`, in one step from the `2t×2t` system
    /// `det [[I + S_ii, S_io], [−S_oi, I − S_oo]]`, `S_ab = X_a M⁻¹ X_bᵀ`.
    pub fn price_exchange(
        &self,
        pool: &Blocks,
        out: usize,
        inn: usize,
    ) -> Result<Status, CriterionError> {
        self.check_pool(pool);
        self.check_removable(out)?;
        self.check_addable(inn)?;
        Ok(Self::status_of(&self.low_rank(pool, Some(inn), Some(out))))
    }

    // --------------------------------------------------------------- updates

    /// Applies a computed update: the design list, `M` by adding/subtracting
    /// the Gram blocks, `M⁻¹` by Woodbury, `ln det M` by the determinant
    /// lemma; refactorizes every `refactor_every` updates. An exchange puts
    /// `plus` at the position of `minus`; an addition appends; a removal keeps
    /// the order of the rest.
    fn apply(&mut self, pool: &Blocks, lr: LowRank, plus: Option<usize>, minus: Option<usize>) {
        match (plus, minus) {
            (Some(inn), Some(out)) => {
                let k = self.position[out];
                self.design[k] = inn;
                self.position[out] = NOT_IN_DESIGN;
                self.position[inn] = k;
            }
            (Some(inn), None) => {
                self.position[inn] = self.design.len();
                self.design.push(inn);
            }
            (None, Some(out)) => {
                let k = self.position[out];
                self.design.remove(k);
                self.position[out] = NOT_IN_DESIGN;
                for (j, &d) in self.design.iter().enumerate().skip(k) {
                    self.position[d] = j;
                }
            }
            (None, None) => {}
        }
        let (p, t) = (self.p, self.t);
        for (q, sign) in [(plus, 1.0), (minus, -1.0)] {
            if let Some(q) = q {
                gather_block(pool.block(q), &mut self.block);
                add_gram(&mut self.m, p, &self.block, t, sign);
            }
        }
        lr.apply_to_col_major(&mut self.m_inv);
        self.ln_det += lr.ln_det_ratio();
        self.cond1 = equilibrated_cond1(&self.m, &self.m_inv, p);
        self.version += 1;
        self.log.push(lr);
        // Keep the log short when refactorizations are rare: a consumer more
        // than LOG_KEEP updates behind recomputes anyway (the pending ranks
        // exceed p).
        if self.log.len() >= 2 * LOG_KEEP {
            self.log.drain(..LOG_KEEP);
            self.log_base += LOG_KEEP as u64;
        }
        self.since_refactor += 1;
        if self.since_refactor >= self.settings.refactor_every {
            // A failure here (possible only for a design at the edge of the
            // singularity rule) keeps the updated values, which are finite,
            // and retries after another `refactor_every` updates.
            if self.refactorize(pool).is_err() {
                self.since_refactor = 0;
            }
        }
    }

    fn apply_status(&mut self, pool: &Blocks, plus: Option<usize>, minus: Option<usize>) -> Status {
        match self.low_rank(pool, plus, minus) {
            Ok(lr) => {
                let status = Self::regular(&lr);
                self.apply(pool, lr, plus, minus);
                status
            }
            Err(s) => s,
        }
    }

    /// Adds pool pose `q` to the design (appended). Always regular.
    pub fn add(&mut self, pool: &Blocks, q: usize) -> Result<Status, CriterionError> {
        self.check_pool(pool);
        self.check_addable(q)?;
        Ok(self.apply_status(pool, Some(q), None))
    }

    /// Removes design pose `q`, unless the result would be numerically
    /// singular ([`Status::Singular`]; the state is then unchanged).
    pub fn remove(&mut self, pool: &Blocks, q: usize) -> Result<Status, CriterionError> {
        self.check_pool(pool);
        self.check_removable(q)?;
        Ok(self.apply_status(pool, None, Some(q)))
    }

    /// Replaces design pose `out` by pool pose `inn` (same design position)
    /// in one rank-`2t` update, unless the result would be numerically
    /// singular ([`Status::Singular`]; the state is then unchanged).
    pub fn exchange(
        &mut self,
        pool: &Blocks,
        out: usize,
        inn: usize,
    ) -> Result<Status, CriterionError> {
        self.check_pool(pool);
        self.check_removable(out)?;
        self.check_addable(inn)?;
        Ok(self.apply_status(pool, Some(inn), Some(out)))
    }

    // ------------------------------------------------------------- refactor

    /// Recomputes `M` from the design (plus ridge), refactors it by Cholesky
    /// and recomputes `M⁻¹` and `ln det M`, discarding accumulated rounding.
    /// On [`CriterionError::Singular`] (Cholesky fails) the state is
    /// unchanged.
    pub fn refactorize(&mut self, pool: &Blocks) -> Result<(), CriterionError> {
        self.check_pool(pool);
        let ridge = ridge_diagonal(&self.ridge_scale, self.settings.ridge);
        let f = Self::factor(
            pool,
            &self.design,
            self.prior.as_ref(),
            &ridge,
            self.settings.max_condition,
            false,
        )?;
        self.install(f);
        Ok(())
    }

    fn install(&mut self, f: Factored) {
        self.m = f.m;
        self.m_inv = f.m_inv;
        self.ln_det = f.ln_det;
        self.cond1 = f.cond1;
        self.since_refactor = 0;
        self.version += 1;
        self.epoch += 1;
        self.log_base = self.version;
        self.log.clear();
    }

    /// Sets the relative ridge `δ` (`M = XᵀX + δR`) and refactorizes;
    /// `set_ridge(0)` drops it. On error (invalid `δ`, or [`CriterionError::Singular`]
    /// under the construction rule) the state is unchanged.
    pub fn set_ridge(&mut self, pool: &Blocks, ridge: f64) -> Result<(), CriterionError> {
        self.check_pool(pool);
        let settings = self.settings.with_ridge(ridge);
        settings.validate()?;
        let diag = ridge_diagonal(&self.ridge_scale, ridge);
        let f = Self::factor(
            pool,
            &self.design,
            self.prior.as_ref(),
            &diag,
            settings.max_condition,
            true,
        )?;
        self.settings = settings;
        self.install(f);
        Ok(())
    }

    /// Sets [`StateSettings::refactor_every`].
    pub fn set_refactor_every(&mut self, k: usize) -> Result<(), CriterionError> {
        let settings = self.settings.with_refactor_every(k);
        settings.validate()?;
        self.settings = settings;
        Ok(())
    }

    /// Measures the drift of the maintained `M`, `M⁻¹` and `ln det M` against
    /// a fresh recomputation from the design. Costs a factorization
    /// (`O(p³ + |D|·t·p²)`); for tests and diagnostics.
    #[must_use]
    pub fn drift(&self, pool: &Blocks) -> Drift {
        self.check_pool(pool);
        let p = self.p;
        let ridge = ridge_diagonal(&self.ridge_scale, self.settings.ridge);
        let fresh = Self::information(pool, &self.design, self.prior.as_ref(), &ridge);
        let ln_det = match cholesky_inverse(view(&fresh, p)) {
            Ok((_, ld)) => (ld - self.ln_det).abs(),
            Err(()) => f64::INFINITY,
        };
        let mut inverse: f64 = 0.0;
        for j in 0..p {
            for i in 0..p {
                let s: f64 = (0..p)
                    .map(|k| fresh[k * p + i] * self.m_inv[j * p + k])
                    .sum();
                let e = if i == j { 1.0 } else { 0.0 };
                inverse = inverse.max((s - e).abs());
            }
        }
        let scale = fresh.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let diff = self
            .m
            .iter()
            .zip(&fresh)
            .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
        // `>` and `>=` are equivalent here (mutation sample, issue #30): the
        // fresh `M` of a state is positive definite (construction and every
        // update refuse a singular one), so `scale > 0`.
        let information = diff / if scale > 0.0 { scale } else { 1.0 };
        Drift {
            ln_det,
            inverse,
            information,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::test_util::random_pool;
    use faer::Mat;

    fn direct(pool: &Blocks, design: &[usize]) -> (f64, Mat<f64>) {
        let m = pool.information(design);
        let (inv, ld) = cholesky_inverse(m.as_ref()).unwrap();
        (ld, view(&inv, m.nrows()).to_owned())
    }

    /// The `min_pivot` a price reports (it sets the proptests' tolerance
    /// and the singularity rule) is `+∞` for an addition, and for a removal
    /// lies between `λ_min(B)` and `det(B)^{1/t}` of the Schur complement `B
    /// = I − X_q M⁻¹ X_qᵀ` computed directly: every Cholesky pivot of an SPD
    /// matrix is at least its smallest eigenvalue, and the smallest of `t`
    /// pivots is at most their geometric mean, `det(B)^{1/t}` (< 1 here).
    #[test]
    fn the_reported_min_pivot_is_that_of_the_removal_schur_complement() {
        let pool = random_pool(40, 3, 9, 11);
        let design = [0, 1, 2, 3, 4, 5];
        let st = InfoState::new(&pool, &design, StateSettings::default()).unwrap();
        match st.price_add(&pool, 7).unwrap() {
            Status::Regular { min_pivot, .. } => assert_eq!(min_pivot, f64::INFINITY),
            s => panic!("adding is never singular: {s:?}"),
        }
        let (_, inv) = direct(&pool, &design);
        for q in [0, 2, 5] {
            let x = pool.block(q);
            let b = nalgebra::DMatrix::from_fn(3, 3, |a, c| {
                let mut v = if a == c { 1.0 } else { 0.0 };
                for k in 0..9 {
                    for l in 0..9 {
                        v -= x[(a, k)] * inv[(k, l)] * x[(c, l)];
                    }
                }
                v
            });
            let eig = b.clone().symmetric_eigenvalues();
            let lmin = eig.iter().copied().fold(f64::INFINITY, f64::min);
            let geo = b.determinant().powf(1.0 / 3.0);
            assert!(
                lmin > 0.0 && geo < 1.0 - 1e-6,
                "pose {q}: λ_min {lmin}, det^(1/3) {geo}"
            );
            match st.price_remove(&pool, q).unwrap() {
                Status::Regular { min_pivot, .. } => assert!(
                    min_pivot >= lmin * (1.0 - 1e-9) && min_pivot <= geo * (1.0 + 1e-9),
                    "pose {q}: pivot {min_pivot} outside [{lmin}, {geo}]"
                ),
                s => panic!("pose {q} is removable: {s:?}"),
            }
        }
    }

    #[test]
    fn updates_match_direct() {
        let pool = random_pool(40, 3, 9, 11);
        let mut st = InfoState::new(&pool, &[0, 1, 2, 3, 4], StateSettings::default()).unwrap();
        let g = st.price_add(&pool, 7).unwrap().delta().unwrap();
        assert!(st.add(&pool, 7).unwrap().is_regular());
        let (ld, inv) = direct(&pool, &[0, 1, 2, 3, 4, 7]);
        assert!((st.ln_det() - ld).abs() < 1e-10);
        assert!((st.m_inv() - &inv).norm_max() < 1e-10 * inv.norm_max());
        let (ld0, _) = direct(&pool, &[0, 1, 2, 3, 4]);
        assert!((ld0 + g - ld).abs() < 1e-10);
        assert!(st.exchange(&pool, 2, 20).unwrap().is_regular());
        assert_eq!(st.design(), &[0, 1, 20, 3, 4, 7]);
        assert!(st.remove(&pool, 1).unwrap().is_regular());
        assert_eq!(st.design(), &[0, 20, 3, 4, 7]);
        assert_eq!(st.position_of(7), Some(4));
        let (ld, inv) = direct(&pool, &[0, 20, 3, 4, 7]);
        assert!((st.ln_det() - ld).abs() < 1e-10);
        assert!((st.m_inv() - &inv).norm_max() < 1e-10 * inv.norm_max());
    }

    #[test]
    fn bad_input_and_singular() {
        let pool = random_pool(10, 3, 9, 5);
        let s = StateSettings::default();
        assert!(matches!(
            InfoState::new(&pool, &[0, 10], s),
            Err(CriterionError::PoseOutOfRange { pose: 10, .. })
        ));
        assert!(matches!(
            InfoState::new(&pool, &[1, 1, 2], s),
            Err(CriterionError::DuplicatePose { pose: 1 })
        ));
        // Two poses: 6 rows for 9 parameters.
        assert_eq!(
            InfoState::new(&pool, &[0, 1], s).unwrap_err(),
            CriterionError::Singular {
                rank_estimate: 6,
                p: 9
            }
        );
        // With a ridge it works, and dropping the ridge is refused.
        let mut st = InfoState::new(&pool, &[0, 1], s.with_ridge(1e-3)).unwrap();
        assert!(matches!(
            st.set_ridge(&pool, 0.0),
            Err(CriterionError::Singular { .. })
        ));
        assert_eq!(st.ridge(), 1e-3);
        st.add(&pool, 2).unwrap().delta().unwrap();
        st.set_ridge(&pool, 0.0).unwrap();
        // Exactly 9 rows: removing any pose is singular, state unchanged.
        let before = st.ln_det();
        let r = st.remove(&pool, 1).unwrap();
        assert!(!r.is_regular(), "{r:?}");
        assert_eq!(st.ln_det(), before);
        assert_eq!(st.design(), &[0, 1, 2]);
        assert!(matches!(
            st.remove(&pool, 5),
            Err(CriterionError::NotInDesign { pose: 5 })
        ));
        assert!(matches!(
            st.add(&pool, 0),
            Err(CriterionError::AlreadyInDesign { pose: 0 })
        ));
        assert!(
            StateSettings::default()
                .with_ridge(f64::NAN)
                .validate()
                .is_err()
        );
    }

    #[test]
    fn refactorizes_periodically_and_drift_is_small() {
        let pool = random_pool(60, 3, 12, 2);
        let design: Vec<usize> = (0..10).collect();
        let mut st = InfoState::new(
            &pool,
            &design,
            StateSettings::default().with_refactor_every(8),
        )
        .unwrap();
        let mut next = 10;
        for k in 0..100 {
            let out = st.design()[k % st.design().len()];
            if st.exchange(&pool, out, next).unwrap().is_regular() {
                next = out;
            }
            assert!(st.updates_since_refactor() < 8);
        }
        assert!(st.epoch() >= 12);
        let d = st.drift(&pool);
        assert!(
            d.ln_det < 1e-10 && d.inverse < 1e-10 && d.information < 1e-14,
            "{d:?}"
        );
    }

    /// Issue #30's mutation sample: a ridge must be finite and `≥ 0` (a
    /// negative or infinite one is refused, as NaN is).
    #[test]
    fn a_negative_or_infinite_ridge_is_refused() {
        let s = StateSettings::default();
        for r in [-1e-3, f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            assert!(s.with_ridge(r).validate().is_err(), "ridge {r}");
        }
        assert!(s.with_ridge(0.0).validate().is_ok());
    }

    /// Every construction and every clone has its own id: caches keyed on
    /// `(id, version)` must never confuse two states.
    #[test]
    fn every_state_and_clone_has_its_own_id() {
        let pool = random_pool(12, 3, 4, 3);
        let s = StateSettings::default();
        let a = InfoState::new(&pool, &[0, 1, 2], s).unwrap();
        let b = InfoState::new(&pool, &[0, 1, 2], s).unwrap();
        let c = a.clone();
        assert!(
            a.id() != b.id() && a.id() != c.id() && b.id() != c.id(),
            "{} {} {}",
            a.id(),
            b.id(),
            c.id()
        );
    }

    /// `r_j = ‖X_pool[:, j]‖² / n_pool`, and `1` for a column that is zero
    /// on the whole pool. The scales are sums of 30 squares of numbers of
    /// order 1: a relative tolerance of 1e-14 covers their rounding.
    #[test]
    fn ridge_scales_are_the_mean_column_information() {
        let base = random_pool(10, 3, 4, 9);
        let mat = Mat::from_fn(30, 5, |r, c| if c == 4 { 0.0 } else { base.mat()[(r, c)] });
        let pool = Blocks::new(mat, 3);
        let s = StateSettings::default().with_ridge(1e-2);
        let st = InfoState::new(&pool, &[0, 1, 2, 3], s).unwrap();
        for c in 0..4 {
            let want: f64 = (0..30).map(|r| pool.mat()[(r, c)].powi(2)).sum::<f64>() / 10.0;
            let got = st.ridge_scales()[c];
            assert!(
                (got - want).abs() <= 1e-14 * want,
                "column {c}: {got} vs {want}"
            );
        }
        assert_eq!(st.ridge_scales()[4], 1.0);
    }

    /// A prior adds its information: `ln det M = ln det(M0 + X_DᵀX_D)`
    /// (both sides Cholesky of the same well-conditioned 6×6 sum, so 1e-10
    /// is generous); a prior of another `p` than the pool's is refused.
    #[test]
    fn a_prior_adds_its_information_and_must_match_the_pool() {
        let pool = random_pool(20, 3, 6, 4);
        let s = StateSettings::default();
        let prior = Prior::from_blocks(&random_pool(3, 3, 6, 8)).unwrap();
        let st = InfoState::with_prior(&pool, &[0, 1], Some(prior.clone()), s).unwrap();
        let m = prior.matrix().to_owned() + pool.information(&[0, 1]);
        let (_, want) = cholesky_inverse(m.as_ref()).unwrap();
        assert!(
            (st.ln_det() - want).abs() < 1e-10,
            "{} vs {want}",
            st.ln_det()
        );
        let wrong = Prior::from_blocks(&random_pool(3, 3, 5, 8)).unwrap();
        assert!(matches!(
            InfoState::with_prior(&pool, &[0, 1, 2], Some(wrong), s),
            Err(CriterionError::UnsupportedShape { .. })
        ));
    }

    /// `condition_estimate` bounds the 2-norm condition number `κ₂(M̃)` of
    /// the equilibrated `M̃ = D^-½ M D^-½` from above, by at most a factor
    /// `p` (`‖A‖₁ ≤ √p ‖A‖₂` for each factor), computed here from
    /// nalgebra's eigenvalues of `M̃` (relative error ~1e-15·κ, so 1e-9 of
    /// slack), after construction and after an update.
    #[test]
    fn condition_estimate_bounds_the_equilibrated_condition_number() {
        let pool = random_pool(30, 3, 6, 17);
        let mut st = InfoState::new(&pool, &[0, 1, 2, 3], StateSettings::default()).unwrap();
        for step in 0..2 {
            let m = st.m();
            let p = m.nrows();
            let a =
                nalgebra::DMatrix::from_fn(p, p, |i, j| m[(i, j)] / (m[(i, i)] * m[(j, j)]).sqrt());
            let ev = a.symmetric_eigenvalues();
            let (lo, hi) = ev
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
            let k2 = hi / lo;
            let est = st.condition_estimate();
            assert!(
                k2 > 2.0,
                "a random design is not that well conditioned: {k2}"
            );
            assert!(
                est >= k2 * (1.0 - 1e-9) && est <= p as f64 * k2 * (1.0 + 1e-9),
                "step {step}: estimate {est}, κ₂ {k2}"
            );
            st.add(&pool, 10 + step).unwrap().delta().unwrap();
        }
    }

    /// Without refactorizations the update log keeps between `LOG_KEEP`
    /// and `2·LOG_KEEP` entries: 127 updates are all there, the 128th
    /// drops the oldest 64 and moves the base to 64.
    #[test]
    fn the_update_log_is_trimmed_at_twice_log_keep() {
        let pool = random_pool(12, 3, 4, 21);
        let s = StateSettings::default().with_refactor_every(10_000);
        let mut st = InfoState::new(&pool, &[0, 1, 2, 3], s).unwrap();
        for k in 0..2 * LOG_KEEP {
            if k % 2 == 0 {
                st.add(&pool, 5).unwrap().delta().unwrap();
            } else {
                st.remove(&pool, 5).unwrap().delta().unwrap();
            }
            let (base, log) = st.updates_since();
            if k + 1 < 2 * LOG_KEEP {
                assert_eq!((base, log.len()), (0, k + 1), "after {} updates", k + 1);
            } else {
                assert_eq!((base, log.len()), (LOG_KEEP as u64, LOG_KEEP));
            }
        }
    }

    /// `drift`'s information error is relative to `max |M|`: scaling the
    /// pool by 2^10 (exact in binary) scales `M` by 2^20 and every rounding
    /// with it, so the figure is the same to the bit — and nonzero after
    /// 32 updates without a refactorization.
    #[test]
    fn the_information_drift_is_relative_to_the_information() {
        let base = random_pool(12, 3, 4, 5);
        let drift_of = |scale: f64| {
            let pool = Blocks::new(Mat::from_fn(36, 4, |r, c| scale * base.mat()[(r, c)]), 3);
            let s = StateSettings::default().with_refactor_every(1000);
            let mut st = InfoState::new(&pool, &[0, 1, 2, 3], s).unwrap();
            for q in 4..12 {
                st.add(&pool, q).unwrap().delta().unwrap();
            }
            for q in 4..12 {
                st.remove(&pool, q).unwrap().delta().unwrap();
            }
            for q in (4..12).rev() {
                st.add(&pool, q).unwrap().delta().unwrap();
            }
            for q in 4..12 {
                st.remove(&pool, q).unwrap().delta().unwrap();
            }
            st.drift(&pool).information
        };
        let (a, b) = (drift_of(1.0), drift_of(1024.0));
        assert!(a > 0.0 && a < 1e-13, "{a}");
        assert_eq!(a, b);
    }

    /// A pool with no unknowns is refused by name, and `settings` reports
    /// the settings the state was built with.
    #[test]
    fn no_unknowns_is_refused_and_settings_are_kept() {
        let empty = Blocks::new(Mat::zeros(6, 0), 3);
        assert!(matches!(
            InfoState::new(&empty, &[0, 1], StateSettings::default()),
            Err(CriterionError::UnsupportedShape { .. })
        ));
        let pool = random_pool(12, 3, 4, 3);
        let s = StateSettings::default()
            .with_ridge(1e-3)
            .with_refactor_every(7)
            .with_max_condition(1e10);
        let st = InfoState::new(&pool, &[0, 1, 2], s).unwrap();
        assert_eq!(*st.settings(), s);
    }
}
