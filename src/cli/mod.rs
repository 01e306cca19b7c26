//! Shared helpers of the command-line subcommands; one file per command group.

pub mod basic;
pub mod bench;
pub mod bound;
pub mod calibrate;
pub mod compliance;
pub mod contact;
pub mod contact_evaluate;
pub mod contact_select;
pub mod figures;
pub mod frames_text;
pub mod measured;
pub mod progress;
pub mod report_dir;
pub mod report_plots;
pub mod reproduce;
pub mod select;
pub mod tour;
pub mod units;

use activecal::io::{ChainChoice, RobotRef, UrdfChain};
use activecal::measure::Visibility;
use activecal::model::{ParamSet, Robot};
use activecal::pool::{Pool, PoolFilter, PoolSource, PoolSpec};
use anyhow::Result;
use serde_json::Value;

/// Parses a comma-separated list, naming the option in the error.
pub fn parse_list<T: std::str::FromStr>(s: &str, what: &str) -> Result<Vec<T>>
where
    T::Err: std::fmt::Display,
{
    s.split(',')
        .map(|x| {
            let x = x.trim();
            x.parse::<T>()
                .map_err(|e| anyhow::anyhow!("{what}: cannot parse '{x}': {e}"))
        })
        .collect()
}

/// The value parser of an option that takes one of a library type's named
/// values ([`activecal::names::Choice`]): `--help` lists the names, and a
/// wrong one is refused with them.
pub fn choice<T: activecal::names::Choice + Send + Sync>()
-> impl clap::builder::TypedValueParser<Value = T> {
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(T::ALL.iter().map(|v| v.name())).try_map(|s| {
        T::from_name(&s).ok_or_else(|| format!("'{s}' is not one of the offered names"))
    })
}

/// Parses `--seed`: a non-negative integer. With `allow_negative_numbers`
/// (on every numeric option), `--seed -1` and `--seed=-1` both reach this
/// parser and get the same message (clap would otherwise take `-1` for an
/// unknown option).
pub fn parse_seed(s: &str) -> std::result::Result<u64, String> {
    s.trim().parse::<u64>().map_err(|_| {
        format!(
            "the seed must be a non-negative integer (0 to {}), got '{s}'",
            u64::MAX
        )
    })
}

/// Parses `--robot` (and `robots --export`): a built-in name or a path,
/// with an optional `:pose` suffix and, as design files of old wrote it,
/// a `#…` chain ([`RobotRef::parse`]).
pub fn parse_robot(s: &str) -> std::result::Result<RobotRef, String> {
    RobotRef::parse(s).map_err(|e| e.to_string())
}

/// The chain options typed on the command line (`--base`, `--tip`,
/// `--lock`, `--frames`), checked: one value, resolved once and given to
/// the command's robot ([`apply_chain`]).
pub fn chain_choice(
    base: Option<String>,
    tip: Option<String>,
    lock: Option<&str>,
    frames: Option<std::path::PathBuf>,
) -> Result<ChainChoice> {
    let lock = match lock {
        Some(l) => ChainChoice::parse_lock(l).map_err(|e| anyhow::anyhow!("--{e}"))?,
        None => Vec::new(),
    };
    if let Some(f) = &frames
        && !f.is_file()
    {
        anyhow::bail!("--frames {}: no such file", f.display());
    }
    Ok(ChainChoice {
        base,
        tip,
        lock,
        frames: frames.map(|f| f.display().to_string()),
    })
}

/// Gives the chain options to a command's robot. A robot that names a chain
/// already (`tiago.urdf#tip=…`, as design files of old did) keeps it; chain
/// options that differ from it are refused, naming both.
pub fn apply_chain(robot: &mut RobotRef, c: &ChainChoice) -> Result<()> {
    if c.is_empty() {
        return Ok(());
    }
    if !robot.chain.is_empty() && robot.chain != *c {
        anyhow::bail!(
            "{} conflicts with the robot '{robot}', which names its chain already ({}); give the chain once",
            chain_options(c),
            robot.chain.fragment()
        );
    }
    robot.chain = c.clone();
    Ok(())
}

