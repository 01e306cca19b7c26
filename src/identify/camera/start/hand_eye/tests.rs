use super::*;
use crate::identify::simulate::{fill_standard_normal, trial_rng};

fn iso(t: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// `n` seeded random flange poses: rotations up to ~π about random axes,
/// positions within ±0.5 m.
fn flanges(n: usize, seed: u64) -> Vec<Isometry3<f64>> {
    let mut rng = trial_rng(seed, 0);
    let mut v = vec![0.0; 6 * n];
    fill_standard_normal(&mut rng, &mut v);
    v.chunks_exact(6)
        .map(|c| iso([0.3 * c[0], 0.3 * c[1], 0.3 * c[2]], [c[3], c[4], c[5]]))
        .collect()
}

/// `Bᵢ = Z⁻¹ Aᵢ X`, the measurements a true `X`, `Z` give.
fn measured(a: &[Isometry3<f64>], x: &Isometry3<f64>, z: &Isometry3<f64>) -> Vec<Isometry3<f64>> {
    a.iter().map(|a| z.inverse() * a * x).collect()
}

fn miss(a: &Isometry3<f64>, b: &Isometry3<f64>) -> (f64, f64) {
    (
        (a.translation.vector - b.translation.vector).norm(),
        a.rotation.angle_to(&b.rotation),
    )
}

/// The true placements of the two mountings' roles: eye-to-hand `X` the
/// target on the flange (10 cm, turned half a turn) and `Z` the camera
/// 1.5 m off in the base; eye-in-hand `X` the camera on the flange and
/// `Z` the board in the base.
fn cases() -> [(&'static str, Isometry3<f64>, Isometry3<f64>); 2] {
    [
        (
            "eye-to-hand",
            iso([0.004, -0.003, 0.1], [3.1, 0.02, 0.03]),
            iso([1.2, 0.6, 0.9], [-2.07, 0.03, 2.08]),
        ),
        (
            "eye-in-hand",
            iso([0.06, 0.0, 0.03], [0.0, 0.0, std::f64::consts::FRAC_PI_2]),
            iso([0.45, 0.15, 0.0], [3.1, 0.0, 0.03]),
        ),
    ]
}

/// Noise-free, the closed form is exact: `X` and `Z` to rounding (the
/// SVDs of well-conditioned 9 × 9 and 3n × 6 matrices: ≈ 1e-15), well
/// inside 1e-9; with 3 poses (the fewest) too.
#[test]
fn noise_free_poses_give_both_placements() {
    for (name, x, z) in cases() {
        for n in [3, 20] {
            let a = flanges(n, 3);
            let b = measured(&a, &x, &z);
            let (xe, ze) = solve_ax_zb(&a, &b).unwrap();
            for (what, e, t) in [("X", xe, x), ("Z", ze, z)] {
                let (dt, dr) = miss(&e, &t);
                assert!(
                    dt < 1e-9 && dr < 1e-9,
                    "{name} {n} poses {what}: {dt} m, {dr} rad"
                );
            }
        }
    }
}

/// One placement known, the other is each pose's and their mean: exact
/// noise-free, even when the flange keeps its orientation (where the
/// closed form of both has no solution).
#[test]
fn one_known_placement_gives_the_other() {
    for (name, x, z) in cases() {
        let r = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.1);
        let a: Vec<Isometry3<f64>> = [[0.4, 0.1, 0.3], [0.5, -0.1, 0.2], [0.3, 0.2, 0.5]]
            .iter()
            .map(|t| Isometry3::from_parts(Translation3::new(t[0], t[1], t[2]), r))
            .collect();
        let b = measured(&a, &x, &z);
        let (dt, dr) = miss(&solve_x_given_z(&a, &b, &z), &x);
        assert!(dt < 1e-12 && dr < 1e-12, "{name} X: {dt} m, {dr} rad");
        let (dt, dr) = miss(&solve_z_given_x(&a, &b, &x), &z);
        assert!(dt < 1e-12 && dr < 1e-12, "{name} Z: {dt} m, {dr} rad");
        assert!(matches!(
            solve_ax_zb(&a, &b),
            Err(HandEyeError::OneAxis { .. })
        ));
    }
}

/// Flange orientations that all turn about one axis (a wrist joint
/// alone) or not at all leave a turn of both placements about that axis
/// free: refused, the spread 0 to rounding. A spread over two axes
/// passes.
#[test]
fn orientations_about_one_axis_are_refused() {
    let (_, x, z) = cases()[0];
    let base = UnitQuaternion::from_euler_angles(0.2, 0.4, -0.1);
    let about_one: Vec<Isometry3<f64>> = (0..10)
        .map(|i| {
            let r = base * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3 * f64::from(i));
            Isometry3::from_parts(Translation3::new(0.1 * f64::from(i), 0.2, 0.3), r)
        })
        .collect();
    let b = measured(&about_one, &x, &z);
    match solve_ax_zb(&about_one, &b) {
        Err(HandEyeError::OneAxis { spread_deg }) => assert!(spread_deg < 1e-5, "{spread_deg}"),
        other => panic!("{other:?}"),
    }
    let a = flanges(10, 5);
    assert!(orientation_spread(&a.iter().map(rotation).collect::<Vec<_>>()) > 10.0);
    assert_eq!(
        solve_ax_zb(&a[..2], &b[..2]).unwrap_err(),
        HandEyeError::TooFewPoses { poses: 2 }
    );
}
