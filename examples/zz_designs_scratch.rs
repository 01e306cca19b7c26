// Scratch: seeded random 30-pose design and the best of 100 random designs by ln det(XᵀX). Not for commit.
use activecal::design::DesignFile;
use activecal::pool::Pool;
use activecal::robot::Robot;
use rand::{RngExt, SeedableRng};
fn random_design(n_pool: usize, n: usize, rng: &mut rand_chacha::ChaCha8Rng) -> Vec<usize> {
    let mut all: Vec<usize> = (0..n_pool).collect();
    for i in 0..n {
        let j = rng.random_range(i..all.len());
        all.swap(i, j);
    }
    all.truncate(n);
    all
}
fn main() {
    let dir = std::env::args().nth(1).unwrap();
    let r = Robot::puma560();
    let pool = Pool::full(&r, 5).unwrap();
    let x = pool.jacobian(&r, &r.nominal);
    let lndet = |d: &[usize]| {
        let m = x.information(d);
        let llt = m.llt(faer::Side::Lower).unwrap();
        let l = llt.L();
        (0..27).map(|i| 2.0 * l[(i, i)].ln()).sum::<f64>()
    };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let first = random_design(pool.len(), 30, &mut rng);
    let mut best = (lndet(&first), first.clone());
    for _ in 1..100 {
        let d = random_design(pool.len(), 30, &mut rng);
        let v = lndet(&d);
        if v > best.0 {
            best = (v, d);
        }
    }
    let idx = |d: &[usize]| d.iter().map(|&k| pool.indices[k]).collect::<Vec<_>>();
    let mut a = DesignFile::new("puma560", 5, idx(&first));
    a.extra
        .insert("ln_det_nominal".into(), lndet(&first).into());
    a.extra.insert(
        "how".into(),
        "random 30 poses, ChaCha8 seed 1, first draw".into(),
    );
    a.write(&std::path::Path::new(&dir).join("random30.json"), true)
        .unwrap();
    let mut b = DesignFile::new("puma560", 5, idx(&best.1));
    b.extra.insert("ln_det_nominal".into(), best.0.into());
    b.extra.insert(
        "how".into(),
        "best of 100 random 30-pose designs by ln det XᵀX (nominal), ChaCha8 seed 1".into(),
    );
    b.write(&std::path::Path::new(&dir).join("best100.json"), true)
        .unwrap();
    println!("random {} best {}", lndet(&first), best.0);
}
