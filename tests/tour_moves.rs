//! The tour's moves checked for collision: a straight joint-space move
//! that sweeps a link through an obstacle is found, with its pair and
//! where on the move; a free move passes; and the repair reorders a tour
//! around a colliding move when another order is free.

use activecal::collision::{CollisionModel, CollisionSpec, Obstacle};
use activecal::select::moves::{MoveSpace, MovesReport, TurnedPose, check_tour};
use activecal::select::tour::MoveCost;

/// `check_tour` against `m` at 1 mm with via candidates `vias`, joints
/// turning whole turns within `turns` (`None`: none does), on a copy of
/// `qs` (returned with the report).
fn tour_with(
    m: &CollisionModel,
    home: Option<&[f64]>,
    qs: &[Vec<f64>],
    order: &mut Vec<usize>,
    vias: &[Vec<f64>],
    turns: Option<&[Option<[f64; 2]>]>,
) -> (MovesReport, Vec<Vec<f64>>) {
    let models = [m];
    let none = vec![None; qs[0].len()];
    let cost = MoveCost::new(&vec![1.0; qs[0].len()]).unwrap();
    let space = MoveSpace {
        cost: &cost,
        models: &models,
        resolution: 1e-3,
        vias,
        turns: turns.unwrap_or(&none),
        keep_order: false,
    };
    let mut qs = qs.to_vec();
    let r = check_tour(&space, home, &mut qs, order);
    (r, qs)
}

/// [`tour_with`] without whole turns: the report.
fn tour(
    m: &CollisionModel,
    home: Option<&[f64]>,
    qs: &[Vec<f64>],
    order: &mut Vec<usize>,
    vias: &[Vec<f64>],
) -> MovesReport {
    tour_with(m, home, qs, order, vias, None).0
}

/// A planar arm: one revolute joint about z carrying a 1 m bar along x.
const ARM: &str = r#"<robot name="bar">
  <link name="base"/>
  <link name="bar">
    <collision><origin xyz="0.5 0 0"/><geometry><box size="1.0 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="bar"/><axis xyz="0 0 1"/>
    <limit lower="-3.1" upper="3.1" effort="1" velocity="1"/>
  </joint>
</robot>"#;

/// The arm's collision model, from its text (no file: the tests run in
/// parallel).
fn model() -> CollisionModel {
    CollisionModel::load(&CollisionSpec {
        urdf: "bar.urdf".into(),
        text: Some(ARM.into()),
        joints: vec!["j1".into()],
        // A 0.2 m cube on the +y axis, 0.8 m out: the bar passes through it
        // at q = π/2.
        obstacles: vec![Obstacle::parse("box:0,0.8,0,0.2,0.2,0.2").unwrap()],
        ..CollisionSpec::default()
    })
    .unwrap()
}

#[test]
fn a_move_through_the_obstacle_is_found_where_it_hits() {
    let m = model();
    assert!(m.contact(&[0.0]).is_none() && m.contact(&[2.5]).is_none());
    let r = m.check_move(&[0.0], &[2.5], 1e-3);
    let (pair, at) = r.contact.expect("the bar sweeps through the cube");
    assert_eq!(pair.link, "bar");
    assert!(pair.obstacle);
    // The bar (half-width 0.05) first touches the cube's face x = −0.1…0.1
    // edge at 0.7 m when its angle is about π/2 − atan(0.15/0.7) ≈ 1.36 rad:
    // at s ≈ 0.54 of the move 0 → 2.5. A 1 mm resolution at ≤ 1 m
    // reach is ≤ 1e-3 rad, 4e-4 of the move; 0.03 allows for the geometry
    // estimate above.
    assert!((at - 1.36 / 2.5).abs() < 0.03, "{at}");
    // The way round (0 → −2.5) is free, checked at more than one step.
    let free = m.check_move(&[0.0], &[-2.5], 1e-3);
    assert!(free.contact.is_none());
    assert!(free.checks > 2);
}

#[test]
fn a_free_move_agrees_with_dense_sampling() {
    // Every configuration on the move, at 1e-4 rad (0.1 mm at the bar's
    // tip), is free when the check says the move is.
    let m = model();
    let (a, b) = (-3.0, 1.2);
    assert!(m.check_move(&[a], &[b], 1e-3).contact.is_none());
    for k in 0..=42_000 {
        let q = a + (b - a) * f64::from(k) / 42_000.0;
        assert!(m.contact(&[q]).is_none(), "q = {q}");
    }
}

