//! Any serial robot: the built-in UR5 and Stanford arms, full-pose
//! measurements, prismatic joints, robot description files (TOML) and URDF
//! import/export, and selection, bounds and calibration on all of them.
//!
//! Tolerances. Positions and rotations that two implementations compose
//! from ~10 rigid transforms of values ≤ 21 m agree to ~100·ε·21 m ≈ 5e-13 m
//! (see `tests/fixtures.rs`), so 1e-12 separates rounding from any real
//! mistake (a wrong parameter moves the point by ≥ 1e-8 m). Central
//! differences with h = 1e-6 err by ~h²·|y'''| ≈ 1e-11 (truncation) plus
//! ε·|y|/h ≈ 5e-9 (rounding at 20 m), so analytic Jacobians are checked to
//! 1e-7 absolute.

use crate::common;

use activecal::blocks::Blocks;
use activecal::bound::{BoundSettings, relaxation_bound};
use activecal::criterion::Indices;
use activecal::criterion::design_ln_det;
use activecal::identify::{LmSettings, identify, simulate, trial_rng};
use activecal::io::robot_toml as file;
use activecal::io::urdf::{self, UrdfOptions};
use activecal::kinematics::{pose, position};
use activecal::measure::JacobianEvaluator;
use activecal::model::{Convention, JointKind, MeasurementKind, ParamSet, ParamTable, Robot};
use activecal::observability::INDEPENDENCE_TOL;
use activecal::observability::require_identifiable;
use activecal::pool::Pool;
use common::eae_design;
use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};
use std::collections::HashMap;
use std::f64::consts::FRAC_PI_2;
use std::path::{Path, PathBuf};

const ALL_BUILTIN: [&str; 6] = [
    "puma560",
    "puma560:pose",
    "ur5",
    "ur5:pose",
    "stanford",
    "stanford:pose",
];

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
}

/// A small LCG: independent of the rand crate's streams.
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Joint values uniform within the limits.
    fn q(&mut self, r: &Robot) -> Vec<f64> {
        r.limits
            .iter()
            .map(|&[lo, hi]| lo + (hi - lo) * self.unit())
            .collect()
    }
}