/// The chain options as typed: `--base B --tip T --lock J=V --frames F`.
pub fn chain_options(c: &ChainChoice) -> String {
    let mut parts = Vec::new();
    if let Some(b) = &c.base {
        parts.push(format!("--base {b}"));
    }
    if let Some(t) = &c.tip {
        parts.push(format!("--tip {t}"));
    }
    if !c.lock.is_empty() {
        let l: Vec<String> = c.lock.iter().map(|(n, v)| format!("{n}={v}")).collect();
        parts.push(format!("--lock {}", l.join(",")));
    }
    if let Some(f) = &c.frames {
        parts.push(format!("--frames {f}"));
    }
    parts.join(" ")
}

/// Loads and validates a robot: a built-in name, or a `.toml` description or
/// `.urdf` file ([`RobotRef::load`]), with its chain.
pub fn load_robot(r: &RobotRef) -> Result<Robot> {
    load_description(r).map(|d| d.robot)
}

/// Refuses a robot without a driven joint (a description whose frames are
/// all fixed, a chain whose joints are all locked): nothing to move.
fn has_joints(name: &str, r: &Robot) -> Result<()> {
    if r.dof() == 0 {
        anyhow::bail!(
            "{name}: this robot has no joints (every frame of its chain is fixed); a robot needs at least one revolute or prismatic joint"
        );
    }
    Ok(())
}

/// Errors if `path` exists and `force` is not set: nothing the user has is
/// replaced without asking. Checked before any work is done.
pub fn refuse_overwrite(path: &std::path::Path, force: bool) -> Result<()> {
    check_outputs(&[("--out", path)], &[], force)
}

/// Checks a command's outputs before any work (see
/// [`activecal::io::atomic::check_outputs`]): each is a file in an existing
/// directory, not an input, not another output, and new unless `force`.
pub fn check_outputs(
    outputs: &[(&str, &std::path::Path)],
    inputs: &[&std::path::Path],
    force: bool,
) -> Result<()> {
    let outs: Vec<activecal::io::atomic::Output<'_>> = outputs
        .iter()
        .map(|&(option, path)| activecal::io::atomic::Output { option, path })
        .collect();
    activecal::io::atomic::check_outputs(&outs, inputs, force)?;
    Ok(())
}

/// Writes `text` to `path` (see [`refuse_overwrite`]), naming the file in
/// any error.
pub fn write_new(path: &std::path::Path, text: &str, force: bool) -> Result<()> {
    refuse_overwrite(path, force)?;
    activecal::io::atomic::write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// Prints `value` as one JSON line, or the human-readable `text`.
pub fn emit(json_out: bool, value: &Value, text: impl FnOnce() -> String) {
    use std::io::Write;
    let s = if json_out {
        format!("{value}\n")
    } else {
        text()
    };
    // A closed pipe (`activecal ... | head`) is not an error worth a panic.
    let _ = std::io::stdout().lock().write_all(s.as_bytes());
}

/// Prints a typed report as one JSON line, or the human-readable `text`.
pub fn emit_report<T: serde::Serialize>(
    json_out: bool,
    report: &T,
    text: impl FnOnce() -> String,
) -> Result<()> {
    let v = serde_json::to_value(report)?;
    emit(json_out, &v, text);
    Ok(())
}

/// Where the candidate poses come from (`--pool`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PoolKind {
    /// The joint-space lattice (`--levels`).
    Lattice,
    /// Uniform random samples inside the joint limits (`--count`, `--pool-seed`).
    Random,
    /// Sobol points inside the joint limits (`--count`, `--pool-seed` to scramble).
    Sobol,
    /// Joint configurations from a CSV or JSON file.
    File(std::path::PathBuf),
}

