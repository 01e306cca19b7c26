//! The certified D-optimal relaxation bound on the whole 15,625-pose PUMA
//! pool: `cargo run --release --example bound_puma -- [N] [first-order]`.

use activecal::bound::{BoundSettings, pool_bound};
use activecal::robot::{ParamSet, Robot};

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().map_or(30, |s| s.parse().expect("N"));
    let first_order_only = args.next().is_some_and(|s| s == "first-order");
    let env = |k: &str, d: f64| std::env::var(k).map_or(d, |v| v.parse().unwrap());
    let settings = BoundSettings::builder()
        .gap_tol(env("GAP_TOL", 1e-6))
        .screen_gap(env("SCREEN_GAP", 1e-2))
        .screen_extra(env("SCREEN_EXTRA", 100.0) as usize)
        .use_conic(!first_order_only)
        .conic(activecal::bound::conic::ConicSettings {
            chordal_merge: std::env::var("MERGE").unwrap_or_else(|_| "clique_graph".into()),
            ..Default::default()
        })
        .build()
        .expect("valid settings");
    let t0 = std::time::Instant::now();
    let (_, _, b) = pool_bound(&Robot::puma560(), ParamSet::Nominal, 5, n, &settings)
        .expect("the PUMA pool is valid input");
    println!(
        "N = {n}: ln_bound = {:.9}  log10_bound = {:.9}  ln_primal = {:.9}  gap = {:.3e}  status = {:?}",
        b.ln_bound,
        b.log10_bound(),
        b.ln_primal,
        b.certificate_gap,
        b.status
    );
    println!(
        "support = {}  first-order: {:?}\nconic: {:?}\nbound seconds = {:.2}, total with pool = {:.2}",
        b.support_size,
        b.first_order,
        b.conic,
        b.seconds,
        t0.elapsed().as_secs_f64()
    );
}
