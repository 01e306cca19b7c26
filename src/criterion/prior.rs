//! Prior information: `M0 = Σ XᵢᵀXᵢ` of poses measured before a selection,
//! which every design then adds to (`M = M0 + XᵀX`). Selection maximises
//! `ln det(M0 + Σ new)`; the bound relaxes the same objective.

use std::sync::Arc;

use faer::{Mat, MatRef};

use super::CriterionError;
use crate::blocks::Blocks;

/// The information of poses already measured, `M0` (`p × p`, symmetric
/// positive semidefinite). Cheap to clone (shared).
#[derive(Clone, Debug)]
pub struct Prior {
    m0: Arc<Mat<f64>>,
    poses: usize,
}

impl PartialEq for Prior {
    fn eq(&self, other: &Self) -> bool {
        self.poses == other.poses && *self.m0 == *other.m0
    }
}

impl Prior {
    /// `M0 = Σ XᵢᵀXᵢ` over every pose of `x` (the identification Jacobian of
    /// the poses already measured, at the parameters the pool's Jacobian
    /// uses). Errors on a non-finite entry.
    pub fn from_blocks(x: &Blocks) -> Result<Self, CriterionError> {
        let m = x.mat();
        for c in 0..m.ncols() {
            for r in 0..m.nrows() {
                if !m[(r, c)].is_finite() {
                    return Err(CriterionError::NonFinite {
                        row: r,
                        col: c,
                        value: m[(r, c)],
                    });
                }
            }
        }
        let all: Vec<usize> = (0..x.n_poses()).collect();
        Ok(Self {
            m0: Arc::new(x.information(&all)),
            poses: x.n_poses(),
        })
    }

    /// A prior given as a matrix (symmetrised as `(M + Mᵀ)/2`). Errors on a
    /// non-square or non-finite matrix. `poses` is informational.
    pub fn from_matrix(m: MatRef<'_, f64>, poses: usize) -> Result<Self, CriterionError> {
        if m.nrows() != m.ncols() || m.nrows() == 0 {
            return Err(CriterionError::UnsupportedShape {
                reason: format!("a prior must be square, got {}×{}", m.nrows(), m.ncols()),
            });
        }
        for c in 0..m.ncols() {
            for r in 0..m.nrows() {
                if !m[(r, c)].is_finite() {
                    return Err(CriterionError::NonFinite {
                        row: r,
                        col: c,
                        value: m[(r, c)],
                    });
                }
            }
        }
        let sym = Mat::from_fn(m.nrows(), m.ncols(), |r, c| 0.5 * (m[(r, c)] + m[(c, r)]));
        Ok(Self {
            m0: Arc::new(sym),
            poses,
        })
    }

    /// `M0`.
    #[must_use]
    pub fn matrix(&self) -> MatRef<'_, f64> {
        (*self.m0).as_ref()
    }

    /// Number of parameters (`M0` is `p × p`).
    #[must_use]
    pub fn p(&self) -> usize {
        self.m0.nrows()
    }

    /// Poses the prior was made of.
    #[must_use]
    pub fn poses(&self) -> usize {
        self.poses
    }

    /// `ln det M0` on equilibrated columns, or `None` when `M0` is singular
    /// (fewer rows than unknowns, or unidentifiable directions).
    #[must_use]
    pub fn ln_det(&self) -> Option<f64> {
        crate::linalg::chol::ln_det_spd_equilibrated(self.matrix())
    }

    /// Adds `M0` to a `p × p` column-major matrix.
    pub(crate) fn add_to(&self, m: &mut [f64]) {
        let p = self.p();
        for c in 0..p {
            for r in 0..p {
                m[c * p + r] += self.m0[(r, c)];
            }
        }
    }
}