/// Parses `--pool`: `lattice`, `random`, `sobol`, `file:PATH`, or a path
/// ending in `.csv` or `.json`.
pub fn parse_pool_kind(s: &str) -> std::result::Result<PoolKind, String> {
    match s {
        "lattice" => Ok(PoolKind::Lattice),
        "random" => Ok(PoolKind::Random),
        "sobol" => Ok(PoolKind::Sobol),
        _ => {
            if let Some(p) = s.strip_prefix("file:") {
                if p.is_empty() {
                    return Err("file: needs a path, e.g. file:poses.csv".into());
                }
                return Ok(PoolKind::File(p.into()));
            }
            let lower = s.to_ascii_lowercase();
            if lower.ends_with(".csv") || lower.ends_with(".json") {
                return Ok(PoolKind::File(s.into()));
            }
            Err(format!(
                "unknown pool '{s}': use lattice, random, sobol, or file:PATH (a CSV or JSON of joint configurations)"
            ))
        }
    }
}

/// Samples of a random or Sobol pool when `--count` is not given (2¹²: a
/// whole number of Sobol strata).
pub const DEFAULT_COUNT: usize = 4096;

/// Lattice values per joint when `--levels` is not given.
pub const DEFAULT_LEVELS: usize = 5;

/// Options that define a pose pool, shared by the commands that need one.
#[derive(clap::Args, Clone, Debug)]
pub struct PoolOpts {
    /// Robot: a built-in name (puma560, ur5, stanford), or a .toml
    /// description or .urdf file; append `:pose` for full-pose measurements.
    #[arg(long, default_value = "puma560", value_parser = parse_robot)]
    pub robot: RobotRef,
    /// Candidate poses: lattice (--levels), random or sobol (--count,
    /// --pool-seed) inside the joint limits, or file:PATH, a CSV with a
    /// header of joint names (or q1..qN) or JSON {"qs": [[...]]} of joint
    /// configurations (a PATH ending in .csv or .json also works).
    #[arg(long, value_name = "lattice|random|sobol|file:PATH", default_value = "lattice", value_parser = parse_pool_kind)]
    pub pool: PoolKind,
    /// Lattice values per joint (--pool lattice) [default: 5].
    #[arg(long, allow_negative_numbers = true)]
    pub levels: Option<usize>,
    /// Samples of --pool random or sobol [default: 4096].
    #[arg(long, allow_negative_numbers = true)]
    pub count: Option<usize>,
    /// Seed of --pool random [default: 0], or of the scramble of --pool
    /// sobol (without it, the plain Sobol sequence).
    #[arg(long, allow_negative_numbers = true)]
    pub pool_seed: Option<u64>,
    /// Parameter set the Jacobian is computed with.
    #[arg(long, value_parser = choice::<ParamSet>(), default_value_t = ParamSet::Nominal)]
    pub params: ParamSet,
    /// Sensor visibility region as JSON, e.g.
    /// '{"kind":"box","min":[-30,-30,-30],"max":[30,30,30]}' or
    /// '{"kind":"cone","apex":[0,0,0],"axis":[0,1,0],"half_angle":0.1,"max_range":40}'.
    #[arg(long)]
    pub visibility: Option<String>,
    /// Remove the candidates where two links of the URDF robot touch (its
    /// collision geometry: boxes, cylinders, spheres, STL meshes), skipping
    /// adjacent links and an SRDF's disabled pairs.
    #[arg(long)]
    pub self_collision: bool,
    /// SRDF whose `disable_collisions` pairs are not checked.
    #[arg(long, value_name = "FILE")]
    pub srdf: Option<std::path::PathBuf>,
    /// Directory searched for `package://` meshes (repeatable; the URDF's
    /// directory and its ancestors are searched too).
    #[arg(long = "package-dir", value_name = "DIR")]
    pub package_dirs: Vec<std::path::PathBuf>,
    /// Remove the candidates where a link touches this box:
    /// box:cx,cy,cz,sx,sy,sz (centre and full sizes, metres, in the base
    /// link's frame; repeatable).
    #[arg(
        long = "obstacle",
        value_name = "box:cx,cy,cz,sx,sy,sz",
        allow_hyphen_values = true
    )]
    pub obstacles: Vec<String>,
    /// Remove the candidates where a link (other than the base's) goes below
    /// z = Z of the base link's frame.
    #[arg(long, value_name = "Z", allow_negative_numbers = true)]
    pub floor: Option<f64>,
    /// Units of --pool file: and --existing values.
    #[command(flatten)]
    pub units: units::UnitOpts,
    /// Add a compliance unknown per revolute joint whose gravity torque
    /// (from the URDF's inertials) varies over the pool, so that designs
    /// separate sag from geometry (as `calibrate --compliance` fits).
    #[arg(long)]
    pub compliance: bool,
    /// Keep candidates this far inside every revolute joint's limits,
    /// degrees: lattice and sampled pools are made over the shrunk ranges, a
    /// file's rows closer to a limit are removed [default: 2 for a .urdf
    /// robot; 0 for the built-in arms (the paper's lattice), .toml
    /// descriptions (their limits as stated) and --pool file:].
    #[arg(long, value_name = "DEGREES", allow_negative_numbers = true)]
    pub margin: Option<f64>,
    /// With --self-collision, --obstacle or --floor: also remove the
    /// candidates where two checked links, or a link and an obstacle, come
    /// closer than this, metres (parry's distance query).
    #[arg(
        long,
        value_name = "METRES",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub clearance: f64,
}