fn urdf_import(name: &str, m: MeasurementKind) -> Robot {
    let o = UrdfOptions {
        measurement: m,
        ..UrdfOptions::default()
    };
    urdf::load(&fixture(name), &o).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The robots every pipeline test runs on: the six built-ins and URDF
/// imports (UR5 and Stanford-type, point and pose).
fn all_robots() -> Vec<Robot> {
    let mut v: Vec<Robot> = ALL_BUILTIN
        .iter()
        .map(|n| Robot::builtin(n).unwrap())
        .collect();
    for f in ["ur5.urdf", "stanford.urdf"] {
        for m in [MeasurementKind::Point, MeasurementKind::Pose] {
            let mut r = urdf_import(f, m);
            r.name = format!("{f}:{}", m.name());
            v.push(r);
        }
    }
    v
}

// ---------------------------------------------------------------------------
// Built-in arms

#[test]
fn builtin_unknowns_have_the_textbook_count_and_are_identifiable() {
    for name in ALL_BUILTIN {
        let r = Robot::builtin(name).unwrap();
        r.validate().unwrap();
        assert_eq!(r.name, name.replace("puma:", "puma560:"));
        // 4 per revolute joint, 2 per prismatic, +3 (point) or +6 (pose).
        let want = match name {
            "puma560" | "ur5" => 27,
            "puma560:pose" | "ur5:pose" => 30,
            "stanford" => 25,
            "stanford:pose" => 28,
            _ => unreachable!(),
        };
        assert_eq!(r.n_unknowns(), want, "{name}");
        assert_eq!(r.minimal_unknowns(), want, "{name}");
        let id = r.check_identifiable().unwrap();
        assert_eq!(id.rank, want, "{name}");
        // The automatic choice finds as many, and the same ones where the
        // hand-written list prefers nothing else (Stanford: γ_3 for γ_4).
        let auto = r.choose_unknowns(&[]).unwrap();
        assert_eq!(auto.len(), want, "{name}");
        if !name.starts_with("stanford") {
            assert_eq!(auto, r.unknowns, "{name}");
        }
        // Kept and dropped candidates are far from the threshold.
        let walk = r.independence(&[]).unwrap();
        let kept = walk
            .iter()
            .filter(|w| w.1 > INDEPENDENCE_TOL)
            .map(|w| w.1)
            .fold(f64::INFINITY, f64::min);
        let dropped = walk
            .iter()
            .filter(|w| w.1 <= INDEPENDENCE_TOL)
            .map(|w| w.1)
            .fold(0.0, f64::max);
        println!("{name}: smallest kept residual {kept:.2e}, largest dropped {dropped:.2e}");
        assert!(
            kept > 1e-2 && dropped < 1e-14,
            "{name}: {kept:e} {dropped:e}"
        );
    }
}

#[test]
fn puma_is_unchanged_and_its_pose_variant_only_adds_the_tool() {
    let p = Robot::puma560();
    let b = Robot::builtin("puma560").unwrap();
    assert_eq!(p.real, b.real);
    assert_eq!(p.nominal, b.nominal);
    assert_eq!(p.unknowns, b.unknowns);
    assert_eq!(p.measurement, MeasurementKind::Point);
    assert!(
        activecal::io::load_description("puma560")
            .unwrap()
            .visibility
            .is_none()
    );
    assert!(p.frames.iter().all(|f| f.joint_kind == JointKind::Revolute));
    let pp = Robot::builtin("puma560:pose").unwrap();
    assert_eq!(pp.measurement, MeasurementKind::Pose);
    assert_eq!(pp.rows_per_pose(), 6);
    for i in 0..7 {
        assert_eq!(pp.real.rows[i], p.real.rows[i]);
        assert_eq!(pp.nominal.rows[i], p.nominal.rows[i]);
    }
    assert_eq!(pp.frames[7].convention, Convention::Hayati);
    assert_eq!(pp.real.rows[7], [0.0; 5]);
    // Same point everywhere.
    let mut g = Lcg(3);
    for _ in 0..100 {
        let q = g.q(&p);
        for set in [ParamSet::Nominal, ParamSet::Real] {
            assert_eq!(
                position(&p, p.params(set), &q),
                position(&pp, pp.params(set), &q)
            );
        }
    }
    let extra: Vec<String> = pp
        .parameter_names()
        .into_iter()
        .filter(|n| !p.parameter_names().contains(n))
        .collect();
    assert_eq!(extra, ["alpha_5", "gamma_6", "beta_6"]);
}

/// An independent standard-DH evaluation: `base · Π Rz(θ_i) Tz(d_i)
/// Tx(a_i) Rx(α_i) · A_tool`, with prismatic joints adding `q` to `d`.
fn dh_fk(
    base: Isometry3<f64>,
    table: &[(f64, f64, f64, f64, bool)],
    tool_a: f64,
    q: &[f64],
) -> Isometry3<f64> {
    let mut t = base;
    for (i, &(theta, d, a, alpha, prismatic)) in table.iter().enumerate() {
        let (th, dd) = if prismatic {
            (theta, d + q[i])
        } else {
            (theta + q[i], d)
        };
        let a = if i == table.len() - 1 { a + tool_a } else { a };
        t = t
            * Isometry3::rotation(Vector3::z() * th)
            * Translation3::new(0.0, 0.0, dd)
            * Translation3::new(a, 0.0, 0.0)
            * Isometry3::rotation(Vector3::x() * alpha);
    }
    t
}

#[test]
fn ur5_and_stanford_nominal_models_are_the_published_dh_tables() {
    // Sensor frame: Rz(π/2) Tx(2 m).
    let base = Isometry3::rotation(Vector3::z() * FRAC_PI_2) * Translation3::new(2.0, 0.0, 0.0);
    // Universal Robots' UR5 table (θ offset, d, a, α); a6 gets the 0.1 m target offset.
    let ur5 = [
        (0.0, 0.089159, 0.0, FRAC_PI_2, false),
        (0.0, 0.0, -0.425, 0.0, false),
        (0.0, 0.0, -0.39225, 0.0, false),
        (0.0, 0.10915, 0.0, FRAC_PI_2, false),
        (0.0, 0.09465, 0.0, -FRAC_PI_2, false),
        (0.0, 0.0823, 0.0, 0.0, false),
    ];
    // The Stanford arm (Paul 1981; Corke's mdl_stanford lengths).
    let stanford = [
        (0.0, 0.412, 0.0, -FRAC_PI_2, false),
        (0.0, 0.154, 0.0, FRAC_PI_2, false),
        (-FRAC_PI_2, 0.0, 0.0, 0.0, true),
        (0.0, 0.0, 0.0, -FRAC_PI_2, false),
        (0.0, 0.0, 0.0, FRAC_PI_2, false),
        (0.0, 0.263, 0.0, 0.0, false),
    ];
    let mut g = Lcg(11);
    for (name, table) in [("ur5:pose", &ur5), ("stanford:pose", &stanford)] {
        let r = Robot::builtin(name).unwrap();
        for _ in 0..500 {
            let q = g.q(&r);
            let want = dh_fk(base, table, 0.1, &q);
            let (rot, p) = pose(&r, &r.nominal, &q);
            assert!((p - want.translation.vector).norm() < 1e-12, "{name} {q:?}");
            let dr = (rot - want.rotation.to_rotation_matrix().into_inner())
                .abs()
                .max();
            assert!(dr < 1e-12, "{name} {q:?}: {dr:e}");
        }
    }
    // The real robots differ from the nominal ones by at most 5 mm / 5 mrad.
    for name in ["ur5", "stanford"] {
        let r = Robot::builtin(name).unwrap();
        let mut differs = 0;
        for (a, b) in r.real.rows.iter().zip(&r.nominal.rows) {
            for c in 0..5 {
                assert!((a[c] - b[c]).abs() <= 5e-3 + 1e-15);
                differs += usize::from(a[c] != b[c]);
            }
        }
        assert!(differs > 20, "{name}: {differs}");
    }
}

// ---------------------------------------------------------------------------
// Jacobians

/// Rotation vector `log(a · bᵀ)`, accurate for small angles too (an
/// `acos` of the trace loses half the digits near 0).
fn rot_log(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Vector3<f64> {
    let r = a * b.transpose();
    let w = Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) / 2.0;
    let s = w.norm();
    if s == 0.0 {
        return Vector3::zeros();
    }
    let theta = s.atan2((r.trace() - 1.0) / 2.0);
    w * (theta / s)
}

fn check_identification_jacobian(r: &Robot, table: &ParamTable, q: &[f64]) {
    let (p, t) = (r.n_unknowns(), r.rows_per_pose());
    let mut jac = vec![0.0; t * p];
    let (rot0, p0) = JacobianEvaluator::new(r, table).eval_pose(q, &mut jac);
    let (rot1, p1) = pose(r, table, q);
    assert_eq!((rot0, p0), (rot1, p1));
    let h = 1e-6;
    for (c, &u) in r.unknowns.iter().enumerate() {
        let mut plus = table.clone();
        plus.set(u, table.get(u) + h);
        let mut minus = table.clone();
        minus.set(u, table.get(u) - h);
        let (rp, pp) = pose(r, &plus, q);
        let (rm, pm) = pose(r, &minus, q);
        let lin = (pp - pm) / (2.0 * h);
        let ang = rot_log(&rp, &rm) / (2.0 * h);
        for k in 0..3 {
            let e = (jac[k * p + c] - lin[k]).abs();
            assert!(
                e < 1e-7,
                "{} {}: position row {k}: {e:e}",
                r.name,
                r.param_name(u)
            );
            if t == 6 {
                let e = (jac[(3 + k) * p + c] - ang[k]).abs();
                assert!(
                    e < 1e-7,
                    "{} {}: orientation row {k}: {e:e}",
                    r.name,
                    r.param_name(u)
                );
            }
        }
    }
    // Joint Jacobian: revolute and prismatic columns, orientation rows.
    let dof = r.dof();
    let mut jj = vec![0.0; t * dof];
    JacobianEvaluator::new(r, table).joint_jacobian(q, &mut jj);
    for j in 0..dof {
        let mut qp = q.to_vec();
        qp[j] += h;
        let mut qm = q.to_vec();
        qm[j] -= h;
        let (rp, pp) = pose(r, table, &qp);
        let (rm, pm) = pose(r, table, &qm);
        let lin = (pp - pm) / (2.0 * h);
        let ang = rot_log(&rp, &rm) / (2.0 * h);
        for k in 0..3 {
            assert!(
                (jj[k * dof + j] - lin[k]).abs() < 1e-7,
                "{} q{}",
                r.name,
                j + 1
            );
            if t == 6 {
                assert!(
                    (jj[(3 + k) * dof + j] - ang[k]).abs() < 1e-7,
                    "{} q{}",
                    r.name,
                    j + 1
                );
            }
        }
    }
}

#[test]
fn pose_and_prismatic_jacobians_match_central_differences() {
    let mut g = Lcg(5);
    for r in all_robots() {
        for set in [ParamSet::Nominal, ParamSet::Real] {
            for _ in 0..40 {
                let q = g.q(&r);
                check_identification_jacobian(&r, r.params(set), &q);
            }
        }
    }
}

#[test]
fn pool_jacobian_has_six_rows_per_pose_for_pose_robots() {
    for name in ["ur5", "ur5:pose", "stanford:pose"] {
        let r = Robot::builtin(name).unwrap();
        let pool = Pool::full(&r, 2).unwrap();
        let x = pool.jacobian(&r, &r.nominal);
        assert_eq!(x.t(), r.rows_per_pose());
        assert_eq!(x.n_poses(), 64);
        let mut jac = vec![0.0; x.t() * r.n_unknowns()];
        JacobianEvaluator::new(&r, &r.nominal).eval(&pool.q(37), &mut jac);
        let b = x.block(37);
        for row in 0..x.t() {
            for c in 0..r.n_unknowns() {
                assert_eq!(b[(row, c)], jac[row * r.n_unknowns() + c]);
            }
        }
    }
}

/// `orientation_scale` w multiplies the orientation rows of the pool
/// Jacobian and nothing else, so `ln det XᵀX` of a design moves with it; a
/// point robot's Jacobian ignores it. Exact: one multiplication per entry.
#[test]
fn orientation_scale_weighs_the_orientation_rows_only() {
    let r = Robot::builtin("stanford:pose").unwrap();
    let mut w = r.clone();
    w.orientation_scale = 0.25;
    let pool = Pool::full(&r, 2).unwrap();
    let (x, xw) = (pool.jacobian(&r, &r.nominal), pool.jacobian(&w, &w.nominal));
    for k in [0, 17, 63] {
        let (b, bw) = (x.block(k), xw.block(k));
        for row in 0..6 {
            for c in 0..r.n_unknowns() {
                let f = if row < 3 { 1.0 } else { 0.25 };
                assert_eq!(bw[(row, c)], f * b[(row, c)], "pose {k} row {row}");
            }
        }
    }
    let design: Vec<usize> = (0..40).collect();
    let (l, lw) = (
        design_ln_det(&x, None, &design).unwrap(),
        design_ln_det(&xw, None, &design).unwrap(),
    );
    assert!(lw < l - 1.0, "{lw} vs {l}");
    let mut p = Robot::stanford();
    let before = Pool::full(&p, 2).unwrap().jacobian(&p, &p.nominal);
    p.orientation_scale = 0.25;
    let after = Pool::full(&p, 2).unwrap().jacobian(&p, &p.nominal);
    assert_eq!(before.mat(), after.mat());
    // Zero, negative and non-finite weights are refused.
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        p.orientation_scale = bad;
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("orientation_scale"), "{e}");
    }
}

