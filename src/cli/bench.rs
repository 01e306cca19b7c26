//! `bench`: medians of the hot paths on the PUMA pool, identification, the
//! relaxation bound by both solvers, and the 10⁶-pose scale run (time and
//! peak memory).

use super::emit;
use activecal::blocks::Blocks;
use activecal::bound::{BoundSettings, RelaxationSolver, relaxation_bound};
use activecal::criterion::{DCriterion, bench_scan};
use activecal::identify::{LmSettings, identify, simulate, trial_rng};
use activecal::model::Robot;
use activecal::pool::Pool;
use activecal::select::{
    Algorithm, CriterionKind, Settings, default_ils_rounds, design_rng, eae, polish, select,
};
use anyhow::Result;
use clap::Args;
use serde_json::{Value, json};
use std::time::Instant;

/// Arguments of `bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Repetitions per measurement (the median is reported).
    #[arg(long, default_value_t = 7, allow_negative_numbers = true)]
    pub reps: usize,
    /// Also run the 10⁶-pose scale test (10 levels per joint, N = 145).
    #[arg(long)]
    pub scale: bool,
    /// Also compare the robots side by side: the certified bound, one EAE
    /// start and the default selection (multi-start with iterated local
    /// search) with its D-efficiency, and each robot's peak memory, on each
    /// robot's 5-level lattice (PUMA, UR5 full pose, and the FIGAROH UR10
    /// and example-robot-data Panda in full pose when run from the
    /// repository, where their URDFs are).
    #[arg(long)]
    pub robots: bool,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// The robots of `bench --robots`: a label and a `--robot` value (with its
