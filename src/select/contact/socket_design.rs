//! The configurations to record for sockets at given positions, as one
//! step: a pool projected onto every socket
//! ([`projected`]; with pool filters, the configurations that pass them,
//! [`filter_projected`]) whose unknowns are those a fit with the known
//! distances between sockets determines, a D-optimal choice with the
//! contact Jacobian (the distances' rows included) exchanged for the
//! predicted true error of the tool point — the whole model's covariance
//! carried to it at generic configurations
//! ([`select_d_optimal`], [`refine_for`], [`true_error_moment`]) — and the
//! figures that judge it, for the true error and for the consistency error
//! held-out contacts measure: the chosen configurations', the median (and
//! quartiles) of random draws of as many configurations from the same pool
//! (the hand-recorded baseline), and the smallest error any design of the
//! pool can reach ([`error_bound`], the convex relaxation, certified).

use super::{ContactSearch, refine_for, select_d_optimal};
use crate::error::Error;
use crate::identify::contact::predict::true_error_moment;
use crate::identify::contact::select::{
    Socket, SocketPool, consistency_moment, determined_pool, filter_projected, information,
    predicted_error, projected,
};
use crate::identify::contact::tool_points;
use crate::measure::contact::KnownDistance;
use crate::model::{ParamTable, Robot};
use nalgebra::{DMatrix, Vector3};
use rand::seq::SliceRandom;
use serde::Serialize;

/// How to build the pool and judge the design.
#[derive(Clone, Debug)]
pub struct SocketDesignSettings {
    /// Configurations in the design.
    pub n: usize,
    /// Joint-space samples projected onto each socket.
    pub samples: usize,
    /// Margin kept inside every joint's limits (radians or metres).
    pub margin: f64,
    /// Distance within which a projected configuration reaches its socket,
    /// metres.
    pub tol: f64,
    /// Random draws of `n` configurations of the baseline.
    pub draws: usize,
    /// Seed of the joint-space samples.
    pub sample_seed: u64,
    /// Seed of the baseline's random draws.
    pub draw_seed: u64,
    /// Filters the projected configurations pass (self-collision,
    /// obstacles), as every pool's do; none by default.
    pub filters: Vec<crate::pool::PoolFilter>,
    /// Distances known between sockets (indices into the sockets), as the
    /// fit will be given them: a known distance fixes the scale, which
    /// contacts alone leave free. None by default.
    pub distances: Vec<KnownDistance>,
    /// Seed of the generic configurations the true error is predicted at.
    pub prediction_seed: u64,
    /// How the exchange searches (seed, rounds of iterated local search).
    pub search: ContactSearch,
}

impl Default for SocketDesignSettings {
    /// 30 configurations, 1000 samples a socket, a 2° margin, 1e-7 m
    /// (a thousandth of the 0.1 mm a socket is reached to), 100 draws.
    fn default() -> Self {
        Self {
            n: 30,
            samples: 1000,
            margin: 2f64.to_radians(),
            tol: 1e-7,
            draws: 100,
            sample_seed: 0,
            draw_seed: 1,
            filters: Vec::new(),
            distances: Vec::new(),
            prediction_seed: 3,
            search: ContactSearch::default(),
        }
    }
}

/// One chosen configuration.
#[derive(Clone, Debug, Serialize)]
pub struct ChosenContact {
    /// Its id in the pool (sample order over the sockets).
    pub id: usize,
    /// The socket it touches.
    pub point: String,
    /// Joint values (radians, metres for prismatic joints), chain order.
    pub q: Vec<f64>,
    /// Distance of its tool point from the socket, metres.
    pub reach_m: f64,
}

/// A socket and how many of its samples reach it.
#[derive(Clone, Debug, Serialize)]
pub struct SocketReach {
    /// The socket.
    #[serde(flatten)]
    pub socket: Socket,
    /// Configurations of the pool at it.
    pub configurations: usize,
}

/// The random baseline: predicted consistency errors of random draws of
/// `n` configurations from the pool, in units of σ.
#[derive(Clone, Debug, Serialize)]
pub struct RandomBaseline {
    /// Draws made.
    pub draws: usize,
    /// Their median, σ.
    pub median_sigma: f64,
    /// Their first quartile, σ.
    pub q1_sigma: f64,
    /// Their third quartile, σ.
    pub q3_sigma: f64,
    /// The best draw, σ.
    pub best_sigma: f64,
}

