//! The `activecal` command line: robots, forward kinematics, pose pools,
//! scoring, selection, bounds and calibration.

mod cli;

use clap::parser::ValueSource;
use clap::{ArgMatches, CommandFactory, FromArgMatches, Parser, Subcommand};
use cli::basic::{FkArgs, PoolArgs, RobotsArgs};
use cli::bench::BenchArgs;
use cli::bound::{BoundArgs, GapArgs};
use cli::calibrate::CalibrateArgs;
use cli::measured::EvaluateArgs;
use cli::reproduce::ReproduceArgs;
use cli::score::ScoreArgs;
use cli::select::SelectArgs;

#[derive(Parser)]
#[command(
    name = "activecal",
    version,
    about = "Pose selection and kinematic calibration for serial robots"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// The base link of a URDF tree's chain (default: the URDF's root);
    /// for every command that takes --robot.
    #[arg(long, global = true, value_name = "LINK")]
    base: Option<String>,
    /// The measured link of a URDF tree's chain (required on a tree; the
    /// error lists the candidates).
    #[arg(long, global = true, value_name = "LINK")]
    tip: Option<String>,
    /// Joints made fixed at a value: JOINT=VALUE,… (radians or metres).
    #[arg(
        long,
        global = true,
        value_name = "JOINT=VALUE,...",
        allow_hyphen_values = true
    )]
    lock: Option<String>,
    /// A frames file written by `calibrate --out cal.yaml`: mounts a .urdf
    /// robot in its measurement frame with its tool or markers (and takes
    /// its chain's base, tip and locked joints unless --base/--tip/--lock
    /// are given).
    #[arg(long, global = true, value_name = "FILE")]
    frames: Option<std::path::PathBuf>,
    /// A kinematics file whose joint origins replace the .urdf robot's:
    /// Universal Robots' default_kinematics.yaml (a factory file, or one
    /// `calibrate --out default_kinematics.yaml` wrote) or a per-joint
    /// origins file (`--out cal_origins.yaml`).
    #[arg(long, global = true, value_name = "FILE")]
    kinematics: Option<std::path::PathBuf>,
    /// A marker (retroreflector, tracked point) on the chain's tip:
    /// LINK@X,Y,Z, its offset in metres in the link's frame (repeatable:
    /// one per marker, in the order the measurement files list them).
    /// Poses are chosen, and the data fitted, for these markers; their
    /// offsets are unknowns of the fit. LINK is the tip (the default
    /// --tip when none is given).
    #[arg(
        long = "marker",
        global = true,
        value_name = "LINK@X,Y,Z",
        allow_hyphen_values = true
    )]
    markers: Vec<String>,
    /// Show progress on stderr even with --json or when stderr is not a
    /// terminal (then as plain lines). Without it, progress is a bar on a
    /// terminal's stderr, and nothing with --json. Never on stdout.
    #[arg(long, global = true)]
    progress: bool,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in robots with their parameter tables, or export a
    /// robot as a description file.
    Robots(RobotsArgs),
    /// Forward kinematics (and identification Jacobian) at one joint vector.
    Fk(FkArgs),
    /// Size of a pose lattice, or the index and angles of one lattice pose.
    Pool(PoolArgs),
    /// Observability indices of a design (ln OI_D, OI, O1-O5, A-trace, rank).
    ///
    /// OI_D = det XᵀX (X the identification Jacobian of the design's poses):
    /// the parameter confidence ellipsoid's volume is ∝ 1/√OI_D. With σ_i
    /// the singular values of X: OI (eq. 1) = (σ_1⋯σ_L)^(1/L) / L; O1 =
    /// (σ_1⋯σ_L)^(1/L) / √m; O2 = σ_max/σ_min; O3 = σ_min; O4 =
    /// σ_min²/σ_max; O5 = 1/Σ(1/σ_i); A-trace: tr (XᵀX)⁻¹.
    Score(ScoreArgs),
    /// Select the poses to measure (EAE, Fedorov, DETMAX or random search).
    Select(SelectArgs),
    /// Benchmark the hot paths (and with --scale the 10^6-pose pool).
    Bench(BenchArgs),
    /// Reproduce the paper's experiment: report, tables and figures.
    Reproduce(ReproduceArgs),
    /// Calibrate: simulated at a design (identification, validation,
    /// Monte-Carlo) or from a file of measurements.
    Calibrate(CalibrateArgs),
    /// A model's errors on measured data (mm and degrees, per pose), without
    /// fitting: the nominal model, or a calibrated description.
    Evaluate(EvaluateArgs),
    /// Certified upper bound on OI_D of every N-pose design (convex relaxation).
    ///
    /// OI_D = det XᵀX of a design. The bound: ln det M(w*) of the relaxation
    /// (weights 0 ≤ w ≤ 1 summing to N), certified by a solver-free formula
    /// so no N-pose pool design can exceed it; support: the poses carrying
    /// relaxation weight.
    Bound(BoundArgs),
    /// A design's D-efficiency against the relaxation bound.
    ///
    /// D-efficiency = (OI_D / bound)^(1/p), OI_D = det XᵀX of the design: 1
    /// means no N-pose design of the pool is better; a design refined off
    /// the pool may exceed the pool's bound (it is said when it does).
    Gap(GapArgs),
    /// A ROS 2 bag's rest periods into the measurement CSV `calibrate
    /// --measurements` reads: each pose a rest of the arm, its measurement
    /// averaged, the clocks aligned (MCAP or SQLite 3; no ROS needed).
    Extract(cli::extract::ExtractArgs),
}

