//! Times one EAE start called from the main thread and from inside a rayon
//! pool (where the scans' parallel sections start without a cross-thread
//! injection): `cargo run --release --example eae_timing`.
use activecal::criterion::DCriterion;
use activecal::model::Robot;
use activecal::pool::Pool;
use activecal::select::{Settings, design_rng, eae};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let r = Robot::puma560();
    let pool = Pool::full(&r, 5).unwrap();
    let x = pool.jacobian(&r, &r.nominal);
    let s = Settings::default();
    let run = |seed: u64| {
        let t0 = Instant::now();
        let sel = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
        (t0.elapsed().as_secs_f64() * 1e3, sel.trace.len())
    };
    let outside: Vec<f64> = (1..=15).map(|k| run(k).0).collect();
    // The first start of the process is what a one-start `select` pays.
    let first = outside[0];
    let tp = rayon::ThreadPoolBuilder::new().build().unwrap();
    let inside: Vec<f64> = tp.install(|| (1..=15).map(|k| run(k).0).collect());
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let one: Vec<f64> = single.install(|| (1..=15).map(|k| run(k).0).collect());
    println!(
        "EAE ms: first start of the process {first:.1}; median of 15: main thread {:.1}, inside a pool {:.1}, one thread {:.1}",
        median(outside),
        median(inside),
        median(one)
    );
}
