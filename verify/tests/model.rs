//! The model builders, without Python: the spec handed to Pinocchio and
//! MuJoCo reproduces activecal's kinematics (and its `joint_chain`), the
//! MJCF carries the spec exactly, and the fixture format round-trips.

use activecal::kinematics::{joint_chain, position};
use activecal::measure::JacobianEvaluator;
use activecal::model::{JointKind, ParamSet, Robot};
use nalgebra::{Matrix4, Vector3};
use verify::compare::{Kinematics, activecal_kinematics, deviation};
use verify::fixture::{self, Fixture, Versions};
use verify::model::{ModelSpec, mjcf, mjcf_of_spec, pinocchio_model_spec, spec_position};
use verify::sample::configurations;
use verify::{TOLERANCE, builtin_robots, synthetic_robot};

fn robots() -> Vec<Robot> {
    let mut r = builtin_robots().unwrap();
    r.push(synthetic_robot());
    r
}

const SETS: [ParamSet; 2] = [ParamSet::Nominal, ParamSet::Real];

/// Position and geometric joint Jacobian (`z_j × (p − o_j)` for a revolute
/// joint, `z_j` for a prismatic one) of the spec, evaluated with 4 × 4
/// matrices: a third implementation, sharing nothing with activecal's.
fn spec_kinematics(spec: &ModelSpec, qs: &[Vec<f64>]) -> Kinematics {
    let dof = spec.dof();
    let mut out = Kinematics::default();
    for q in qs {
        let mut t = Matrix4::identity();
        let mut axes = Vec::new();
        for ((p, &kind), &qk) in spec.placements.iter().zip(&spec.kinds).zip(q) {
            t *= p.homogeneous();
            axes.push((
                kind,
                Vector3::new(t[(0, 2)], t[(1, 2)], t[(2, 2)]),
                Vector3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)]),
            ));
            let mut m = Matrix4::identity();
            match kind {
                JointKind::Revolute => {
                    let (s, c) = qk.sin_cos();
                    m[(0, 0)] = c;
                    m[(0, 1)] = -s;
                    m[(1, 0)] = s;
                    m[(1, 1)] = c;
                }
                JointKind::Prismatic => m[(2, 3)] = qk,
            }
            t *= m;
        }
        t *= spec.tool.homogeneous();
        let p = Vector3::new(t[(0, 3)], t[(1, 3)], t[(2, 3)]);
        let mut jac = vec![0.0; 3 * dof];
        for (j, (kind, z, o)) in axes.iter().enumerate() {
            let col = match kind {
                JointKind::Revolute => z.cross(&(p - o)),
                JointKind::Prismatic => *z,
            };
            for r in 0..3 {
                jac[r * dof + j] = col[r];
            }
        }
        out.position.push([p.x, p.y, p.z]);
        out.jacobian.push(jac);
    }
    out
}

#[test]
fn spec_reproduces_activecal_position_and_joint_jacobian() {
    for robot in robots() {
        let qs = configurations(&robot, 1000, 42);
        for set in SETS {
            let table = robot.params(set);
            let spec = pinocchio_model_spec(&robot, table).unwrap();
            let dev = deviation(
                &spec_kinematics(&spec, &qs),
                &activecal_kinematics(&robot, table, &qs),
            )
            .unwrap();
            assert!(dev.within(TOLERANCE), "{} {set:?}: {dev:?}", robot.name);
            // And ModelSpec::transform agrees with the hand-rolled walk above.
            for q in qs.iter().take(50) {
                assert!((spec_position(&spec, q) - position(&robot, table, q)).norm() < TOLERANCE);
            }
        }
    }
}

#[test]
fn spec_equals_activecal_joint_chain() {
    for robot in robots() {
        for set in SETS {
            let table = robot.params(set);
            let spec = pinocchio_model_spec(&robot, table).unwrap();
            let chain = joint_chain(&robot, table);
            assert_eq!(spec.dof(), chain.placements.len());
            assert_eq!(spec.kinds, chain.kinds);
            let pairs = spec
                .placements
                .iter()
                .zip(&chain.placements)
                .chain([(&spec.tool, &chain.tool)]);
            for (a, b) in pairs {
                let d = (a.homogeneous() - b.to_homogeneous()).abs().max();
                // Translations ≤ 20 m built by different formulas: rounding only.
                assert!(
                    d < 1e-13,
                    "{} {set:?}: placements differ by {d:e}",
                    robot.name
                );
            }
        }
    }
}

#[test]
fn joint_jacobian_is_the_gamma_column_of_the_identification_jacobian() {
    // What the fixtures call "Jacobian columns of the joint offsets gamma".
    let robot = Robot::puma560();
    let p = robot.n_unknowns();
    let dof = robot.dof();
    for set in SETS {
        let table = robot.params(set);
        let mut ev = JacobianEvaluator::new(&robot, table);
        for q in configurations(&robot, 20, 3) {
            let (mut x, mut jj) = (vec![0.0; 3 * p], vec![0.0; 3 * dof]);
            ev.eval(&q, &mut x);
            ev.joint_jacobian(&q, &mut jj);
            for (c, u) in robot.unknowns.iter().enumerate() {
                let Some(j) = robot.frames[u.frame].joint else {
                    continue;
                };
                if u.symbol != activecal::model::Symbol::Gamma {
                    continue;
                }
                for r in 0..3 {
                    assert_eq!(x[r * p + c], jj[r * dof + j]);
                }
            }
        }
    }
}

