//! Variance components: each residual block's σ estimated from its own
//! residuals, so that blocks measured with different noise (a tracker's
//! positions and its orientations, each marker of a motion-capture body)
//! are weighted by what the data say of them, not by a fixed scale.
//!
//! A sensor's rows fall into blocks by their [`RowKind`]: the position rows
//! of each measured point (one block, or one per marker) and the
//! orientation rows. At a fit, block `b` with residuals `r_b` (unweighted:
//! metres, radians) has the estimate (Förstner's variance-component
//! estimation)
//!
//! `σ_b² = r_bᵀ r_b / ρ_b`,  `ρ_b = n_b − Σ_{i∈b} h_ii`,
//!
//! where `h_ii = x_iᵀ (XᵀX)⁻¹ x_i` are the diagonal entries of the hat
//! matrix of the weighted Jacobian `X`: `ρ_b` is the block's share of the
//! residual degrees of freedom (`Σ_b ρ_b = rows − p`). Reweighting with `w_b
//! ∝ 1/σ_b` and refitting until the σ's settle gives the weights the data's
//! own noise implies ([`crate::identify::fit::fit_weighted`]).

use super::{Calibration, Identification, Residuals, Result};
use crate::data::Measurements;
use crate::measure::RowKind;
use crate::model::{ParamTable, Robot};
use crate::names::phrase;
use nalgebra::DMatrix;
use serde::Serialize;

/// One residual block's estimated noise.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BlockSigma {
    /// The block: `position`, `marker K`, `orientation` or `pixels`.
    pub block: String,
    /// Its rows over all poses.
    pub rows: usize,
    /// Its redundancy `ρ_b` (degrees of freedom of its σ).
    pub redundancy: f64,
    /// The estimated σ per coordinate, in the block's unit.
    pub sigma: f64,
    /// The unit of `sigma`: `m`, `rad` or `px`.
    pub unit: &'static str,
}