// ---------------------------------------------------------------------------
// URDF

/// `Rz(y) Ry(p) Rx(r)`, URDF's rpy, built from three axis rotations.
fn rpy_rotation(r: f64, p: f64, y: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), y)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), p)
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), r)
}

/// Direct URDF forward kinematics: `Π origin_k · motion_k(q_k)` from the root
/// to `tip`, the motion a rotation about or a translation along the joint's
/// (normalised) axis.
fn urdf_fk(path: &Path, tip: &str, q: &[f64]) -> Isometry3<f64> {
    let u = urdf_rs::read_file(path).unwrap();
    let by_child: HashMap<&str, &urdf_rs::Joint> = u
        .joints
        .iter()
        .map(|j| (j.child.link.as_str(), j))
        .collect();
    let mut chain = Vec::new();
    let mut at = tip;
    while let Some(j) = by_child.get(at) {
        chain.push(*j);
        at = &j.parent.link;
    }
    chain.reverse();
    let mut t = Isometry3::identity();
    let mut k = 0;
    for j in chain {
        let [x, y, z] = j.origin.xyz.0;
        let [rr, pp, yy] = j.origin.rpy.0;
        t *= Isometry3::from_parts(Translation3::new(x, y, z), rpy_rotation(rr, pp, yy));
        let axis = Unit::new_normalize(Vector3::from(j.axis.xyz.0));
        use urdf_rs::JointType as T;
        match j.joint_type {
            T::Revolute | T::Continuous => {
                t *= Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_axis_angle(&axis, q[k]),
                );
                k += 1;
            }
            T::Prismatic => {
                t *= Translation3::from(axis.into_inner() * q[k]);
                k += 1;
            }
            _ => {}
        }
    }
    assert_eq!(k, q.len());
    t
}

fn assert_same_fk(r: &Robot, want: &Isometry3<f64>, q: &[f64], tol: f64) {
    let (rot, p) = pose(r, &r.nominal, q);
    let dp = (p - want.translation.vector).norm();
    let dr = (rot - want.rotation.to_rotation_matrix().into_inner())
        .abs()
        .max();
    assert!(dp < tol, "{}: q={q:?}: position off by {dp:e}", r.name);
    assert!(dr < tol, "{}: q={q:?}: rotation off by {dr:e}", r.name);
}

