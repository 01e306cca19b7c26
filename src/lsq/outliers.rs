//! Gross errors found as metrology software finds them: Baarda's data
//! snooping with each pose's residual block tested as one (Pope's τ test in
//! its externally studentised form).
//!
//! At a least-squares fit with weighted Jacobian `X` (`m` rows, `p`
//! unknowns, `f = m − p` residual degrees of freedom), pose `i`'s residual
//! block `r_i` (`t` rows) has the covariance `σ² Q_i`, `Q_i = I − X_i
//! (XᵀX)⁻¹ X_iᵀ`: the pose's share of the redundancy (`tr Q_i` is its
//! redundancy number). Its test value
//!
//! `T_i = r_iᵀ Q_i⁺ r_i`  (`k_i = rank Q_i` degrees of freedom)
//!
//! is the drop in the residual sum of squares when the pose is left out, so
//! `s_(i)² = (RSS − T_i) / (f − k_i)` estimates σ² without it, and
//!
//! `F_i = (T_i / k_i) / s_(i)²  ~  F(k_i, f − k_i)`
//!
//! for a pose without a gross error (exactly for a linear model with normal
//! noise; the stated σ is not needed). When the sensor's σ is stated,
//! Baarda's own form uses it instead: `T_i / σ² ~ χ²(k_i)` (reported as
//! `F_i = T_i / (k_i σ²)` on `(k_i, ∞)` degrees of freedom, `dof.1 = 0`):
//! then a misfit of every pose (a stated σ too small, a model that misses
//! something) flags every pose, which the callers refuse to call glitches. A pose is flagged when its tail
//! probability is below `α / n` (Bonferroni over the `n` poses tested, so
//! that clean data are flagged at most a fraction `α` of the time), the
//! largest `F_i` first; the fit is then repeated without it and the test
//! repeated ([`crate::identify::fit`] callers iterate).

use super::{LsqError, Residuals, Result};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// The default family-wise false-alarm rate of the test: on clean data, one
/// data set in a hundred has a pose flagged.
pub const ALPHA: f64 = 0.01;

/// One pose's test.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoseTest {
    /// The pose (0-based, in the measurements tested).
    pub pose: usize,
    /// `F_i` (see the module documentation).
    pub statistic: f64,
    /// Its degrees of freedom `k_i` and `f − k_i` (0 for the test with the
    /// stated σ: the χ² form).
    pub dof: (usize, usize),
    /// `P(F > F_i)`.
    pub p_value: f64,
    /// The pose's redundancy number `tr Q_i` (0: the unknowns fit it
    /// exactly, nothing can be tested).
    pub redundancy: f64,
}

/// An eigenvalue of `Q_i` below this is taken as 0: the pose's rows the
/// unknowns fit exactly (its scale is 1, `Q_i`'s eigenvalues lie in [0, 1]).
const REDUNDANCY_TOL: f64 = 1e-8;

/// The test of each of the first `poses` blocks of `block_rows` rows of
/// `prob` at `theta` (see the module documentation), with the stated `sigma`
/// (in the residuals' unit) when given; `None` when `XᵀX` is singular (no
/// fit to test) or no degree of freedom is left.
pub fn pose_tests<R: Residuals>(
    prob: &mut R,
    theta: &[f64],
    poses: usize,
    sigma: Option<f64>,
) -> Option<Vec<PoseTest>> {
    let t = prob.block_rows().max(1);
    let tester = Tester::new(prob, theta, sigma)?;
    let n = poses.min(tester.r.len() / t);
    Some(
        (0..n)
            .filter_map(|i| tester.test(i, &(i * t..(i + 1) * t).collect::<Vec<_>>()))
            .collect(),
    )
}

/// A least-squares fit's residuals and Jacobian, ready to test any set of
/// its rows as one block (the module documentation's `T_i` and `F_i`).
pub struct Tester {
    x: DMatrix<f64>,
    r: DVector<f64>,
    chol: nalgebra::Cholesky<f64, nalgebra::Dyn>,
    rss: f64,
    f: usize,
    sigma: Option<f64>,
}

impl Tester {
    /// The residuals and Jacobian of `prob` at `theta`, with the stated
    /// `sigma` when given; `None` when `XᵀX` is singular or no degree of
    /// freedom is left.
    pub fn new<R: Residuals>(prob: &mut R, theta: &[f64], sigma: Option<f64>) -> Option<Tester> {
        let (m, n) = (prob.n_residuals(), prob.n_params());
        let mut r = vec![0.0; m];
        let mut jac = faer::Mat::<f64>::zeros(m, n);
        if !prob.eval(theta, &mut r, Some(&mut jac)) || m <= n {
            return None;
        }
        let x = DMatrix::from_fn(m, n, |i, j| jac[(i, j)]);
        let chol = (x.transpose() * &x).cholesky()?;
        let rss: f64 = r.iter().map(|v| v * v).sum();
        // Rows that measure nothing (a camera's point not seen: residual
        // and Jacobian row zero) are no degrees of freedom.
        let empty = (0..m)
            .filter(|&i| r[i] == 0.0 && x.row(i).iter().all(|v| *v == 0.0))
            .count();
        Some(Tester {
            x,
            r: DVector::from_vec(r),
            chol,
            rss,
            f: (m - empty).saturating_sub(n),
            sigma,
        })
    }

