use activecal::pool::Pool;
use activecal::robot::Robot;
use rand::SeedableRng;
fn main() {
    let r = Robot::puma560();
    let pool = Pool::full(&r, 5).unwrap();
    let t0 = std::time::Instant::now();
    let x = pool.jacobian(&r, &r.nominal);
    println!("jacobian {:?}", t0.elapsed());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let mut best = f64::MIN;
    let mut v = vec![];
    for _ in 0..5000 {
        let d = rand::seq::index::sample(&mut rng, pool.len(), 30).into_vec();
        let m = x.information(&d);
        let llt = m.llt(faer::Side::Lower).unwrap();
        let l = llt.L();
        let ld: f64 = (0..27).map(|i| 2.0 * l[(i, i)].ln()).sum();
        v.push(ld / std::f64::consts::LN_10);
        best = best.max(ld);
    }
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    println!(
        "best log10 {} median {} min {}",
        best / std::f64::consts::LN_10,
        v[2500],
        v[0]
    );
}
