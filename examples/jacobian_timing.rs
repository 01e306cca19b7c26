//! Times the pool Jacobian (`jacobian_of` through `Pool::jacobian`) on a
//! 6-level lattice (6⁶ = 46 656 poses) for a point and a full-pose robot, on
//! one thread (the machine is shared; one thread gives the steadiest medians):
//! `cargo run --release --example jacobian_timing`.
use activecal::model::Robot;
use activecal::pool::Pool;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    for name in ["puma560", "ur5:pose"] {
        let r = Robot::builtin(name).expect("a built-in robot");
        let pool = Pool::full(&r, 6).expect("a 6-level pool");
        let ms: Vec<f64> = one.install(|| {
            (0..31)
                .map(|_| {
                    let t0 = Instant::now();
                    let x = pool.jacobian(&r, &r.nominal);
                    std::hint::black_box(&x);
                    t0.elapsed().as_secs_f64() * 1e3
                })
                .collect()
        });
        println!(
            "{name}: {} poses, pool Jacobian ms, median of 31 on one thread: {:.2} (min {:.2})",
            pool.len(),
            median(ms.clone()),
            ms.iter().copied().fold(f64::INFINITY, f64::min)
        );
    }
}
