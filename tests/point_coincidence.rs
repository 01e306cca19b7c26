//! The contact sensor (points the tool touches again and again, known
//! distances between them): Jacobian rows against central differences, bad
//! inputs, and the figures of issue 29 on MUKCa's real Panda data
//! (`fixtures/mukca`).

use activecal::data::ContactFile;
use activecal::data::NamedDistance;
use activecal::identify::contact::{
    ContactFit, ContactSettings, HoldoutMode, fit_contacts, holdout_by_placement, resolve_distances,
};
use activecal::identify::{Calibration, LossChoice, Residuals};
use activecal::io::contacts::{parse_contacts, read_contacts};
use activecal::io::load_robot;
use activecal::measure::contact::{ContactSensor, KnownDistance};
use activecal::model::Robot;
use activecal::units::Units;
use faer::Mat;
use std::path::Path;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/mukca");

fn panda() -> Robot {
    load_robot(&format!("{DIR}/panda.urdf#tip=ball_link"))
        .expect("MUKCa's Panda with its ball link")
}

fn contacts(robot: &Robot) -> ContactFile {
    read_contacts(
        Path::new(&format!("{DIR}/panda_2.csv")),
        robot,
        Units::default(),
    )
    .expect("panda_2")
}

/// The two sockets of every placement, 50.0 mm apart.
fn sockets(file: &ContactFile) -> Vec<NamedDistance> {
    activecal::identify::contact::placements(file)
        .into_iter()
        .map(|p| NamedDistance {
            a: format!("{p}/0"),
            b: format!("{p}/1"),
            metres: 0.05,
        })
        .collect()
}

/// Every column of the residual Jacobian (robot unknowns, tool offset,
/// points; pose rows and the distance row) is the central difference of the
/// residual. Step 1e-6 on parameters of O(0.1–1) (metres, radians):
/// truncation O(h²·|r'''|) ≈ 1e-12, rounding ε·|r|/h ≈ 1e-10; 1e-7
/// separates a right column from any wrong one (entries O(0.1–1)).
#[test]
fn jacobian_rows_are_central_differences() {
    let robot = panda();
    let file = contacts(&robot).subset(&(0..12).chain(31..43).collect::<Vec<_>>());
    let distances = vec![KnownDistance {
        a: 0,
        b: 1,
        metres: 0.05,
    }];
    let sensor = ContactSensor::new(file.points.clone(), distances);
    let measured: Vec<f64> = file
        .groups
        .iter()
        .flat_map(|&g| ContactSensor::value_of(g))
        .collect();
    let mut prob =
        Calibration::with_sensor(&robot, &robot.nominal, &file.qs, Box::new(sensor), measured);
    let mut theta = robot.unknown_values(&robot.nominal);
    // A tool offset and points off the data, so that no row is zero.
    theta.extend_from_slice(&[0.01, -0.02, 0.03]);
    let own0 = activecal::identify::contact::start_own(&robot, &robot.nominal, &file);
    theta.extend(own0[3..].iter().map(|v| v + 0.004));
    let (m, n) = (prob.n_residuals(), prob.n_params());
    assert_eq!(m, 3 * file.qs.len() + 1);
    let mut r = vec![0.0; m];
    let mut jac = Mat::<f64>::zeros(m, n);
    assert!(prob.eval(&theta, &mut r, Some(&mut jac)));
    let h = 1e-6;
    for c in 0..n {
        let (mut tp, mut tm) = (theta.clone(), theta.clone());
        tp[c] += h;
        tm[c] -= h;
        let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
        prob.eval(&tp, &mut rp, None);
        prob.eval(&tm, &mut rm, None);
        for i in 0..m {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            assert!(
                (jac[(i, c)] - fd).abs() < 1e-7,
                "row {i} column {c}: {} vs {fd}",
                jac[(i, c)]
            );
        }
    }
}

/// Bad inputs name the file, the point and the lines.
#[test]
fn bad_inputs_are_explained() {
    let robot = panda();
    let head = "panda_joint1,panda_joint2,panda_joint3,panda_joint4,panda_joint5,panda_joint6,panda_joint7,point\n";
    let row = |p: &str| format!("0,0,0,-1.5,0,1.5,0.7,{p}\n");
    let e = |t: &str| {
        parse_contacts(t, "c.csv", &robot, Units::default())
            .unwrap_err()
            .to_string()
    };
    let short = format!(
        "{head}{}{}{}{}{}",
        row("a"),
        row("a"),
        row("a"),
        row("b"),
        row("b")
    );
    assert!(
        e(&short).contains("c.csv: point 'b' has 2 row(s) (line 5, 6)"),
        "{}",
        e(&short)
    );
    let full_pose = head.replace(",point", ",x1,y1,z1,qw1,qx1,qy1,qz1,point");
    assert!(
        e(&full_pose).contains("no measured position or orientation"),
        "{}",
        e(&full_pose)
    );
    let ok = format!("{head}{}{}{}", row("a"), row("a"), row("a"));
    let file = parse_contacts(&ok, "c.csv", &robot, Units::default()).unwrap();
    let unknown = [NamedDistance {
        a: "a".into(),
        b: "z".into(),
        metres: 0.05,
    }];
    let msg = resolve_distances(&file, &unknown, true)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("c.csv has no point 'z'") && msg.contains("its points: a"),
        "{msg}"
    );
}

