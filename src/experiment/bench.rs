//! The project's own benchmark (`bench`): medians of the hot paths on the
//! PUMA pool (forward kinematics and Jacobian, the scans, one EAE start, a
//! polish), identification, the relaxation bound by both solvers, the
//! 10⁶-pose scale run and robots side by side, each with its peak memory.
//! Returns a typed report; the caller renders it
//! ([`crate::render::bench_text`], the report [`crate::report::bench`]).

use super::ExperimentError;
use crate::blocks::Blocks;
use crate::bound::{BoundSettings, RelaxationSolver, relaxation_bound};
use crate::criterion::{DCriterion, ScanTimings, bench_scan};
use crate::error::Error;
use crate::identify::{LmSettings, identify, simulate, trial_rng};
use crate::model::Robot;
use crate::pool::Pool;
pub use crate::report::bench::{BenchReport, BoundRow, RobotRow, ScaleRun, TimingRow};
use crate::select::{
    Algorithm, CriterionKind, Selection, Settings, default_ils_rounds, design_rng, eae, polish,
    select,
};
use std::time::Instant;

/// What to run.
#[derive(Clone, Copy, Debug)]
pub struct BenchSettings {
    /// Repetitions per timing (the median is reported), ≥ 1.
    pub reps: usize,
    /// Also the 10⁶-pose scale run.
    pub scale: bool,
    /// Also the robots side by side ([`ROBOTS`]).
    pub robots: bool,
}

/// The robots compared side by side: a label and a robot reference (with
/// its chain fragment). File robots are found from the repository's root.
pub const ROBOTS: [(&str, &str); 4] = [
    ("PUMA 560, points", "puma560"),
    ("UR5, full pose", "ur5:pose"),
    (
        "UR10 (FIGAROH), full pose",
        "fixtures/figaroh/ur10_robot.urdf:pose#tip=wrist_3_link",
    ),
    (
        "Panda, full pose",
        "fixtures/example-robot-data/panda.urdf:pose#tip=panda_hand_tcp",
    ),
];

/// Runs the benchmark.
///
/// # Errors
/// `reps` 0, or a failing step (a robot's file that does not load).
pub fn run(s: BenchSettings) -> Result<BenchReport, ExperimentError> {
    if s.reps == 0 {
        return Err(
            Error::Invalid("0 repetitions: the median needs at least 1 repetition".into()).into(),
        );
    }
    let mut table = Vec::new();
    let k = kernels(s.reps, &mut table)?;
    let lm = lm_rows(&k, s.reps, &mut table)?;
    let bounds = bound_rows(&k.x, &mut table)?;
    let scale = s
        .scale
        .then(|| scale_run(&k.robot, &mut table))
        .transpose()?;
    let peak = peak_mib();
    let (robots, skipped) = if s.robots {
        let (r, sk) = robot_rows()?;
        (Some(r), sk)
    } else {
        (None, Vec::new())
    };
    Ok(BenchReport {
        threads: rayon::current_num_threads(),
        jacobian_ms: k.t_jac * 1e3,
        jacobian_ns_per_pose: k.t_jac * 1e9 / k.pool.len() as f64,
        scan: k.scan,
        eae_ms: k.t_eae * 1e3,
        polish_ms: k.t_pol * 1e3,
        polish_iterations: k.polish_iterations,
        lm_point_ms: lm.point.0 * 1e3,
        lm_point_iterations: lm.point.1,
        lm_pose_ms: lm.pose.0 * 1e3,
        lm_pose_iterations: lm.pose.1,
        bounds,
        scale,
        peak_mib: peak,
        robots,
        table,
        skipped,
        reps: s.reps,
    })
}

