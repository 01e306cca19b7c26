//! Carathéodory reduction of a relaxation point's support.
//!
//! On lattices the optimum of (R) is carried by many tied poses: the
//! information `M(w)` is unique but `w` is not, and a barrier method lands at
//! the analytic centre of the optimal face, spreading weight over hundreds
//! or thousands of poses (1,993 on the UR10 full-pose lattice, p = 30). The
//! Newton system grows with the cube of its candidates, so carrying them all
//! into the next screening round is what makes full-pose bounds slow.
//!
//! Any `w` has a twin with the same `M(w)` and `Σ w` and at most
//! `m = p(p+1)/2 + 1` poses strictly between 0 and 1 (Carathéodory: the
//! free weights are coordinates of a point of an `m`-dimensional space).
//! [`reduce`] finds one: with `A` the `m × f` matrix whose column `i` is
//! `(svec(X_iᵀX_i), 1)` over the `f` free poses, every null vector `z` of
//! `A` moves `w` without changing `M` or `Σ w`; stepping along it until a
//! weight reaches 0 or 1 frees one pose at a time, `f − m` times. The null
//! basis comes from one QR of `Aᵀ`; after each step the remaining basis
//! vectors are combined so that the pose just fixed stays fixed.
//!
//! Rounding moves `M` by about `ε·‖A‖·Σ|step|`; the reduced point is not
//! trusted, only used as the next round's candidates and warm start: the
//! bound is always the certificate (eq. C) of a point evaluated afresh.

use crate::blocks::Blocks;
use faer::Mat;

/// Weight within this of 0 or 1 counts as fixed there.
const FIXED: f64 = 1e-12;