fn settings(loss: LossChoice) -> ContactSettings {
    ContactSettings::builder().loss(loss).build().unwrap()
}

/// Issue 29's acceptance on MUKCa's `panda_2`: leave one placement out.
/// Figures are means over the held-out placements of each placement's RMS
/// distance to its sockets' means (the issue's table; measured 0.420 mm,
/// 0.325 mm without `high`, distance error 0.169 mm mean): the bars are
/// the issue's.
#[test]
fn panda_2_leave_one_placement_out_meets_the_issue() {
    let robot = panda();
    let file = contacts(&robot);
    let given = sockets(&file);
    let h = holdout_by_placement(
        &robot,
        &robot.nominal,
        &file,
        &given,
        &settings(LossChoice::L2),
        &HoldoutMode::LeaveOneOut,
    )
    .unwrap();
    assert_eq!(h.folds.len(), 9);
    assert!(h.folds.iter().all(|f| f.converged));
    assert!(h.pooled_nominal_mm > 8.0, "{}", h.pooled_nominal_mm);
    assert!(h.mean_calibrated_mm <= 0.42, "{}", h.mean_calibrated_mm);
    let others: Vec<f64> = h
        .folds
        .iter()
        .filter(|f| f.held_out != "high")
        .map(|f| f.figures.calibrated_mm)
        .collect();
    let without_high = others.iter().sum::<f64>() / others.len() as f64;
    assert!(without_high <= 0.33, "{without_high}");
    assert!(h.mean_distance_error_mm.unwrap() <= 0.2, "{:?}", h);
}

/// Trained on `front_left` alone, judged on the eight other placements
/// (measured: mean 0.554 mm, 0.455 mm without `high`; the issue's table
/// gives 0.55 and 0.46 mm at two decimals, so the bars are 0.555 and 0.465).
#[test]
fn panda_2_trained_on_front_left() {
    let robot = panda();
    let file = contacts(&robot);
    let given = sockets(&file);
    let h = holdout_by_placement(
        &robot,
        &robot.nominal,
        &file,
        &given,
        &settings(LossChoice::L2),
        &HoldoutMode::TrainOn("front_left".into()),
    )
    .unwrap();
    assert_eq!(h.folds.len(), 8);
    assert!(h.folds.iter().all(|f| f.converged));
    assert!(h.mean_calibrated_mm < 0.555, "{}", h.mean_calibrated_mm);
    let others: Vec<f64> = h
        .folds
        .iter()
        .filter(|f| f.held_out != "high")
        .map(|f| f.figures.calibrated_mm)
        .collect();
    let without_high = others.iter().sum::<f64>() / others.len() as f64;
    assert!(without_high < 0.465, "{without_high}");
    assert!(h.mean_distance_error_mm.unwrap() <= 0.2, "{:?}", h);
}

/// Why training on `front_left` alone gives 0.554 mm (L2) and not less:
/// two of its 60 rows are faulty (file lines 242 and 243, `front_left/1`,
/// 1.3 and 1.8 mm from their socket's mean after calibration, where the
/// others are within 0.5 mm), and on one placement they pull the fit. A
/// Huber loss at 0.5 mm down-weights exactly these two (weights 0.40 and
/// 0.29) and the held-out mean falls to 0.511 mm (0.407 without `high`);
/// an L2 fit without the two rows gives 0.502 mm (0.398). Neither the
/// distance's weight (0.552–0.554 mm for weights 1 to 1000) nor the
/// contact pivot tolerance (the same unknowns from 3e-4 to 3e-2) moves it.
/// The bars sit between the L2 figure and the measured ones.
#[test]
fn front_left_holds_two_faulty_rows_a_robust_fit_names() {
    let robot = panda();
    let file = contacts(&robot);
    let given = sockets(&file);
    let train_on = HoldoutMode::TrainOn("front_left".into());
    let huber = holdout_by_placement(
        &robot,
        &robot.nominal,
        &file,
        &given,
        &settings(LossChoice::Huber { scale: 5e-4 }),
        &train_on,
    )
    .unwrap();
    for f in &huber.folds {
        let lines: Vec<usize> = f.downweighted.iter().map(|d| d.line).collect();
        assert_eq!(lines, vec![242, 243], "{:?}", f.downweighted);
        assert!(f.downweighted.iter().all(|d| d.point == "front_left/1"));
    }
    assert!(
        huber.mean_calibrated_mm < 0.53,
        "{}",
        huber.mean_calibrated_mm
    );
    let kept: Vec<usize> = (0..file.qs.len())
        .filter(|&i| ![242, 243].contains(&file.lines[i]))
        .collect();
    let without = holdout_by_placement(
        &robot,
        &robot.nominal,
        &file.subset(&kept),
        &given,
        &settings(LossChoice::L2),
        &train_on,
    )
    .unwrap();
    assert!(
        without.mean_calibrated_mm < 0.52,
        "{}",
        without.mean_calibrated_mm
    );
}