/// The joint-limit margin of a URDF robot when `--margin` is not given,
/// degrees: clear of the hard stops, where a badly calibrated
/// arm's controller faults, by more than a calibration's usual joint
/// offsets (tenths of a degree).
pub const DEFAULT_MARGIN_DEG: f64 = 2.0;

/// Poses measured before a selection (`--existing`): their prior
/// information `M0` and its report.
pub struct Existing {
    /// `M0 = Σ XᵢᵀXᵢ` of the poses, at the pool's parameters.
    pub prior: activecal::criterion::Prior,
    /// What the file held.
    pub report: activecal::report::ExistingReport,
    /// Their joint values (a design file stores them).
    pub qs: Vec<Vec<f64>>,
}

/// Reads the poses of `--existing FILE` (a CSV or JSON of joint
/// configurations, a JSON measurement file or a design file: the same
/// reader as `--pool file:…`; or a design written as YAML) and makes their
/// prior information at `params`.
pub fn load_existing(
    path: &std::path::Path,
    robot: &Robot,
    params: ParamSet,
    units: activecal::units::Units,
) -> Result<Existing> {
    use activecal::io::design_formats::DesignFormat;
    use anyhow::Context;
    if DesignFormat::of(path).ok() == Some(DesignFormat::Yaml) {
        // A design written as YAML: its joint values.
        let d = activecal::io::design::DesignFile::read(path)
            .and_then(|d| d.joint_values(robot))
            .map_err(|e| anyhow::anyhow!("--existing {}: {e}", path.display()))?;
        return existing_from(path.display().to_string(), d, Vec::new(), robot, params);
    }
    let c = activecal::pool::read_configurations_in(path, robot, units).context("--existing")?;
    existing_from(path.display().to_string(), c.qs, c.notes, robot, params)
}