#[test]
fn puma_urdf_fixture_is_the_nominal_model_and_imports_to_its_positions() {
    let puma = Robot::puma560();
    let text = urdf::to_urdf(&puma, &puma.nominal).unwrap();
    let path = fixture("puma560.urdf");
    if std::env::var_os("ACTIVECAL_REGEN_ROBOT_FIXTURES").is_some() {
        std::fs::write(&path, &text).unwrap();
    }
    let stored = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        stored, text,
        "fixtures/puma560.urdf is stale: rerun with ACTIVECAL_REGEN_ROBOT_FIXTURES=1"
    );
    for m in [MeasurementKind::Point, MeasurementKind::Pose] {
        let r = urdf_import("puma560.urdf", m);
        assert_eq!(r.dof(), 6);
        assert_eq!(r.limits, puma.limits);
        assert_eq!(r.n_unknowns(), r.minimal_unknowns());
        assert_eq!(
            r.n_unknowns(),
            if m == MeasurementKind::Point { 27 } else { 30 }
        );
        // Equal to the built-in model on the whole 5-level lattice and 2000
        // random joint vectors (rotations too: the tip is frame 6).
        let lattice = Pool::full(&puma, 5).unwrap();
        let mut g = Lcg(17);
        let mut worst = 0.0f64;
        for k in 0..lattice.len() + 2000 {
            let q = if k < lattice.len() {
                lattice.q(k)
            } else {
                g.q(&puma)
            };
            let (rot, p) = pose(&r, &r.nominal, &q);
            let (rot0, p0) = pose(&puma, &puma.nominal, &q);
            worst = worst.max((p - p0).norm());
            assert!((p - p0).norm() < 1e-12, "q={q:?}: {:e}", (p - p0).norm());
            assert!((rot - rot0).abs().max() < 1e-12);
        }
        println!("puma560.urdf ({m:?}): max |Δp| {worst:.1e} m over 17,625 poses");
    }
}

