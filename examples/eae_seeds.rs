//! The distribution of EAE results over 20 seeds (one start, and 8 starts with
//! a Fedorov polish), and whether the eigenvalue-OI criterion picks the same
//! designs as the determinant: `cargo run --release --example eae_seeds`.
use activecal::criterion::{DCriterion, OiCriterion};
use activecal::model::Robot;
use activecal::pool::Pool;
use activecal::select::*;
use std::time::Instant;
fn main() {
    let r = Robot::puma560();
    let pool = Pool::full(&r, 5).unwrap();
    let x = pool.jacobian(&r, &r.nominal);
    let l10 = std::f64::consts::LN_10;
    let mut one = vec![];
    let mut pol = vec![];
    for seed in 1..=20u64 {
        let s = Settings::builder().seed(seed).build().unwrap();
        let sel = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
        one.push(sel.ln_oid / l10);
        let m = multistart(
            &x,
            DCriterion::new,
            Algorithm::Eae,
            &Settings::builder()
                .seed(seed)
                .starts(8)
                .polish(true)
                .build()
                .unwrap(),
        )
        .unwrap();
        pol.push(m.ln_oid / l10);
    }
    let f = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        format!(
            "min {:.4} median {:.4} max {:.4}",
            v[0],
            v[v.len() / 2],
            v[v.len() - 1]
        )
    };
    println!("one EAE start, 20 seeds: {}", f(&mut one));
    println!("8-start EAE + polish, 20 seeds: {}", f(&mut pol));
    let mut same = 0;
    for seed in 1..=5u64 {
        let s = Settings::builder().seed(seed).build().unwrap();
        let d = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
        let o = eae(&x, &mut OiCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
        if d.poses == o.poses {
            same += 1;
        }
        println!(
            "seed {seed}: det {:.5} oi {:.5} same {}",
            d.ln_oid / l10,
            o.ln_oid / l10,
            d.poses == o.poses
        );
    }
    println!("same designs: {same}/5");
    let t0 = Instant::now();
    let m = multistart(
        &x,
        DCriterion::new,
        Algorithm::Eae,
        &Settings::builder()
            .seed(1)
            .starts(20)
            .polish(true)
            .build()
            .unwrap(),
    )
    .unwrap();
    println!(
        "20 starts + polish: {:.4} in {:?}",
        m.ln_oid / l10,
        t0.elapsed()
    );
}