/// Reduces the free support of `w` (pool weights) among the positions
/// `cand`, keeping `M(w)` and `Σ w`; returns the positions of `cand` that
/// still carry weight, ascending. `x` is the (scaled) pool Jacobian.
pub(crate) fn reduce(x: &Blocks, w: &mut [f64], cand: &[usize]) -> Vec<usize> {
    let (t, p) = (x.t(), x.p());
    let m = p * (p + 1) / 2 + 1;
    let free: Vec<usize> = cand
        .iter()
        .copied()
        .filter(|&i| w[i] > FIXED && w[i] < 1.0 - FIXED)
        .collect();
    let f = free.len();
    if f > m {
        // Aᵀ (f × m): row k = (svec(X_kᵀX_k), 1) of free pose k.
        let xm = x.mat();
        let mut at = Mat::<f64>::zeros(f, m);
        for (k, &i) in free.iter().enumerate() {
            let mut col = 0;
            for a in 0..p {
                for b in a..p {
                    let mut s = 0.0;
                    for r in 0..t {
                        s += xm[(i * t + r, a)] * xm[(i * t + r, b)];
                    }
                    at[(k, col)] = s;
                    col += 1;
                }
            }
            at[(k, m - 1)] = 1.0;
        }
        let q = at.qr().compute_Q();
        // Null basis of A: the last f − m columns of Q.
        let mut basis: Vec<Vec<f64>> = (m..f).map(|c| q.col(c).iter().copied().collect()).collect();
        let mut wf: Vec<f64> = free.iter().map(|&i| w[i]).collect();
        while let Some(z) = basis.pop() {
            // Largest step along z keeping every free weight in [0, 1].
            let mut step = f64::INFINITY;
            let mut hit = usize::MAX;
            for (k, (&wk, &zk)) in wf.iter().zip(&z).enumerate() {
                // `zk >= 1e-14` is equivalent: it differs only at exactly
                // 1e-14, a component of rounding size either way (the step
                // it allows is as long as the others or not taken).
                let room = if zk > 1e-14 {
                    (1.0 - wk) / zk
                } else if zk < -1e-14 {
                    wk / -zk
                } else {
                    continue;
                };
                // `room <= step` is equivalent: on a tie it fixes the last
                // of the tied weights instead of the first; the other lands
                // on its bound too (to rounding, then clamped) and the next
                // vector's room for it is 0. Either is a valid Carathéodory
                // step (M and Σ w kept, one more pose fixed), and exact ties
                // do not occur on data in general position.
                if room < step {
                    step = room;
                    hit = k;
                }
            }
            if hit == usize::MAX {
                continue;
            }
            for (wk, &zk) in wf.iter_mut().zip(&z) {
                *wk = (*wk + step * zk).clamp(0.0, 1.0);
            }
            wf[hit] = if z[hit] > 0.0 { 1.0 } else { 0.0 };
            // Keep the pose just fixed where it is in every later move.
            let zh = z[hit];
            for v in &mut basis {
                let c = v[hit] / zh;
                if c != 0.0 {
                    for (vk, &zk) in v.iter_mut().zip(&z) {
                        *vk -= c * zk;
                    }
                    v[hit] = 0.0;
                }
            }
        }
        for (k, &i) in free.iter().enumerate() {
            w[i] = wf[k];
        }
    }
    let mut kept: Vec<usize> = cand.iter().copied().filter(|&i| w[i] > FIXED).collect();
    kept.sort_unstable();
    kept
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bound::variance::information;

    #[test]
    fn keeps_the_information_and_the_sum_on_at_most_m_free_poses() {
        // 60 random 2 × 3 blocks (m = 3·4/2 + 1 = 7), spread weights.
        let (n, t, p) = (60, 2, 3);
        let mut seed = 3u64;
        let mut rnd = || crate::linalg::test_rng::lcg(&mut seed);
        let x = Blocks::new(Mat::from_fn(n * t, p, |_, _| rnd()), t);
        let mut w: Vec<f64> = (0..n)
            .map(|i| 0.02 + 0.1 * ((i * 7) % 13) as f64 / 13.0)
            .collect();
        w[5] = 1.0;
        w[9] = 0.0;
        let before = information(&x, &w);
        let sum: f64 = w.iter().sum();
        let cand: Vec<usize> = (0..n).collect();
        let kept = reduce(&x, &mut w, &cand);
        let after = information(&x, &w);
        let free = w.iter().filter(|&&v| v > FIXED && v < 1.0 - FIXED).count();
        assert!(free <= p * (p + 1) / 2 + 1, "{free} free poses");
        let ones = w.iter().filter(|&&v| v >= 1.0 - FIXED).count();
        assert!(
            kept.len() <= ones + p * (p + 1) / 2 + 1,
            "{} kept",
            kept.len()
        );
        assert!(kept.len() < 15, "{} of {n} kept", kept.len());
        assert!(kept.contains(&5) && !kept.contains(&9));
        assert!(w.iter().all(|&v| (0.0..=1.0).contains(&v)));
        assert!((w.iter().sum::<f64>() - sum).abs() < 1e-10 * sum);
        let scale = before.norm_l2();
        assert!((&after - &before).norm_l2() < 1e-10 * scale, "M moved");
    }

    /// Weights already at 0 or 1 are not free: they stay exactly where
    /// they are, and do not use up null vectors (the free support still
    /// ends at most `m`). Half of 60 candidates fixed, a third of those at 1.
    #[test]
    fn fixed_weights_stay_fixed() {
        let (n, t, p) = (60, 2, 3);
        let mut seed = 11u64;
        let mut rnd = || crate::linalg::test_rng::lcg(&mut seed);
        let x = Blocks::new(Mat::from_fn(n * t, p, |_, _| rnd()), t);
        let w0: Vec<f64> = (0..n)
            .map(|i| match i % 6 {
                0 => 1.0,
                1 | 2 => 0.0,
                _ => 0.05 + 0.8 * ((i * 5) % 11) as f64 / 11.0,
            })
            .collect();
        let mut w = w0.clone();
        let before = information(&x, &w);
        let cand: Vec<usize> = (0..n).collect();
        let kept = reduce(&x, &mut w, &cand);
        for i in 0..n {
            if w0[i] == 0.0 || w0[i] == 1.0 {
                assert_eq!(w[i], w0[i], "pose {i} moved");
            }
        }
        let free = w.iter().filter(|&&v| v > FIXED && v < 1.0 - FIXED).count();
        assert!(free <= p * (p + 1) / 2 + 1, "{free} free poses");
        assert!(kept.iter().all(|&i| w[i] > FIXED));
        // M kept: sums of 60 O(1) products, 1e-10 relative as above.
        let after = information(&x, &w);
        assert!((&after - &before).norm_l2() < 1e-10 * before.norm_l2());
    }
}
