//! Units cannot change a decision. Every command decides rank on the
//! column-scaled (equilibrated) problem (`activecal::observability::
//! MAX_CONDITION`), so
//!
//! - the PUMA in millimetres gets the same design from every algorithm as in
//!   metres, with `ln OI_D` shifted by exactly `2·(angle unknowns)·ln 1000`;
//! - arbitrary column scales of a pool Jacobian (a ridge start included)
//!   change no design;
//! - `select`, `bound`, `score`/`gap` and `calibrate` agree on whether a robot
//!   is identifiable: a sensor 900 km away (one column 10⁶ times the others:
//!   raw `κ(XᵀX) ≈ 2e16`, equilibrated `≈ 2e4`) is accepted by all of them,
//!   two DH axes 1e-5 rad apart (equilibrated `κ ≈ 1e15`: `d` of both frames
//!   along the common normal cannot be told apart) refused by all of them.

use crate::common;

use activecal::blocks::Blocks;
use activecal::bound::{BoundError, BoundSettings, RelaxationSolver, relaxation_bound};
use activecal::criterion::Indices;
use activecal::identify::{LmSettings, identify, simulate, trial_rng};
use activecal::model::{Robot, Symbol};
use activecal::observability::identifiability;
use activecal::pool::Pool;
use activecal::select::{Algorithm, CriterionKind, Settings, select};
use common::{fails_with, json_of};

/// The robot with lengths in millimetres: every `a` and `d` times 1000 (the
/// PUMA has no prismatic joint, so its limits stay). Positions come out in
/// millimetres, so an angle unknown's column is 1000 times its column in
/// metres and a length unknown's column is unchanged.
fn millimetres(r: &Robot) -> Robot {
    let mut mm = r.clone();
    for t in [&mut mm.real, &mut mm.nominal] {
        for row in &mut t.rows {
            row[Symbol::A.column()] *= 1000.0;
            row[Symbol::D.column()] *= 1000.0;
        }
    }
    mm
}

fn pool(r: &Robot, levels: usize) -> Blocks {
    Pool::full(r, levels).unwrap().jacobian(r, &r.nominal)
}

/// `X·diag(s)`.
fn scale_columns(x: &Blocks, s: &[f64]) -> Blocks {
    let m = x.mat();
    Blocks::new(
        faer::Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)] * s[j]),
        x.t(),
    )
}

#[test]
fn puma_in_millimetres_gets_the_same_designs_from_every_algorithm() {
    let m = Robot::puma560();
    let mm = millimetres(&m);
    let angles = m
        .unknowns
        .iter()
        .filter(|u| matches!(u.symbol, Symbol::Gamma | Symbol::Alpha | Symbol::Beta))
        .count();
    assert_eq!(angles, 15);
    let shift = 2.0 * angles as f64 * 1000f64.ln();
    let (xm, xmm) = (pool(&m, 5), pool(&mm, 5));
    let s = Settings::builder().designs(2000).build().unwrap();
    for alg in [
        Algorithm::Eae,
        Algorithm::Fedorov,
        Algorithm::Detmax,
        Algorithm::Random,
    ] {
        let a = select(&xm, CriterionKind::Det, alg, &s).unwrap();
        let b = select(&xmm, CriterionKind::Det, alg, &s).unwrap();
        assert_eq!(a.poses, b.poses, "{alg:?}: metres vs millimetres");
        // ln det of the same design, each from its own factorization: both
        // err by ~(m + p)·ε·κ_s ≈ 1e-10 (κ_s ≈ 2e4) plus the rounding of
        // scaling the entries; 1e-8 absolute is ample and far below any
        // difference between two designs.
        assert!(
            (b.ln_oid - a.ln_oid - shift).abs() < 1e-8,
            "{alg:?}: {} vs {} + {shift}",
            b.ln_oid,
            a.ln_oid
        );
    }
    // The eigenvalue OI criterion too (O(p³) per candidate: the 3-level pool).
    let (xm, xmm) = (pool(&m, 3), pool(&mm, 3));
    let s = Settings::builder().n(15).initial(10).build().unwrap();
    let a = select(&xm, CriterionKind::Oi, Algorithm::Eae, &s).unwrap();
    let b = select(&xmm, CriterionKind::Oi, Algorithm::Eae, &s).unwrap();
    assert_eq!(a.poses, b.poses, "OI criterion");
}

