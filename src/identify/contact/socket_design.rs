//! The configurations to record for sockets at given positions, as one
//! step: a pool projected onto every socket
//! ([`projected`]; with pool filters, the configurations that pass them,
//! [`filter_projected`]), a D-optimal choice with the contact Jacobian
//! exchanged for the predicted consistency error
//! ([`select_d_optimal`], [`refine_for_consistency`]), and the figures that
//! judge it: the predicted consistency error of the chosen configurations,
//! the median (and quartiles) of random draws of as many configurations
//! from the same pool (the hand-recorded baseline), and the smallest error
//! any design of the pool can reach ([`consistency_bound`], the convex
//! relaxation, certified).

use super::select::{
    Socket, SocketPool, determined_pool, filter_projected, predicted_consistency, projected,
    refine_for_consistency, select_d_optimal,
};
use super::tool_points;
use crate::error::Error;
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
    /// The D-optimal choice's predicted consistency error, σ.
    pub d_optimal_sigma: f64,
    /// The chosen configurations' predicted consistency error (the
    /// D-optimal choice exchanged for it), σ.
    pub predicted_sigma: f64,
    /// The random baseline.
    pub random: RandomBaseline,
    /// `random.median_sigma / predicted_sigma`.
    pub ratio_to_random: f64,
    /// The relaxation bound.
    pub bound: ConsistencyBound,
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
    let pool = determined_pool(robot, table, file)?;
    let p = pool.blocks[0].ncols();
    if pool.qs.len() < settings.n || 3 * settings.n < p {
        return Err(Error::Invalid(format!(
            "{} configurations: the pool has {} configurations and {p} unknowns (3 rows a configuration: at least {} configurations)",
            settings.n,
            pool.qs.len(),
            p.div_ceil(3)
        ))
        .into());
    }
    let start = select_d_optimal(&pool, settings.n);
    let d_optimal_sigma = predicted_consistency(&pool, &start);
    let chosen = refine_for_consistency(&pool, start);
    let predicted_sigma = predicted_consistency(&pool, &chosen);
    let random = random_baseline(&pool, settings);
    let bound = consistency_bound(&pool, settings.n);
    Ok(SocketDesign {
        robot: robot.name.clone(),
        joint_names: crate::units::joint_names(robot),
        points: reach_counts(sockets, &pool),
        samples_per_point: settings.samples,
        pool: pool.qs.len(),
        robot_unknowns: pool.robot.n_unknowns(),
        unknowns: p,
        configurations: chosen_contacts(robot, table, sockets, &pool, &chosen),
        d_optimal_sigma,
        predicted_sigma,
        ratio_to_random: random.median_sigma / predicted_sigma,
        random,
        bound,
        pool_stats,
    })
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

/// The predicted consistency errors of `settings.draws` random draws of
/// `settings.n` pool configurations (without replacement).
fn random_baseline(pool: &SocketPool, settings: &SocketDesignSettings) -> RandomBaseline {
    let mut rng = crate::identify::trial_rng(settings.draw_seed, 1);
    let mut ids: Vec<usize> = (0..pool.qs.len()).collect();
    let mut v: Vec<f64> = (0..settings.draws)
        .map(|_| {
            ids.shuffle(&mut rng);
            predicted_consistency(pool, &ids[..settings.n])
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

/// Most iterations of [`consistency_bound`].
pub const BOUND_ITERATIONS: usize = 3000;
/// Relative distance between the relaxation's value and its certified
/// bound at which [`consistency_bound`] stops.
pub const BOUND_GAP: f64 = 1e-3;

/// The convex relaxation of choosing `n` configurations for the smallest
/// predicted consistency error: weights `w_q ≥ 0` on the pool summing to
/// `n`, minimising `φ(w) = tr(M(w)⁻¹ W)` (`M(w) = Σ w_q X_qᵀX_q`, `W` the
/// [`consistency_moment`](super::select::consistency_moment)), by the
/// multiplicative algorithm `w_q ← w_q √(n d_q / φ)`, `d_q = tr(X_q M⁻¹ W
/// M⁻¹ X_qᵀ)` (Silvey–Titterington–Torsney).
/// Every `n`-configuration design is such a weighting, and for any `M`,
/// `tr(M⁻¹W) ≥ 2t·φ − t²·tr(M₀⁻¹WM₀⁻¹M)` (completing the square with
/// `M₀` the weights reached), which at the best `t` gives
/// `φ* ≥ φ² / (n · max_q d_q)`: the certified bound. Columns are
/// equilibrated to the pool's unit diagonal first (the trace is unchanged).
#[must_use]
pub fn consistency_bound(pool: &SocketPool, n: usize) -> ConsistencyBound {
    let (blocks, w_mom) = equilibrated(pool);
    let (k, p, nf) = (blocks.len(), w_mom.nrows(), n as f64);
    let mut w = vec![nf / k as f64; k];
    let (mut phi, mut lower, mut iterations) = (f64::INFINITY, 0.0, 0);
    while iterations < BOUND_ITERATIONS {
        iterations += 1;
        let mut m = DMatrix::zeros(p, p);
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
        lower = phi * phi / (nf * dmax);
        if phi - lower <= BOUND_GAP * phi {
            break;
        }
        for (wi, di) in w.iter_mut().zip(&d) {
            *wi *= (nf * di / phi).sqrt();
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

/// The pool's blocks and consistency moment with columns scaled to the
/// pool information's unit diagonal.
fn equilibrated(pool: &SocketPool) -> (Vec<DMatrix<f64>>, DMatrix<f64>) {
    let p = pool.blocks[0].ncols();
    let mut diag = vec![0.0; p];
    for b in &pool.blocks {
        for (c, d) in diag.iter_mut().enumerate() {
            *d += b.column(c).norm_squared();
        }
    }
    let s: Vec<f64> = diag
        .iter()
        .map(|&d| if d > 0.0 { 1.0 / d.sqrt() } else { 1.0 })
        .collect();
    let scale = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(s));
    let blocks = pool.blocks.iter().map(|b| b * &scale).collect();
    let w = super::select::consistency_moment(pool);
    (blocks, &scale * w * &scale)
}