    /// The test of the block of `rows` as unit `pose`; `None` when the
    /// unknowns fit it exactly or too few degrees of freedom are left.
    #[must_use]
    pub fn test(&self, pose: usize, rows: &[usize]) -> Option<PoseTest> {
        let (q, ri) = self.block(rows)?;
        block_test(pose, &q, &ri, self.rss, self.f, self.sigma)
    }

    /// `T` and `k` of the block of `rows` (the drop in the residual sum of
    /// squares when they are left out, and its degrees of freedom; see the
    /// module documentation); `None` when nothing of it can be tested.
    #[must_use]
    pub fn drop_in_rss(&self, rows: &[usize]) -> Option<(f64, usize)> {
        let (q, ri) = self.block(rows)?;
        let (t, k) = t_and_k(&q, &ri);
        (k > 0).then_some((t, k))
    }

    /// The residual sum of squares, its degrees of freedom and the stated
    /// σ the tests use.
    #[must_use]
    pub fn rss(&self) -> (f64, usize, Option<f64>) {
        (self.rss, self.f, self.sigma)
    }

    /// `Q` of the block of `rows` and its residuals, the rows that measure
    /// nothing left out.
    fn block(&self, rows: &[usize]) -> Option<(DMatrix<f64>, DVector<f64>)> {
        // Rows that measure nothing leave `Q`'s eigenvalue 1 with no
        // residual: not a degree of freedom of the block.
        let rows: Vec<usize> = rows
            .iter()
            .copied()
            .filter(|&i| !(self.r[i] == 0.0 && self.x.row(i).iter().all(|v| *v == 0.0)))
            .collect();
        let t = rows.len();
        if t == 0 {
            return None;
        }
        let xi = self.x.select_rows(&rows);
        let ri = self.r.select_rows(&rows);
        let q = DMatrix::<f64>::identity(t, t) - &xi * self.chol.solve(&xi.transpose());
        Some((q, ri))
    }
}

/// `T = rᵀ Q⁺ r` and `k = rank Q` of a block.
fn t_and_k(q: &DMatrix<f64>, ri: &DVector<f64>) -> (f64, usize) {
    let eig = q.clone().symmetric_eigen();
    let mut stat = 0.0;
    let mut k = 0;
    for (j, &lambda) in eig.eigenvalues.iter().enumerate() {
        if lambda > REDUNDANCY_TOL {
            let u = eig.eigenvectors.column(j);
            stat += u.dot(ri).powi(2) / lambda;
            k += 1;
        }
    }
    (stat, k)
}

/// The test of `t` (a block's `T`) on `k` rows, against the stated `sigma`
/// (χ²) or, without one, against the σ estimated without the block from
/// `rss` on `f` degrees of freedom (F): the statistic, its degrees of
/// freedom and its tail; `None` when no degree of freedom is left.
#[must_use]
pub fn tail_of(
    t: f64,
    k: usize,
    rss: f64,
    f: usize,
    sigma: Option<f64>,
) -> Option<(f64, (usize, usize), f64)> {
    if k == 0 || f <= k {
        return None;
    }
    if let Some(s) = sigma.filter(|s| *s > 0.0) {
        let x = t / (s * s);
        return Some((
            x / k as f64,
            (k, 0),
            crate::stats::chi2_upper_tail(x, k as f64),
        ));
    }
    let d2 = f - k;
    let s2 = ((rss - t) / d2 as f64).max(f64::MIN_POSITIVE);
    let statistic = (t / k as f64) / s2;
    Some((
        statistic,
        (k, d2),
        crate::stats::f_upper_tail(statistic, k as f64, d2 as f64),
    ))
}

/// The test of one block with residual covariance factor `q` and
/// residuals `ri` (see [`pose_tests`]).
fn block_test(
    pose: usize,
    q: &DMatrix<f64>,
    ri: &DVector<f64>,
    rss: f64,
    f: usize,
    sigma: Option<f64>,
) -> Option<PoseTest> {
    let (stat, k) = t_and_k(q, ri);
    let (statistic, dof, p_value) = tail_of(stat, k, rss, f, sigma)?;
    Some(PoseTest {
        pose,
        statistic,
        dof,
        p_value,
        redundancy: q.trace(),
    })
}