/// The smallest predicted consistency error of any weighting of the pool
/// summing to `n` configurations (the convex relaxation of the choice): no
/// `n`-configuration design of the pool is below `certified_sigma`.
#[derive(Clone, Debug, Serialize)]
pub struct ConsistencyBound {
    /// The relaxation's value reached, σ.
    pub relaxed_sigma: f64,
    /// A certified lower bound on the relaxation's optimum, σ
    /// (`φ² / (n · max_q d_q)` of the weights reached, see
    /// [`consistency_bound`]).
    pub certified_sigma: f64,
    /// Pool configurations carrying weight above 1e-3.
    pub support: usize,
    /// Iterations of the multiplicative algorithm.
    pub iterations: usize,
}

/// A design judged by one predicted error (units of σ, the contact noise
/// per coordinate): the chosen configurations', the D-optimal choice's, random
/// draws' from the same pool and the pool's certified bound.
#[derive(Clone, Debug, Serialize)]
pub struct Judged {
    /// The D-optimal choice's predicted error, σ.
    pub d_optimal_sigma: f64,
    /// The chosen configurations' predicted error, σ.
    pub predicted_sigma: f64,
    /// The random baseline.
    pub random: RandomBaseline,
    /// `random.median_sigma / predicted_sigma`.
    pub ratio_to_random: f64,
    /// The relaxation bound.
    pub bound: ConsistencyBound,
}

/// The design for sockets, with its figures. Consistency errors are in
/// units of σ, the contact noise per coordinate.
#[derive(Clone, Debug, Serialize)]
pub struct SocketDesign {
    /// The robot's name.
    pub robot: String,
    /// The chain's joint names, in the order of the joint values.
    pub joint_names: Vec<String>,
    /// The sockets and their pool configurations.
    pub points: Vec<SocketReach>,
    /// Joint-space samples projected onto each socket.
    pub samples_per_point: usize,
    /// Configurations in the pool.
    pub pool: usize,
    /// Robot unknowns the pool determines (the gauge and weaker ones fixed).
    pub robot_unknowns: usize,
    /// Columns of the contact Jacobian: robot unknowns, tool offset, points.
    pub unknowns: usize,
    /// The chosen configurations.
    pub configurations: Vec<ChosenContact>,
    /// The known distances between sockets the design counts on.
    pub known_distances: usize,
    /// The chosen configurations' predicted consistency error (how far a
    /// calibrated model's contacts scatter about their socket, per
    /// coordinate), against the D-optimal choice's, random draws' and the
    /// pool's bound (the keys of earlier versions, kept).
    #[serde(flatten)]
    pub consistency: Judged,
    /// The chosen configurations' predicted true error of the tool point
    /// (3-D RMS at generic configurations, the whole model's covariance
    /// carried to it), the criterion they are chosen by, against the
    /// D-optimal choice's, random draws' and the pool's bound.
    pub true_error: Judged,
    /// What the pool filters removed of the projected configurations
    /// (absent without a filter).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pool_stats: Option<crate::pool::PoolStats>,
}

/// Chooses `settings.n` configurations that touch `sockets` for `robot`
/// with `table` (tool offset 0: the chain's tip is the tool point), and
/// judges them (see the module docs). Errors: no socket, a socket
/// reached by fewer than 3 samples, fewer pool configurations than `n`, or
/// `n` too small to determine the pool's unknowns.
pub fn design_for_sockets(
    robot: &Robot,
    table: &ParamTable,
    sockets: &[Socket],
    settings: &SocketDesignSettings,
) -> crate::identify::Result<SocketDesign> {
    check(sockets, settings)?;
    // Steps: projection, D-optimal choice, exchanges, two judgements.
    let task = crate::progress::Task::start("configurations for the sockets", Some(5));
    task.note(|| "projecting samples onto the sockets".into());
    let mut rng = crate::identify::trial_rng(settings.sample_seed, 0);
    let file = projected(
        robot,
        table,
        sockets,
        settings.samples,
        settings.margin,
        settings.tol,
        &mut rng,
    )?;
    let (file, pool_stats) = if settings.filters.is_empty() {
        (file, None)
    } else {
        let (kept, stats) = filter_projected(robot, table, &file, &settings.filters)?;
        (kept, Some(stats))
    };
    let pool = determined_pool(robot, table, file, &settings.distances)?;
    let p = pool.p();
    if pool.qs.len() < settings.n || 3 * settings.n + pool.constraints.nrows() < p {
        return Err(Error::Invalid(format!(
            "{} configurations: the pool has {} configurations and {p} unknowns (3 rows a configuration: at least {} configurations)",
            settings.n,
            pool.qs.len(),
            p.saturating_sub(pool.constraints.nrows()).div_ceil(3)
        ))
        .into());
    }
    task.inc(1);
    task.note(|| "D-optimal choice".into());
    let start = select_d_optimal(&pool, settings.n, &settings.search)?;
    task.inc(1);
    task.note(|| "exchanges for the predicted true error".into());
    let true_w = true_error_moment(&pool, table, settings.prediction_seed);
    let chosen = refine_for(&pool, &start, &true_w, &settings.search)?;
    task.inc(1);
    task.note(|| "judging: random draws and the bound, consistency".into());
    let consistency_w = consistency_moment(&pool);
    let consistency = judged(&pool, &start, &chosen, &consistency_w, settings);
    task.inc(1);
    task.note(|| "judging: random draws and the bound, true error".into());
    let true_error = judged(&pool, &start, &chosen, &true_w, settings);
    task.inc(1);
    Ok(SocketDesign {
        robot: robot.name.clone(),
        joint_names: crate::units::joint_names(robot),
        points: reach_counts(sockets, &pool),
        samples_per_point: settings.samples,
        pool: pool.qs.len(),
        robot_unknowns: pool.robot.n_unknowns(),
        unknowns: p,
        configurations: chosen_contacts(robot, table, sockets, &pool, &chosen),
        known_distances: settings.distances.len(),
        consistency,
        true_error,
        pool_stats,
    })
}

