//! TEMPORARY: the former contact exchange, kept only to measure the common one against (removed before merge).
#![allow(missing_docs)]
use crate::identify::contact::select::{SocketPool, consistency_moment, information};
use nalgebra::DMatrix;
/// Improves `design` by exchanges that lower its predicted consistency
/// error (see [`refine_for`] with [`consistency_moment`]).
#[must_use]
pub fn refine_for_consistency(pool: &SocketPool, design: Vec<usize>) -> Vec<usize> {
    refine_for(pool, design, &consistency_moment(pool))
}

/// Improves `design` by exchanges that lower `tr(M⁻¹ W)` for the moment `w`
/// (an I-optimal criterion, [`predicted_error`]), each swap priced by the
/// Sherman–Morrison–Woodbury update, until no swap lowers it (at most 10
/// sweeps).
#[must_use]
pub fn refine_for(pool: &SocketPool, mut design: Vec<usize>, w: &DMatrix<f64>) -> Vec<usize> {
    let p = w.nrows();
    let ridge = DMatrix::identity(p, p) * 1e-12 * information(pool, &design).trace() / p as f64;
    // tr((A + BᵀB)⁻¹ W) = tr(A⁻¹W) − tr((I + B A⁻¹ Bᵀ)⁻¹ B A⁻¹ W A⁻¹ Bᵀ).
    let drop = |a_inv: &DMatrix<f64>, g: &DMatrix<f64>, i: usize| -> f64 {
        let b = &pool.block(i);
        let s = DMatrix::identity(3, 3) + b * a_inv * b.transpose();
        let v = b * g * b.transpose();
        s.try_inverse().map_or(0.0, |si| (si * v).trace())
    };
    for _ in 0..10 {
        let mut improved = false;
        for k in 0..design.len() {
            let mut rest = design.clone();
            let out = rest.swap_remove(k);
            let Some(a_inv) = (information(pool, &rest) + &ridge).try_inverse() else {
                continue;
            };
            let g = &a_inv * w * &a_inv;
            let keep = drop(&a_inv, &g, out);
            let best = (0..pool.qs.len())
                .filter(|i| !design.contains(i))
                .map(|i| (i, drop(&a_inv, &g, i)))
                .max_by(|x, y| x.1.total_cmp(&y.1));
            if let Some((j, v)) = best
                && v > keep * (1.0 + 1e-9)
            {
                design[k] = j;
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    design
}

/// `n` configurations of the pool chosen greedily for the largest
/// `ln det M` (a ridge of 1e-9 of the information's mean diagonal starts
/// it), then improved by exchanges (Fedorov) until no swap raises it; each
/// candidate priced by the matrix determinant lemma,
/// `ln det(A + BᵀB) = ln det A + ln det(I₃ + B A⁻¹ Bᵀ)`.
#[must_use]
pub fn select_d_optimal(pool: &SocketPool, n: usize) -> Vec<usize> {
    let p = pool.p();
    let all = information(pool, &(0..pool.qs.len()).collect::<Vec<_>>());
    let ridge = DMatrix::identity(p, p) * (1e-9 * all.trace() / p as f64);
    let gain = |a_inv: &DMatrix<f64>, i: usize| -> f64 {
        let b = &pool.block(i);
        let s = DMatrix::identity(3, 3) + b * a_inv * b.transpose();
        s.determinant().max(f64::MIN_POSITIVE).ln()
    };
    let inverse = |m: DMatrix<f64>| m.try_inverse().expect("a ridged information is invertible");
    let mut design: Vec<usize> = Vec::with_capacity(n);
    while design.len() < n.min(pool.qs.len()) {
        let a_inv = inverse(information(pool, &design) + &ridge);
        let best = (0..pool.qs.len())
            .filter(|i| !design.contains(i))
            .max_by(|&x, &y| gain(&a_inv, x).total_cmp(&gain(&a_inv, y)))
            .expect("candidates remain");
        design.push(best);
    }
    for _ in 0..10 {
        let mut improved = false;
        for k in 0..design.len() {
            let mut rest = design.clone();
            let out = rest.swap_remove(k);
            let a_inv = inverse(information(pool, &rest) + &ridge);
            let keep = gain(&a_inv, out);
            let best = (0..pool.qs.len())
                .filter(|i| !design.contains(i))
                .map(|i| (i, gain(&a_inv, i)))
                .max_by(|x, y| x.1.total_cmp(&y.1));
            if let Some((j, g)) = best
                && g > keep + 1e-9
            {
                design[k] = j;
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    design
}