/// Resets the process's peak resident memory (VmHWM) to its current size
/// (`/proc/self/clear_refs`, Linux ≥ 4.0), so that [`peak_mib`] measures
/// the next step alone; false where that is not possible.
fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Peak resident memory of this process (VmHWM), in MiB; 0 if unknown.
#[must_use]
pub fn peak_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|v| v.parse::<f64>().ok())
            })
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The median wall time of `reps` runs of `f` (at least one), seconds,
/// and the last run's result.
fn time<F: FnMut() -> R, R>(reps: usize, mut f: F) -> (f64, R) {
    let mut ts = Vec::with_capacity(reps);
    let mut last = None;
    for _ in 0..reps.max(1) {
        let t0 = Instant::now();
        last = Some(f());
        ts.push(t0.elapsed().as_secs_f64());
    }
    (median(ts), last.expect("at least one rep"))
}

fn row(what: &str, median_ms: f64, note: String) -> TimingRow {
    TimingRow {
        what: what.into(),
        median_ms,
        note,
    }
}

/// The kernels on the PUMA pool and what the later sections reuse.
struct Kernels {
    robot: Robot,
    pool: Pool,
    x: Blocks,
    sel: Selection,
    scan: ScanTimings,
    t_jac: f64,
    t_eae: f64,
    t_pol: f64,
    polish_iterations: usize,
}

fn eae_run(x: &Blocks, s: &Settings, seed: u64) -> Result<Selection, Error> {
    eae(x, &mut DCriterion::new(), s, &mut design_rng(seed, 0))
}

/// The kernel rows (PUMA, 15,625 poses).
fn kernels(reps: usize, rows: &mut Vec<TimingRow>) -> Result<Kernels, ExperimentError> {
    let robot = Robot::puma560();
    let pool = Pool::full(&robot, 5)?;
    let (t_jac, x) = time(reps, || pool.jacobian(&robot, &robot.nominal));
    let s = Settings::default();
    let sel = eae_run(&x, &s, 1)?;
    let scan = bench_scan(&x, &sel.poses, reps)
        .map_err(|e| Error::Invalid(format!("the criterion's scans: {e}")))?;
    let mut seed = 0;
    let (t_eae, last) = time(reps, || {
        seed += 1;
        eae_run(&x, &s, seed)
    });
    last?;
    let (t_pol, pol) = time(reps.min(3), || {
        polish(&x, &mut DCriterion::new(), sel.clone(), &s)
    });
    let polish_iterations = pol?.trace.len() - sel.trace.len();
    let per = |ns: f64, n: usize| ns * n as f64 * 1e-6;
    rows.extend([
        row(
            "FK + Jacobian, whole 15,625 pool",
            t_jac * 1e3,
            format!("{:.0} ns/pose", t_jac * 1e9 / pool.len() as f64),
        ),
        row(
            "add-gain scan (maintained V_i)",
            per(scan.add_gain_ns, scan.n_candidates),
            format!("{:.2} ns/candidate", scan.add_gain_ns),
        ),
        row(
            "eigenvalue OI recomputed per candidate",
            per(scan.oi_eigen_ns, scan.n_candidates),
            format!("{:.0} ns/candidate", scan.oi_eigen_ns),
        ),
        row(
            "  speed-up of the update over eigen-recompute",
            f64::NAN,
            format!("{:.0}x", scan.speedup),
        ),
        row(
            "V_i full recompute (X M^-1 X^T)",
            per(scan.variances_full_ns, scan.n_pool),
            format!("{:.2} ns/pose", scan.variances_full_ns),
        ),
        row(
            "V_i rank-2t update after an exchange",
            per(scan.variances_update_ns, scan.n_pool),
            format!("{:.2} ns/pose", scan.variances_update_ns),
        ),
        row(
            "exchange prices, one out-pose",
            per(scan.exchange_one_out_ns, scan.n_candidates),
            format!("{:.2} ns/candidate", scan.exchange_one_out_ns),
        ),
        row(
            "one EAE start (12 -> 30 poses)",
            t_eae * 1e3,
            format!("{} steps", sel.trace.len()),
        ),
        row(
            "Fedorov polish of an EAE design",
            t_pol * 1e3,
            format!(
                "{polish_iterations} exchanges, {:.1} ms/iter",
                t_pol * 1e3 / (polish_iterations + 1) as f64
            ),
        ),
    ]);
    Ok(Kernels {
        robot,
        pool,
        x,
        sel,
        scan,
        t_jac,
        t_eae,
        t_pol,
        polish_iterations,
    })
}

