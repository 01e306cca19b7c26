use activecal::criterion::DCriterion;
use activecal::pool::Pool;
use activecal::robot::Robot;
use activecal::select::*;
use std::time::Instant;
fn main() {
    let r = Robot::puma560();
    let pool = Pool::full(&r, 5).unwrap();
    let x = pool.jacobian(&r, &r.nominal);
    let l10 = std::f64::consts::LN_10;
    for seed in 0..5u64 {
        let s = Settings {
            seed,
            ..Default::default()
        };
        let t0 = Instant::now();
        let sel = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(seed, 0)).unwrap();
        let t1 = t0.elapsed();
        let t0 = Instant::now();
        let p = polish(&x, &mut DCriterion::new(), sel.clone(), &s).unwrap();
        println!(
            "seed {seed}: eae {:.4} in {:?} ({} steps); polished {:.4} in {:?} ({} steps)",
            sel.ln_oid / l10,
            t1,
            sel.trace.len(),
            p.ln_oid / l10,
            t0.elapsed(),
            p.trace.len() - sel.trace.len()
        );
    }
    let t0 = Instant::now();
    let s = Settings {
        starts: 20,
        polish: true,
        ..Default::default()
    };
    let sel = multistart(&x, DCriterion::new, Algorithm::Eae, &s).unwrap();
    println!(
        "multistart 20 + polish: {:.4} in {:?}",
        sel.ln_oid / l10,
        t0.elapsed()
    );
    for alg in [Algorithm::Fedorov, Algorithm::Detmax] {
        let t0 = Instant::now();
        let s = Settings::default();
        let sel = multistart(&x, DCriterion::new, alg, &s).unwrap();
        println!(
            "{alg:?}: {:.4} in {:?} ({} steps)",
            sel.ln_oid / l10,
            t0.elapsed(),
            sel.trace.len()
        );
    }
}