#[test]
fn column_scales_change_no_design_even_from_a_ridge_start() {
    let r = Robot::puma560();
    let x = pool(&r, 4);
    // Scales spanning 1e-4 … 1e4, none a power of two, so rounding differs.
    let s: Vec<f64> = (0..x.p())
        .map(|j| 10f64.powf(((j * 7) % 9) as f64 - 4.0) * 1.37)
        .collect();
    let xs = scale_columns(&x, &s);
    // Five initial poses give 15 rows for 27 unknowns: the start needs the
    // ridge, which must scale with its column.
    let settings = Settings::builder()
        .initial(5)
        .starts(2)
        .designs(500)
        .build()
        .unwrap();
    for alg in [
        Algorithm::Eae,
        Algorithm::Fedorov,
        Algorithm::Detmax,
        Algorithm::Random,
    ] {
        let a = select(&x, CriterionKind::Det, alg, &settings).unwrap();
        let b = select(&xs, CriterionKind::Det, alg, &settings).unwrap();
        assert_eq!(a.poses, b.poses, "{alg:?}");
        if alg == Algorithm::Eae {
            assert!(
                a.trace.iter().any(|t| t.ridge),
                "EAE did not start on a ridge"
            );
            let ra: Vec<bool> = a.trace.iter().map(|t| t.ridge).collect();
            let rb: Vec<bool> = b.trace.iter().map(|t| t.ridge).collect();
            assert_eq!(ra, rb, "the ridge was dropped at another step");
        }
    }
}

/// The PUMA's real geometry edited by `edit`, as the nominal model, with a
/// real robot 1e-2 of [`perturbation`](activecal::model::catalogue::perturbation)
/// away (at most 5e-5 per unknown): calibration from the nominal model is
/// then a nearly linear problem even with a 900 km lever arm (the paper's
/// Table II start, 0.065 rad off in `gamma_a`, would put the start 59 km
/// from every measurement), so its rank speaks for the design alone.
fn puma_edited(edit: impl Fn(&mut Robot)) -> Robot {
    let mut r = Robot::puma560();
    r.nominal = r.real.clone();
    edit(&mut r);
    r.real = r.nominal.clone();
    for &u in &r.unknowns.clone() {
        let v = r.nominal.get(u) + 1e-2 * activecal::model::catalogue::perturbation(u);
        r.real.set(u, v);
    }
    r
}

/// The PUMA with its measurement frame 900 km away (`a_a = 9e5` m).
fn far_sensor() -> Robot {
    puma_edited(|r| r.nominal.rows[0][Symbol::A.column()] = 9e5)
}

/// The PUMA with the DH frame `2` twisted by 1e-5 rad instead of π/2: the
/// axes of joints 3 and 4 are 1e-5 rad apart, where DH's `d` of both frames
/// slide along a common normal that is nearly undefined.
fn near_parallel_dh_axes() -> Robot {
    puma_edited(|r| {
        let k = r.frames.iter().position(|f| f.label == "2").unwrap();
        r.nominal.rows[k][Symbol::Alpha.column()] = 1e-5;
    })
}