/// The D-optimal `start` and the `chosen` configurations judged by the
/// predicted error of moment `w`, against random draws and the pool's
/// bound.
fn judged(
    pool: &SocketPool,
    start: &[usize],
    chosen: &[usize],
    w: &DMatrix<f64>,
    settings: &SocketDesignSettings,
) -> Judged {
    let predicted_sigma = predicted_error(pool, chosen, w);
    let random = random_baseline(pool, w, settings);
    Judged {
        d_optimal_sigma: predicted_error(pool, start, w),
        predicted_sigma,
        ratio_to_random: random.median_sigma / predicted_sigma,
        random,
        bound: error_bound(pool, settings.n, w),
    }
}

/// The inputs checked before the pool is built.
fn check(sockets: &[Socket], s: &SocketDesignSettings) -> crate::identify::Result<()> {
    let bad = |m: String| Err(Error::Invalid(m).into());
    if sockets.is_empty() {
        return bad("no socket to choose configurations for".into());
    }
    for (k, a) in sockets.iter().enumerate() {
        if a.position.iter().any(|v| !v.is_finite()) {
            return bad(format!(
                "point '{}': a position is three finite numbers (metres)",
                a.name
            ));
        }
        if sockets[..k].iter().any(|b| b.name == a.name) {
            return bad(format!("point '{}' is given twice", a.name));
        }
    }
    if s.n == 0 || s.samples == 0 || s.draws == 0 {
        return bad(format!(
            "{} configurations from {} samples a socket, {} random draws: each must be at least 1",
            s.n, s.samples, s.draws
        ));
    }
    Ok(())
}

/// How many pool configurations each socket has.
fn reach_counts(sockets: &[Socket], pool: &SocketPool) -> Vec<SocketReach> {
    sockets
        .iter()
        .enumerate()
        .map(|(g, s)| SocketReach {
            socket: s.clone(),
            configurations: pool.sockets.iter().filter(|&&k| k == g).count(),
        })
        .collect()
}

/// The chosen pool configurations with their sockets and reach.
fn chosen_contacts(
    robot: &Robot,
    table: &ParamTable,
    sockets: &[Socket],
    pool: &SocketPool,
    chosen: &[usize],
) -> Vec<ChosenContact> {
    let qs: Vec<Vec<f64>> = chosen.iter().map(|&i| pool.qs[i].clone()).collect();
    let tips = tool_points(robot, table, &[0.0; 3], &qs);
    chosen
        .iter()
        .zip(qs)
        .zip(tips)
        .map(|((&i, q), t)| {
            let s = &sockets[pool.sockets[i]];
            ChosenContact {
                id: i,
                point: s.name.clone(),
                q,
                reach_m: (t - Vector3::from(s.position)).norm(),
            }
        })
        .collect()
}

/// The predicted errors (moment `w`) of `settings.draws` random draws of
/// `settings.n` pool configurations (without replacement).
fn random_baseline(
    pool: &SocketPool,
    w: &DMatrix<f64>,
    settings: &SocketDesignSettings,
) -> RandomBaseline {
    let mut rng = crate::identify::trial_rng(settings.draw_seed, 1);
    let mut ids: Vec<usize> = (0..pool.qs.len()).collect();
    let mut v: Vec<f64> = (0..settings.draws)
        .map(|_| {
            ids.shuffle(&mut rng);
            predicted_error(pool, &ids[..settings.n], w)
        })
        .collect();
    v.sort_by(f64::total_cmp);
    RandomBaseline {
        draws: v.len(),
        median_sigma: quantile(&v, 0.5),
        q1_sigma: quantile(&v, 0.25),
        q3_sigma: quantile(&v, 0.75),
        best_sigma: v[0],
    }
}