impl Command {
    /// Records on `calibrate`, `select` and `evaluate` the options typed on the
    /// command line (`matches`: the whole line's).
    fn record_given(&mut self, matches: &ArgMatches) {
        let Some((name, sub)) = matches.subcommand() else {
            return;
        };
        let mut root = Cli::command();
        root.build();
        let Some(cmd) = root.find_subcommand(name) else {
            return;
        };
        let given = cli::acts_on::Given::of(cmd, sub);
        match self {
            Command::Calibrate(a) => a.given = given,
            Command::Select(a) => a.given = given,
            Command::Evaluate(a) => a.given = given,
            _ => {}
        }
    }

    /// Refuses, before any work, each option typed with a sensor it does
    /// not act on ([`cli::acts_on`]'s table of the command).
    fn refuse_unused_options(&self) -> anyhow::Result<()> {
        use cli::acts_on::{CALIBRATE, EVALUATE, SELECT, check};
        match self {
            Command::Calibrate(a) => check(CALIBRATE, &a.given, calibrate_sensors(a)),
            Command::Select(a) => check(SELECT, &a.given, &[select_sensor(a)]),
            Command::Evaluate(a) => check(EVALUATE, &a.given, evaluate_sensors(a)),
            _ => Ok(()),
        }
    }

    /// Gives the chain options to the command's robot, resolved once; a
    /// command without a `--robot` refuses them.
    fn take_chain(&mut self, c: &activecal::io::ChainChoice) -> anyhow::Result<()> {
        let robot = match self {
            Command::Robots(a) => a.export.as_mut().or(a.robot.as_mut()),
            Command::Fk(a) => Some(&mut a.robot),
            Command::Pool(a) => Some(&mut a.pool.robot),
            Command::Score(a) => Some(&mut a.pool.robot),
            Command::Select(a) => Some(&mut a.pool.robot),
            Command::Bound(a) => Some(&mut a.pool.robot),
            Command::Calibrate(a) => Some(&mut a.robot),
            Command::Evaluate(a) => Some(&mut a.robot),
            Command::Extract(a) => Some(&mut a.robot),
            Command::Bench(_) | Command::Reproduce(_) | Command::Gap(_) => None,
        };
        match robot {
            Some(r) => cli::apply_chain(r, c),
            None if c.is_empty() => Ok(()),
            None => anyhow::bail!(
                "{} applies to a command that takes --robot (or `robots --export`); this one does not (a design file names its robot and chain)",
                cli::chain_options(c)
            ),
        }
    }
}

fn main() {
    // faer's own default runs its large factorizations (the bound's Newton
    // system) on every core, with waiting threads spinning: 8 % of the
    // PUMA bound's profile, and results that could depend on the core
    // count. Parallelism is ours to choose (rayon, over starts and pools).
    faer::set_global_parallelism(faer::Par::Seq);
    let matches = Cli::command().get_matches();
    let mut cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    cli.command.record_given(&matches);
    // Pool options typed on the command line (not defaulted): `score`
    // refuses those that conflict with a `--design`.
    let given = |sub: &str| -> Vec<&'static str> {
        let Some(m) = matches.subcommand_matches(sub) else {
            return Vec::new();
        };
        [
            "robot",
            "levels",
            "visibility",
            "pool",
            "count",
            "pool_seed",
            "margin",
            "clearance",
            "self_collision",
            "obstacles",
            "floor",
        ]
        .into_iter()
        .filter(|id| m.value_source(id) == Some(ValueSource::CommandLine))
        .collect()
    };
    let json = matches
        .subcommand()
        .and_then(|(_, m)| m.try_get_one::<bool>("json").ok().flatten().copied())
        .unwrap_or(false);
    cli::progress::install_for(cli.progress, json);
    cap_threads();
    let mut command = cli.command;
    if let Err(e) = command.refuse_unused_options() {
        report_error(&e);
        std::process::exit(1);
    }
    let chain = cli::chain_choice(
        cli.base,
        cli.tip,
        cli.lock.as_deref(),
        cli.frames,
        cli.kinematics,
        &cli.markers,
    )
    .and_then(|c| command.take_chain(&c));
    if let Err(e) = chain {
        report_error(&e);
        std::process::exit(1);
    }
    let r = match command {
        Command::Robots(a) => cli::basic::cmd_robots(a),
        Command::Fk(a) => cli::basic::cmd_fk(a),
        Command::Pool(a) => cli::basic::cmd_pool(a),
        Command::Score(a) => cli::score::cmd_score(a, &given("score")),
        Command::Select(a) if !a.points.is_empty() => cli::contact_select::cmd_select_points(&a),
        Command::Select(a) if a.camera.camera_info.is_some() => {
            cli::camera_select::cmd_select_camera(&a)
        }
        Command::Select(a) => cli::select::cmd_select(a),
        Command::Bench(a) => cli::bench::cmd_bench(a),
        Command::Reproduce(a) => cli::reproduce::cmd_reproduce(a),
        Command::Calibrate(a) => cli::calibrate::cmd_calibrate(a),
        Command::Evaluate(a) if cli::contact::is_contact_file(&a.measurements) => {
            cli::contact_evaluate::cmd_evaluate_contacts(&a)
        }
        Command::Evaluate(a) => cli::measured::cmd_evaluate(a),
        Command::Bound(a) => cli::bound::cmd_bound(a),
        Command::Gap(a) => cli::bound::cmd_gap(a),
        Command::Extract(a) => cli::extract::cmd_extract(a),
    };
    if std::env::var_os("ACTIVECAL_DEBUG_READS").is_some() {
        // Each input file and how often it was read (once is the rule).
        for (path, n) in activecal::io::read::reads() {
            cli::diag(&format!("read {n}× {}", path.display()));
        }
    }
    if let Err(e) = r {
        report_error(&e);
        let not_converged = e.downcast_ref::<cli::calibrate::NotConverged>().is_some();
        std::process::exit(if not_converged {
            cli::calibrate::EXIT_NOT_CONVERGED
        } else {
            1
        });
    }
}

