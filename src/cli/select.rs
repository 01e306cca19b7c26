//! `select`: pose selection (for `score`, see [`super::score`]).

use super::{PoolOpts, emit_report, parse_list};
use activecal::experiment::select::SelectRun;
use activecal::options::Restriction;
use activecal::options::{
    Algorithm, CriterionKind, SelectSettings as Settings, default_ils_rounds,
};
use activecal::report::SelectReport;
use anyhow::{Result, bail};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `select`.
#[derive(Args)]
pub struct SelectArgs {
    #[command(flatten)]
    pub pool: PoolOpts,
    /// Poses in the design.
    #[arg(long, default_value_t = 30, allow_negative_numbers = true)]
    pub n: usize,
    /// The selection algorithm.
    #[arg(long, value_parser = super::choice::<Algorithm>(), default_value_t = Algorithm::Eae)]
    pub algorithm: Algorithm,
    /// Initial random poses of EAE (fixed poses included), 1..=N [default:
    /// 12, or N when N is smaller].
    #[arg(long, allow_negative_numbers = true)]
    pub initial: Option<usize>,
    /// Independent random starts, run in parallel; the best (by the
    /// criterion) is kept.
    #[arg(long, default_value_t = 2, allow_negative_numbers = true)]
    pub starts: usize,
    /// Rounds of iterated local search per start after the algorithm: climb
    /// to a local optimum of single exchanges (modified Fedorov), then ILS
    /// times exchange --kick random design poses, climb again, keep the
    /// better design. 0 runs the algorithm alone (the paper's EAE).
    /// [default: 12 on a 15,625-pose point pool, fewer on larger pools and
    /// full poses, 0 from about 10⁵ point poses]. With the defaults the
    /// PUMA experiment reaches D-efficiency 0.984–0.987 (median 0.985 over
    /// 10 seeds) in under a second, where one EAE start stops at
    /// 0.970–0.982.
    #[arg(long, allow_negative_numbers = true)]
    pub ils: Option<usize>,
    /// Design poses exchanged at random per round of --ils.
    #[arg(long, default_value_t = 3, allow_negative_numbers = true)]
    pub kick: usize,
    /// Choose the poses for a calibration that keeps closed-form inverse
    /// kinematics (`calibrate --keep-axis-relations`): the unknowns that
    /// would change the nominal model's parallel, perpendicular or
    /// intersecting joint axes are left out of the criterion.
    #[arg(long)]
    pub keep_axis_relations: bool,
    /// Random designs drawn by --algorithm random [default: 5000].
    #[arg(long, allow_negative_numbers = true)]
    pub designs: Option<usize>,
    /// Polish the best start with Fedorov exchange.
    #[arg(long)]
    pub polish: bool,
    /// Seed of every random choice.
    #[arg(
        long,
        default_value_t = 1,
        value_parser = super::parse_seed,
        allow_negative_numbers = true
    )]
    pub seed: u64,
    /// Pose ids (lattice indices) every design must contain.
    #[arg(long)]
    pub fixed: Option<String>,
    /// det (ln OI_D, with O(p²) updates) or oi (the paper's eigenvalue OI, recomputed).
    #[arg(long, value_parser = super::choice::<CriterionKind>(), default_value_t = CriterionKind::Det)]
    pub criterion: CriterionKind,
    /// Write the design file here, in the format of its extension (.json,
    /// .csv, .yaml); repeatable: one run, several formats, each written
    /// atomically.
    #[arg(long)]
    pub out: Vec<PathBuf>,
    /// Overwrite --out if it exists.
    #[arg(long)]
    pub force: bool,
    /// Also compute the relaxation bound and report the design's
    /// D-efficiency. The bound: a certified upper bound on ln OI_D (OI_D =
    /// det XᵀX) of every N-pose design of the pool (the convex relaxation);
    /// D-efficiency: (OI_D / bound)^(1/p), 1 = no pool design is better;
    /// support: the poses carrying relaxation weight.
    #[arg(long)]
    pub gap: bool,
    /// Solver of the bound for `--gap` (see `bound`).
    #[arg(long, value_parser = super::choice::<activecal::options::RelaxationSolver>(), default_value_t = activecal::options::RelaxationSolver::Newton, requires = "gap")]
    pub gap_solver: activecal::options::RelaxationSolver,
    /// Poses already measured: a CSV or JSON of joint configurations (as
    /// --pool file: reads them) or a JSON measurement file. The new poses
    /// maximise ln det(M0 + XᵀX) with M0 the information of these, and
    /// --gap reports the D-efficiency against the bound with M0.
    #[arg(long, value_name = "FILE")]
    pub existing: Option<PathBuf>,
    /// Move each selected pose continuously in joint space (within the
    /// limits and the pool's filters) to increase ln OI_D; the gain is
    /// reported per pose and in total, and with --gap against the pool's
    /// bound (which a refined design may exceed). --out then stores the
    /// refined joint values.
    #[arg(long)]
    pub refine: bool,
    /// Passes over the poses of --refine (fewer when a pass gains nothing).
    #[arg(long, default_value_t = 3, requires = "refine")]
    pub refine_sweeps: usize,
    /// Visiting order of the design: `time` orders the poses to take the
    /// least total move time (a move takes max_j |Δq_j|/v_j with the URDF's
    /// joint speed limits, 1 rad/s where none is given: nearest neighbour,
    /// then 2-opt and Or-opt), `none` keeps selection order [default: time
    /// when the robot's speed limits are known (a URDF robot), else none].
    #[arg(long, value_enum)]
    pub order: Option<Order>,
    /// Start of the visiting path (the arm's position before the first
    /// pose), joint values comma separated (radians or metres).
    #[arg(long, value_name = "Q1,...", allow_hyphen_values = true)]
    pub home: Option<String>,
    /// Write a report directory: report.md, report.json and figures (PNG
    /// and SVG) of the "how many poses" curve (for N from the fewest that
    /// can identify the robot to three times that: the best design's
    /// D-efficiency against the certified bound, and the position error
    /// predicted at 1,000 random configurations from the design's
    /// covariance σ²(XᵀX)⁻¹), the poses against the joint limits and the
    /// tour. An existing non-empty directory needs --force.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// With --report: the position error you want to reach, mm (RMS at
    /// random configurations); the curve then recommends the smallest N
    /// predicted to reach it. Without it, the curve's knee: the smallest N
    /// where 10 % more poses gain less than 5 %.
    #[arg(
        long,
        value_name = "MM",
        requires = "report",
        allow_negative_numbers = true
    )]
    pub target_error: Option<f64>,
    /// Sensor noise σ per measured coordinate, metres: the error predicted
    /// after calibrating with the chosen poses is printed (and in --json,
    /// `predicted`), and --report's curve uses it [default there: 0.01, as
    /// `calibrate --noise`].
    #[arg(long, allow_negative_numbers = true)]
    pub noise: Option<f64>,
    /// Orientation noise σ per axis of a full-pose sensor, radians: the
    /// design weighs a radian of orientation as `--noise`/RAD metres (as
    /// `calibrate` weighs the data by their estimated σ's), and --report
    /// predicts with it. Default: the robot's orientation scale (1 m/rad).
    #[arg(long, value_name = "RAD", allow_negative_numbers = true)]
    pub orientation_noise: Option<f64>,
    /// Choose configurations that touch a socket at this position instead
    /// of poses of a pool: NAME=X,Y,Z (base frame, metres; repeatable).
    /// Joint-space samples (--count, default 1000 a socket; --pool-seed)
    /// are projected onto each socket within the limits less --margin,
    /// and --n are chosen with the contact Jacobian for the tool point's
    /// predicted true error; it and the predicted consistency error are
    /// compared with random draws (--seed) and the pool's bound.
    #[arg(long = "point", value_name = "NAME=X,Y,Z", allow_hyphen_values = true)]
    pub points: Vec<String>,
    /// A distance known between two --point sockets, `A,B=METRES`
    /// (repeatable), as `calibrate` will be given it: it fixes the scale
    /// that contacts alone leave free, so the design determines one more
    /// unknown.
    #[arg(long, value_name = "A,B=METRES", requires = "points")]
    pub point_distance: Vec<String>,
    /// Poses chosen for a camera (`--camera-info` and its options).
    #[command(flatten)]
    pub camera: super::camera_opts::CameraOpts,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// The options typed on the command line (set after parsing).
    #[arg(skip)]
    pub given: super::acts_on::Given,
}