/// The `f` quantile of sorted `v` (linear between order statistics).
fn quantile(v: &[f64], f: f64) -> f64 {
    let x = f * (v.len() - 1) as f64;
    let (lo, hi) = (x.floor() as usize, x.ceil() as usize);
    if lo == hi || v[hi] == v[lo] {
        return v[lo];
    }
    v[lo] + (x - lo as f64) * (v[hi] - v[lo])
}

/// Most iterations of [`error_bound`].
pub const BOUND_ITERATIONS: usize = 3000;
/// Relative distance between the relaxation's value and its certified
/// bound at which [`error_bound`] stops.
pub const BOUND_GAP: f64 = 1e-3;

/// [`error_bound`] for the predicted consistency error
/// ([`consistency_moment`]).
#[must_use]
pub fn consistency_bound(pool: &SocketPool, n: usize) -> ConsistencyBound {
    error_bound(pool, n, &consistency_moment(pool))
}

/// The convex relaxation of choosing `n` configurations for the smallest
/// predicted error of moment `w_mom` ([`predicted_error`]): weights
/// `w_q ≥ 0` on the pool summing to `n`, minimising `φ(w) = tr(M(w)⁻¹ W)`
/// (`M(w) = M₀ + Σ w_q X_qᵀX_q`, `M₀ = CᵀC` the known distances' rows,
/// which every design has), by the multiplicative algorithm
/// `w_q ← w_q √d_q` renormalised to `n`, `d_q = tr(X_q M⁻¹ W M⁻¹ X_qᵀ)`
/// (Silvey–Titterington–Torsney).
/// Every `n`-configuration design is such a weighting, and for any `M`,
/// `tr(M⁻¹W) ≥ 2t·φ − t²·tr(G M)` with `G = M̂⁻¹WM̂⁻¹` at the weights
/// reached `M̂` (completing the square); `tr(G M) ≤ tr(G M₀) + n · max_q d_q`,
/// so at the best `t`, `φ* ≥ φ² / (tr(G M₀) + n · max_q d_q)`: the certified
/// bound. Columns are equilibrated to the pool's unit diagonal first (the
/// trace is unchanged).
#[must_use]
pub fn error_bound(pool: &SocketPool, n: usize, w_mom: &DMatrix<f64>) -> ConsistencyBound {
    let (blocks, fixed, w_mom) = equilibrated(pool, w_mom);
    let (k, nf) = (blocks.len(), n as f64);
    let mut w = vec![nf / k as f64; k];
    let (mut phi, mut lower, mut iterations) = (f64::INFINITY, 0.0, 0);
    while iterations < BOUND_ITERATIONS {
        iterations += 1;
        let mut m = fixed.clone();
        for (b, &wi) in blocks.iter().zip(&w) {
            m += b.transpose() * b * wi;
        }
        let Some(mi) = m.cholesky().map(|c| c.inverse()) else {
            break;
        };
        let g = &mi * &w_mom * &mi;
        phi = (&mi * &w_mom).trace();
        let d: Vec<f64> = blocks
            .iter()
            .map(|b| (b * &g * b.transpose()).trace())
            .collect();
        let dmax = d.iter().copied().fold(0.0, f64::max);
        lower = phi * phi / ((&g * &fixed).trace() + nf * dmax);
        if phi - lower <= BOUND_GAP * phi {
            break;
        }
        for (wi, di) in w.iter_mut().zip(&d) {
            *wi *= di.max(0.0).sqrt();
        }
        let s: f64 = w.iter().sum();
        w.iter_mut().for_each(|v| *v *= nf / s);
    }
    ConsistencyBound {
        relaxed_sigma: phi.sqrt(),
        certified_sigma: lower.max(0.0).sqrt(),
        support: w.iter().filter(|&&v| v > 1e-3).count(),
        iterations,
    }
}

/// The pool's blocks, its fixed information `CᵀC` and the moment `w` with
/// columns scaled to the pool information's unit diagonal.
fn equilibrated(
    pool: &SocketPool,
    w: &DMatrix<f64>,
) -> (Vec<DMatrix<f64>>, DMatrix<f64>, DMatrix<f64>) {
    let all = information(pool, &(0..pool.qs.len()).collect::<Vec<_>>());
    let s: Vec<f64> = (0..all.nrows())
        .map(|c| {
            let d = all[(c, c)];
            if d > 0.0 { 1.0 / d.sqrt() } else { 1.0 }
        })
        .collect();
    let scale = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(s));
    let blocks = (0..pool.qs.len()).map(|i| pool.block(i) * &scale).collect();
    let c = &pool.constraints * &scale;
    (blocks, c.transpose() * c, &scale * w * &scale)
}