#[test]
fn urdf_imports_reproduce_direct_urdf_kinematics() {
    let mut g = Lcg(23);
    for (file, tip) in [
        ("ur5.urdf", "target"),
        ("stanford.urdf", "target"),
        ("puma560.urdf", "tip"),
    ] {
        for m in [MeasurementKind::Point, MeasurementKind::Pose] {
            let r = urdf_import(file, m);
            r.validate().unwrap();
            // Generic chains: the textbook number of unknowns.
            assert_eq!(r.n_unknowns(), r.minimal_unknowns(), "{file} {m:?}");
            r.check_identifiable().unwrap();
            let mut worst = 0.0f64;
            for _ in 0..2000 {
                let q = g.q(&r);
                let want = urdf_fk(&fixture(file), tip, &q);
                assert_same_fk(&r, &want, &q, 1e-12);
                worst = worst.max((position(&r, &r.nominal, &q) - want.translation.vector).norm());
            }
            println!(
                "{file} ({m:?}): {} unknowns; frames {}; max |Δp| {worst:.1e} m",
                r.n_unknowns(),
                r.frames
                    .iter()
                    .map(|f| format!("{}:{:?}", f.label, f.convention))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
        }
    }
}

#[test]
fn urdf_conventions_follow_the_parallel_axes() {
    // UR5: shoulder, elbow and wrist-1 axes are parallel → Hayati for the
    // frames of joints 2 and 3; the root z is joint 1's axis → the `m` frame.
    let r = urdf_import("ur5.urdf", MeasurementKind::Point);
    let conv: Vec<(&str, Convention)> = r
        .frames
        .iter()
        .map(|f| (f.label.as_str(), f.convention))
        .collect();
    use Convention::{Dh, Hayati};
    assert_eq!(
        conv,
        [
            ("m", Dh),
            ("base", Dh),
            ("shoulder_pan_joint", Dh),
            ("shoulder_lift_joint", Hayati),
            ("elbow_joint", Hayati),
            ("wrist_1_joint", Dh),
            ("wrist_2_joint", Dh),
            ("wrist_3_joint", Dh),
            ("tool", Hayati),
        ]
    );
    assert!(
        r.unknowns.iter().all(|u| u.frame != 0),
        "the m frame has no unknowns"
    );
    let s = urdf_import("stanford.urdf", MeasurementKind::Point);
    let boom = s.frames.iter().find(|f| f.label == "boom_slide").unwrap();
    assert_eq!(boom.joint_kind, JointKind::Prismatic);
    assert_eq!(boom.convention, Hayati); // the roll axis is coaxial with the boom
    assert_eq!(s.limits[2], [0.3, 1.0]);
    assert_eq!(s.limits[5], urdf::CONTINUOUS_RANGE); // continuous
    // A threshold above 90° is refused; a tiny one turns Hayati frames into DH.
    let bad = UrdfOptions {
        parallel_threshold: 2.0,
        ..UrdfOptions::default()
    };
    assert!(urdf::load(&fixture("ur5.urdf"), &bad).is_err());
}

#[test]
fn to_urdf_round_trips_every_builtin() {
    let mut g = Lcg(29);
    for name in ALL_BUILTIN {
        let r = Robot::builtin(name).unwrap();
        for set in [ParamSet::Nominal, ParamSet::Real] {
            let text = urdf::to_urdf(&r, r.params(set)).unwrap();
            let o = UrdfOptions {
                measurement: r.measurement,
                ..UrdfOptions::default()
            };
            let back = urdf::parse(&text, name, &o).unwrap();
            // At the nominal table the URDF's frames carry every unknown of
            // the built-in; at the real one, the UR5's tool frame (a Hayati
            // frame turned −90° by β) leaves α_tool a pivot of 7.6e-7 on
            // generic configurations, whose set fails the rank rule: it is
            // dropped (issue #39: choosing and checking agree).
            match set {
                ParamSet::Nominal => assert_eq!(back.n_unknowns(), r.n_unknowns(), "{name}"),
                ParamSet::Real => assert!(
                    back.n_unknowns() + 1 >= r.n_unknowns() && back.n_unknowns() <= r.n_unknowns(),
                    "{name}: {} of {}",
                    back.n_unknowns(),
                    r.n_unknowns()
                ),
            }
            back.check_identifiable().unwrap();
            assert_eq!(back.limits, r.limits);
            for _ in 0..300 {
                let q = g.q(&r);
                let (rot, p) = pose(&back, &back.nominal, &q);
                let (rot0, p0) = pose(&r, r.params(set), &q);
                assert!((p - p0).norm() < 1e-12, "{name}: {:e}", (p - p0).norm());
                assert!((rot - rot0).abs().max() < 1e-12);
            }
        }
    }
}

#[test]
fn urdf_rpy_is_exact_near_gimbal_lock() {
    for pitch in [FRAC_PI_2, -FRAC_PI_2, FRAC_PI_2 - 1e-9, 0.3, -1.2] {
        for (r, y) in [(0.2, -0.7), (-2.9, 3.0), (0.0, 0.0)] {
            let rot = rpy_rotation(r, pitch, y).to_rotation_matrix();
            let a = urdf::rpy(&rot);
            let back = rpy_rotation(a[0], a[1], a[2]).to_rotation_matrix();
            let e = (rot.matrix() - back.matrix()).abs().max();
            assert!(e < 1e-15 * 8.0, "pitch {pitch}: {e:e}");
        }
    }
}

fn urdf_err(text: &str, tip: Option<&str>) -> String {
    let o = UrdfOptions {
        tip: tip.map(str::to_string),
        ..UrdfOptions::default()
    };
    urdf::parse(text, "t.urdf", &o).unwrap_err().to_string()
}

/// A URDF of the given joints (links are implied by them).
fn mini_urdf(joints: &str) -> String {
    format!("<robot name=\"t\">\n{joints}</robot>")
}

const J_AB: &str = r#"<joint name="j1" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0.2" rpy="0 0.4 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="0" velocity="0"/></joint>"#;
const J_CD: &str = r#"<joint name="j3" type="fixed"><parent link="c"/><child link="d"/><origin xyz="0.1 0.05 0.2" rpy="0 0 0"/></joint>"#;
const J_BC: &str = r#"<joint name="j2" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0.5 0 0" rpy="1.2 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="0" velocity="0"/></joint>"#;

#[test]
fn malformed_urdf_files_get_clear_errors() {
    let cases: Vec<(String, Option<&str>, &str)> = vec![
        ("<robot name=\"x\"><joint".into(), None, "not a valid URDF"),
        (
            mini_urdf(&format!(
                "{J_AB}{J_BC}<joint name=\"j3\" type=\"fixed\"><parent link=\"b\"/><child link=\"d\"/></joint>"
            )),
            None,
            "candidate tips: c (2 joints), d (1 joint)",
        ),
        (
            mini_urdf(&format!("{J_AB}{J_BC}")),
            Some("zz"),
            "tip link 'zz' is not in the URDF",
        ),
        (
            mini_urdf(&J_AB.replace("revolute", "floating")),
            None,
            "joint 'j1' is Floating",
        ),
        (
            mini_urdf(&J_AB.replace("lower=\"-1\" upper=\"1\"", "lower=\"1\" upper=\"-1\"")),
            None,
            "joint 'j1': inverted limits [1, -1]",
        ),
        (
            mini_urdf(&J_AB.replace(
                "<limit lower=\"-1\" upper=\"1\" effort=\"0\" velocity=\"0\"/>",
                "<limit effort=\"0\" velocity=\"0\"/>",
            )),
            None,
            "joint 'j1': empty range",
        ),
        (
            mini_urdf(&J_AB.replace("<axis xyz=\"0 0 1\"/>", "<axis xyz=\"0 0 0\"/>")),
            None,
            "joint 'j1': the axis",
        ),
        (
            mini_urdf(&J_AB.replace("0.3 0 0.2", "0.3 nan 0.2")),
            None,
            "joint 'j1': the origin is not finite",
        ),
        (
            mini_urdf(&format!(
                "{J_AB}<joint name=\"j2\" type=\"fixed\"><parent link=\"c\"/><child link=\"d\"/></joint>"
            )),
            None,
            "root links",
        ),
        (
            mini_urdf(
                r#"<joint name="f" type="fixed"><parent link="a"/><child link="b"/></joint>"#,
            ),
            None,
            "no revolute or prismatic joint",
        ),
        (
            mini_urdf(&format!(
                "{J_AB}{}",
                J_BC.replace("<limit", "<mimic joint=\"j1\"/><limit")
            )),
            None,
            "joint 'j2' mimics another joint",
        ),
    ];
    for (text, tip, want) in cases {
        let e = urdf_err(&text, tip);
        assert!(e.starts_with("t.urdf: "), "{e}");
        assert!(e.contains(want), "want '{want}' in: {e}");
    }
    // A valid two-joint chain with a tip off the last axis imports; its point
    // sees 4·2 + 3 = 11 unknowns. With the tip on the last axis (link c) the
    // point does not move with joint 2 at the nominal parameters, and only 9
    // are identifiable (the chooser finds them; no error).
    let on_axis = urdf::parse(
        &mini_urdf(&format!("{J_AB}{J_BC}")),
        "t",
        &UrdfOptions::default(),
    )
    .unwrap();
    println!(
        "tip on the last axis: {}",
        on_axis.parameter_names().join(" ")
    );
    assert_eq!(on_axis.n_unknowns(), 9);
    let ok = urdf::parse(
        &mini_urdf(&format!("{J_AB}{J_BC}{J_CD}")),
        "t",
        &UrdfOptions::default(),
    )
    .unwrap();
    assert_eq!(ok.n_unknowns(), 11);
}

// ---------------------------------------------------------------------------
// Robot description files (TOML)

#[test]
fn toml_round_trips_every_builtin_bit_for_bit() {
    for name in ALL_BUILTIN {
        let r = Robot::builtin(name).unwrap();
        let text = file::to_toml(&r);
        let back = file::parse(&text, name, None).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_eq!(back.name, r.name);
        assert_eq!(back.real, r.real, "{name}");
        assert_eq!(back.nominal, r.nominal, "{name}");
        assert_eq!(back.unknowns, r.unknowns, "{name}");
        assert_eq!(back.limits, r.limits, "{name}");
        assert_eq!(back.measurement, r.measurement);
        assert_eq!(back.orientation_scale, r.orientation_scale);
        for (a, b) in back.frames.iter().zip(&r.frames) {
            assert_eq!(
                (&a.label, a.convention, a.joint, a.joint_kind),
                (&b.label, b.convention, b.joint, b.joint_kind)
            );
        }
    }
}

#[test]
fn toml_fixtures_load() {
    // fixtures/puma560.toml is the built-in PUMA written by to_toml.
    let puma = Robot::puma560();
    let path = fixture("puma560.toml");
    if std::env::var_os("ACTIVECAL_REGEN_ROBOT_FIXTURES").is_some() {
        std::fs::write(&path, file::to_toml(&puma)).unwrap();
    }
    let r = activecal::io::load_robot(path.to_str().unwrap()).unwrap();
    assert_eq!(
        (&r.real, &r.nominal, &r.unknowns, &r.limits),
        (&puma.real, &puma.nominal, &puma.unknowns, &puma.limits)
    );
    // The hand-written SCARA: all axes parallel, a prismatic quill, automatic
    // unknowns: 4R + 2P + 3 = 17 of them, no d along the parallel axes but
    // the last frame's.
    let s = activecal::io::load_robot(fixture("scara.toml").to_str().unwrap()).unwrap();
    assert_eq!(s.dof(), 4);
    assert_eq!(s.frames[3].joint_kind, JointKind::Prismatic);
    assert!((s.limits[0][1] - 105f64.to_radians()).abs() < 1e-15);
    s.check_identifiable().unwrap();
    println!(
        "scara: {} unknowns (4R+2P+3 = {}): {}",
        s.n_unknowns(),
        s.minimal_unknowns(),
        s.parameter_names().join(" ")
    );
    assert_eq!(s.n_unknowns(), 17);
    assert_eq!(s.minimal_unknowns(), 17);
    // A description importing a URDF, measured in full pose, with a region.
    let path = fixture("ur5_pose.toml");
    let u = activecal::io::load_robot(path.to_str().unwrap()).unwrap();
    assert_eq!(u.name, path.to_str().unwrap()); // loaded by path: named by it
    assert_eq!(file::load(&path).unwrap().name, "ur5-urdf:pose");
    assert_eq!(u.rows_per_pose(), 6);
    assert_eq!(u.n_unknowns(), 30);
    assert!(
        activecal::io::load_description(path.to_str().unwrap())
            .unwrap()
            .visibility
            .is_some()
    );
    let direct = urdf_import("ur5.urdf", MeasurementKind::Pose);
    assert_eq!(u.nominal, direct.nominal);
}

#[test]
fn load_accepts_names_and_files_and_explains_the_rest() {
    for name in [
        "puma560",
        "puma",
        "ur5",
        "stanford",
        "ur5:pose",
        "puma:pose",
    ] {
        activecal::io::load_robot(name).unwrap();
    }
    let e = activecal::io::load_robot("kuka").unwrap_err().to_string();
    assert!(
        e.contains("unknown robot 'kuka'") && e.contains("ur5") && e.contains(".urdf"),
        "{e}"
    );
    let e = activecal::io::load_robot("/nonexistent/arm.toml")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("/nonexistent/arm.toml:"), "{e}");
    let e = activecal::io::load_robot(fixture("puma560_nominal.json").to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown robot file type"), "{e}");
    let path = fixture("ur5.urdf");
    let r = activecal::io::load_robot(path.to_str().unwrap()).unwrap();
    assert_eq!(
        (r.name.as_str(), r.measurement, r.n_unknowns()),
        (path.to_str().unwrap(), MeasurementKind::Point, 27)
    );
    // `:pose` after a file, as after a built-in name: the URDF imported for
    // full poses, a point description turned into its full-pose variant;
    // the name keeps the suffix so that design files load the same robot.
    let name = format!("{}:pose", path.to_str().unwrap());
    let r = activecal::io::load_robot(&name).unwrap();
    let direct = urdf_import("ur5.urdf", MeasurementKind::Pose);
    assert_eq!(
        (r.name.as_str(), r.measurement),
        (name.as_str(), MeasurementKind::Pose)
    );
    assert_eq!(r.unknowns, direct.unknowns);
    assert_eq!(r.nominal, direct.nominal);
    let scara = format!("{}:pose", fixture("scara.toml").to_str().unwrap());
    let s = activecal::io::load_robot(&scara).unwrap();
    assert_eq!((s.rows_per_pose(), s.n_unknowns()), (6, 4 * 3 + 2 + 6));
    s.check_identifiable().unwrap();
    let e = activecal::io::load_robot("/nonexistent/arm.urdf:pose")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("/nonexistent/arm.urdf:"), "{e}");
}