/// The prior information of poses `qs` (from `file`) at `params`.
pub fn existing_from(
    file: String,
    qs: Vec<Vec<f64>>,
    notes: Vec<String>,
    robot: &Robot,
    params: ParamSet,
) -> Result<Existing> {
    activecal::resources::MemoryBudget::from_env()?.check(
        &format!("the Jacobian of {} existing poses", qs.len()),
        activecal::pool::memory_estimate(robot, qs.len()),
    )?;
    if let Some(k) = qs.iter().position(|q| q.len() != robot.dof()) {
        anyhow::bail!(
            "{file}: existing pose {} has {} joint values, the robot {}",
            k + 1,
            qs[k].len(),
            robot.dof()
        );
    }
    let x = activecal::blocks::jacobian_of(robot, robot.params(params), qs.len(), |k, q| {
        q.copy_from_slice(&qs[k]);
    });
    let prior = activecal::criterion::Prior::from_blocks(&x)
        .map_err(|e| anyhow::anyhow!("{file}: the existing poses' Jacobian: {e}"))?;
    let report = activecal::report::ExistingReport::new(file, &x, &prior, notes);
    Ok(Existing { prior, report, qs })
}

/// Text lines about the existing poses of a report.
pub fn existing_text(e: &activecal::report::ExistingReport) -> String {
    let mut s = format!(
        "existing: {} poses from {} (rank {}), log10 det M0 {}\n",
        e.poses,
        e.file,
        e.rank,
        e.log10_det
            .map_or("singular (-inf)".to_string(), |v| format!("{v:.4}"))
    );
    for n in &e.notes {
        s += &format!("note: {n}\n");
    }
    s
}

/// A robot, its pose pool and the pool's identification Jacobian.
pub struct PoolCtx {
    /// The robot.
    pub robot: Robot,
    /// The pool.
    pub pool: Pool,
    /// Identification Jacobian of every pool pose.
    pub x: activecal::blocks::Blocks,
}

/// The filters of a pool: `--visibility`, else the robot description's
/// region, else none.
pub fn filters(
    visibility: Option<&str>,
    described: Option<&Visibility>,
) -> Result<Vec<PoolFilter>> {
    Ok(match (visibility, described) {
        (Some(v), _) => {
            let vis: Visibility =
                serde_json::from_str(v).map_err(|e| anyhow::anyhow!("--visibility: {e}"))?;
            vis.validate()
                .map_err(|e| anyhow::anyhow!("--visibility: {e}"))?;
            vec![PoolFilter::Visibility(vis)]
        }
        (None, Some(vis)) => vec![PoolFilter::Visibility(vis.clone())],
        (None, None) => vec![],
    })
}

/// Loads a robot with its description's visibility region (validated).
pub fn load_description(r: &RobotRef) -> Result<activecal::io::Description> {
    let d = r.load()?;
    d.robot.validate()?;
    has_joints(&r.to_string(), &d.robot)?;
    Ok(d)
}

/// A built pool with its Jacobian at `params` (reserved fallibly: memory
/// the system refuses is an error, not an abort).
pub fn with_jacobian(robot: Robot, pool: Pool, params: ParamSet) -> Result<PoolCtx> {
    let x = pool.try_jacobian(&robot, robot.params(params))?;
    Ok(PoolCtx { robot, pool, x })
}

/// The robot with the compliance unknowns a design was chosen for
/// (`select --compliance`), or as it is.
pub fn design_compliance(robot: Robot, d: &activecal::io::design::DesignFile) -> Result<Robot> {
    if d.compliance.is_empty() {
        return Ok(robot);
    }
    let g = compliance::gravity_for(&robot, None, None)?;
    Ok(activecal::identify::compliance::with_compliant_joints(
        &robot,
        &g,
        &d.compliance,
    )?)
}