/// The noise σ of `select --report` when `--noise` is not given, metres
/// (`calibrate`'s default).
pub const DEFAULT_REPORT_NOISE: f64 = super::calibrate::DEFAULT_NOISE;

/// Random designs drawn by `--algorithm random` when `--designs` is not
/// given.
pub const DEFAULT_DESIGNS: usize = 5000;

/// Options of one algorithm given with another, or that the chosen order
/// leaves unused: refused rather than silently ignored.
fn refuse_unused(a: &SelectArgs, reorder: bool) -> Result<()> {
    if let (Some(i), false) = (a.initial, a.algorithm == Algorithm::Eae) {
        bail!(
            "--initial {i} sets EAE's initial design; --algorithm {} does not use it",
            a.algorithm
        );
    }
    if let (Some(d), false) = (a.designs, a.algorithm == Algorithm::Random) {
        bail!(
            "--designs {d} is the number of random designs of --algorithm random; --algorithm {} draws none",
            a.algorithm
        );
    }
    if a.home.is_some() && !reorder {
        bail!(
            "--home starts the visiting path of --order time; the design keeps its selection order here (--order none, the default for a robot without joint speed limits)"
        );
    }
    Ok(())
}

/// How `select` orders the design's poses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Order {
    /// Least total move time.
    Time,
    /// Selection order.
    None,
}