/// Runs rayon's workers only as many as the linear-algebra backend's
/// per-thread buffers allow within the memory budget
/// ([`activecal::resources::threads_within`]): each thread that multiplies
/// matrices allocates twice the L3 cache, outside any budget, and aborts
/// when it cannot (`ulimit -v 2000000` with 4 threads and 150 MiB of L3).
/// `RAYON_NUM_THREADS` (or the core count) is the most it runs.
fn cap_threads() {
    use activecal::resources::{MemoryBudget, backend_buffer_bytes, threads_within};
    // A malformed ACTIVECAL_MAX_MEMORY is reported by the command itself.
    let Ok(budget) = MemoryBudget::from_env() else {
        return;
    };
    let wanted = std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.trim().parse::<usize>().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from));
    let n = threads_within(&budget, backend_buffer_bytes(), wanted);
    if n < wanted {
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
}

/// Prints an error with the options it calls for: a unit to change
/// ([`cli::units::flag_hint`]) or the option that gives the input it names
/// ([`cli::hints::option_hints`]).
fn report_error(e: &anyhow::Error) {
    cli::diag(&format!("error: {e:#}"));
    let unit = cli::units::flag_hint(e);
    for h in unit
        .map(str::to_string)
        .into_iter()
        .chain(cli::hints::option_hints(e))
    {
        cli::diag(&format!("hint: {h}"));
    }
}

// Which sensors a command line is for (the tables of `cli::acts_on` say
// which options act on each); here, above the command's argument types.
use cli::acts_on::{self, Sensor};

/// The sensors a `calibrate` command line may be for, before its data are
/// read: points and full poses are told apart once the file is read
/// (`calibrate::from_measurements` checks again).
fn calibrate_sensors(a: &cli::calibrate::CalibrateArgs) -> &'static [acts_on::Sensor] {
    if a.images.is_some() && a.bag.is_some() {
        return &[Sensor::BagImages];
    }
    if a.images.is_some() {
        return &[Sensor::Images];
    }
    if a.bag.is_some() {
        // A bag's measurement is known by its option before it is read.
        return if a.from_bag.gives_poses() {
            &[Sensor::BagPoses]
        } else {
            &[Sensor::BagPoints]
        };
    }
    match (&a.observations, &a.measurements) {
        (Some(_), _) => &[Sensor::Pixels],
        (None, Some(m)) if cli::contact::is_contact_file(m) => &[Sensor::Contacts],
        (None, Some(_)) => acts_on::MEASURED,
        (None, None) => &[Sensor::Simulated],
    }
}

/// The sensors an `evaluate` command line may be for: contacts, or
/// points and full poses (which its table does not tell apart).
fn evaluate_sensors(a: &cli::measured::EvaluateArgs) -> &'static [acts_on::Sensor] {
    if cli::contact::is_contact_file(&a.measurements) {
        &[Sensor::Contacts]
    } else {
        acts_on::MEASURED
    }
}

/// The sensor of a `select` command line: `--point` (sockets), else
/// `--camera-info` (a camera), else a pool of poses.
fn select_sensor(a: &cli::select::SelectArgs) -> acts_on::Sensor {
    if !a.points.is_empty() {
        Sensor::Sockets
    } else if a.camera.camera_info.is_some() {
        Sensor::Camera
    } else {
        Sensor::Pool
    }
}