#[test]
fn the_tour_is_reordered_around_a_colliding_move_or_reports_it() {
    let m = model();
    // Poses at −2, 0 and 1: visiting 1 → −2 → 0 crosses nothing. From a
    // home at 2.0 (beyond the cube) every first move crosses it: no order
    // avoids that (one joint), so it is reported, from home.
    let qs = vec![vec![-2.0], vec![0.0], vec![1.0]];
    let mut order = vec![2, 0, 1]; // 1 → −2 → 0
    let r = tour(&m, None, &qs, &mut order, &[]);
    assert!(r.colliding.is_empty(), "{r:?}");
    assert_eq!(r.colliding_before, 0);
    let mut order = vec![0, 1, 2];
    let r = tour(&m, Some(&[2.0]), &qs, &mut order, &[]);
    assert_eq!(r.colliding.len(), 1, "{r:?}");
    let c = &r.colliding[0];
    assert_eq!(c.from, None); // from home
    assert_eq!(c.pair.link, "bar");
}

#[test]
fn a_kept_order_is_never_changed_to_avoid_a_colliding_move() {
    // Poses at 1.0, 2.5 and 2.0 visited 2.5 → 1.0 → 2.0: both moves cross
    // the cube (1.36…1.78 rad). Reversing the last two (2.5 → 2.0 → 1.0)
    // frees the first move, so the repair reorders; with the user's order
    // kept (`--order none`) it may not, and both moves are reported.
    let m = model();
    let qs = vec![vec![1.0], vec![2.5], vec![2.0]];
    let models = [&m];
    let cost = MoveCost::new(&[1.0]).unwrap();
    let none = vec![None];
    let run = |keep_order: bool| {
        let space = MoveSpace {
            cost: &cost,
            models: &models,
            resolution: 1e-3,
            vias: &[],
            turns: &none,
            keep_order,
        };
        let mut order = vec![1, 0, 2];
        let mut q = qs.clone();
        let r = check_tour(&space, None, &mut q, &mut order);
        (order, r)
    };
    let (order, r) = run(false);
    assert_ne!(order, vec![1, 0, 2]);
    assert!(r.reordered && r.colliding.len() == 1, "{r:?}");
    let (order, r) = run(true);
    assert_eq!(order, vec![1, 0, 2]);
    assert!(!r.reordered, "{r:?}");
    assert_eq!((r.colliding_before, r.colliding.len()), (2, 2), "{r:?}");
}

#[test]
fn a_colliding_move_is_reported_where_it_first_hits_in_the_direction_of_travel() {
    // Visiting 2.5 → 0 (the later pose first): one joint, so no order
    // avoids the cube, and the move is reported. The bar is in the cube for
    // angles of about π/2 ± 0.21 (1.36…1.78 rad, see the first test);
    // travelling down from 2.5 it first touches at 1.78, s ≈ (2.5 − 1.78) /
    // 2.5 ≈ 0.29, not at 0.54 (where the move 0 → 2.5 first touches) nor at
    // 1 − 0.54 (the last contact travelling down). 0.03 as in the first
    // test.
    let m = model();
    let qs = vec![vec![0.0], vec![2.5]];
    let mut order = vec![1, 0];
    let r = tour(&m, None, &qs, &mut order, &[]);
    assert_eq!(order, vec![1, 0], "two poses: nothing to reorder");
    assert_eq!(r.colliding.len(), 1, "{r:?}");
    let c = &r.colliding[0];
    assert_eq!((c.from, c.to), (Some(0), 1));
    assert!((c.at - (2.5 - 1.78) / 2.5).abs() < 0.03, "{}", c.at);
}

/// The moves of `fixtures/example-robot-data/tour_moves_coal.json`: for the
/// Panda (SRDF, on a table) and the UR10 (on a table, beside a wall), every
/// pose and move of a selected tour and 30 long moves across it, with
/// Pinocchio + Coal's verdicts (`verify/python/coal_moves.py`, written by
/// `verify/tests/live_tour.rs`).
#[derive(serde::Deserialize)]
struct Scene {
    scene: String,
    spec: SceneSpec,
    coal: Vec<CoalMove>,
}

#[derive(serde::Deserialize)]
struct SceneSpec {
    urdf: String,
    srdf: Option<String>,
    joints: Vec<String>,
    floor: Option<f64>,
    boxes: Vec<[f64; 6]>,
    resolution: f64,
    moves: Vec<[Vec<f64>; 2]>,
}

#[derive(serde::Deserialize)]
struct CoalMove {
    collides: bool,
    at: Option<f64>,
    pair: Option<[String; 2]>,
    resolution_s: f64,
}

/// A contact's names as activecal gives them (Coal names a geometry
/// `LINK_K`), sorted.
fn link_names(pair: &[String; 2]) -> [String; 2] {
    let strip = |n: &String| match n.rsplit_once('_') {
        Some((link, k)) if k.parse::<usize>().is_ok() => link.to_string(),
        _ => n.clone(),
    };
    let mut v = [strip(&pair[0]), strip(&pair[1])];
    v.sort();
    v
}