/// A robust loss names the `high` placement's shifted blocks among the rows
/// it down-weights (hole_0 rows 9–17 are file lines 320–328).
#[test]
fn huber_names_the_shifted_high_rows() {
    let robot = panda();
    let file = contacts(&robot);
    let known = resolve_distances(&file, &sockets(&file), true).unwrap();
    let fit = fit_contacts(
        &robot,
        &robot.nominal,
        &file,
        &known,
        &settings(LossChoice::Huber { scale: 6e-4 }),
    )
    .unwrap();
    assert!(fit.converged);
    let down = activecal::identify::contact::holdout::downweighted_rows(&fit, &file);
    let high0: Vec<usize> = down
        .iter()
        .filter(|d| d.point == "high/0")
        .map(|d| d.line)
        .collect();
    for line in 320..=328 {
        assert!(
            high0.contains(&line),
            "line {line} not down-weighted: {high0:?}"
        );
    }
    // The last joint's origin is seen only through the tool offset: the
    // reason names the offset its motion resembles.
    assert!(
        fit.fixed
            .iter()
            .any(|f| f.name == "a_panda_joint7" && f.reason.contains("tool_y")),
        "{:?}",
        fit.fixed
    );
    // The gauge is named: the whole setup turns about the base's vertical.
    assert!(
        fit.fixed
            .iter()
            .any(|f| f.name == "gamma_panda_joint1" && f.reason.contains("rigid motion"))
    );
}

/// Five placements of MUKCa's configurations (the seeds of the synthetic
/// truths), their sockets' known distances, and the fit of the real
/// contacts there (which unknowns these configurations determine).
fn five_placements(robot: &Robot) -> (ContactFile, Vec<NamedDistance>, ContactFit) {
    use activecal::identify::contact::placement_of;
    let real = contacts(robot);
    let keep = [
        "back_left",
        "front_left",
        "front_center",
        "mid_right",
        "mid-high",
    ];
    let rows: Vec<usize> = (0..real.qs.len())
        .filter(|&i| keep.contains(&placement_of(&real.points[real.groups[i]])))
        .collect();
    let seeds = real.subset(&rows);
    let given = sockets(&seeds);
    let known = resolve_distances(&seeds, &given, true).unwrap();
    let first = fit_contacts(
        robot,
        &robot.nominal,
        &seeds,
        &known,
        &settings(LossChoice::L2),
    );
    (seeds, given, first.unwrap())
}

/// `robot`'s nominal table with each unknown whose name `perturb` accepts
/// off by ±1 mm or ±1 mrad (signs drawn from `rng`).
fn perturbed<R: rand::Rng>(
    robot: &Robot,
    perturb: impl Fn(&str) -> bool,
    rng: &mut R,
) -> activecal::model::ParamTable {
    use rand::RngExt as _;
    let names = robot.parameter_names();
    let mut truth = robot.nominal.clone();
    for (k, u) in robot.unknowns.iter().enumerate() {
        if perturb(&names[k]) {
            let s = if rng.random::<bool>() { 1e-3 } else { -1e-3 };
            truth.set(*u, truth.get(*u) + s);
        }
    }
    truth
}

/// Contacts of `truth` at the configurations of `seeds` with seat noise
/// `sigma` (metres), the sockets' distances as the truth makes them, and
/// those resolved for a fit.
fn simulated<R: rand::Rng>(
    robot: &Robot,
    truth: &activecal::model::ParamTable,
    seeds: &ContactFile,
    given: &[NamedDistance],
    sigma: f64,
    rng: &mut R,
) -> (ContactFile, Vec<NamedDistance>, Vec<KnownDistance>) {
    use activecal::identify::contact::project::simulate_contacts;
    let (sim, pts) = simulate_contacts(robot, truth, &[0.0; 3], seeds, sigma, 0.0, rng).unwrap();
    let exact: Vec<NamedDistance> = given
        .iter()
        .map(|d| NamedDistance {
            metres: (pts[sim.point_index(&d.a).unwrap()] - pts[sim.point_index(&d.b).unwrap()])
                .norm(),
            ..d.clone()
        })
        .collect();
    let known = resolve_distances(&sim, &exact, true).unwrap();
    (sim, exact, known)
}