/// One line per filter (what it removed) and per note of a pool's build.
pub fn pool_stats_text(st: &activecal::pool::PoolStats) -> String {
    let mut s = format!("pool: {} candidates", st.candidates);
    for f in &st.filters {
        s += &format!(", {} filter removed {} of {}", f.filter, f.removed, f.seen);
    }
    s += &format!(", {} kept\n", st.kept);
    for f in &st.filters {
        if let Some(c) = &f.contacts {
            s += &format!(
                "  {} filter: {} removed by two links touching, {} by a link touching an obstacle; {} pairs, the largest:\n",
                f.filter, c.self_collision, c.obstacle, c.distinct_pairs
            );
            for p in &c.top {
                s += &format!(
                    "    {:>7}  {} – {}{}\n",
                    p.removed,
                    p.link,
                    p.other,
                    if p.obstacle { " (obstacle)" } else { "" }
                );
            }
        }
        if let Some(w) = &f.warning {
            s += &format!("warning: {w}");
            let own = f
                .contacts
                .as_ref()
                .and_then(|c| c.top.first())
                .is_some_and(|p| !p.obstacle);
            if own {
                s += " (give the SRDF with --srdf FILE)";
            }
            s += "\n";
        }
    }
    for n in &st.notes {
        s += &format!("note: {n}\n");
    }
    s
}

impl PoolOpts {
    /// The pool source these options describe; an option that does not
    /// apply to the chosen pool is an error.
    pub fn source(&self) -> Result<PoolSource> {
        let lattice = matches!(self.pool, PoolKind::Lattice);
        let sampled = matches!(self.pool, PoolKind::Random | PoolKind::Sobol);
        if self.levels.is_some() && !lattice {
            anyhow::bail!("--levels applies to --pool lattice only");
        }
        if !sampled && (self.count.is_some() || self.pool_seed.is_some()) {
            anyhow::bail!("--count and --pool-seed apply to --pool random or sobol only");
        }
        let count = self.count.unwrap_or(DEFAULT_COUNT);
        Ok(match &self.pool {
            PoolKind::Lattice => PoolSource::Lattice {
                levels: self.levels.unwrap_or(DEFAULT_LEVELS),
            },
            PoolKind::Random => PoolSource::Random {
                count,
                seed: self.pool_seed.unwrap_or(0),
            },
            PoolKind::Sobol => PoolSource::Sobol {
                count,
                seed: self.pool_seed,
            },
            PoolKind::File(p) => PoolSource::File {
                path: p.display().to_string(),
            },
        })
    }

    /// The pool these options describe, for a robot description.
    pub fn spec(&self, d: &activecal::io::Description) -> Result<PoolSpec> {
        let mut filters = filters(self.visibility.as_deref(), d.visibility.as_ref())?;
        filters.extend(self.collision_filters(&d.robot)?);
        Ok(PoolSpec {
            source: self.source()?,
            filters,
            margin: self.margin_radians()?,
        })
    }

    /// The joint-limit margin in radians: `--margin`, else
    /// [`DEFAULT_MARGIN_DEG`] for a URDF robot and a generated pool, else 0
    /// (a built-in arm keeps the paper's lattice, a `.toml` description
    /// states its limits as its pools should use them — an export of a
    /// built-in arm gives the same pool —, a file of poses is taken as
    /// given).
    pub fn margin_radians(&self) -> Result<f64> {
        let deg = match self.margin {
            Some(m) if !(m.is_finite() && m >= 0.0) => {
                anyhow::bail!("--margin {m}: the margin is an angle >= 0 degrees")
            }
            Some(m) => m,
            None if self.robot.is_urdf() && !matches!(self.pool, PoolKind::File(_)) => {
                DEFAULT_MARGIN_DEG
            }
            None => 0.0,
        };
        Ok(deg.to_radians())
    }

