//! `select --refine`: poses moved continuously off the pool never lower
//! `ln OI_D`, stay inside the joint limits and the pool's filters, and the
//! reported values are those of the refined joint values.

use activecal::criterion::DCriterion;
use activecal::measure::Visibility;
use activecal::model::Robot;
use activecal::pool::{PoolFilter, PoolSpec};
use activecal::select::{RefineSettings, Settings, design_rng, eae, refine};

fn ln_det_of(robot: &Robot, qs: &[Vec<f64>]) -> f64 {
    let x = activecal::blocks::jacobian_of(robot, &robot.nominal, qs.len(), |k, q| {
        q.copy_from_slice(&qs[k]);
    });
    activecal::criterion::design_ln_det(&x, None, &(0..qs.len()).collect::<Vec<_>>()).unwrap()
}

#[test]
fn refinement_never_lowers_ln_det_and_respects_limits_and_filters() {
    let r = Robot::puma560();
    // A box that cuts the workspace: the refined poses must stay inside it.
    let half = Visibility::Box {
        min: [-100.0, -100.0, -100.0],
        max: [100.0, 100.0, 0.5],
    };
    let pool = PoolSpec::lattice(3)
        .with_filter(PoolFilter::Visibility(half.clone()))
        .build(&r, &r.nominal)
        .unwrap();
    let x = pool.jacobian(&r, &r.nominal);
    let settings = RefineSettings::builder().sweeps(2).build().unwrap();
    for seed in 1..=4u64 {
        let sel = eae(
            &x,
            &mut DCriterion::new(),
            &Settings::default(),
            &mut design_rng(seed, 0),
        )
        .unwrap();
        let qs: Vec<Vec<f64>> = sel.poses.iter().map(|&k| pool.q(k)).collect();
        let out = refine(
            &r,
            &r.nominal,
            &r.nominal,
            &pool.spec.filters,
            None,
            &qs,
            &settings,
        )
        .unwrap();
        // The start is the selection's design, recomputed.
        assert!((out.ln_oid_before - sel.ln_oid).abs() < 1e-9 * sel.ln_oid.abs());
        assert!(out.gain > 0.0, "seed {seed}: no gain");
        let refined: Vec<Vec<f64>> = out.poses.iter().map(|p| p.q.clone()).collect();
        // What is reported is what the refined joint values give.
        let direct = ln_det_of(&r, &refined);
        assert!(
            (out.ln_oid - direct).abs() < 1e-9 * direct.abs(),
            "{} vs {direct}",
            out.ln_oid
        );
        assert!(direct >= sel.ln_oid);
        // The per-pose gains add up to the total (tracked vs fresh sums:
        // rounding of ~100 Cholesky factorisations of p = 27).
        let sum: f64 = out.poses.iter().map(|p| p.gain).sum();
        assert!(
            (sum - out.gain).abs() < 1e-8 * direct.abs(),
            "{sum} vs {}",
            out.gain
        );
        for q in &refined {
            for (v, [lo, hi]) in q.iter().zip(&r.limits) {
                assert!(lo <= v && v <= hi);
            }
            let p = activecal::kinematics::position(&r, &r.nominal, q);
            assert!(half.sees(&p), "seed {seed}: a refined pose left the filter");
        }
    }
    // A pose outside the filter to begin with is refused.
    let outside = (0..729)
        .map(|i| pool.lattice().unwrap().q(i).unwrap())
        .find(|q| !half.sees(&activecal::kinematics::position(&r, &r.nominal, q)))
        .unwrap();
    let mut qs: Vec<Vec<f64>> = (0..30).map(|k| pool.q(k)).collect();
    qs[0] = outside;
    assert!(
        refine(
            &r,
            &r.nominal,
            &r.nominal,
            &pool.spec.filters,
            None,
            &qs,
            &settings
        )
        .is_err()
    );
}