/// Synthetic truth: the Panda with every estimated joint origin off by
/// ±1 mm or ±1 mrad, five placements of MUKCa's configurations moved onto
/// their sockets (damped least squares) with 0.02 mm of seat noise: the fit
/// from nominal recovers every estimated unknown within 3σ, and leaving a
/// placement out, the calibrated consistency is at the noise floor
/// (≤ 0.05 mm: √3·0.02 = 0.035 mm is the RMS distance of a noisy row to
/// its point, plus the spread of the estimate).
#[test]
fn synthetic_truth_is_fitted_to_the_noise_floor() {
    let robot = panda();
    let (seeds, given, first) = five_placements(&robot);
    let l2 = settings(LossChoice::L2);
    let mut rng = activecal::identify::trial_rng(29, 0);
    let truth = perturbed(
        &robot,
        |n| !first.fixed.iter().any(|f| f.name == n),
        &mut rng,
    );
    let (sim, exact, known) = simulated(&robot, &truth, &seeds, &given, 2e-5, &mut rng);
    let fit = fit_contacts(&robot, &robot.nominal, &sim, &known, &l2).unwrap();
    assert!(fit.converged, "{:?}", fit.stop);
    let std = fit.std.as_ref().unwrap();
    let n_kin = fit.robot.n_unknowns();
    for (k, u) in fit.robot.unknowns.iter().enumerate() {
        let err = fit.estimate[k] - truth.get(*u);
        assert!(
            err.abs() <= 3.0 * std[k],
            "{}: off by {err:e}, σ {:e}",
            fit.names[k],
            std[k]
        );
    }
    for c in 0..3 {
        assert!(
            fit.estimate[n_kin + c].abs() <= 3.0 * std[n_kin + c],
            "tool offset {c}"
        );
    }
    let h = holdout_by_placement(
        &robot,
        &robot.nominal,
        &sim,
        &exact,
        &l2,
        &HoldoutMode::LeaveOneOut,
    )
    .unwrap();
    assert!(h.mean_calibrated_mm <= 0.05, "{:?}", h.mean_calibrated_mm);
    assert!(h.pooled_nominal_mm > 1.0, "{}", h.pooled_nominal_mm);
}

/// Noise-free contacts of a true Panda (every unknown the data determine at
/// all off by ±1 mm or ±1 mrad, the weakly determined ones included —
/// joint 6's γ and d, which the fit of the real data fixes because their σ
/// there is tenths of a radian) recover the truth: with no noise their σ
/// vanishes, so they are estimated, and the calibrated ball is where the
/// truth puts it to 1e-6 mm at random configurations. A constant pivot bar
/// fixed them and left 0.01 mm of true error (issue #39).
#[test]
fn noise_free_contacts_recover_the_weakly_determined_unknowns() {
    let robot = panda();
    let (seeds, given, first) = five_placements(&robot);
    let l2 = settings(LossChoice::L2);
    let weak: Vec<&str> = first
        .fixed
        .iter()
        .filter(|f| f.reason.starts_with("weakly determined"))
        .map(|f| f.name.as_str())
        .collect();
    assert!(
        !weak.is_empty(),
        "the real data fix no weak unknown: {:?}",
        first.fixed
    );
    // Every unknown but those the data cannot see at all: the weak ones too.
    let undetermined = |n: &str| first.fixed.iter().any(|f| f.name == n) && !weak.contains(&n);
    let mut rng = activecal::identify::trial_rng(31, 0);
    let truth = perturbed(&robot, |n| !undetermined(n), &mut rng);
    let (sim, _, known) = simulated(&robot, &truth, &seeds, &given, 0.0, &mut rng);
    let fit = fit_contacts(&robot, &robot.nominal, &sim, &known, &l2).unwrap();
    assert!(fit.converged, "{:?}", fit.stop);
    for w in &weak {
        assert!(
            fit.names.iter().any(|n| n == w),
            "{w} not estimated: {:?}",
            fit.fixed
        );
    }
    // The parameters to 1e-6 (a weak direction converges last: γ₆ ends
    // 1.4e-7 rad off, along a direction that moves the ball by far less).
    for (k, u) in fit.robot.unknowns.iter().enumerate() {
        let err = fit.estimate[k] - truth.get(*u);
        assert!(err.abs() < 1e-6, "{}: off by {err:e}", fit.names[k]);
    }
    // The ball where the truth puts it, to 1e-6 mm, at random
    // configurations (the gauge's unknowns are the truth's: nominal).
    let tool = nalgebra::Vector3::from(fit.tool_offset);
    for q in activecal::observability::generic_configurations(&robot, 200, 5) {
        let (r, p) = activecal::kinematics::pose(&fit.robot, &fit.table, &q);
        let (_, p0) = activecal::kinematics::pose(&robot, &truth, &q);
        let e = (p + r * tool - p0).norm();
        assert!(e < 1e-9, "true error {:e} mm", e * 1e3);
    }
}