    /// The self-collision and obstacle filters of `--self-collision`,
    /// `--obstacle` and `--floor` (one filter each kind, so that the pool
    /// statistics say what each removed); `--srdf` and `--package-dir`
    /// without them are errors.
    pub fn collision_filters(&self, robot: &Robot) -> Result<Vec<PoolFilter>> {
        use activecal::collision::{CollisionFilter, CollisionSpec, Obstacle};
        let obstacles = self
            .obstacles
            .iter()
            .map(|o| Obstacle::parse(o).map_err(anyhow::Error::msg))
            .collect::<Result<Vec<_>>>()?;
        if let Some(z) = self.floor
            && !z.is_finite()
        {
            anyhow::bail!("--floor {z}: not a finite height");
        }
        let any_obstacle = !obstacles.is_empty() || self.floor.is_some();
        if !(self.clearance.is_finite() && self.clearance >= 0.0) {
            anyhow::bail!("--clearance {}: a distance >= 0 metres", self.clearance);
        }
        if !self.self_collision && !any_obstacle {
            if self.clearance > 0.0 {
                anyhow::bail!("--clearance applies with --self-collision, --obstacle or --floor");
            }
            if self.srdf.is_some() || !self.package_dirs.is_empty() {
                anyhow::bail!(
                    "--srdf and --package-dir apply with --self-collision, --obstacle or --floor"
                );
            }
            return Ok(Vec::new());
        }
        if self.srdf.is_some() && !self.self_collision {
            anyhow::bail!("--srdf lists pairs of links for --self-collision, which is not given");
        }
        let Some(chain) = UrdfChain::of(robot) else {
            anyhow::bail!(
                "--self-collision, --obstacle and --floor need a URDF robot with collision geometry (--robot FILE.urdf); {} has none",
                self.robot
            );
        };
        for (opt, p) in self
            .srdf
            .iter()
            .map(|p| ("--srdf", p))
            .chain(self.package_dirs.iter().map(|p| ("--package-dir", p)))
        {
            if !p.exists() {
                anyhow::bail!("{opt} {}: no such file or directory", p.display());
            }
        }
        let base_spec = CollisionSpec {
            urdf: chain.file,
            text: Some(chain.text),
            joints: chain.joints,
            lock: chain.lock,
            base: Some(chain.base),
            srdf: self.srdf.as_ref().map(|p| p.display().to_string()),
            package_dirs: self
                .package_dirs
                .iter()
                .map(|p| p.display().to_string())
                .collect(),
            clearance: self.clearance,
            ..CollisionSpec::default()
        };
        let mut out = Vec::new();
        if self.self_collision {
            out.push(PoolFilter::Collision(CollisionFilter::new(CollisionSpec {
                self_collision: true,
                ..base_spec.clone()
            })));
        }
        if any_obstacle {
            out.push(PoolFilter::Collision(CollisionFilter::new(CollisionSpec {
                obstacles,
                floor: self.floor,
                srdf: None,
                ..base_spec
            })));
        }
        Ok(out)
    }

    /// Loads the robot, builds the pool and its Jacobian. A pool file is
    /// read in the options' units.
    pub fn load(&self) -> Result<PoolCtx> {
        self.load_for(load_description(&self.robot)?)
    }

    /// Builds the pool of these options and its Jacobian for a robot
    /// already loaded (from [`PoolOpts::robot`]).
    pub fn load_for(&self, d: activecal::io::Description) -> Result<PoolCtx> {
        let spec = self.spec(&d)?;
        if let PoolSource::File { path } = &spec.source {
            let rows = activecal::pool::read_configurations_in(
                std::path::Path::new(path),
                &d.robot,
                self.units.units(),
            )?;
            let pool = spec.build_listed(&d.robot, &d.robot.nominal, rows)?;
            let robot = self.compliant(d.robot, &pool)?;
            return with_jacobian(robot, pool, self.params);
        }
        let pool = spec.build(&d.robot, &d.robot.nominal)?;
        let robot = self.compliant(d.robot, &pool)?;
        with_jacobian(robot, pool, self.params)
    }

    /// With `--compliance`, the robot with a compliance unknown per joint
    /// whose gravity torque varies over the pool.
    fn compliant(&self, robot: Robot, pool: &Pool) -> Result<Robot> {
        if !self.compliance {
            return Ok(robot);
        }
        let g = compliance::gravity_for(&robot, None, None)?;
        let qs: Vec<Vec<f64>> = (0..pool.len()).map(|k| pool.q(k)).collect();
        Ok(activecal::identify::compliance::with_compliance_at(&robot, &g, &qs).0)
    }
}