/// The two calibrations' median seconds and iterations.
struct LmTimes {
    point: (f64, usize),
    pose: (f64, usize),
}

/// Identification rows: one Levenberg–Marquardt calibration of the EAE
/// design from the nominal start, points (PUMA, σ = 1 cm) and full poses
/// (UR5, σ = 1 mm).
fn lm_rows(
    k: &Kernels,
    reps: usize,
    rows: &mut Vec<TimingRow>,
) -> Result<LmTimes, ExperimentError> {
    let lm_time = |r: &Robot,
                   pool: &Pool,
                   poses: &[usize],
                   sigma: f64|
     -> Result<(f64, usize), ExperimentError> {
        let qs: Vec<Vec<f64>> = poses.iter().map(|&k| pool.q(k)).collect();
        let meas = simulate(r, &r.real, &qs, sigma, &mut trial_rng(1, 0))?;
        let lm = LmSettings::default();
        let (t, id) = time(reps, || identify(r, &r.nominal, &meas, &lm));
        Ok((t, id?.iterations))
    };
    let point = lm_time(&k.robot, &k.pool, &k.sel.poses, 0.01)?;
    let ur5 = Robot::builtin("ur5:pose")?;
    let pool6 = Pool::full(&ur5, 3)?;
    let x6 = pool6.jacobian(&ur5, &ur5.nominal);
    let sel6 = eae_run(&x6, &Settings::default(), 1)?;
    let pose = lm_time(&ur5, &pool6, &sel6.poses, 0.001)?;
    rows.push(row(
        "LM calibration, PUMA, 30 points (p = 27)",
        point.0 * 1e3,
        format!("{} iterations", point.1),
    ));
    rows.push(row(
        "LM calibration, UR5, 30 full poses (p = 30)",
        pose.0 * 1e3,
        format!("{} iterations", pose.1),
    ));
    Ok(LmTimes { point, pose })
}

/// The relaxation bound on the kernels' pool by each candidate-set solver
/// (one run each: seconds, not microseconds).
fn bound_rows(x: &Blocks, rows: &mut Vec<TimingRow>) -> Result<Vec<BoundRow>, ExperimentError> {
    let n = Settings::default().n;
    let mut bounds = Vec::new();
    for solver in [RelaxationSolver::Clarabel, RelaxationSolver::Newton] {
        let settings = BoundSettings::builder().solver(solver).build()?;
        let b = relaxation_bound(x, None, n, &settings)?;
        rows.push(row(
            &format!("relaxation bound, {solver:?}"),
            b.seconds * 1e3,
            format!(
                "candidate solves {:.2} s, certified gap {:.1e}",
                b.conic.seconds, b.certificate_gap
            ),
        ));
        bounds.push(BoundRow {
            solver,
            seconds: b.seconds,
            solver_seconds: b.conic.seconds,
            ln_bound: b.ln_bound,
            certificate_gap: b.certificate_gap,
        });
    }
    Ok(bounds)
}

