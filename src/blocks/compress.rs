//! Blocks with no more rows a pose than the pose's information has rank.
//!
//! Every criterion, bound and prediction of the project depends on a pose's
//! rows only through its information `XᵢᵀXᵢ`. A camera's `2N` pixel rows
//! (`N` target points seen) depend on the unknowns only through the
//! target's 6-DOF placement in the camera, so `XᵢᵀXᵢ` has rank at most 6
//! however many points are seen; 96 rows a pose then cost the selection and
//! the bound 16 times what 6 rows do. [`Blocks::compressed`] replaces each
//! block by `r` rows with the same information, `r` the block's numerical
//! rank: with `X̃ᵢ = Xᵢ S⁻¹` (`S` the block's column norms, so units cannot
//! change the rank) and its thin SVD `X̃ᵢ = U Σ Vᵀ`, the rows `Σ_r V_rᵀ S`
//! give `(Σ_r V_rᵀ S)ᵀ(Σ_r V_rᵀ S) = S V_r Σ_r² V_rᵀ S = XᵢᵀXᵢ` up to the
//! dropped singular values.

use super::Blocks;
use faer::Mat;
use rayon::prelude::*;

/// The largest `σ_max² / σ²` of a kept singular value of a column-scaled
/// block: `1e20`, i.e. `σ / σ_max > 1e-10`. The singular values a block's
/// structure makes zero come out of the SVD at `≈ ε · σ_max ≈ 1e-16 σ_max`,
/// six orders below the cut, and a kept direction with `σ / σ_max` just
/// above it adds `1e-20` relative to the pose's largest information, below
/// the `1e-13` at which [`crate::linalg::rank::MAX_CONDITION`] judges a
/// whole design: what is dropped cannot change any decision.
pub const COMPRESS_MAX_CONDITION: f64 = 1e20;

impl Blocks {
    /// The same poses with each block replaced by rows of the same
    /// information `XᵢᵀXᵢ` (to the dropped singular values, see the module
    /// docs), as many a pose as the largest block rank; a pose of lower
    /// rank is padded with zero rows. Returns `self`'s copy when no pose
    /// has fewer rows than rank (`t ≤` every rank), and the largest rank.
    #[must_use]
    pub fn compressed(&self) -> (Blocks, usize) {
        let (t, p, n) = (self.t(), self.p(), self.n_poses());
        let reduced: Vec<Mat<f64>> = (0..n)
            .into_par_iter()
            .map(|i| reduce_block(self.block(i)))
            .collect();
        let rank = reduced.iter().map(Mat::nrows).max().unwrap_or(0).max(1);
        if rank >= t {
            return (self.clone(), t);
        }
        let mut mat = Mat::<f64>::zeros(n * rank, p);
        for (i, r) in reduced.iter().enumerate() {
            for k in 0..r.nrows() {
                for c in 0..p {
                    mat[(i * rank + k, c)] = r[(k, c)];
                }
            }
        }
        (Blocks::new(mat, rank), rank)
    }
}

/// Poses [`Blocks::sample_rank`] looks at, evenly spaced over the pool.
const RANK_SAMPLE: usize = 256;

impl Blocks {
    /// The largest rank of a pose's information `XᵢᵀXᵢ` (under
    /// [`COMPRESS_MAX_CONDITION`], column-scaled) over up to 256 poses
    /// evenly spaced over the blocks: how many independent rows one pose
    /// gives, the `r` of the fewest poses `⌈p / r⌉` that can determine `p`
    /// unknowns. 0 for no pose.
    #[must_use]
    pub fn sample_rank(&self) -> usize {
        let n = self.n_poses();
        let step = n.div_ceil(RANK_SAMPLE).max(1);
        (0..n)
            .step_by(step)
            .collect::<Vec<_>>()
            .par_iter()
            .map(|&i| reduce_block(self.block(i)).nrows())
            .max()
            .unwrap_or(0)
    }
}

/// `Σ_r V_rᵀ S` of one block (see the module docs): `r × p`, `r` its rank
/// under [`COMPRESS_MAX_CONDITION`]; 0 rows for a zero block.
fn reduce_block(b: faer::MatRef<'_, f64>) -> Mat<f64> {
    let (t, p) = (b.nrows(), b.ncols());
    let s: Vec<f64> = (0..p)
        .map(|c| {
            let n = (0..t).map(|r| b[(r, c)] * b[(r, c)]).sum::<f64>().sqrt();
            if n > 0.0 && n.is_finite() { n } else { 1.0 }
        })
        .collect();
    let scaled = Mat::from_fn(t, p, |r, c| b[(r, c)] / s[c]);
    let Ok(svd) = scaled.thin_svd() else {
        // The SVD did not converge: keep the block as it is (its
        // information is then exact, only not compressed).
        return b.to_owned();
    };
    let sv: Vec<f64> = (0..svd.S().dim()).map(|k| svd.S()[k]).collect();
    let top = sv.iter().copied().fold(0.0, f64::max);
    if !(top > 0.0) {
        return Mat::zeros(0, p);
    }
    let kept: Vec<usize> = (0..sv.len())
        .filter(|&k| sv[k] * sv[k] * COMPRESS_MAX_CONDITION > top * top)
        .collect();
    let v = svd.V();
    Mat::from_fn(kept.len(), p, |r, c| sv[kept[r]] * v[(c, kept[r])] * s[c])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block of rank 2 with 5 rows and columns of very different scales
    /// (1e6 apart, as metres against a sensor far away) compresses to 2
    /// rows of the same information, to rounding (`1e-12` relative to the
    /// largest entry: the SVD's backward error is `≈ p·ε`).
    #[test]
    fn a_block_compresses_to_its_rank_with_the_same_information() {
        let (t, p) = (5, 4);
        let a = Mat::from_fn(t, 2, |r, c| {
            ((r * 7 + c * 3) % 5) as f64 - 2.0 + 0.1 * c as f64
        });
        let w = Mat::from_fn(2, p, |r, c| ((r + 2 * c) % 3) as f64 + 0.5);
        let scale = [1.0, 1e6, 1e-3, 1.0];
        let x = Mat::from_fn(t, p, |r, c| {
            (0..2).map(|k| a[(r, k)] * w[(k, c)]).sum::<f64>() * scale[c]
        });
        let full = Mat::from_fn(2 * t, p, |r, c| {
            if r < t {
                x[(r, c)]
            } else {
                2.0 * x[(r - t, c)]
            }
        });
        let blocks = Blocks::new(full, t);
        let (c, rank) = blocks.compressed();
        assert_eq!(rank, 2);
        assert_eq!((c.t(), blocks.sample_rank()), (2, 2));
        for i in 0..2 {
            let (m0, m1) = (blocks.information(&[i]), c.information(&[i]));
            for r in 0..p {
                for k in 0..p {
                    let tol = 1e-12 * (m0[(r, r)] * m0[(k, k)]).sqrt();
                    assert!(
                        (m0[(r, k)] - m1[(r, k)]).abs() <= tol,
                        "{i} {r} {k}: {} {}",
                        m0[(r, k)],
                        m1[(r, k)]
                    );
                }
            }
        }
    }

    /// Blocks of full rank are returned as they are.
    #[test]
    fn full_rank_blocks_are_kept() {
        let x = Mat::from_fn(6, 3, |r, c| {
            if r % 3 == c {
                1.0 + r as f64
            } else {
                0.1 * (r + c) as f64
            }
        });
        let b = Blocks::new(x, 3);
        let (c, rank) = b.compressed();
        assert_eq!((rank, c.t(), c.n_poses()), (3, 3, 2));
        assert_eq!(c.mat(), b.mat());
    }
}
