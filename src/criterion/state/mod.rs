//! The information state of a design over a pose pool: `M = XᵀX (+ δR)`,
//! `M⁻¹`, `ln det M`, updated by the paper's formulas (eq. (4)–(22)) in
//! block form.

use std::sync::atomic::{AtomicU64, Ordering};

mod accessors;
mod settings;

pub use settings::{Drift, StateSettings, Status};

use super::CriterionError;
use super::lowrank::{LowRank, woodbury};
use super::prior::Prior;
use crate::blocks::Blocks;
use crate::linalg::chol::cholesky_inverse;
use crate::linalg::eigen::EigenScratch;
use crate::linalg::gram::{add_gram, gather_block, view};
use crate::linalg::rank::{
    eigenvalues_regular, equilibrated_cond1, equilibrated_eigenvalues, equilibrated_rank,
};

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
        let mut settings = self.settings;
        settings.ridge = ridge;
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
        let mut settings = self.settings;
        settings.refactor_every = k;
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
mod tests;