/// Runs `select`.
pub fn cmd_select(a: SelectArgs) -> Result<()> {
    check_select_outputs(&a)?;
    // Cheap checks of the ordering's inputs before the pool is built.
    let mut described = super::load_description(&a.pool.robot)?;
    if a.keep_axis_relations {
        described.robot = Restriction::KeepAxisRelations.apply(&described.robot)?;
    }
    if let Some(so) = a.orientation_noise {
        described.robot.orientation_scale =
            activecal::experiment::pool::orientation_scale(&described.robot, a.noise, so)?;
    }
    let speeds = activecal::io::joint_speeds::joint_speeds(&described.robot)?;
    let home = super::tour::parse_home(a.home.as_deref(), &described.robot)?;
    refuse_unused(&a, a.order.map_or(speeds.is_some(), |o| o == Order::Time))?;
    // Refused, never clamped (as `reproduce` does).
    let initial = match a.initial {
        Some(i) if i == 0 || i > a.n => bail!(
            "--initial {i}: the initial EAE design must have 1..=N poses (--n {})",
            a.n
        ),
        Some(i) => i,
        None => Settings::default().initial.min(a.n),
    };
    let ctx = a.pool.load_for(described)?;
    let existing = a
        .existing
        .as_deref()
        .map(|p| super::load_existing(p, &ctx.robot, a.pool.params, a.pool.units.units()))
        .transpose()?;
    let prior = existing.as_ref().map(|e| e.prior.clone());
    let s = selection_settings(&a, &ctx, initial, prior)?;
    let run = SelectRun {
        criterion: a.criterion,
        algorithm: a.algorithm,
        settings: s.clone(),
        visiting: activecal::experiment::visiting::Visiting {
            reorder: a.order.map_or(speeds.is_some(), |o| o == Order::Time),
            home,
            // Pool poses under the D criterion: not refined ones.
            may_swap: a.criterion == CriterionKind::Det && !a.refine,
        },
        gap: a
            .gap
            .then(|| {
                activecal::options::BoundSettings::builder()
                    .solver(a.gap_solver)
                    .build()
            })
            .transpose()?,
        refine: a
            .refine
            .then(|| {
                activecal::options::RefineSettings::builder()
                    .sweeps(a.refine_sweeps)
                    .build()
            })
            .transpose()?,
        noise: a.noise,
        params: a.pool.params,
    };
    let outcome =
        activecal::experiment::select::run(&ctx.robot, &ctx.pool, &ctx.x, existing.as_ref(), &run)?;
    let (report, seconds) = (&outcome.report, outcome.seconds);
    for out in &a.out {
        super::tour::write_design(&outcome.design, out, a.force)?;
    }
    let recommended = match &a.report {
        Some(dir) => report_dir(&a, &ctx, &s, dir, report)?,
        None => None,
    };
    emit_report(a.json, report, || {
        super::pool_stats_text(&ctx.pool.stats)
            + &activecal::render::select_text::text(report, &s, seconds)
            + &recommended.map_or(String::new(), |r| {
                activecal::render::folder::recommendation_text(&r)
            })
    })
}

