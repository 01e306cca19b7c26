use activecal::bound::{BoundSettings, conic::ConicSettings, relaxation_bound};
use activecal::pool::Pool;
use activecal::robot::Robot;
fn main() {
    let r = Robot::puma560();
    let pool = Pool::full(&r, 3).unwrap();
    let x = pool.jacobian(&r, &r.nominal);
    let s = BoundSettings::builder()
        .direct_limit(0)
        .screen_extra(60)
        .conic(ConicSettings {
            verbose: false,
            chordal_merge: std::env::var("MERGE").unwrap_or("clique_graph".into()),
            ..ConicSettings::default()
        })
        .build()
        .unwrap();
    let b = relaxation_bound(&x, 12, &s).unwrap();
    println!("{:?} {:?}", b.first_order, b.conic);
}