/// The true error the fit's covariance predicts for the tool point (at
/// random configurations) is what a true Panda shows: over 12 draws of
/// 0.02 mm seat noise at five placements of MUKCa's configurations, the
/// RMS true error is within 1.3× of the RMS prediction (the 1.3 of the
/// issue; 12 draws of a ~0.01 mm figure scatter by ~10 %). The gauge's
/// unknowns are the truth's (nominal), so the two models compare directly.
#[test]
fn contacts_predict_their_true_error() {
    use activecal::identify::contact::predict::predicted_true_error;
    let robot = panda();
    let (seeds, given, first) = five_placements(&robot);
    let l2 = settings(LossChoice::L2);
    let mut rng = activecal::identify::trial_rng(41, 0);
    let truth = perturbed(
        &robot,
        |n| !first.fixed.iter().any(|f| f.name == n),
        &mut rng,
    );
    let eval = activecal::observability::generic_configurations(&robot, 1000, 9);
    let (mut true2, mut pred2) = (0.0, 0.0);
    let draws = 12;
    for _ in 0..draws {
        let (sim, _, known) = simulated(&robot, &truth, &seeds, &given, 2e-5, &mut rng);
        let fit = fit_contacts(&robot, &robot.nominal, &sim, &known, &l2).unwrap();
        assert!(fit.converged, "{:?}", fit.stop);
        let predicted = predicted_true_error(&fit, 1000, 3).unwrap().rms_mm;
        let tool = nalgebra::Vector3::from(fit.tool_offset);
        let e2: f64 = eval
            .iter()
            .map(|q| {
                let (r, p) = activecal::kinematics::pose(&fit.robot, &fit.table, q);
                let (_, p0) = activecal::kinematics::pose(&robot, &truth, q);
                (p + r * tool - p0).norm_squared()
            })
            .sum::<f64>()
            / eval.len() as f64;
        true2 += e2 * 1e6;
        pred2 += predicted * predicted;
    }
    let (t, p) = ((true2 / draws as f64).sqrt(), (pred2 / draws as f64).sqrt());
    println!("contacts: true error {t:.5} mm RMS over {draws} draws, predicted {p:.5} mm");
    assert!(
        t / p < 1.3 && p / t < 1.3,
        "true {t:.5} mm, predicted {p:.5} mm"
    );
}

/// Selection for a socket at `front_left/0`'s (nominal) position: 30
/// configurations chosen D-optimally from a pool projected onto the socket,
/// then exchanged for the predicted consistency error, against the median
/// of 100 random 30-configuration draws from the same pool (the
/// hand-recorded baseline); every pool configuration reaches the socket to
/// 0.1 mm. Measured (600 samples, 498 reach): D-optimal 0.481 σ, refined
/// 0.476 σ, random median 0.588 σ (1.235×), and the convex relaxation
/// certifies that no 30-configuration design of this pool is below
/// 0.469 σ: the issue's 1.5× is out of reach of any design of the pool
/// (median / bound = 1.25). Random draws are already nearly I-optimal on
/// average (their mean information gives 0.494 σ); what they lose is the
/// scatter of a 90-row, 25-unknown information matrix (about
/// 3n/(3n − p − 1) = 1.41 in variance, 1.19 in σ). So the test asserts
/// that the choice beats random clearly (1.2×), is within 2% of the bound
/// (1.5% measured), and that 1.5× is beyond the bound (so the shortfall is
/// the pool's, not the search's).
#[test]
fn selected_contacts_beat_random_draws() {
    use activecal::identify::contact::select::{Socket, predicted_consistency, socket_pool};
    use activecal::identify::contact::{group_means, tool_points};
    use activecal::select::contact::socket_design::consistency_bound;
    use activecal::select::contact::{refine_for_consistency, select_d_optimal};
    use rand::seq::SliceRandom;
    let robot = panda();
    let real = contacts(&robot);
    let g = real.point_index("front_left/0").unwrap();
    let pts = tool_points(&robot, &robot.nominal, &[0.0; 3], &real.qs);
    let socket = group_means(&pts, &real.groups, real.points.len())[g];
    let mut rng = activecal::identify::trial_rng(29, 1);
    let at = Socket {
        name: "front_left/0".into(),
        position: socket.into(),
    };
    let pool = socket_pool(
        &robot,
        &robot.nominal,
        &[at],
        &[],
        600,
        2f64.to_radians(),
        1e-7,
        &mut rng,
    )
    .unwrap();
    assert!(
        pool.qs.len() >= 100,
        "{} configurations reach the socket",
        pool.qs.len()
    );
    let reach = tool_points(&robot, &robot.nominal, &[0.0; 3], &pool.qs);
    assert!(reach.iter().all(|t| (t - socket).norm() <= 1e-4));
    let search = Default::default();
    let design = select_d_optimal(&pool, 30, &search).unwrap();
    assert_eq!(design.len(), 30);
    let d_opt = predicted_consistency(&pool, &design);
    let design = refine_for_consistency(&pool, &design, &search).unwrap();
    let chosen = predicted_consistency(&pool, &design);
    let ids: Vec<usize> = (0..pool.qs.len()).collect();
    let mut random: Vec<f64> = (0..100)
        .map(|_| {
            let mut d = ids.clone();
            d.shuffle(&mut rng);
            predicted_consistency(&pool, &d[..30])
        })
        .collect();
    random.sort_by(f64::total_cmp);
    let median = 0.5 * (random[49] + random[50]);
    eprintln!(
        "pool {}, unknowns {}: D-optimal {d_opt:.4} σ, refined {chosen:.4} σ, random median {median:.4} σ",
        pool.qs.len(),
        pool.p()
    );
    assert!(
        chosen.is_finite() && median >= 1.2 * chosen,
        "{chosen} vs {median}"
    );
    assert!(chosen <= d_opt, "{chosen} vs {d_opt}");
    let bound = consistency_bound(&pool, 30);
    eprintln!("bound {:?}", bound);
    // Certified: no design is below it (1e-9: rounding of traces of O(1)).
    assert!(bound.certified_sigma <= chosen + 1e-9);
    assert!(
        chosen <= 1.02 * bound.certified_sigma,
        "{chosen} vs {bound:?}"
    );
    assert!(
        median < 1.5 * bound.certified_sigma,
        "{median} vs {bound:?}"
    );
}

