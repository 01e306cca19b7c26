//! A small benchmark of the batched scans, for the `bench` CLI subcommand.

use std::time::Instant;

use serde::Serialize;

use super::CriterionError;
use super::criteria::{Criterion, DCriterion, OiCriterion};
use super::state::{InfoState, StateSettings};
use super::variances::PoolVariances;
use crate::blocks::Blocks;

/// Timings of [`bench_scan`], in nanoseconds per candidate pose (wall clock,
/// all rayon threads), best of the repetitions.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ScanTimings {
    /// Candidates per scan: every pool pose, as a selection scans them.
    pub n_candidates: usize,
    /// Pool poses.
    pub n_pool: usize,
    /// Parameters.
    pub p: usize,
    /// Rows per pose.
    pub t: usize,
    /// Rayon threads.
    pub threads: usize,
    /// Add-gain scan `ln det(I + V_i)` from maintained variances
    /// ([`DCriterion::price_adds`]).
    pub add_gain_ns: f64,
    /// Full recomputation of every `V_i = X_i M⁻¹ X_iᵀ` (per pool pose).
    pub variances_full_ns: f64,
    /// Incremental update of every `V_i` after one exchange (rank `2t`,
    /// per pool pose), including the state update.
    pub variances_update_ns: f64,
    /// Exchange prices for one out-pose over all candidates
    /// ([`DCriterion::price_exchanges`]).
    pub exchange_one_out_ns: f64,
    /// The paper's eigenvalue OI recomputed per candidate
    /// ([`OiCriterion::price_adds`]).
    pub oi_eigen_ns: f64,
    /// `oi_eigen_ns / add_gain_ns`.
    pub speedup: f64,
}

fn best_of<F: FnMut()>(reps: usize, mut f: F) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..reps.max(1) {
        let t0 = Instant::now();
        f();
        best = best.min(t0.elapsed().as_nanos() as f64);
    }
    best
}

/// Times the batched add-gain scan of [`DCriterion`] against recomputing the
/// eigenvalue OI per candidate ([`OiCriterion`]), side by side, plus the
/// variance recomputation, the incremental variance update and a one-out
/// exchange scan, on the design `design` of `pool` (with default
/// [`StateSettings`]). Each measurement is the best of `reps` runs
/// (`reps ≥ 1`); the OI scan dominates the cost (`O(p³)` per candidate).
/// Runs inside a rayon pool of `rayon::current_num_threads()` threads, so
/// the timings exclude the cold start of a parallel call made from outside a
/// pool (run selection loops inside `ThreadPool::install` for the same
/// reason).
pub fn bench_scan(
    pool: &Blocks,
    design: &[usize],
    reps: usize,
) -> Result<ScanTimings, CriterionError> {
    bench_scan_with_threads(pool, design, reps, rayon::current_num_threads())
}

/// [`bench_scan`] in a rayon pool of `threads` threads (`≥ 1`). With
/// `threads = 1` the timings are the per-candidate arithmetic alone, free of
/// thread wake-ups — the stable number on a loaded machine.
pub fn bench_scan_with_threads(
    pool: &Blocks,
    design: &[usize],
    reps: usize,
    threads: usize,
) -> Result<ScanTimings, CriterionError> {
    // Measure inside a rayon pool, as a selection loop running in one sees
    // it: a parallel call from a thread outside any pool also pays the
    // wake-up of the pool's sleeping workers (up to a scheduler time slice,
    // milliseconds, on a loaded machine), which would swamp a scan of
    // ~0.5 ms.
    match rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
    {
        Ok(tp) => tp.install(|| scan(pool, design, reps)),
        Err(_) => scan(pool, design, reps),
    }
}

fn scan(pool: &Blocks, design: &[usize], reps: usize) -> Result<ScanTimings, CriterionError> {
    let state = InfoState::new(pool, design, StateSettings::default())?;
    let n = pool.n_poses();
    // Every pool pose, as a selection scans them (the design's own poses
    // are priced `-∞`): one contiguous run of blocks.
    let cands: Vec<usize> = (0..n).collect();
    let nc = cands.len().max(1) as f64;
    let mut out = vec![0.0; cands.len()];

    let mut d = DCriterion::new();
    d.price_adds(pool, &state, &cands, &mut out); // builds the variances
    let add = best_of(reps, || d.price_adds(pool, &state, &cands, &mut out));

    let mut pv = PoolVariances::new(pool, &state);
    let full = best_of(reps, || pv.recompute(pool, &state));

    // One exchange and the variance update it triggers (setup untimed).
    let inn = (0..n).find(|&i| !state.contains(i));
    let out_pose = state.design().first().copied();
    let mut update = f64::NAN;
    if let (Some(inn), Some(o)) = (inn, out_pose) {
        update = f64::INFINITY;
        for _ in 0..reps.max(1) {
            let mut st = state.clone();
            let mut pv = PoolVariances::new(pool, &st);
            let t0 = Instant::now();
            let _ = st.exchange(pool, o, inn);
            pv.sync(pool, &st);
            update = update.min(t0.elapsed().as_nanos() as f64);
        }
    }

    let mut ex = vec![0.0; cands.len()];
    let exch = match out_pose {
        Some(o) => best_of(reps, || {
            d.price_exchanges(pool, &state, &[o], &cands, &mut ex)
        }),
        None => f64::NAN,
    };

    let mut oi = OiCriterion::new();
    let oi_t = best_of(reps, || oi.price_adds(pool, &state, &cands, &mut out));

    Ok(ScanTimings {
        n_candidates: cands.len(),
        n_pool: n,
        p: pool.p(),
        t: pool.t(),
        threads: rayon::current_num_threads(),
        add_gain_ns: add / nc,
        variances_full_ns: full / n.max(1) as f64,
        variances_update_ns: update / n.max(1) as f64,
        exchange_one_out_ns: exch / nc,
        oi_eigen_ns: oi_t / nc,
        speedup: oi_t / add,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::test_util::random_pool;

    #[test]
    fn bench_scan_runs_on_a_small_pool() {
        let pool = random_pool(300, 3, 9, 1);
        let design: Vec<usize> = (0..6).collect();
        let s = bench_scan(&pool, &design, 1).unwrap();
        assert_eq!(s.n_candidates, 300);
        assert!(s.add_gain_ns > 0.0 && s.oi_eigen_ns > 0.0 && s.speedup.is_finite());
    }

    /// The paper-sized scan (15,625 poses, p = 27, t = 3, 30-pose design) on
    /// random data. Run with
    /// `cargo test --release --lib criterion::bench -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn bench_scan_paper_size() {
        let pool = random_pool(15_625, 3, 27, 42);
        let design: Vec<usize> = (0..30).map(|i| i * 521).collect();
        for threads in [1, 2] {
            let s = bench_scan_with_threads(&pool, &design, 5, threads).unwrap();
            println!("{}", serde_json::to_string_pretty(&s).unwrap());
        }
    }
}
