use activecal::pool::Pool;
use activecal::robot::Robot;
use activecal::select::random_search;
fn main() {
    let r = Robot::puma560();
    let pool = Pool::full(&r, 5).unwrap();
    let all: Vec<usize> = (0..pool.len()).collect();
    for (name, table) in [("nominal", &r.nominal), ("real", &r.real)] {
        let x = pool.jacobian(&r, table);
        for n in [20, 25, 30] {
            let rs = random_search(&x, &all, &[], n, 5000, 1);
            let mut v = rs.ln_oid.clone();
            v.sort_by(f64::total_cmp);
            let l = std::f64::consts::LN_10;
            println!(
                "{name} N={n}: best {:.3} median {:.3} min {:.3}",
                rs.best_ln_oid / l,
                v[2500] / l,
                v[0] / l
            );
        }
    }
}
