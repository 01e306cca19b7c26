//! The pool options every pool-using command shares (`--pool`, `--levels`,
//! `--count`, margins, filters), resolved once into a `PoolSpec`, and the
//! pool with its Jacobian.

use super::{choice, load_description, parse_robot, units};
use activecal::io::{RobotRef, UrdfChain};
use activecal::model::{ParamSet, Robot};
use activecal::options::Visibility;
use activecal::options::{PoolFilter, PoolSource, PoolSpec};
use anyhow::Result;

pub use activecal::options::{DEFAULT_LEVELS, PoolKind};

/// Parses `--pool`: `lattice`, `random`, `sobol`, `file:PATH`, or a path
/// ending in `.csv` or `.json` ([`PoolKind`]).
pub fn parse_pool_kind(s: &str) -> std::result::Result<PoolKind, String> {
    s.parse()
}

/// Options that define a pose pool, shared by the commands that need one.
#[derive(clap::Args, Clone, Debug)]
pub struct PoolOpts {
    /// Robot: a built-in name (puma560, ur5, stanford), or a .toml
    /// description or .urdf file; append `:pose` for full-pose measurements
    /// (`:NAME` for a sensor registered by
    /// that name).
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
    /// With --self-collision, for a URDF without an SRDF: do not check the
    /// link pairs that touch in at least 95 % of 1,000 random
    /// configurations within the joint limits (MoveIt's "always in
    /// collision" rule); they are listed in the pool statistics.
    #[arg(long)]
    pub skip_always_touching: bool,
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
/// degrees ([`activecal::options::DEFAULT_URDF_MARGIN_DEG`]).
pub const DEFAULT_MARGIN_DEG: f64 = activecal::options::DEFAULT_URDF_MARGIN_DEG;

/// A robot, its pose pool and the pool's identification Jacobian
/// ([`activecal::experiment::pool::build_pool`]).
pub type PoolCtx = activecal::experiment::pool::PoolRun;

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

/// How this command line says where an SRDF is given, ending the pool
/// filters' note on a robot without one.
pub const SRDF_HINT: &str =
    " (give the SRDF with --srdf FILE, or without one --skip-always-touching)";

/// One line per filter (what it removed) and per note of a pool's build.
pub fn pool_stats_text(st: &activecal::report::PoolStats) -> String {
    activecal::render::pool_text::pool_stats_text(st, SRDF_HINT)
}

impl PoolOpts {
    /// The pool source these options describe; an option that does not
    /// apply to the chosen pool is an error.
    pub fn source(&self) -> Result<PoolSource> {
        Ok(PoolSource::of(
            &self.pool,
            self.levels,
            self.count,
            self.pool_seed,
        )?)
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
            None => activecal::options::default_margin_deg(self.robot.is_urdf(), &self.source()?),
        };
        Ok(deg.to_radians())
    }

    /// The self-collision and obstacle filters of `--self-collision`,
    /// `--obstacle` and `--floor` (one filter each kind, so that the pool
    /// statistics say what each removed); `--srdf` and `--package-dir`
    /// without them are errors.
    pub fn collision_filters(&self, robot: &Robot) -> Result<Vec<PoolFilter>> {
        self.collision_filters_on(UrdfChain::of(robot))
    }

    /// [`Self::collision_filters`] of a chain of a URDF tree given as it
    /// is (`None`: a robot not imported from a URDF): for a camera's chain
    /// from its own link, whose joints drive the whole tree by name with
    /// the tree's root as the frame of obstacles.
    pub fn collision_filters_on(&self, chain: Option<UrdfChain>) -> Result<Vec<PoolFilter>> {
        let choice = self.collision_choice(false)?;
        if !choice.any() {
            return Ok(Vec::new());
        }
        let Some(chain) = chain else {
            anyhow::bail!(
                "--self-collision, --obstacle and --floor need a URDF robot with collision geometry (--robot FILE.urdf); {} has none",
                self.robot
            );
        };
        Ok(choice.filters(chain))
    }

    /// What `--self-collision`, `--srdf`, `--package-dir`, `--clearance`,
    /// `--obstacle` and `--floor` ask the collision check to do, checked
    /// ([`activecal::io::collision_choice::CollisionChoice::validate`]; the
    /// files must exist; `--package-dir` without a check only when
    /// `sight_meshes`: a camera's line of sight reads them).
    pub fn collision_choice(
        &self,
        sight_meshes: bool,
    ) -> Result<activecal::io::collision_choice::CollisionChoice> {
        use activecal::options::Obstacle;
        let obstacles = self
            .obstacles
            .iter()
            .map(|o| Obstacle::parse(o).map_err(anyhow::Error::msg))
            .collect::<Result<Vec<_>>>()?;
        let choice = activecal::io::collision_choice::CollisionChoice {
            self_collision: self.self_collision,
            skip_always_touching: self.skip_always_touching,
            srdf: self.srdf.as_ref().map(|p| p.display().to_string()),
            package_dirs: self
                .package_dirs
                .iter()
                .map(|p| p.display().to_string())
                .collect(),
            clearance: self.clearance,
            obstacles,
            floor: self.floor,
        };
        choice.validate()?;
        if !choice.any() && !sight_meshes && !self.package_dirs.is_empty() {
            anyhow::bail!("--package-dir applies with --self-collision, --obstacle or --floor");
        }
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
        Ok(choice)
    }

    /// Loads the robot, builds the pool and its Jacobian. A pool file is
    /// read in the options' units.
    pub fn load(&self) -> Result<PoolCtx> {
        self.load_for(load_description(&self.robot)?)
    }

    /// Builds the pool of these options and its Jacobian for a robot
    /// already loaded (from [`PoolOpts::robot`]); a pool file is read in
    /// the options' units.
    pub fn load_for(&self, d: activecal::io::Description) -> Result<PoolCtx> {
        let spec = self.spec(&d)?;
        Ok(activecal::experiment::pool::build_pool(
            d.robot,
            &spec,
            None,
            self.units.units(),
            self.params,
            self.compliance,
        )?)
    }
}
