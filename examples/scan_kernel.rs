//! Times the add-gain scan on one thread against two floors measured in the
//! same process: reading each candidate's packed block (memory), and one
//! libm `ln` per candidate. PUMA 15,625-pose pool, a default EAE design:
//! `cargo run --release --example scan_kernel`.
use activecal::criterion::{DCriterion, InfoState, PoolVariances, StateSettings};
use activecal::model::Robot;
use activecal::pool::Pool;
use activecal::select::{Settings, design_rng, eae};
use std::hint::black_box;
use std::time::Instant;

/// Median over 301 runs of `f`, in ns per candidate.
fn per_candidate(n: usize, mut f: impl FnMut()) -> f64 {
    let mut ts: Vec<f64> = (0..301)
        .map(|_| {
            let t0 = Instant::now();
            f();
            t0.elapsed().as_nanos() as f64 / n as f64
        })
        .collect();
    ts.sort_by(f64::total_cmp);
    ts[ts.len() / 2]
}

fn main() {
    let robot = Robot::puma560();
    let x = Pool::full(&robot, 5)
        .unwrap()
        .jacobian(&robot, &robot.nominal);
    let s = Settings::default();
    let sel = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(1, 0)).unwrap();
    let st = InfoState::new(&x, &sel.poses, StateSettings::default()).unwrap();
    let pv = PoolVariances::new(&x, &st);
    let cands: Vec<usize> = (0..x.n_poses()).collect();
    let n = cands.len();
    let mut out = vec![0.0; n];
    let tp = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    tp.install(|| {
        let scan = per_candidate(n, || pv.add_gains(black_box(&cands), &mut out));
        let read = per_candidate(n, || {
            for (o, &i) in out.iter_mut().zip(black_box(&cands)) {
                *o = pv.packed(i).iter().sum();
            }
        });
        let dets: Vec<f64> = out.iter().map(|v| 1.0 + v.abs()).collect();
        let ln = per_candidate(n, || {
            for (o, d) in out.iter_mut().zip(black_box(&dets)) {
                *o = d.ln();
            }
        });
        println!("one thread, {n} candidates, median of 301 (ns per candidate):");
        println!("  add-gain scan   {scan:.2}");
        println!("  read the block  {read:.2}");
        println!("  libm ln alone   {ln:.2}");
    });
}