/// The pose the test flags at family-wise rate `alpha`: the largest `F_i`
/// whose tail is below `alpha / n` (`n` the poses tested), or `None`.
#[must_use]
pub fn flagged(tests: &[PoseTest], alpha: f64) -> Option<&PoseTest> {
    let n = tests.len().max(1) as f64;
    tests
        .iter()
        .filter(|t| t.p_value < alpha / n)
        .max_by(|a, b| a.statistic.total_cmp(&b.statistic))
}

/// A unit of the data (a pose, a contact row, a camera's point) the test
/// flagged: its test (the unit's index in the data given) and the bound
/// its tail fell below.
#[derive(Clone, Debug, PartialEq)]
pub struct Flag<U> {
    /// The unit, in the data given.
    pub unit: U,
    /// Its test when flagged.
    pub test: PoseTest,
    /// `α / n`, `n` the units tested.
    pub threshold: f64,
}

/// What data snooping needs of a calibration: a fit with some units left
/// out, and the unit the test flags at a fit.
pub trait Snoop {
    /// What is left out: a pose, a row, a point of a pose.
    type Unit: Clone;
    /// The fit.
    type Fit: Clone;
    /// Why a fit could not be made.
    type Error;
    /// The fit with the units `out` left out, from the last fit `from`
    /// when given.
    fn fit(
        &mut self,
        out: &[Self::Unit],
        from: Option<&Self::Fit>,
    ) -> std::result::Result<Self::Fit, Self::Error>;
    /// The unit the test flags at `fit` (made with `out` left out) at
    /// family-wise rate `alpha` ([`flagged`]), if any; or why the units
    /// flagged are not isolated glitches (every unit is then kept).
    fn flag(&mut self, fit: &Self::Fit, out: &[Self::Unit], alpha: f64) -> Flagged<Self::Unit>;
}

/// What [`Snoop::flag`] found.
#[derive(Clone, Debug, PartialEq)]
pub enum Flagged<U> {
    /// No unit is flagged.
    Clean,
    /// This unit.
    Unit(Flag<U>),
    /// Too many units of one kind are flagged (e.g. many rows of one
    /// contact point): not glitches but a model or a setup other than
    /// assumed, in these words.
    Systematic(String),
}

/// Why [`snoop`] kept every unit.
#[derive(Clone, Debug, PartialEq)]
pub enum Capped {
    /// The test would leave out more than the most allowed.
    Total,
    /// [`Flagged::Systematic`], with its words.
    Systematic(String),
}

/// The outcome of [`snoop`].
#[derive(Clone, Debug)]
pub struct Snooped<F, U> {
    /// The fit of the units kept (of every unit when `capped`).
    pub fit: F,
    /// The units left out, in the order the test found them.
    pub out: Vec<Flag<U>>,
    /// Why every unit is kept though the test flags some, if it does.
    pub capped: Option<Capped>,
}

/// Baarda's data snooping iterated: the unit the test flags at rate
/// `alpha` left out and the fit repeated, until none is flagged; when the
/// test would leave out more than `most` units, every unit is kept (the
/// data are then not a few glitches but a noise or a model other than
/// assumed, which leaving units out would hide).
pub fn snoop<S: Snoop>(
    s: &mut S,
    alpha: f64,
    most: usize,
) -> std::result::Result<Snooped<S::Fit, S::Unit>, S::Error> {
    let all = s.fit(&[], None)?;
    let mut fit = all.clone();
    let mut out: Vec<Flag<S::Unit>> = Vec::new();
    loop {
        let units: Vec<S::Unit> = out.iter().map(|f| f.unit.clone()).collect();
        let flag = match s.flag(&fit, &units, alpha) {
            Flagged::Clean => break,
            Flagged::Unit(f) => f,
            Flagged::Systematic(why) => {
                return Ok(Snooped {
                    fit: all,
                    out: Vec::new(),
                    capped: Some(Capped::Systematic(why)),
                });
            }
        };
        if out.len() >= most {
            return Ok(Snooped {
                fit: all,
                out: Vec::new(),
                capped: Some(Capped::Total),
            });
        }
        out.push(flag);
        let units: Vec<S::Unit> = out.iter().map(|f| f.unit.clone()).collect();
        fit = s.fit(&units, Some(&fit))?;
    }
    Ok(Snooped {
        fit,
        out,
        capped: None,
    })
}

/// At most this fraction of the poses is left out as gross errors: beyond
/// it the data are not a few glitches but a noise or a model other than
/// assumed, which leaving poses out would hide.
pub const MOST_OUTLIERS: f64 = 0.2;

/// The note when the test flags more than `most` of `n` `units`: every
/// unit is kept.
#[must_use]
pub fn too_many_note(most: usize, n: usize, units: &str) -> String {
    format!(
        "the gross-error test flags more than {most} {units} ({:.0} % of {n}): not isolated glitches but a noise larger than the sensor's or a model that misses something (joint sag under gravity: {}); every one is kept",
        MOST_OUTLIERS * 100.0,
        crate::names::phrase::COMPLIANCE
    )
}

