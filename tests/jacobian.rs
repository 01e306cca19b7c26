//! The analytic identification Jacobian against central finite differences
//! over the whole 15,625-pose PUMA lattice, at both parameter sets.

use activecal::kinematics::position;
use activecal::model::{ParamSet, Robot};
use activecal::observability::identifiability;
use activecal::pool::Pool;

#[test]
fn analytic_jacobian_matches_central_differences_on_whole_lattice() {
    let robot = Robot::puma560();
    let pool = Pool::full(&robot, 5).unwrap();
    let p = robot.n_unknowns();
    for set in [ParamSet::Nominal, ParamSet::Real] {
        let table = robot.params(set);
        let x = pool.jacobian(&robot, table);
        let m = x.mat();
        // Central differences: truncation error ~h²·|p'''| ≈ 1e-12·20 m and
        // rounding ~ε·|p|/h ≈ 2e-16·21/1e-6 ≈ 4e-9 m per entry. Column norms
        // over the lattice are ≥ 1 (125 poses · ≥0.1 m), so the relative
        // column error is far below the 1e-7 required.
        let h = 1e-6;
        let mut err = vec![0.0f64; p];
        let mut norm = vec![0.0f64; p];
        for k in 0..pool.len() {
            let q = pool.q(k);
            for (c, &u) in robot.unknowns.iter().enumerate() {
                let mut plus = table.clone();
                plus.set(u, table.get(u) + h);
                let mut minus = table.clone();
                minus.set(u, table.get(u) - h);
                let fd = (position(&robot, &plus, &q) - position(&robot, &minus, &q)) / (2.0 * h);
                for r in 0..3 {
                    let a = m[(3 * k + r, c)];
                    err[c] += (a - fd[r]).powi(2);
                    norm[c] += a * a;
                }
            }
        }
        let names = robot.parameter_names();
        for c in 0..p {
            let rel = (err[c] / norm[c]).sqrt();
            assert!(
                rel < 1e-7,
                "{set:?} column {}: relative error {rel:e}",
                names[c]
            );
        }
    }
}

fn random_designs(n_designs: usize, size: usize, pool_len: usize) -> Vec<Vec<usize>> {
    // A small LCG keeps this test independent of the rand crate's streams.
    let mut s: u64 = 0x2545_F491_4F6C_DD1D;
    (0..n_designs)
        .map(|_| {
            (0..size)
                .map(|_| {
                    s = s
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (s >> 33) as usize % pool_len
                })
                .collect()
        })
        .collect()
}

#[test]
fn puma_unknowns_identifiable_from_random_30_pose_designs() {
    let robot = Robot::puma560();
    let pool = Pool::full(&robot, 5).unwrap();
    let x = pool.jacobian(&robot, &robot.nominal);
    for design in random_designs(20, 30, pool.len()) {
        let id = identifiability(&robot, &x.select(&design));
        assert_eq!(id.rank, 27, "design {design:?}: {:?}", id.unidentifiable);
        assert!(id.unidentifiable.is_empty());
    }
}

#[test]
fn alpha_5_is_named_unidentifiable() {
    let mut names: Vec<String> = Robot::puma560().parameter_names();
    names.push("alpha_5".into());
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let robot = Robot::puma560().with_unknown_names(&refs).unwrap();
    assert_eq!(robot.n_unknowns(), 28);
    let pool = Pool::full(&robot, 5).unwrap();
    let x = pool.jacobian(&robot, &robot.nominal);
    let design = &random_designs(1, 30, pool.len())[0];
    let id = identifiability(&robot, &x.select(design));
    assert_eq!(id.rank, 27);
    assert_eq!(id.unidentifiable, vec!["alpha_5".to_string()]);
    let err =
        activecal::observability::require_identifiable(&robot, &x.select(design)).unwrap_err();
    assert!(err.to_string().contains("alpha_5"));
}