/// Plane contacts: every column of the residual Jacobian with an unknown
/// plane (chart `a, b` and offset `d`) and a known one, beside points, is
/// the central difference of the residual (same step and bar as above);
/// a plane with a zero normal is refused, naming it.
#[test]
fn plane_rows_are_central_differences() {
    use activecal::measure::contact::{Plane, PlaneKind};
    let robot = panda();
    let file = contacts(&robot).subset(&(0..12).chain(31..43).collect::<Vec<_>>());
    let planes = vec![
        Plane {
            name: "table".into(),
            kind: PlaneKind::Unknown {
                n0: [0.1, -0.2, 1.0],
            },
        },
        Plane {
            name: "wall".into(),
            kind: PlaneKind::Known {
                normal: [1.0, 0.5, 0.0],
                offset: 0.3,
            },
        },
    ];
    let zero = ContactSensor::new(file.points.clone(), Vec::new()).with_planes(vec![Plane {
        name: "floor".into(),
        kind: PlaneKind::Known {
            normal: [0.0; 3],
            offset: 0.0,
        },
    }]);
    assert!(
        zero.unwrap_err()
            .contains("plane 'floor': normal (0, 0, 0) is zero")
    );
    let sensor = ContactSensor::new(file.points.clone(), Vec::new())
        .with_planes(planes)
        .unwrap();
    // Rows 0–3 touch the unknown plane, 4–7 the known one, the rest points.
    let tags: Vec<usize> = (0..file.qs.len())
        .map(|i| match i {
            0..4 => 2,
            4..8 => 3,
            _ => file.groups[i],
        })
        .collect();
    let measured: Vec<f64> = tags
        .iter()
        .flat_map(|&g| ContactSensor::value_of(g))
        .collect();
    let mut prob =
        Calibration::with_sensor(&robot, &robot.nominal, &file.qs, Box::new(sensor), measured);
    let mut theta = robot.unknown_values(&robot.nominal);
    theta.extend_from_slice(&[0.01, -0.02, 0.03]);
    let own0 = activecal::identify::contact::start_own(&robot, &robot.nominal, &file);
    theta.extend(own0[3..].iter().map(|v| v + 0.004));
    theta.extend_from_slice(&[0.05, -0.03, 0.4]);
    let (m, n) = (prob.n_residuals(), prob.n_params());
    assert_eq!(n, theta.len());
    let mut r = vec![0.0; m];
    let mut jac = Mat::<f64>::zeros(m, n);
    assert!(prob.eval(&theta, &mut r, Some(&mut jac)));
    assert!(
        r[0].abs() > 1e-3 && r[1] == 0.0,
        "a plane row and its two zeros"
    );
    let h = 1e-6;
    for c in 0..n {
        let (mut tp, mut tm) = (theta.clone(), theta.clone());
        tp[c] += h;
        tm[c] -= h;
        let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
        prob.eval(&tp, &mut rp, None);
        prob.eval(&tm, &mut rm, None);
        for i in 0..m {
            let fd = (rp[i] - rm[i]) / (2.0 * h);
            assert!(
                (jac[(i, c)] - fd).abs() < 1e-7,
                "row {i} column {c}: {} vs {fd}",
                jac[(i, c)]
            );
        }
    }
}

