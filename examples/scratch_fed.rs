use activecal::criterion::*;
use activecal::pool::Pool;
use activecal::robot::Robot;
use std::time::Instant;
fn main() {
    let r = Robot::puma560();
    let pool = Pool::full(&r, 5).unwrap();
    let x = pool.jacobian(&r, &r.nominal);
    let design: Vec<usize> = (0..30).map(|i| i * 517 % 15625).collect();
    let st = InfoState::new(&x, &design, StateSettings::default()).unwrap();
    let mut c = DCriterion::new();
    let all: Vec<usize> = (0..15625).collect();
    let mut out = vec![0.0; 15625 * 30];
    for _ in 0..3 {
        let t0 = Instant::now();
        c.price_exchanges(&x, &st, &design, &all, &mut out);
        println!("exchanges {:?}", t0.elapsed());
    }
    let t0 = Instant::now();
    let v = c.variances(&x, &st);
    let _ = v.cross_terms(&x, &st, &design);
    println!("cross {:?}", t0.elapsed());
    let mut out = vec![0.0; 15625];
    let t0 = Instant::now();
    c.price_adds(&x, &st, &all, &mut out);
    println!("adds {:?}", t0.elapsed());
}