/// chain fragment).
const ROBOTS: [(&str, &str); 4] = [
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

/// Resets the process's peak resident memory (VmHWM) to its current size
/// (`/proc/self/clear_refs`, Linux ≥ 4.0), so that [`peak_mib`] measures
/// the next step alone; false where that is not possible.
fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// One row of `bench --robots`, as JSON.
fn robot_row(label: &str, spec: &str) -> Result<Value> {
    let robot = activecal::io::load_robot(spec)?;
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
    let one = eae(&x, &mut DCriterion::new(), &s, &mut design_rng(1, 0))?;
    let t_one = t0.elapsed().as_secs_f64();
    let ds = Settings::builder()
        .starts(2)
        .ils(default_ils_rounds(x.n_poses(), x.t()))
        .build()?;
    let t0 = Instant::now();
    let best = select(&x, CriterionKind::Det, Algorithm::Eae, &ds)?;
    let t_def = t0.elapsed().as_secs_f64();
    let eff = |ln: f64| activecal::bound::gap::d_efficiency(Some(ln), b.ln_bound, x.p());
    Ok(json!({
        "robot": label, "spec": spec, "p": x.p(), "t": x.t(), "poses": x.n_poses(),
        "bound_s": b.seconds, "bound_gap": b.certificate_gap, "bound_status": b.status,
        "eae_s": t_one, "eae_d_efficiency": eff(one.ln_oid),
        "select_s": t_def, "select_ils": ds.ils, "select_d_efficiency": eff(best.ln_oid),
        "peak_mib": if reset { json!(peak_mib()) } else { Value::Null },
    }))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

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

/// Peak resident memory of this process (VmHWM), in MiB; 0 if unknown.
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

fn eae_run(x: &Blocks, s: &Settings, seed: u64) -> activecal::select::Selection {
    eae(x, &mut DCriterion::new(), s, &mut design_rng(seed, 0)).expect("EAE on the PUMA pool")
}

/// A row of the timing table: what, median milliseconds (NaN: none), note.
type Row = (String, f64, String);

/// The kernels on the PUMA pool: FK and Jacobian, the scans, one EAE
/// start, a polish.
struct Kernels {
    robot: Robot,
    pool: Pool,
    x: Blocks,
    sel: activecal::select::Selection,
    json: Value,
}

/// Runs `bench`: each section's timings as rows of one table, in JSON or
/// as text.
pub fn cmd_bench(a: BenchArgs) -> Result<()> {
    if a.reps == 0 {
        anyhow::bail!("--reps 0: the median needs at least 1 repetition");
    }
    let mut rows = Vec::new();
    let k = kernels(a.reps, &mut rows)?;
    let lm = lm_rows(&k, a.reps, &mut rows)?;
    let bounds = bound_rows(&k.x, &mut rows)?;
    let mut v = k.json;
    if let (Some(v), Value::Object(lm)) = (v.as_object_mut(), lm) {
        v.extend(lm);
    }
    v["bounds"] = bounds;
    if a.scale {
        v["scale"] = scale_rows(&k.robot, &mut rows)?;
    }
    v["peak_mib"] = json!(peak_mib());
    let robot_rows = if a.robots { robot_rows()? } else { Vec::new() };
    if a.robots {
        v["robots"] = Value::Array(robot_rows.clone());
    }
    v["table"] = Value::Array(
        rows.iter()
            .map(|(n, ms, note)| json!({"what": n, "median_ms": ms, "note": note}))
            .collect(),
    );
    emit(a.json, &v, || bench_text(a.reps, &rows, &robot_rows))
}

/// The kernel rows (PUMA, 15,625 poses).
fn kernels(reps: usize, rows: &mut Vec<Row>) -> Result<Kernels> {
    let robot = Robot::puma560();
    let pool = Pool::full(&robot, 5)?;
    let (t_jac, x) = time(reps, || pool.jacobian(&robot, &robot.nominal));
    let s = Settings::default();
    let sel = eae_run(&x, &s, 1);
    let scan = bench_scan(&x, &sel.poses, reps)?;
    let mut seed = 0;
    let (t_eae, _) = time(reps, || {
        seed += 1;
        eae_run(&x, &s, seed)
    });
    let (t_pol, pol) = time(reps.min(3), || {
        polish(&x, &mut DCriterion::new(), sel.clone(), &s).expect("polish")
    });
    let polish_iters = pol.trace.len() - sel.trace.len();
    rows.extend([
        (
            "FK + Jacobian, whole 15,625 pool".into(),
            t_jac * 1e3,
            format!("{:.0} ns/pose", t_jac * 1e9 / pool.len() as f64),
        ),
        (
            "add-gain scan (maintained V_i)".into(),
            scan.add_gain_ns * scan.n_candidates as f64 * 1e-6,
            format!("{:.2} ns/candidate", scan.add_gain_ns),
        ),
        (
            "eigenvalue OI recomputed per candidate".into(),
            scan.oi_eigen_ns * scan.n_candidates as f64 * 1e-6,
            format!("{:.0} ns/candidate", scan.oi_eigen_ns),
        ),
        (
            "  speed-up of the update over eigen-recompute".into(),
            f64::NAN,
            format!("{:.0}x", scan.speedup),
        ),
        (
            "V_i full recompute (X M^-1 X^T)".into(),
            scan.variances_full_ns * scan.n_pool as f64 * 1e-6,
            format!("{:.2} ns/pose", scan.variances_full_ns),
        ),
        (
            "V_i rank-2t update after an exchange".into(),
            scan.variances_update_ns * scan.n_pool as f64 * 1e-6,
            format!("{:.2} ns/pose", scan.variances_update_ns),
        ),
        (
            "exchange prices, one out-pose".into(),
            scan.exchange_one_out_ns * scan.n_candidates as f64 * 1e-6,
            format!("{:.2} ns/candidate", scan.exchange_one_out_ns),
        ),
        (
            "one EAE start (12 -> 30 poses)".into(),
            t_eae * 1e3,
            format!("{} steps", sel.trace.len()),
        ),
        (
            "Fedorov polish of an EAE design".into(),
            t_pol * 1e3,
            format!(
                "{polish_iters} exchanges, {:.1} ms/iter",
                t_pol * 1e3 / (polish_iters + 1) as f64
            ),
        ),
    ]);
    let json = json!({
        "threads": rayon::current_num_threads(),
        "jacobian_ms": t_jac * 1e3, "jacobian_ns_per_pose": t_jac * 1e9 / pool.len() as f64,
        "scan": scan, "eae_ms": t_eae * 1e3, "polish_ms": t_pol * 1e3, "polish_iterations": polish_iters,
    });
    Ok(Kernels {
        robot,
        pool,
        x,
        sel,
        json,
    })
}

/// Identification rows: one Levenberg–Marquardt calibration of the EAE
/// design from the nominal start, points (PUMA, σ = 1 cm) and full poses
/// (UR5, σ = 1 mm).
fn lm_rows(k: &Kernels, reps: usize, rows: &mut Vec<Row>) -> Result<Value> {
    let lm_time = |r: &Robot, pool: &Pool, poses: &[usize], sigma: f64| -> Result<(f64, usize)> {
        let qs: Vec<Vec<f64>> = poses.iter().map(|&k| pool.q(k)).collect();
        let meas = simulate(r, &r.real, &qs, sigma, &mut trial_rng(1, 0))?;
        let lm = LmSettings::default();
        let (t, id) = time(reps, || identify(r, &r.nominal, &meas, &lm));
        Ok((t, id?.iterations))
    };
    let (t_lm, it) = lm_time(&k.robot, &k.pool, &k.sel.poses, 0.01)?;
    let ur5 = Robot::builtin("ur5:pose")?;
    let pool6 = Pool::full(&ur5, 3)?;
    let x6 = pool6.jacobian(&ur5, &ur5.nominal);
    let sel6 = eae(
        &x6,
        &mut DCriterion::new(),
        &Settings::default(),
        &mut design_rng(1, 0),
    )?;
    let (t_lm6, it6) = lm_time(&ur5, &pool6, &sel6.poses, 0.001)?;
    rows.push((
        "LM calibration, PUMA, 30 points (p = 27)".into(),
        t_lm * 1e3,
        format!("{it} iterations"),
    ));
    rows.push((
        "LM calibration, UR5, 30 full poses (p = 30)".into(),
        t_lm6 * 1e3,
        format!("{it6} iterations"),
    ));
    Ok(json!({
        "lm_point_ms": t_lm * 1e3, "lm_point_iterations": it,
        "lm_pose_ms": t_lm6 * 1e3, "lm_pose_iterations": it6,
    }))
}

/// The relaxation bound on the kernels' pool by each candidate-set solver
/// (one run each: seconds, not microseconds).
fn bound_rows(x: &Blocks, rows: &mut Vec<Row>) -> Result<Value> {
    let n = Settings::default().n;
    let mut bounds = Vec::new();
    for solver in [RelaxationSolver::Clarabel, RelaxationSolver::Newton] {
        let settings = BoundSettings::builder().solver(solver).build()?;
        let b = relaxation_bound(x, None, n, &settings)?;
        rows.push((
            format!("relaxation bound, {solver:?}"),
            b.seconds * 1e3,
            format!(
                "candidate solves {:.2} s, certified gap {:.1e}",
                b.conic.seconds, b.certificate_gap
            ),
        ));
        bounds.push(
            json!({"solver": solver, "seconds": b.seconds, "solver_seconds": b.conic.seconds,
            "ln_bound": b.ln_bound, "certificate_gap": b.certificate_gap}),
        );
    }
    Ok(Value::Array(bounds))
}

/// The 10⁶-pose pool (`--scale`): Jacobian, one EAE start for N = 145,
/// the bound for N = 30.
fn scale_rows(robot: &Robot, rows: &mut Vec<Row>) -> Result<Value> {
    {
        let big = Pool::full(robot, 10)?;
        let t0 = Instant::now();
        let xb = big.jacobian(&robot, &robot.nominal);
        let t_bj = t0.elapsed().as_secs_f64();
        let sb = Settings::builder().n(145).build()?;
        let t0 = Instant::now();
        let selb = eae(&xb, &mut DCriterion::new(), &sb, &mut design_rng(1, 0))?;
        let t_be = t0.elapsed().as_secs_f64();
        rows.push((
            "10^6 pool: FK + Jacobian".into(),
            t_bj * 1e3,
            format!("{} poses", big.len()),
        ));
        rows.push((
            "10^6 pool: one EAE start, N = 145".into(),
            t_be * 1e3,
            format!("log10 OI_D {:.3}", selb.ln_oid / std::f64::consts::LN_10),
        ));
        let peak_eae = peak_mib();
        // The bound over the 10⁶ poses for N = 30 (Newton: Clarabel's
        // rounds on ~2,000 candidates take minutes each).
        let settings = BoundSettings::builder()
            .solver(RelaxationSolver::Newton)
            .build()?;
        let bb = relaxation_bound(&xb, None, Settings::default().n, &settings)?;
        rows.push((
            "10^6 pool: relaxation bound, N = 30 (Newton)".into(),
            bb.seconds * 1e3,
            format!(
                "log10 {:.4}, gap {:.1e}, {} rounds",
                bb.log10_bound(),
                bb.certificate_gap,
                bb.conic.rounds
            ),
        ));
        Ok(
            json!({"poses": big.len(), "jacobian_s": t_bj, "eae_s": t_be, "n": 145,
            "log10_oid": selb.ln_oid / std::f64::consts::LN_10, "steps": selb.trace.len(), "peak_mib_eae": peak_eae,
            "bound_s": bb.seconds, "bound_log10": bb.log10_bound(), "bound_gap": bb.certificate_gap,
            "bound_status": bb.status, "peak_mib": peak_mib()}),
        )
    }
}

/// `--robots`: one row per robot found (file robots are skipped, with a
/// note, outside the repository).
fn robot_rows() -> Result<Vec<Value>> {
    let mut out = Vec::new();
    for (label, spec) in ROBOTS {
        let file = spec.split([':', '#']).next().unwrap_or(spec);
        if file.contains('/') && !std::path::Path::new(file).exists() {
            super::diag(&format!(
                "bench: {label} skipped: {file} not found (run from the repository)"
            ));
            continue;
        }
        out.push(robot_row(label, spec)?);
    }
    Ok(out)
}

/// The text report: the timing table, peak memory, the robots' table.
fn bench_text(reps: usize, table: &[Row], robot_rows: &[Value]) -> String {
    let mut s = format!(
        "activecal bench ({} threads, median of {reps})\n",
        rayon::current_num_threads()
    );
    s += &format!("{:<48} {:>12}  {}\n", "", "median ms", "");
    for (n, ms, note) in table {
        let ms = if ms.is_nan() {
            String::new()
        } else {
            format!("{ms:.3}")
        };
        s += &format!("{n:<48} {ms:>12}  {note}\n");
    }
    s += &format!("peak memory: {:.0} MiB\n", peak_mib());
    if !robot_rows.is_empty() {
        s += "\nrobots side by side (5-level lattices, N = 30; one run each):\n";
        s += &format!(
            "{:<28} {:>3} {:>2} {:>7} {:>8} {:>8} {:>9} {:>10} {:>9} {:>8}\n",
            "robot",
            "p",
            "t",
            "poses",
            "bound s",
            "EAE s",
            "EAE eff",
            "select s",
            "sel eff",
            "peak MiB"
        );
        for r in robot_rows {
            s += &format!(
                "{:<28} {:>3} {:>2} {:>7} {:>8.2} {:>8.3} {:>9.4} {:>10.3} {:>9.4} {:>8.0}\n",
                r["robot"].as_str().unwrap_or(""),
                r["p"],
                r["t"],
                r["poses"],
                r["bound_s"].as_f64().unwrap_or(f64::NAN),
                r["eae_s"].as_f64().unwrap_or(f64::NAN),
                r["eae_d_efficiency"].as_f64().unwrap_or(f64::NAN),
                r["select_s"].as_f64().unwrap_or(f64::NAN),
                r["select_d_efficiency"].as_f64().unwrap_or(f64::NAN),
                r["peak_mib"].as_f64().unwrap_or(f64::NAN),
            );
        }
        s += "(select: 2 starts with the default iterated local search; eff: D-efficiency against the certified bound)\n";
    }
    s
}