/// The Coal fixture's scenes (the Panda and the UR10 with their moves and
/// Coal's verdicts).
fn coal_scenes() -> Vec<Scene> {
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!(
        "{root}/fixtures/example-robot-data/tour_moves_coal.json"
    ))
    .unwrap();
    let fixture: serde_json::Value = serde_json::from_str(&text).unwrap();
    serde_json::from_value(fixture["scenes"].clone()).unwrap()
}

/// A scene's collision model: self-collision, its SRDF, floor and boxes.
fn scene_model(sp: &SceneSpec) -> CollisionModel {
    let root = env!("CARGO_MANIFEST_DIR");
    CollisionModel::load(&CollisionSpec {
        urdf: format!("{root}/{}", sp.urdf),
        joints: sp.joints.clone(),
        self_collision: true,
        srdf: sp.srdf.as_ref().map(|f| format!("{root}/{f}")),
        floor: sp.floor,
        obstacles: sp
            .boxes
            .iter()
            .map(|b| Obstacle::Box {
                center: [b[0], b[1], b[2]],
                size: [b[3], b[4], b[5]],
            })
            .collect(),
        ..CollisionSpec::default()
    })
    .unwrap()
}

#[test]
fn moves_on_the_panda_and_the_ur10_are_checked_as_coal_checks_them() {
    let scenes = coal_scenes();
    assert_eq!(scenes.len(), 2);
    for s in &scenes {
        let sp = &s.spec;
        let m = scene_model(sp);
        let mut colliding = 0;
        for (k, ([a, b], coal)) in sp.moves.iter().zip(&s.coal).enumerate() {
            let ours = m.check_move(a, b, sp.resolution);
            assert_eq!(
                ours.contact.is_some(),
                coal.collides,
                "{} move {k}: activecal {:?}, Coal {:?} at {:?}",
                s.scene,
                ours.contact,
                coal.pair,
                coal.at
            );
            let Some((pair, at)) = ours.contact else {
                continue;
            };
            colliding += 1;
            // Both stop at their first check in contact, and near contact
            // each steps at most 1 mm of its fastest point's motion (Coal's
            // step is `resolution_s`; activecal's bound on the fastest point
            // is within a factor 2 of Coal's): 3 of Coal's steps.
            let coal_at = coal.at.unwrap();
            assert!(
                (at - coal_at).abs() <= 3.0 * coal.resolution_s,
                "{} move {k}: first contact at {at}, Coal's at {coal_at}",
                s.scene
            );
            let mut names = [pair.link.clone(), pair.other.clone()];
            names.sort();
            assert_eq!(
                names,
                link_names(coal.pair.as_ref().unwrap()),
                "{} move {k}",
                s.scene
            );
        }
        // The fixture has colliding moves to test (10 on the Panda, 24 on
        // the UR10 when it was written).
        assert!(colliding >= 5, "{}: {colliding} colliding moves", s.scene);
    }
}

/// A bar on a lift: a prismatic joint along z, then the bar's yaw (the
/// first test's arm, raised or lowered).
const LIFT: &str = r#"<robot name="lift">
  <link name="base"/>
  <link name="carriage"/>
  <link name="bar">
    <collision><origin xyz="0.5 0 0"/><geometry><box size="1.0 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="lift" type="prismatic">
    <parent link="base"/><child link="carriage"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="yaw" type="revolute">
    <parent link="carriage"/><child link="bar"/><axis xyz="0 0 1"/>
    <limit lower="-3.1" upper="3.1" effort="1" velocity="1"/>
  </joint>
</robot>"#;

#[test]
fn a_move_no_order_avoids_goes_through_a_free_via_configuration() {
    // The cube of the first test (z from −0.1 to 0.1) and the bar at height
    // 0: yawing from 0 to 2.5 sweeps through it, and with two poses no
    // order avoids that. Of the two via candidates (both add 2.5 rad of
    // largest-joint travel, tried in index order), the first sits in the
    // cube (yaw π/2 at height 0), so moving to it collides; the second
    // passes over the cube: raised to 0.5 m while yawing to π/2, the bar is
    // above 0.39 m (clear of the cube's top at 0.1 m plus its half-height)
    // whenever its yaw is within the cube's 1.36…1.78 rad.
    let m = CollisionModel::load(&CollisionSpec {
        urdf: "lift.urdf".into(),
        text: Some(LIFT.into()),
        joints: vec!["lift".into(), "yaw".into()],
        obstacles: vec![Obstacle::parse("box:0,0.8,0,0.2,0.2,0.2").unwrap()],
        ..CollisionSpec::default()
    })
    .unwrap();
    let half = std::f64::consts::FRAC_PI_2;
    let qs = vec![vec![0.0, 0.0], vec![0.0, 2.5]];
    let vias = vec![vec![0.0, half], vec![0.5, half]];
    let mut order = vec![0, 1];
    let r = tour(&m, None, &qs, &mut order, &vias);
    assert!(r.colliding.is_empty(), "{r:?}");
    assert_eq!(r.colliding_before, 1);
    assert_eq!(r.via.len(), 1, "{r:?}");
    let v = &r.via[0];
    assert_eq!((v.from, v.to, v.candidate), (Some(0), 1, 1));
    // Without candidates the move is reported.
    let r = tour(&m, None, &qs, &mut order, &[]);
    assert_eq!((r.via.len(), r.colliding.len()), (0, 1));
}