/// The value of attribute `name` in each tag that starts with `tag`.
fn attrs<'a>(xml: &'a str, tag: &str, name: &str) -> Vec<&'a str> {
    xml.split('<')
        .filter(|t| t.starts_with(tag))
        .filter_map(|t| {
            let key = format!(" {name}=\"");
            let start = t.find(&key)? + key.len();
            Some(&t[start..start + t[start..].find('"')?])
        })
        .collect()
}

fn parse(v: &str) -> Vec<f64> {
    v.split(' ').map(|x| x.parse().unwrap()).collect()
}

#[test]
fn mjcf_carries_the_spec_exactly() {
    for robot in robots() {
        for set in SETS {
            let table = robot.params(set);
            let spec = pinocchio_model_spec(&robot, table).unwrap();
            let xml = mjcf(&robot, table).unwrap();
            assert_eq!(xml, mjcf_of_spec(&spec));
            let dof = robot.dof();
            let names: Vec<String> = (1..=dof).map(|k| format!("q{k}")).collect();
            assert_eq!(attrs(&xml, "joint", "name"), names);
            assert_eq!(attrs(&xml, "joint", "axis"), vec!["0 0 1"; dof]);
            let types: Vec<&str> = spec
                .kinds
                .iter()
                .map(|k| match k {
                    JointKind::Revolute => "hinge",
                    JointKind::Prismatic => "slide",
                })
                .collect();
            assert_eq!(attrs(&xml, "joint", "type"), types);
            assert_eq!(attrs(&xml, "inertial", "mass").len(), dof);
            assert_eq!(attrs(&xml, "site", "name"), ["ee"]);
            assert_eq!(xml.matches("<body ").count(), dof);
            assert_eq!(xml.matches("</body>").count(), dof);
            let pos = attrs(&xml, "body", "pos");
            let quat = attrs(&xml, "body", "quat");
            for (k, p) in spec.placements.iter().enumerate() {
                assert_eq!(parse(pos[k]), p.translation, "exact round trip");
                assert_eq!(parse(quat[k]), p.quat_wxyz());
            }
            assert_eq!(parse(attrs(&xml, "site", "pos")[0]), spec.tool.translation);
        }
    }
}

#[test]
fn quaternions_reproduce_the_rotations() {
    for robot in robots() {
        let spec = pinocchio_model_spec(&robot, &robot.real).unwrap();
        for p in spec.placements.iter().chain([&spec.tool]) {
            let [w, x, y, z] = p.quat_wxyz();
            let q =
                nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
            let m = q.to_rotation_matrix();
            for r in 0..3 {
                for c in 0..3 {
                    assert!((m[(r, c)] - p.rotation[r][c]).abs() < 1e-15);
                }
            }
        }
    }
}

#[test]
fn bad_joint_order_is_an_error() {
    let mut robot = Robot::puma560();
    robot.frames[1].joint = Some(1);
    robot.frames[2].joint = Some(0);
    assert!(pinocchio_model_spec(&robot, &robot.nominal).is_err());
}

fn sample_fixture(robot: &Robot, set: ParamSet) -> Fixture {
    let qs = configurations(robot, 5, 1);
    let k = activecal_kinematics(robot, robot.params(set), &qs);
    let versions = Versions {
        python: "3.11.7".into(),
        numpy: "2.4.1".into(),
        pinocchio: "4.1.0".into(),
        mujoco: "4.0.0".into(),
    };
    Fixture::new(robot, set, versions, &qs, 5, &k, Default::default()).unwrap()
}

#[test]
fn fixture_text_round_trips_and_is_deterministic() {
    let robot = synthetic_robot();
    let f = sample_fixture(&robot, ParamSet::Real);
    let text = f.to_json();
    assert_eq!(text, sample_fixture(&robot, ParamSet::Real).to_json());
    let back = Fixture::from_json(&text).unwrap();
    assert_eq!(back, f, "every f64 survives the text exactly");
    assert_eq!(back.samples.len(), 5 + 128);
    // One sample per line.
    assert_eq!(
        text.lines()
            .filter(|l| l.starts_with("    {\"q\":"))
            .count(),
        133
    );
}

#[test]
fn committed_fixtures_are_canonical() {
    // The files in fixtures/ are exactly what `regen` prints for their
    // content: nobody edited them by hand, and they parse.
    let dir = fixture::default_dir();
    for robot in builtin_robots().unwrap() {
        for set in SETS {
            let path = dir.join(fixture::file_name(&robot.name, set));
            let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
                panic!("{}: {e} (run `{}`)", path.display(), fixture::REGEN_COMMAND)
            });
            let f = Fixture::from_json(&text).unwrap();
            assert_eq!(
                f.to_json(),
                text,
                "{} is not in canonical form",
                path.display()
            );
            assert_eq!(f.robot, robot.name);
            assert_eq!(f.samples.len(), f.n_random + f.n_corners);
            assert_eq!(f.n_corners, 1 << robot.dof());
        }
    }
}