/// What each command concludes about `robot` on its 3-level lattice, in
/// process: (select found a design, bound certified the pool, score's rank is
/// full, calibrate's rank is full). Score and calibrate run on the design
/// select found, or on 40 poses spread over the pool when it found none.
fn verdicts(robot: &Robot) -> [bool; 4] {
    let x = pool(robot, 3);
    let s = Settings::builder().n(30).build().unwrap();
    let sel = select(&x, CriterionKind::Det, Algorithm::Eae, &s);
    // The Newton solver: certified the same way as Clarabel's, ten times
    // faster on this pool.
    let settings = BoundSettings::builder()
        .solver(RelaxationSolver::Newton)
        .build()
        .unwrap();
    let bound = relaxation_bound(&x, None, 30, &settings);
    if let Err(e) = &bound {
        assert!(matches!(e, BoundError::RankDeficient { .. }), "{e}");
    }
    let poses: Vec<usize> = match &sel {
        Ok(sel) => sel.poses.clone(),
        Err(_) => (0..40).map(|k| k * (x.n_poses() / 40)).collect(),
    };
    let score = Indices::from_design(&x, &poses);
    let pool_all = Pool::full(robot, 3).unwrap();
    let qs: Vec<Vec<f64>> = poses.iter().map(|&k| pool_all.q(k)).collect();
    let meas = simulate(robot, &robot.real, &qs, 1e-5, &mut trial_rng(3, 0)).unwrap();
    let id = identify(robot, &robot.nominal, &meas, &LmSettings::default()).unwrap();
    // The identification's own rank agrees with the rule on the design's
    // Jacobian at the nominal parameters (the estimate moves it little).
    let design = x.select(&poses);
    assert_eq!(
        identifiability(robot, &design).rank == robot.n_unknowns(),
        id.rank == robot.n_unknowns()
    );
    [
        sel.is_ok(),
        bound.is_ok(),
        score.rank == x.p(),
        id.rank == robot.n_unknowns(),
    ]
}

#[test]
fn select_bound_score_and_calibrate_agree_on_identifiability() {
    // Raw κ(XᵀX) of the far sensor's designs is ~2e16, beyond any fixed
    // threshold on the raw matrix; equilibrated it is the PUMA's ~2e4.
    assert_eq!(verdicts(&far_sensor()), [true; 4], "900 km sensor");
    assert_eq!(
        verdicts(&near_parallel_dh_axes()),
        [false; 4],
        "DH axes 1e-5 apart"
    );
    // The loaders apply the same rule: the near-parallel robot's description
    // is refused, naming the unknowns that cannot be told apart.
    let e = near_parallel_dh_axes().check_identifiable().unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("d_2") && msg.contains("d_3"), "{msg}");
    assert!(far_sensor().check_identifiable().is_ok());
}

#[test]
fn the_commands_agree_on_a_sensor_900_km_away() {
    let dir =
        std::env::temp_dir().join(format!("activecal-unit-invariance-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let robot = dir.join("far.toml");
    std::fs::write(&robot, activecal::io::robot_toml::to_toml(&far_sensor())).unwrap();
    let design = dir.join("design.json");
    let (r, d) = (robot.to_str().unwrap(), design.to_str().unwrap());
    let sel = json_of(&[
        "select", "--robot", r, "--levels", "3", "--n", "30", "--out", d, "--json",
    ]);
    assert_eq!(sel["poses"].as_array().unwrap().len(), 30);
    let bound = json_of(&[
        "bound", "--robot", r, "--levels", "3", "--n", "30", "--solver", "newton", "--json",
    ]);
    assert_eq!(bound["status"], "certified", "{bound}");
    let score = json_of(&["score", "--design", d, "--json"]);
    assert_eq!(score["singular"], false, "{score}");
    assert_eq!(score["rank"], 27);
    let gap = json_of(&["gap", "--design", d, "--solver", "newton", "--json"]);
    assert!(gap["d_efficiency"].as_f64().unwrap() > 0.5, "{gap}");
    let cal = json_of(&[
        "calibrate",
        "--robot",
        r,
        "--design",
        d,
        "--noise",
        "1e-5",
        "--validation",
        "20",
        "--json",
    ]);
    let text = cal.to_string();
    assert!(text.contains("\"rank\":27"), "{text}");
    // The near-parallel robot is refused by every command at load, with the
    // unknowns named.
    let bad = dir.join("par.toml");
    std::fs::write(
        &bad,
        activecal::io::robot_toml::to_toml(&near_parallel_dh_axes()),
    )
    .unwrap();
    let b = bad.to_str().unwrap();
    for args in [
        vec!["select", "--robot", b, "--levels", "3"],
        vec!["bound", "--robot", b, "--levels", "3", "--solver", "newton"],
        vec!["score", "--robot", b, "--levels", "3", "--poses", "1,2,3"],
        vec!["calibrate", "--robot", b, "--design", d],
    ] {
        fails_with(&args, "not identifiable");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