/// The block of each of a sensor's rows per pose and the blocks' names
/// (positions grouped by point: one block for one point, one per marker).
#[must_use]
pub fn row_blocks(kinds: &[RowKind], points: usize) -> (Vec<usize>, Vec<(String, &'static str)>) {
    let mut blocks: Vec<(String, &'static str)> = Vec::new();
    let mut of_row = Vec::with_capacity(kinds.len());
    let mut position = 0;
    for kind in kinds {
        let name = match kind {
            RowKind::Position => {
                let k = position / 3;
                position += 1;
                (
                    if points > 1 {
                        format!("marker {}", k + 1)
                    } else {
                        "position".into()
                    },
                    "m",
                )
            }
            RowKind::Orientation => ("orientation".to_string(), "rad"),
            RowKind::Pixel => ("pixels".to_string(), "px"),
        };
        let b = match blocks.iter().position(|n| n.0 == name.0) {
            Some(b) => b,
            None => {
                blocks.push(name);
                blocks.len() - 1
            }
        };
        of_row.push(b);
    }
    (of_row, blocks)
}

/// Each residual block's σ at the fit `id` of `robot` to `meas` from
/// `start` (see the module documentation). A block without redundancy
/// (every row fitted exactly by the parameters) has σ `NaN`. With a robust
/// loss, `pose_weights` are its weights `w_i` (empty: all 1): each pose's
/// rows count `w_i` times in the sums, its residuals and Jacobian rows by
/// `√w_i` in the hat matrix, so that a pose the loss sets aside does not
/// inflate the σ the fit's σ̂ is computed without.
pub fn block_sigmas(
    robot: &Robot,
    start: &ParamTable,
    meas: &Measurements,
    id: &Identification,
    pose_weights: &[f64],
) -> Result<Vec<BlockSigma>> {
    let mut cal = Calibration::new(robot, start, meas)?;
    let (t, n) = (cal.block_rows(), cal.n_params());
    let kinds = cal.sensor().row_kinds().to_vec();
    let weights = cal.sensor().weights().to_vec();
    let (of_row, names) = row_blocks(&kinds, cal.sensor().points_per_pose());
    let m = cal.n_residuals();
    let mut r = vec![0.0; m];
    let mut jac = faer::Mat::<f64>::zeros(m, n);
    cal.eval(&id.estimate, &mut r, Some(&mut jac));
    let w = |i: usize| pose_weights.get(i / t.max(1)).copied().unwrap_or(1.0);
    for i in 0..(t * meas.len()).min(m) {
        let s = w(i).sqrt();
        for j in 0..n {
            jac[(i, j)] *= s;
        }
    }
    let hat = hat_diagonal(&jac);
    let mut sum = vec![(0usize, 0.0f64, 0.0f64, 0.0f64); names.len()];
    for i in 0..(t * meas.len()).min(m) {
        let c = i % t;
        let b = of_row[c];
        let unweighted = r[i] / weights[c];
        sum[b].0 += 1;
        sum[b].1 += w(i);
        sum[b].2 += w(i) * unweighted * unweighted;
        sum[b].3 += hat.get(i).copied().unwrap_or(f64::NAN);
    }
    Ok(names
        .into_iter()
        .zip(sum)
        .map(|((block, unit), (rows, counted, ss, h))| {
            let redundancy = counted - h;
            BlockSigma {
                block,
                rows,
                redundancy,
                sigma: if redundancy > 1e-9 {
                    (ss / redundancy).sqrt()
                } else {
                    f64::NAN
                },
                unit,
            }
        })
        .collect())
}

/// σ̂ of a fit tested against the sensor's stated σ: `f σ̂² / σ² ~ χ²(f)`
/// when the stated σ is right, the model complete and the data free of
/// gross errors.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NoiseTest {
    /// The stated σ per coordinate (metres).
    pub stated_m: f64,
    /// The fit's σ̂ per coordinate (metres).
    pub estimated_m: f64,
    /// `σ̂ / σ`.
    pub ratio: f64,
    /// Residual degrees of freedom `f`.
    pub dof: usize,
    /// `P(χ²(f) ≥ f σ̂²/σ²)`: small when σ̂ is too large.
    pub p_larger: f64,
    /// `P(χ²(f) ≤ f σ̂²/σ²)`: small when σ̂ is too small.
    pub p_smaller: f64,
    /// Whether the test rejects the stated σ at [`NOISE_TEST_ALPHA`] (two
    /// sided).
    pub rejected: bool,
}

/// The two-sided rate at which [`NoiseTest`] rejects a stated σ that is
/// right: 1 in 1,000 (a warning, not a verdict, so it errs on silence).
pub const NOISE_TEST_ALPHA: f64 = 1e-3;

impl NoiseTest {
    /// The test of `sigma_hat` on `dof` degrees of freedom against `stated`
    /// (both metres); `None` without degrees of freedom or a σ.
    #[must_use]
    pub fn new(stated: f64, sigma_hat: f64, dof: usize) -> Option<NoiseTest> {
        if dof == 0 || !(stated > 0.0) || !sigma_hat.is_finite() {
            return None;
        }
        let ratio = sigma_hat / stated;
        let x = dof as f64 * ratio * ratio;
        let p_larger = crate::stats::chi2_upper_tail(x, dof as f64);
        let p_smaller = crate::stats::chi2_cdf(x, dof as f64);
        Some(NoiseTest {
            stated_m: stated,
            estimated_m: sigma_hat,
            ratio,
            dof,
            p_larger,
            p_smaller,
            rejected: p_larger.min(p_smaller) < 0.5 * NOISE_TEST_ALPHA,
        })
    }

    /// The warning a rejected test gives, naming the likely causes; `None`
    /// when the stated σ stands.
    #[must_use]
    pub fn warning(&self) -> Option<String> {
        if !self.rejected {
            return None;
        }
        let head = format!(
            "the residuals' σ̂ {:.4} mm per coordinate is {:.2}× the stated noise {:.4} mm (χ² test on {} degrees of freedom, P = {:.1e})",
            self.estimated_m * 1e3,
            self.ratio,
            self.stated_m * 1e3,
            self.dof,
            self.p_larger.min(self.p_smaller)
        );
        Some(if self.ratio > 1.0 {
            format!(
                "{head}: the sensor is noisier than stated, a gross error is left in the data ({}), or the model misses something (joint sag under gravity: {}; a flexing tool or mount); the σ's and the predicted error use σ̂",
                phrase::OUTLIER_SCREEN,
                phrase::COMPLIANCE
            )
        } else {
            format!(
                "{head}: the sensor is better than stated, or the data were averaged or smoothed; the σ's and the predicted error use σ̂"
            )
        })
    }
}

/// What a stated noise other than a position's is of: the words and the
/// unit of its warning.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum NoiseOf {
    /// A tracker's orientations (radians; printed in degrees).
    Orientation,
    /// A camera's detected points (pixels).
    Pixels,
}

/// σ̂ of a block other than positions tested against the sensor's stated
/// σ, as [`NoiseTest`] (the same χ² test), in the block's own unit.
#[derive(Clone, Debug, Serialize)]
pub struct BlockNoiseTest {
    /// The block.
    pub of: NoiseOf,
    /// The unit of `stated` and `estimated`: `rad` or `px`.
    pub unit: &'static str,
    /// The stated σ per coordinate.
    pub stated: f64,
    /// σ̂ per coordinate.
    pub estimated: f64,
    /// `σ̂ / σ`.
    pub ratio: f64,
    /// Degrees of freedom of σ̂.
    pub dof: usize,
    /// `P(χ²(f) ≥ f σ̂²/σ²)`: small when σ̂ is too large.
    pub p_larger: f64,
    /// `P(χ²(f) ≤ f σ̂²/σ²)`: small when σ̂ is too small.
    pub p_smaller: f64,
    /// Whether the test rejects the stated σ at [`NOISE_TEST_ALPHA`].
    pub rejected: bool,
}