/// Every file of a `select` run, whichever kind (pool, camera, sockets):
/// the pool's inputs (robot, frames, `--pool file:`, SRDF, mesh
/// directories), `--existing`, the camera's `--camera-info` and
/// `--target`, the `--out` files and the `--report` directory; checked
/// once, before any work ([`super::run_files::RunFiles::check`]).
pub fn select_files(a: &SelectArgs) -> super::run_files::RunFiles {
    let mut f = super::run_files::RunFiles::new();
    super::run_files::pool(&mut f, &a.pool)
        .input("--existing", a.existing.as_deref())
        .input("--camera-info", a.camera.camera_info.as_deref())
        .input("--target", a.camera.target.as_deref())
        .outputs("--out", &a.out)
        .dir("--report", a.report.as_deref());
    f
}

/// `--out` files' formats (by extension), checked before any work.
pub fn check_out_formats(outs: &[PathBuf]) -> Result<()> {
    for out in outs {
        activecal::io::design_formats::DesignFormat::of(out)
            .map_err(|e| anyhow::anyhow!("--out {e}"))?;
    }
    Ok(())
}

/// The files and report options of `select`, checked before any work:
/// every output against every input and every other output, an existing
/// file, a missing directory, the format, the noise.
fn check_select_outputs(a: &SelectArgs) -> Result<()> {
    super::run_files::check(&select_files(a), a.force)?;
    check_out_formats(&a.out)?;
    if let Some(n) = a.noise.filter(|v| !(v.is_finite() && *v > 0.0)) {
        bail!("--noise {n}: the sensor noise σ must be a finite number > 0 (metres)");
    }
    Ok(())
}

/// The selection's settings from the options, the pool and the poses
/// already measured (`--fixed` ids checked against the pool).
fn selection_settings(
    a: &SelectArgs,
    ctx: &super::PoolCtx,
    initial: usize,
    prior: Option<activecal::options::Prior>,
) -> Result<Settings> {
    let fixed_ids: Vec<usize> = match &a.fixed {
        Some(f) => parse_list(f, "--fixed")?,
        None => vec![],
    };
    activecal::io::design::check_unique(&fixed_ids)?;
    let fixed = ctx.pool.positions_of(&fixed_ids)?;
    Ok(Settings::builder()
        .n(a.n)
        .initial(initial.max(fixed.len()))
        .starts(a.starts)
        .designs(a.designs.unwrap_or(DEFAULT_DESIGNS))
        .polish(a.polish)
        .ils(
            a.ils
                .unwrap_or_else(|| default_ils_rounds(ctx.x.n_poses(), ctx.x.t())),
        )
        .kick(a.kick)
        .seed(a.seed)
        .fixed(fixed)
        .prior(prior)
        .build()?)
}

/// `--report DIR`: the "how many poses" curve and the selection's figures;
/// returns the size the curve recommends.
fn report_dir(
    a: &SelectArgs,
    ctx: &super::PoolCtx,
    s: &Settings,
    dir: &std::path::Path,
    report: &SelectReport,
) -> Result<Option<activecal::report::Recommendation>> {
    let on = activecal::experiment::select::CurveOf {
        robot: &ctx.robot,
        params: a.pool.params,
        x: &ctx.x,
        ids: &ctx.pool.ids,
        settings: s,
        criterion: a.criterion,
        algorithm: a.algorithm,
        n: a.n,
    };
    let curve = activecal::experiment::select::how_many_curve(
        on,
        a.noise.unwrap_or(DEFAULT_REPORT_NOISE),
        a.target_error,
    )?;
    activecal::render::folder::selection(dir, &ctx.robot, report, &curve, a.noise.is_none())?;
    Ok(curve.recommended)
}