/// The 10⁶-pose pool: Jacobian, one EAE start for N = 145, the bound for
/// N = 30 (Newton: Clarabel's rounds on ~2,000 candidates take minutes
/// each).
fn scale_run(robot: &Robot, rows: &mut Vec<TimingRow>) -> Result<ScaleRun, ExperimentError> {
    let big = Pool::full(robot, 10)?;
    let t0 = Instant::now();
    let xb = big.jacobian(robot, &robot.nominal);
    let jacobian_s = t0.elapsed().as_secs_f64();
    let sb = Settings::builder().n(145).build()?;
    let t0 = Instant::now();
    let selb = eae(&xb, &mut DCriterion::new(), &sb, &mut design_rng(1, 0))?;
    let eae_s = t0.elapsed().as_secs_f64();
    let log10_oid = selb.ln_oid / std::f64::consts::LN_10;
    rows.push(row(
        "10^6 pool: FK + Jacobian",
        jacobian_s * 1e3,
        format!("{} poses", big.len()),
    ));
    rows.push(row(
        "10^6 pool: one EAE start, N = 145",
        eae_s * 1e3,
        format!("log10 OI_D {log10_oid:.3}"),
    ));
    let peak_mib_eae = peak_mib();
    let settings = BoundSettings::builder()
        .solver(RelaxationSolver::Newton)
        .build()?;
    let bb = relaxation_bound(&xb, None, Settings::default().n, &settings)?;
    rows.push(row(
        "10^6 pool: relaxation bound, N = 30 (Newton)",
        bb.seconds * 1e3,
        format!(
            "log10 {:.4}, gap {:.1e}, {} rounds",
            bb.log10_bound(),
            bb.certificate_gap,
            bb.conic.rounds
        ),
    ));
    Ok(ScaleRun {
        poses: big.len(),
        jacobian_s,
        eae_s,
        n: 145,
        log10_oid,
        steps: selb.trace.len(),
        peak_mib_eae,
        bound_s: bb.seconds,
        bound_log10: bb.log10_bound(),
        bound_gap: bb.certificate_gap,
        bound_status: bb.status,
        peak_mib: peak_mib(),
    })
}

/// The robots of [`ROBOTS`] whose files are found (from the repository's
/// root), and a note for each skipped.
fn robot_rows() -> Result<(Vec<RobotRow>, Vec<String>), ExperimentError> {
    let (mut out, mut skipped) = (Vec::new(), Vec::new());
    for (label, spec) in ROBOTS {
        let file = spec.split([':', '#']).next().unwrap_or(spec);
        if file.contains('/') && !std::path::Path::new(file).exists() {
            skipped.push(format!(
                "{label} skipped: {file} not found (run from the repository)"
            ));
            continue;
        }
        out.push(robot_row(label, spec)?);
    }
    Ok((out, skipped))
}

/// One robot side by side: its bound, one EAE start and the default
/// selection with their D-efficiencies, and its peak memory.
fn robot_row(label: &str, spec: &str) -> Result<RobotRow, ExperimentError> {
    let robot = crate::io::load_robot(spec)?;
    robot.validate()?;
    let reset = reset_peak();
    let pool = Pool::full(&robot, 5)?;
    let x = pool.jacobian(&robot, &robot.nominal);
    let settings = BoundSettings::builder()
        .solver(RelaxationSolver::Newton)
        .build()?;
    let s = Settings::default();
    let b = relaxation_bound(&x, None, s.n, &settings)?;
    let t0 = Instant::now();
    let one = eae_run(&x, &s, 1)?;
    let eae_s = t0.elapsed().as_secs_f64();
    let ds = Settings::builder()
        .starts(2)
        .ils(default_ils_rounds(x.n_poses(), x.t()))
        .build()?;
    let t0 = Instant::now();
    let best = select(&x, CriterionKind::Det, Algorithm::Eae, &ds)?;
    let select_s = t0.elapsed().as_secs_f64();
    let eff = |ln: f64| crate::bound::gap::d_efficiency(Some(ln), b.ln_bound, x.p());
    Ok(RobotRow {
        robot: label.into(),
        spec: spec.into(),
        p: x.p(),
        t: x.t(),
        poses: x.n_poses(),
        bound_s: b.seconds,
        bound_gap: b.certificate_gap,
        bound_status: b.status,
        eae_s,
        eae_d_efficiency: eff(one.ln_oid),
        select_s,
        select_ils: ds.ils,
        select_d_efficiency: eff(best.ln_oid),
        peak_mib: reset.then(peak_mib),
    })
}
