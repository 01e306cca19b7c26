//! The certified D-optimal relaxation bound on the whole 15,625-pose PUMA
//! pool (5 levels per joint, nominal parameters):
//! `cargo run --release --example bound_puma -- [N] [first-order]`.

use activecal::bound::{BoundSettings, pool_bound};
use activecal::model::{ParamSet, Robot};

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .map_or(30, |s| s.parse().expect("N is a number"));
    let first_order_only = args.next().is_some_and(|s| s == "first-order");
    let settings = BoundSettings::builder()
        .use_conic(!first_order_only)
        .build()
        .expect("valid settings");
    let (_, _, b) = pool_bound(&Robot::puma560(), ParamSet::Nominal, 5, n, &settings)
        .expect("the PUMA pool is valid input");
    println!(
        "N = {n}: ln_bound = {:.9}  log10_bound = {:.9}  ln_primal = {:.9}  gap = {:.3e}  {:?}",
        b.ln_bound,
        b.log10_bound(),
        b.ln_primal,
        b.certificate_gap,
        b.status
    );
    println!(
        "support = {}\nfirst order: {:?}\nclarabel: {:?}\nseconds = {:.2}",
        b.support_size, b.first_order, b.conic, b.seconds
    );
}