impl BlockNoiseTest {
    /// The test of `sigma_hat` on `dof` degrees of freedom against `stated`
    /// (both in `of`'s unit: radians, pixels); `None` without degrees of
    /// freedom or a σ.
    #[must_use]
    pub fn new(of: NoiseOf, stated: f64, sigma_hat: f64, dof: usize) -> Option<Self> {
        let t = NoiseTest::new(stated, sigma_hat, dof)?;
        Some(Self {
            of,
            unit: match of {
                NoiseOf::Orientation => "rad",
                NoiseOf::Pixels => "px",
            },
            stated,
            estimated: sigma_hat,
            ratio: t.ratio,
            dof,
            p_larger: t.p_larger,
            p_smaller: t.p_smaller,
            rejected: t.rejected,
        })
    }

    /// The warning a rejected test gives, naming the likely causes; `None`
    /// when the stated σ stands.
    #[must_use]
    pub fn warning(&self) -> Option<String> {
        if !self.rejected {
            return None;
        }
        let (what, value, stated, per, worse) = match self.of {
            NoiseOf::Orientation => (
                "the orientations' σ̂",
                format!("{:.4}°", self.estimated.to_degrees()),
                format!("{:.4}°", self.stated.to_degrees()),
                "axis",
                format!(
                    "the tracker's orientations are noisier than stated, a gross error is left in the data ({}), or the model misses something (joint sag under gravity: {}; a flexing tool or mount)",
                    phrase::OUTLIER_SCREEN,
                    phrase::COMPLIANCE
                ),
            ),
            NoiseOf::Pixels => (
                "the pixels' σ̂",
                format!("{:.3} px", self.estimated),
                format!("{:.3} px", self.stated),
                "coordinate",
                format!(
                    "the detector is noisier than stated, a gross error is left in the pixels ({}), the intrinsics are off ({}), or the model misses something (joint sag under gravity; a flexing mount)",
                    phrase::OUTLIER_SCREEN,
                    phrase::REFINE_INTRINSICS
                ),
            ),
        };
        let head = format!(
            "{what} {value} per {per} is {:.2}× the stated noise {stated} (χ² test on {} degrees of freedom, P = {:.1e})",
            self.ratio,
            self.dof,
            self.p_larger.min(self.p_smaller)
        );
        Some(if self.ratio > 1.0 {
            format!("{head}: {worse}; the σ's and the predicted error use σ̂")
        } else {
            format!(
                "{head}: the sensor is better than stated, or the data were averaged or smoothed; the σ's and the predicted error use σ̂"
            )
        })
    }
}

/// The orientation block's σ among `blocks` (full poses) tested against
/// the `stated` orientation noise (radians), when one was given; its
/// degrees of freedom the block's redundancy, rounded.
#[must_use]
pub fn orientation_test(stated: Option<f64>, blocks: &[BlockSigma]) -> Option<BlockNoiseTest> {
    let b = blocks.iter().find(|b| b.block == "orientation")?;
    BlockNoiseTest::new(
        NoiseOf::Orientation,
        stated?,
        b.sigma,
        b.redundancy.round() as usize,
    )
}

/// The diagonal of the hat matrix `X (XᵀX)⁻¹ Xᵀ` (NaN when `XᵀX` is
/// singular): the leverage of each row.
fn hat_diagonal(x: &faer::Mat<f64>) -> Vec<f64> {
    let (m, n) = (x.nrows(), x.ncols());
    let xm = DMatrix::from_fn(m, n, |i, j| x[(i, j)]);
    let gram = xm.transpose() * &xm;
    let Some(chol) = gram.cholesky() else {
        return vec![f64::NAN; m];
    };
    let z = chol.solve(&xm.transpose());
    (0..m)
        .map(|i| (0..n).map(|k| xm[(i, k)] * z[(k, i)]).sum())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::RowKind::{Orientation, Position};

    /// A pose's rows make a position and an orientation block; three markers
    /// make three position blocks.
    #[test]
    fn rows_fall_into_blocks_by_kind_and_point() {
        let (rows, names) = row_blocks(
            &[
                Position,
                Position,
                Position,
                Orientation,
                Orientation,
                Orientation,
            ],
            1,
        );
        assert_eq!(rows, vec![0, 0, 0, 1, 1, 1]);
        assert_eq!(names[0].0, "position");
        assert_eq!(names[1], ("orientation".to_string(), "rad"));
        let (rows, names) = row_blocks(&[Position; 9], 3);
        assert_eq!(rows, vec![0, 0, 0, 1, 1, 1, 2, 2, 2]);
        assert_eq!(names[2].0, "marker 3");
    }

    /// The leverages of a full-column-rank X sum to its rank, and a row
    /// alone in its direction has leverage 1.
    #[test]
    fn leverages_sum_to_the_rank() {
        let x = faer::Mat::from_fn(5, 2, |i, j| match (i, j) {
            (0, 0) => 1.0,
            (0, 1) => 0.0,
            (_, 0) => 0.0,
            (i, _) => i as f64,
        });
        let h = hat_diagonal(&x);
        assert!((h.iter().sum::<f64>() - 2.0).abs() < 1e-12);
        assert!((h[0] - 1.0).abs() < 1e-12);
    }
}