/// The same selection judged where it matters for a calibration: the
/// predicted consistency error (variance of the unknowns the socket
/// determines, robot and tool offset) at the configurations MUKCa recorded
/// at the eight other placements of `panda_2`, not at the pool it was
/// chosen from. Measured: D-optimal 0.408 σ, exchanged 0.397 σ, median of
/// 100 random draws 0.494 σ (1.245×): the ratio is that of the pool (1.235×),
/// so judging elsewhere does not bring the issue's 1.5× either. Asserted:
/// the choice beats the random median by 1.15× there too.
#[test]
fn selected_contacts_judged_at_other_placements() {
    use activecal::identify::contact::select::{
        Socket, SocketPool, consistency_moment, socket_pool, with_unknowns_of,
    };
    use activecal::identify::contact::{group_means, placement_of, tool_points};
    use activecal::select::contact::{refine_for_consistency, select_d_optimal};
    use nalgebra::DMatrix;
    use rand::seq::SliceRandom;
    let robot = panda();
    let real = contacts(&robot);
    let g = real.point_index("front_left/0").unwrap();
    let pts = tool_points(&robot, &robot.nominal, &[0.0; 3], &real.qs);
    let at = Socket {
        name: "front_left/0".into(),
        position: group_means(&pts, &real.groups, real.points.len())[g].into(),
    };
    let mut rng = activecal::identify::trial_rng(29, 1);
    let margin = 2f64.to_radians();
    let pool = socket_pool(
        &robot,
        &robot.nominal,
        &[at],
        &[],
        600,
        margin,
        1e-7,
        &mut rng,
    )
    .unwrap();
    let rows: Vec<usize> = (0..real.qs.len())
        .filter(|&i| placement_of(&real.points[real.groups[i]]) != "front_left")
        .collect();
    let eval = with_unknowns_of(
        &pool,
        &robot.nominal,
        &real.points,
        rows.iter().map(|&i| real.qs[i].clone()).collect(),
        rows.iter().map(|&i| real.groups[i]).collect(),
    );
    // Robot unknowns and tool offset lead both column sets; the points'
    // columns drop out of a moment centred per point.
    let k = pool.robot.n_unknowns() + 3;
    let w = consistency_moment(&eval).view((0, 0), (k, k)).into_owned();
    let score = |pool: &SocketPool, d: &[usize]| -> f64 {
        let p = pool.p();
        let mut m = DMatrix::zeros(p, p);
        for &i in d {
            m += pool.block(i).transpose() * pool.block(i);
        }
        m.try_inverse().map_or(f64::INFINITY, |mi| {
            (mi.view((0, 0), (k, k)) * &w).trace().sqrt()
        })
    };
    let search = Default::default();
    let d_opt = select_d_optimal(&pool, 30, &search).unwrap();
    let chosen = refine_for_consistency(&pool, &d_opt, &search).unwrap();
    let ids: Vec<usize> = (0..pool.qs.len()).collect();
    let mut random: Vec<f64> = (0..100)
        .map(|_| {
            let mut d = ids.clone();
            d.shuffle(&mut rng);
            score(&pool, &d[..30])
        })
        .collect();
    random.sort_by(f64::total_cmp);
    let median = 0.5 * (random[49] + random[50]);
    let (a, b) = (score(&pool, &d_opt), score(&pool, &chosen));
    eprintln!(
        "other placements: D-optimal {a:.4} σ, exchanged {b:.4} σ, random median {median:.4} σ"
    );
    assert!(b.is_finite() && median >= 1.15 * b, "{b} vs {median}");
}