#[test]
fn a_stretch_of_poses_turned_by_a_whole_turn_goes_round_the_other_way() {
    // The bar of the first test, its joint turning within ±6.2 rad (more
    // than a turn: the move check does not read the URDF's limits). Poses
    // at 0, 2.5 and 2.0, in that order: the cube is at 1.36…1.78 rad, so
    // 0 → 2.5 crosses it, and with every pose but the first beyond it no
    // order avoids it (0 → 2.0 crosses it too). Turning 2.5 and 2.0 by −1
    // turn (−3.78, −4.28: the same angles) makes the move 0 → −3.78 go
    // round the other way, through −π/2 and −π, while the move between the
    // two is unchanged. Turning 2.5 alone would leave −3.78 → 2.0 crossing
    // the cube, and turning 0 does not fit (±2π is beyond ±6.2).
    let m = model();
    let qs = vec![vec![0.0], vec![2.5], vec![2.0]];
    let mut order = vec![0, 1, 2];
    let turns = [Some([-6.2, 6.2])];
    let (r, turned) = tour_with(&m, None, &qs, &mut order, &[], Some(&turns));
    assert!(r.colliding.is_empty() && r.via.is_empty(), "{r:?}");
    assert_eq!((r.colliding_before, r.reordered), (1, false));
    assert_eq!(order, vec![0, 1, 2]);
    let expected = |pose| TurnedPose {
        pose,
        turns: vec![-1],
    };
    assert_eq!(r.turned, vec![expected(1), expected(2)]);
    let tau = std::f64::consts::TAU;
    assert_eq!(turned, vec![vec![0.0], vec![2.5 - tau], vec![2.0 - tau]]);
    // The new moves are free by the move check, and by dense sampling at
    // 1e-4 rad (0.1 mm at the bar's 1 m tip, a tenth of the resolution).
    for w in turned.windows(2) {
        assert!(m.check_move(&w[0], &w[1], 1e-3).contact.is_none());
        let (a, b) = (w[0][0], w[1][0]);
        let steps = ((b - a).abs() / 1e-4).ceil() as usize;
        for k in 0..=steps {
            let q = a + (b - a) * k as f64 / steps as f64;
            assert!(m.contact(&[q]).is_none(), "q = {q}");
        }
    }
    // Within ±3.1 rad (less than a turn) no pose can turn: reported.
    let (r, same) = tour_with(&m, None, &qs, &mut order, &[], Some(&[Some([-3.1, 3.1])]));
    assert_eq!((r.turned.len(), r.colliding.len()), (0, 1), "{r:?}");
    assert_eq!(same, qs);
}

/// The moves checked in parallel (a path's moves at once, repairs two at a
/// time) give the same tour and counts on one thread as on two: the
/// Panda's fixture scene, the ends of its colliding moves as a tour.
#[test]
fn a_tour_s_checks_do_not_depend_on_the_thread_count() {
    let scenes = coal_scenes();
    let s = scenes.iter().find(|s| s.scene == "panda").unwrap();
    let sp = &s.spec;
    let m = scene_model(sp);
    // The ends of the moves Coal finds colliding, in turn: the tour's
    // moves a → b collide and have to be repaired.
    let qs: Vec<Vec<f64>> = sp
        .moves
        .iter()
        .zip(&s.coal)
        .filter(|(_, c)| c.collides)
        .flat_map(|([a, b], _)| [a.clone(), b.clone()])
        .collect();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut order: Vec<usize> = (0..qs.len()).collect();
            let (r, turned) = tour_with(&m, None, &qs, &mut order, &[], None);
            (r, order, turned)
        })
    };
    let one = run(1);
    assert!(
        one.0.colliding_before >= 4,
        "the scene exercises repairs: {:?}",
        one.0
    );
    assert_eq!(one, run(2));
}