/// Line (1-based) of the first line of `text` containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

/// `text` with the `k`-th (0-based) line containing `needle` replaced.
fn replace_nth(text: &str, needle: &str, k: usize, new: &str) -> String {
    let mut seen = 0;
    text.lines()
        .map(|l| {
            if l.contains(needle) {
                seen += 1;
                if seen == k + 1 {
                    return new.to_string();
                }
            }
            l.to_string()
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn toml_err(text: &str) -> String {
    file::parse(text, "arm.toml", None).unwrap_err().to_string()
}

/// `orientation_scale` in a description: written and read back for full
/// poses, refused for points and out of range, with the place.
#[test]
fn orientation_scale_in_descriptions() {
    let mut r = Robot::builtin("ur5:pose").unwrap();
    r.orientation_scale = 0.29;
    let text = file::to_toml(&r);
    assert!(text.contains("orientation_scale = 0.29"), "{text}");
    assert_eq!(
        file::parse(&text, "a.toml", None)
            .unwrap()
            .orientation_scale,
        0.29
    );
    let l = line_of(&text, "orientation_scale");
    let e = toml_err(&text.replace("orientation_scale = 0.29", "orientation_scale = -2.0"));
    assert!(
        e.contains(&format!("line {l}")) && e.contains("orientation_scale = -2"),
        "{e}"
    );
    let point = text.replace("measurement = \"pose\"", "measurement = \"point\"");
    let e = toml_err(&point);
    assert!(
        e.contains(&format!("line {l}")) && e.contains("needs `measurement = \"pose\"`"),
        "{e}"
    );
    // The built-in default when the key is absent.
    let plain = file::to_toml(&Robot::builtin("ur5:pose").unwrap());
    assert_eq!(
        file::parse(&plain, "a.toml", None)
            .unwrap()
            .orientation_scale,
        activecal::model::DEFAULT_ORIENTATION_SCALE
    );
}

#[test]
fn malformed_descriptions_get_errors_that_point_to_the_place() {
    let base = file::to_toml(&Robot::puma560());
    file::parse(&base, "arm.toml", None).unwrap();

    // Syntax: the TOML parser's line and column.
    let t = base.replace("name = \"puma560\"", "name = \"puma560");
    let e = toml_err(&t);
    assert!(e.starts_with("arm.toml: ") && e.contains("line 2"), "{e}");

    // An unknown key, inside frame "3".
    let l = line_of(&base, "label = \"3\"");
    let t = replace_nth(&base, "label = \"3\"", 0, "label = \"3\"\ncolour = \"red\"");
    let e = toml_err(&t);
    assert!(
        e.contains("unknown field `colour`") && e.contains(&format!("line {}", l + 1)),
        "{e}"
    );

    // A missing table row.
    let t = replace_nth(&base, "nominal = ", 2, "");
    let e = toml_err(&t);
    assert!(
        e.contains("missing field `nominal`") && e.contains("line"),
        "{e}"
    );

    // NaN in frame "3".
    let l = line_of(&base, "label = \"3\"") + 4;
    let t = replace_nth(&base, "real = ", 4, "real = [0.0, nan, 0.0, 0.4331, 10.0]");
    let e = toml_err(&t);
    assert!(
        e.contains(&format!(
            "line {l}, column 8: frame '3': real alpha is not a finite number (NaN)"
        )),
        "{e}"
    );

    // A duplicate frame label.
    let l = line_of(&base, "label = \"4\"");
    let t = base.replace("label = \"4\"", "label = \"3\"");
    let e = toml_err(&t);
    assert!(
        e.contains(&format!(
            "line {l}, column 9: duplicate frame label '3' (first used on line {})",
            line_of(&base, "label = \"3\"")
        )),
        "{e}"
    );

    // No unknowns.
    let t: String = base
        .lines()
        .filter(|l| !l.starts_with("unknowns"))
        .collect::<Vec<_>>()
        .join("\n");
    let e = toml_err(&t);
    assert!(e.contains("no unknowns"), "{e}");

    // An unidentifiable unknown: alpha of the last joint frame for a point.
    let l = line_of(&base, "unknowns = [\"gamma\", \"a\", \"d\"]");
    let t = base.replace(
        "unknowns = [\"gamma\", \"a\", \"d\"]",
        "unknowns = [\"gamma\", \"alpha\", \"a\", \"d\"]",
    );
    let e = toml_err(&t);
    assert!(
        e.contains(&format!(
            "line {l}, column 12: unknowns alpha_5 are not identifiable from point measurements"
        )),
        "{e}"
    );

    // Inverted joint limits on frame "2" (joint q3).
    let l = line_of(&base, "label = \"2\"") + 3;
    let t = replace_nth(&base, "limits = ", 2, "limits = [1.0, -1.0]");
    let e = toml_err(&t);
    assert!(
        e.contains(&format!(
            "line {l}, column 10: frame '2': joint q3 has inverted limits [1, -1]"
        )),
        "{e}"
    );

    // More: β on a DH frame, a short row, limits on a fixed frame, degrees on
    // a prismatic joint, a bad measurement, auto plus a list, no frames.
    let t = base.replace(
        "unknowns = [\"gamma\", \"alpha\", \"a\", \"d\"]",
        "unknowns = [\"gamma\", \"beta\"]",
    );
    assert!(toml_err(&t).contains("frame '0' is a DH frame: it has no beta"));
    let t = replace_nth(&base, "real = ", 0, "real = [1.0, 2.0, 3.0, 4.0]");
    assert!(toml_err(&t).contains("frame 'a': `real` has 4 values, a Hayati frame needs 5"));
    let t = replace_nth(
        &base,
        "joint = \"fixed\"",
        0,
        "joint = \"fixed\"\nlimits = [0.0, 1.0]",
    );
    assert!(toml_err(&t).contains("frame 'a' is fixed: it has no joint limits"));
    let t = replace_nth(&base, "joint = \"revolute\"", 0, "joint = \"prismatic\"").replacen(
        "limits = [",
        "limits_deg = [",
        1,
    );
    assert!(toml_err(&t).contains("joint q1 is prismatic: give `limits` in metres"));
    let t = base.replace("measurement = \"point\"", "measurement = \"laser\"");
    let e = toml_err(&t);
    assert!(
        e.contains("measurement = \"laser\": unknown (known: point, pose, markers"),
        "{e}"
    );
    let t = base.replace(
        "measurement = \"point\"",
        "measurement = \"point\"\nunknowns = \"auto\"",
    );
    assert!(toml_err(&t).contains("give one or the other"));
    assert!(toml_err("name = \"x\"\n").contains("no frames"));
    let t = replace_nth(&base, "unknowns = ", 3, "unknowns = [\"gamma\", \"gamma\"]");
    assert!(toml_err(&t).contains("'gamma' is listed twice"));
    let t = replace_nth(
        &base,
        "real = ",
        1,
        "real = [0.0, -1.5707963267948966, 1e300, 0.6858, 10.0]",
    );
    assert!(toml_err(&t).contains("out of range"));
}

#[test]
fn auto_unknowns_for_a_description_are_the_builtin_choice() {
    let puma = Robot::puma560();
    let t: String = file::to_toml(&puma)
        .lines()
        .filter(|l| !l.starts_with("unknowns"))
        .collect::<Vec<_>>()
        .join("\n")
        + "\n";
    let t = t.replace(
        "measurement = \"point\"",
        "measurement = \"point\"\nunknowns = \"auto\"",
    );
    let r = file::parse(&t, "auto.toml", None).unwrap();
    assert_eq!(r.unknowns, puma.unknowns);
    assert_eq!(r.name, "puma560");
    // And with_measurement adds the tool orientation for full poses.
    let pp = puma.with_measurement(MeasurementKind::Pose).unwrap();
    assert_eq!(
        pp.unknowns,
        Robot::builtin("puma560:pose").unwrap().unknowns
    );
    let back = pp.with_measurement(MeasurementKind::Point).unwrap();
    assert_eq!(back.unknowns, puma.unknowns);
}

// ---------------------------------------------------------------------------
// Selection, scoring, bounds and calibration on every robot

fn pool_x(r: &Robot, levels: usize) -> (Pool, Blocks) {
    let pool = Pool::full(r, levels).unwrap();
    let x = pool.jacobian(r, &r.nominal);
    (pool, x)
}

#[test]
fn select_and_score_run_on_every_robot() {
    for r in all_robots() {
        let (_, x) = pool_x(&r, 3);
        let sel = eae_design(&x);
        assert_eq!(sel.poses.len(), 30, "{}", r.name);
        let mut sorted = sel.poses.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 30);
        // Scoring (the `score` command's library call) agrees with the run.
        let ind = Indices::from_design(&x, &sel.poses);
        assert_eq!(ind.rank, r.n_unknowns(), "{}", r.name);
        let direct = design_ln_det(&x, None, &sel.poses).unwrap();
        assert!((direct - sel.ln_oid).abs() < 1e-6, "{}", r.name);
        assert!((ind.ln_oid - sel.ln_oid).abs() < 1e-6, "{}", r.name);
        require_identifiable(&r, &x.select(&sel.poses)).unwrap();
        // It beats every one of 50 random designs.
        let mut g = Lcg(41);
        let best_random = (0..50)
            .map(|_| {
                let mut d: Vec<usize> = Vec::new();
                while d.len() < 30 {
                    let k = (g.unit() * x.n_poses() as f64) as usize;
                    if !d.contains(&k) {
                        d.push(k);
                    }
                }
                design_ln_det(&x, None, &d).unwrap_or(f64::NEG_INFINITY)
            })
            .fold(f64::NEG_INFINITY, f64::max);
        println!(
            "{}: p = {}, t = {}, EAE ln OI_D {:.2} vs best of 50 random {:.2}",
            r.name,
            r.n_unknowns(),
            r.rows_per_pose(),
            sel.ln_oid,
            best_random
        );
        assert!(sel.ln_oid > best_random, "{}", r.name);
    }
}

#[test]
fn bound_runs_on_every_robot_and_lies_above_the_selected_design() {
    for r in all_robots() {
        let (_, x) = pool_x(&r, 3);
        let sel = eae_design(&x);
        // The bound is valid at any gap; a loose target keeps this test short.
        let settings = BoundSettings::builder()
            .use_conic(false)
            .gap_tol(1e-2)
            .build()
            .unwrap();
        let b =
            relaxation_bound(&x, None, 30, &settings).unwrap_or_else(|e| panic!("{}: {e}", r.name));
        println!(
            "{}: bound {:.3} ≥ EAE {:.3} (gap {:.2e}, {:?}, {:.2} s)",
            r.name, b.ln_bound, sel.ln_oid, b.certificate_gap, b.status, b.seconds
        );
        assert!(
            b.ln_bound.is_finite() && b.ln_bound >= sel.ln_oid - 1e-9,
            "{}",
            r.name
        );
    }
}

/// Zero-noise calibration from the nominal start recovers the real unknowns
/// on every robot, point and full pose: the library's Levenberg–Marquardt
/// with the orientation residual `w log(R(θ) R_measᵀ)` and its exact
/// Jacobian. 1e-8 rad or m: the iteration stops at a relative step of 1e-10
/// on unknowns of size ≤ 20, and a wrong orientation residual or row (sign,
/// axis, weight) stalls far above that. (The exact Jacobian with `J_l⁻¹` is
/// checked against differences of the residual in `identify::lm`'s tests.)
#[test]
fn calibration_recovers_the_real_robot() {
    for mut r in all_robots() {
        if r.measurement == MeasurementKind::Pose {
            // A weight other than 1 exercises the scaling of the rows.
            r.orientation_scale = 0.3;
        }
        let (pool, x) = pool_x(&r, 3);
        let sel = eae_design(&x);
        let qs: Vec<Vec<f64>> = sel.poses.iter().map(|&k| pool.q(k)).collect();
        let meas = simulate(&r, &r.real, &qs, 0.0, &mut trial_rng(1, 0)).unwrap();
        assert_eq!(
            meas.orientations().len(),
            if r.measurement == MeasurementKind::Pose {
                30
            } else {
                0
            }
        );
        let id = identify(&r, &r.nominal, &meas, &LmSettings::default()).unwrap();
        assert!(id.converged(), "{}: {:?}", r.name, id.status);
        assert_eq!(id.dof, r.rows_per_pose() * 30 - r.n_unknowns());
        let truth = r.unknown_values(&r.real);
        let err = id
            .estimate
            .iter()
            .zip(&truth)
            .map(|(e, t)| (e - t).abs())
            .fold(0.0, f64::max);
        println!(
            "{}: calibrated in {} iterations, max |θ̂ − θ| {err:.1e}",
            r.name, id.iterations
        );
        assert!(err < 1e-8, "{}: {err:e}", r.name);
    }
}