/// `0..n` without `out`, in order.
#[must_use]
pub fn kept_of(n: usize, out: &[usize]) -> Vec<usize> {
    (0..n).filter(|i| !out.contains(i)).collect()
}

/// How a calibration treats poses the test flags.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum OutlierChoice {
    /// Flag, leave out and refit, one pose at a time, at this family-wise
    /// false-alarm rate.
    Drop {
        /// The rate (default [`ALPHA`]).
        alpha: f64,
    },
    /// Keep every pose (the test is still reported).
    Keep,
}

impl Default for OutlierChoice {
    fn default() -> Self {
        OutlierChoice::Drop { alpha: ALPHA }
    }
}

/// A pose left out as a gross error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Outlier {
    /// The pose: its row among the measurements given (0-based).
    pub pose: usize,
    /// Its test when flagged.
    pub test: PoseTest,
    /// The bound its tail fell below (`α / n`).
    pub threshold: f64,
    /// Its position residual at the final fit (mm, RMS over its points).
    pub residual_mm: f64,
}

impl OutlierChoice {
    /// Checks the choice's rate: in (0, 1) ([`check_choice`]).
    ///
    /// # Errors
    /// A rate outside (0, 1).
    pub fn validate(self) -> Result<()> {
        check_choice(self)
    }
}

/// Checks an [`OutlierChoice`]'s rate: in (0, 1).
pub fn check_choice(c: OutlierChoice) -> Result<()> {
    match c {
        OutlierChoice::Drop { alpha } if !(alpha > 0.0 && alpha < 1.0) => Err(LsqError::Invalid(
            format!("outlier test rate {alpha}: must be in (0, 1)"),
        )),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight line fitted to points, one of them off: `Residuals` with
    /// blocks of one row.
    struct Line {
        x: Vec<f64>,
        y: Vec<f64>,
    }

    impl Residuals for Line {
        fn n_residuals(&self) -> usize {
            self.x.len()
        }
        fn n_params(&self) -> usize {
            2
        }
        fn eval(&mut self, th: &[f64], r: &mut [f64], jac: Option<&mut faer::Mat<f64>>) -> bool {
            for (i, (x, y)) in self.x.iter().zip(&self.y).enumerate() {
                r[i] = th[0] + th[1] * x - y;
            }
            if let Some(j) = jac {
                for (i, x) in self.x.iter().enumerate() {
                    j[(i, 0)] = 1.0;
                    j[(i, 1)] = *x;
                }
            }
            true
        }
    }

    /// The least-squares line through the points.
    fn fit(l: &Line) -> [f64; 2] {
        let n = l.x.len() as f64;
        let (sx, sy) = (l.x.iter().sum::<f64>(), l.y.iter().sum::<f64>());
        let sxx: f64 = l.x.iter().map(|x| x * x).sum();
        let sxy: f64 = l.x.iter().zip(&l.y).map(|(x, y)| x * y).sum();
        let b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
        [(sy - b * sx) / n, b]
    }

    #[test]
    fn the_deletion_test_equals_the_refit_without_the_pose() {
        // Deterministic scatter and one gross error at x = 7.
        let x: Vec<f64> = (0..20).map(f64::from).collect();
        let mut y: Vec<f64> = x
            .iter()
            .map(|x| 1.0 + 0.5 * x + 0.01 * (3.7 * x).sin())
            .collect();
        y[7] += 0.5;
        let mut l = Line { x, y };
        let th = fit(&l);
        let tests = pose_tests(&mut l, &th, 20, None).unwrap();
        let worst = flagged(&tests, ALPHA).expect("the gross error is flagged");
        assert_eq!(worst.pose, 7);
        // T_7 is the drop in RSS when pose 7 is left out: refit and compare.
        let rss = |l: &Line, th: [f64; 2]| -> f64 {
            l.x.iter()
                .zip(&l.y)
                .map(|(x, y)| (th[0] + th[1] * x - y).powi(2))
                .sum()
        };
        let full = rss(&l, th);
        let mut w = Line {
            x: l.x.clone(),
            y: l.y.clone(),
        };
        w.x.remove(7);
        w.y.remove(7);
        let without = rss(&w, fit(&w));
        let s2 = without / 17.0;
        let expected = (full - without) / s2;
        assert!(
            (worst.statistic - expected).abs() < 1e-8 * expected,
            "{} vs {expected}",
            worst.statistic
        );
        // Without it, nothing is flagged.
        let th = fit(&w);
        let tests = pose_tests(&mut w, &th, 19, None).unwrap();
        assert!(flagged(&tests, ALPHA).is_none(), "{tests:?}");
    }
}