/// `select --point`'s choice against a true Panda (issue #39, item 6):
/// two sockets 50 mm apart (MUKCa's `front_left` block where the nominal
/// model puts it) with their distance known; 30 configurations chosen
/// D-optimally then exchanged for the tool point's predicted true error,
/// and 20 random 30-configuration designs of the same pool. The truth has
/// every unknown the design counts on off by ±1 mm or ±1 mrad; each design
/// is moved onto the true sockets with 0.02 mm of seat noise (40 draws for
/// the chosen design, 4 per random one), calibrated, and compared with the
/// truth at 300 generic configurations. Asserted: the pooled true error of
/// the chosen design and of the random ones are each within 1.3× of what
/// the design predicts for them (`√tr(M⁻¹W)·σ`, the criterion itself), and
/// the known distance adds the unknown contacts alone cannot see (the
/// scale). The ratio chosen/random is printed, not asserted: it is what the
/// pool allows (the certified bound is printed beside it).
#[test]
fn select_point_predicts_the_true_error_of_its_choice_and_of_random_draws() {
    use activecal::identify::contact::predict::true_error_moment;
    use activecal::identify::contact::select::{
        Socket, determined_pool, predicted_error, projected,
    };
    use activecal::identify::contact::{group_means, tool_points};
    use activecal::select::contact::socket_design::error_bound;
    use activecal::select::contact::{refine_for, select_d_optimal};
    use rand::seq::SliceRandom;
    let robot = panda();
    let real = contacts(&robot);
    let pts = tool_points(&robot, &robot.nominal, &[0.0; 3], &real.qs);
    let means = group_means(&pts, &real.groups, real.points.len());
    let sockets: Vec<Socket> = ["front_left/0", "front_left/1"]
        .iter()
        .map(|n| Socket {
            name: (*n).into(),
            position: means[real.point_index(n).unwrap()].into(),
        })
        .collect();
    let given = vec![NamedDistance {
        a: sockets[0].name.clone(),
        b: sockets[1].name.clone(),
        metres: 0.05,
    }];
    let mut rng = activecal::identify::trial_rng(43, 0);
    let margin = 2f64.to_radians();
    let file = projected(
        &robot,
        &robot.nominal,
        &sockets,
        300,
        margin,
        1e-7,
        &mut rng,
    )
    .unwrap();
    let known = resolve_distances(&file, &given, true).unwrap();
    let pool = determined_pool(&robot, &robot.nominal, file.clone(), &known).unwrap();
    let without = determined_pool(&robot, &robot.nominal, file.clone(), &[]).unwrap();
    assert_eq!(
        pool.robot.n_unknowns(),
        without.robot.n_unknowns() + 1,
        "a known distance determines the scale"
    );
    let w = true_error_moment(&pool, &robot.nominal, 3);
    let search = Default::default();
    let chosen = refine_for(
        &pool,
        &select_d_optimal(&pool, 30, &search).unwrap(),
        &w,
        &search,
    )
    .unwrap();
    let estimated = pool.robot.parameter_names();
    let truth = perturbed(
        &robot,
        |n| estimated[..pool.robot.n_unknowns()].iter().any(|e| e == n),
        &mut rng,
    );
    let (sigma, l2) = (2e-5, settings(LossChoice::L2));
    let eval = activecal::observability::generic_configurations(&robot, 300, 9);
    // Mean squared true error (m²) of `draws` calibrations from `design`.
    let true_ms = |design: &[usize], draws: usize, rng: &mut rand_chacha::ChaCha8Rng| -> f64 {
        let seeds = file.subset(design);
        let mut sum = 0.0;
        for _ in 0..draws {
            let (sim, _, known) = simulated(&robot, &truth, &seeds, &given, sigma, rng);
            let fit = fit_contacts(&robot, &robot.nominal, &sim, &known, &l2).unwrap();
            assert!(fit.converged, "{:?}", fit.stop);
            let tool = nalgebra::Vector3::from(fit.tool_offset);
            sum += eval
                .iter()
                .map(|q| {
                    let (r, p) = activecal::kinematics::pose(&fit.robot, &fit.table, q);
                    let (_, p0) = activecal::kinematics::pose(&robot, &truth, q);
                    (p + r * tool - p0).norm_squared()
                })
                .sum::<f64>()
                / eval.len() as f64;
        }
        sum / draws as f64
    };
    let chosen_true = true_ms(&chosen, 40, &mut rng).sqrt() * 1e3;
    let chosen_pred = predicted_error(&pool, &chosen, &w) * sigma * 1e3;
    let ids: Vec<usize> = (0..pool.qs.len()).collect();
    let (mut rand_true, mut rand_pred, mut per_design) = (0.0, 0.0, Vec::new());
    for _ in 0..20 {
        let mut d = ids.clone();
        d.shuffle(&mut rng);
        let ms = true_ms(&d[..30], 4, &mut rng);
        per_design.push(ms.sqrt() * 1e3);
        rand_true += ms / 20.0;
        rand_pred += (predicted_error(&pool, &d[..30], &w) * sigma * 1e3).powi(2) / 20.0;
    }
    let (rand_true, rand_pred) = (rand_true.sqrt() * 1e3, rand_pred.sqrt());
    per_design.sort_by(f64::total_cmp);
    let median = 0.5 * (per_design[9] + per_design[10]);
    let bound = error_bound(&pool, 30, &w).certified_sigma * sigma * 1e3;
    println!(
        "select --point, true Panda: chosen true {chosen_true:.5} mm (predicted {chosen_pred:.5} mm); random designs pooled true {rand_true:.5} mm (predicted {rand_pred:.5} mm), median of 20 {median:.5} mm; chosen/median {:.3}; bound {bound:.5} mm",
        chosen_true / median
    );
    for (t, p) in [(chosen_true, chosen_pred), (rand_true, rand_pred)] {
        assert!(
            t / p < 1.3 && p / t < 1.3,
            "true {t:.5} mm, predicted {p:.5} mm"
        );
    }
}
