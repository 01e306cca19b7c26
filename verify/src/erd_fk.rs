//! Forward kinematics of the `example-robot-data` arms ([`crate::erd`])
//! against Pinocchio: the joint vectors, the comparison, and the fixtures
//! `fixtures/example-robot-data/fk/<arm>.json` that plain `cargo test`
//! reads (`tests/erd_fixtures.rs`).
//!
//! For an arm with base link `b` and tip link `t`, the reference is
//! Pinocchio's `buildModelFromUrdf` of the same file and
//! `framesForwardKinematics`: `oMf(b)⁻¹ · oMf(t)`, the tip's placement in the
//! base link's frame — activecal's measurement frame is the chosen base
//! link, which need not be the URDF's root. The chain's joints are set by
//! name (a continuous joint, `nq = 2` in Pinocchio, as `(cos q, sin q)`),
//! locked joints at their values, every other joint of the tree at
//! Pinocchio's neutral configuration (they do not move the tip relative to
//! the base). activecal imports the arm by name,
//! `activecal::io::load_robot("<file>#base=…;tip=…;lock=…")`, as the command
//! line does, and evaluates its end frame with
//! [`activecal::kinematics::Evaluator`] at the nominal (URDF) parameters.
//!
//! Joint vectors: [`N_SAMPLES`] uniform in Pinocchio's joint limits
//! (continuous joints in [−π, π]) from a fixed seed, independent of
//! activecal's limits. Tolerance: [`crate::TOLERANCE`] = 1e-12 m on positions
//! and 1e-12 on rotation entries (the arms reach at most 2 m from their base;
//! see the constant's derivation).

use crate::erd::Arm;
use crate::fixture::Versions;
use crate::sample::SplitMix64;
use activecal::io::{ChainChoice, load_robot};
use activecal::kinematics::Evaluator;
use activecal::model::Robot;
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// Version of the fixture layout.
pub const FORMAT: u32 = 1;
/// Seed of the joint vectors (live check and fixtures alike).
pub const SEED: u64 = 60_000_014;
/// Joint vectors per arm.
pub const N_SAMPLES: usize = 20;
/// What a fixture's poses are.
pub const REFERENCE: &str = "Pinocchio buildModelFromUrdf + framesForwardKinematics: \
     oMf(base)^-1 * oMf(tip), the tip link's placement in the base link's frame \
     (base: the URDF's root when null); rotation row-major (columns: the tip's axes), \
     position in metres";

pub use crate::placement::Placement;

/// Largest deviation between two lists of placements.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PoseDeviation {
    /// `max |Δp|` over samples and coordinates (metres).
    pub position: f64,
    /// `max |ΔR|` over samples and entries.
    pub rotation: f64,
}

impl PoseDeviation {
    /// Whether both are at most `tol` (NaN never is).
    #[must_use]
    pub fn within(&self, tol: f64) -> bool {
        self.position <= tol && self.rotation <= tol
    }
}

/// Entry-wise comparison; a NaN anywhere gives a NaN deviation.
pub fn pose_deviation(a: &[Placement], b: &[Placement]) -> Result<PoseDeviation> {
    if a.len() != b.len() {
        bail!("{} placements vs {}", a.len(), b.len());
    }
    let mut d = PoseDeviation::default();
    let max = |m: f64, x: f64, y: f64| {
        let e = (x - y).abs();
        if e.is_nan() || m.is_nan() {
            f64::NAN
        } else {
            m.max(e)
        }
    };
    for (p, q) in a.iter().zip(b) {
        for i in 0..3 {
            d.position = max(d.position, p.position[i], q.position[i]);
            for j in 0..3 {
                d.rotation = max(d.rotation, p.rotation[i][j], q.rotation[i][j]);
            }
        }
    }
    Ok(d)
}

/// `n` joint vectors uniform in the boxes `limits`, from `seed`
/// ([`SplitMix64`], so that they never change with a dependency).
#[must_use]
pub fn joint_vectors(limits: &[[f64; 2]], n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            limits
                .iter()
                .map(|&[lo, hi]| lo + (hi - lo) * rng.next_f64())
                .collect()
        })
        .collect()
}

/// The range sampled for a joint with Pinocchio's `nq` and position limits:
/// [−π, π] for a continuous joint (`nq = 2`, whose limits are not angles),
/// the limits otherwise.
pub fn sampling_range(name: &str, nq: usize, limits: Option<[f64; 2]>) -> Result<[f64; 2]> {
    match (nq, limits) {
        (2, _) => Ok([-PI, PI]),
        (1, Some([lo, hi])) if lo.is_finite() && hi.is_finite() && lo < hi => Ok([lo, hi]),
        _ => bail!("joint {name}: nq = {nq}, limits {limits:?}: no range to sample"),
    }
}

/// The `#base=…;tip=…;lock=…` name of an arm's chain in the URDF at `path`,
/// as `--base`, `--tip` and `--lock` write it.
#[must_use]
pub fn robot_name(arm: &Arm, path: &Path) -> String {
    let choice = ChainChoice {
        base: arm.base.map(str::to_string),
        tip: Some(arm.tip.to_string()),
        lock: arm.lock.iter().map(|&(n, v)| (n.to_string(), v)).collect(),
        frames: None,
        kinematics: None,
        markers: Vec::new(),
    };
    format!("{}{}", path.display(), choice.fragment())
}

/// activecal's import of an arm from the URDF at `path` (by its robot name,
/// [`robot_name`]).
pub fn load(arm: &Arm, path: &Path) -> Result<Robot> {
    let name = robot_name(arm, path);
    load_robot(&name).with_context(|| format!("activecal importing {name}"))
}

/// The imported chain's joint names (the driven frames' labels, in joint
/// order).
#[must_use]
pub fn chain_joints(robot: &Robot) -> Vec<String> {
    let mut v = vec![String::new(); robot.dof()];
    for f in &robot.frames {
        if let Some(j) = f.joint {
            v[j].clone_from(&f.label);
        }
    }
    v
}

/// activecal's end frame at each `q`, at the nominal parameters.
#[must_use]
pub fn activecal_poses(robot: &Robot, qs: &[Vec<f64>]) -> Vec<Placement> {
    let mut ev = Evaluator::new(robot, &robot.nominal);
    qs.iter()
        .map(|q| {
            let e = ev.end_frame(q);
            Placement {
                rotation: std::array::from_fn(|i| std::array::from_fn(|j| e.rotation[(i, j)])),
                position: [e.position.x, e.position.y, e.position.z],
            }
        })
        .collect()
}

/// The workspace root (the parent of `verify/`).
#[must_use]
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `fixtures/example-robot-data/`: the URDF copies.
#[must_use]
pub fn default_dir() -> PathBuf {
    workspace().join("fixtures").join("example-robot-data")
}

/// One joint vector and Pinocchio's placement of the tip.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FkSample {
    /// The chain's joint values (radians, metres), locked joints excluded.
    pub q: Vec<f64>,
    /// Tip position in the base link's frame (metres).
    pub position: [f64; 3],
    /// Tip rotation in the base link's frame, row-major.
    pub rotation: [[f64; 3]; 3],
}

/// A `fixtures/example-robot-data/fk/<arm>.json` file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FkFixture {
    /// [`FORMAT`].
    pub format: u32,
    /// The arm's name ([`Arm::name`]).
    pub arm: String,
    /// The URDF copy, relative to the workspace.
    pub urdf: String,
    /// The file in the package, relative to its `robots/` directory.
    pub upstream: String,
    /// The `example-robot-data` version the file comes from.
    pub example_robot_data: String,
    /// Base link (`null`: the URDF's root).
    pub base: Option<String>,
    /// Tip link.
    pub tip: String,
    /// Locked joints and their values.
    pub lock: Vec<(String, f64)>,
    /// The chain's moving joints, the order of `q`.
    pub joints: Vec<String>,
    /// The command that regenerates the file.
    pub regenerate: String,
    /// Seed of the joint vectors.
    pub seed: u64,
    /// Software that produced the values.
    pub versions: Versions,
    /// [`REFERENCE`].
    pub reference: String,
    /// The joint vectors and placements.
    pub samples: Vec<FkSample>,
}

impl FkFixture {
    /// A fixture of `arm` from Pinocchio's placements at `qs`.
    pub fn new(
        arm: &Arm,
        erd_version: &str,
        versions: Versions,
        qs: &[Vec<f64>],
        poses: &[Placement],
    ) -> Result<FkFixture> {
        let Some(file) = arm.fixture_urdf() else {
            bail!("arm {} has no fixture of its own", arm.name);
        };
        if qs.len() != poses.len() {
            bail!("{} joint vectors, {} placements", qs.len(), poses.len());
        }
        Ok(FkFixture {
            format: FORMAT,
            arm: arm.name.into(),
            urdf: format!("fixtures/example-robot-data/{file}"),
            upstream: arm.urdf.into(),
            example_robot_data: erd_version.into(),
            base: arm.base.map(str::to_string),
            tip: arm.tip.into(),
            lock: arm.lock.iter().map(|&(n, v)| (n.to_string(), v)).collect(),
            joints: arm.joints.iter().map(|j| (*j).to_string()).collect(),
            regenerate: crate::fixture::REGEN_COMMAND.into(),
            seed: SEED,
            versions,
            reference: REFERENCE.into(),
            samples: qs
                .iter()
                .zip(poses)
                .map(|(q, p)| FkSample {
                    q: q.clone(),
                    position: p.position,
                    rotation: p.rotation,
                })
                .collect(),
        })
    }

    /// The stored placements.
    #[must_use]
    pub fn poses(&self) -> Vec<Placement> {
        self.samples
            .iter()
            .map(|s| Placement {
                rotation: s.rotation,
                position: s.position,
            })
            .collect()
    }

    /// The file's text: keys in declaration order, one sample per line,
    /// shortest round-trip decimals, trailing newline.
    #[must_use]
    pub fn to_json(&self) -> String {
        use crate::fixture::{json_lines as lines, json_value as j};
        let fields: [(&str, String); 14] = [
            ("format", j(&self.format)),
            ("arm", j(&self.arm)),
            ("urdf", j(&self.urdf)),
            ("upstream", j(&self.upstream)),
            ("example_robot_data", j(&self.example_robot_data)),
            ("base", j(&self.base)),
            ("tip", j(&self.tip)),
            ("lock", j(&self.lock)),
            ("joints", j(&self.joints)),
            ("regenerate", j(&self.regenerate)),
            ("seed", j(&self.seed)),
            ("versions", j(&self.versions)),
            ("reference", j(&self.reference)),
            ("samples", lines(&self.samples)),
        ];
        crate::fixture::json_object(&fields)
    }

    /// Reads a fixture file.
    pub fn read(path: &Path) -> Result<FkFixture> {
        crate::fixture::read_versioned(path, FORMAT, |f: &FkFixture| f.format)
    }
}

/// The live part (feature `live`): Pinocchio's placements from the installed
/// package's URDFs, and the fixtures' regeneration.
#[cfg(feature = "live")]
pub mod live {
    use super::*;
    use crate::bridge::Bridge;
    use crate::erd::{ARMS, Coverage, ERD_VERSION};

    /// The installed package's version and `robots/` directory; an error if
    /// the version is not [`ERD_VERSION`], which the table was read from.
    pub fn robots_dir(bridge: &Bridge) -> Result<PathBuf> {
        let (version, dir) = bridge.erd_location()?;
        if version != ERD_VERSION {
            bail!(
                "example-robot-data {version} is installed, the arms were read from {ERD_VERSION} \
                 (verify/requirements.txt)"
            );
        }
        Ok(dir)
    }

    /// Pinocchio's view of an arm's chain: the moving joints from the base
    /// to the tip, locked ones included, with their `nq` and limits.
    pub fn pinocchio_chain(
        bridge: &Bridge,
        arm: &Arm,
        path: &Path,
    ) -> Result<Vec<crate::bridge::PinJoint>> {
        bridge.urdf_chain(path, arm.base, arm.tip)
    }

    /// The sampling ranges of the arm's free joints (table order), from
    /// Pinocchio's model; an error unless Pinocchio's chain is the table's
    /// joints with the locked ones.
    pub fn sampling_ranges(bridge: &Bridge, arm: &Arm, path: &Path) -> Result<Vec<[f64; 2]>> {
        let chain = pinocchio_chain(bridge, arm, path)?;
        let free: Vec<&crate::bridge::PinJoint> = chain
            .iter()
            .filter(|j| !arm.lock.iter().any(|(n, _)| *n == j.name))
            .collect();
        let names: Vec<&str> = free.iter().map(|j| j.name.as_str()).collect();
        if names != arm.joints {
            bail!(
                "{}: Pinocchio's chain from {:?} to {} has the free joints {names:?}, the table {:?}",
                arm.name,
                arm.base,
                arm.tip,
                arm.joints
            );
        }
        if chain.len() != free.len() + arm.lock.len() {
            bail!("{}: a locked joint is not on Pinocchio's chain", arm.name);
        }
        free.iter()
            .map(|j| sampling_range(&j.name, j.nq, j.limits))
            .collect()
    }

    /// Pinocchio's placements of the tip in the base link's frame at `qs`
    /// (the arm's free joints), locked joints at their values.
    pub fn pinocchio_poses(
        bridge: &Bridge,
        arm: &Arm,
        path: &Path,
        qs: &[Vec<f64>],
    ) -> Result<Vec<Placement>> {
        let mut names: Vec<String> = arm.joints.iter().map(|j| (*j).to_string()).collect();
        names.extend(arm.lock.iter().map(|(n, _)| (*n).to_string()));
        let full: Vec<Vec<f64>> = qs
            .iter()
            .map(|q| {
                let mut v = q.clone();
                v.extend(arm.lock.iter().map(|&(_, x)| x));
                v
            })
            .collect();
        bridge.urdf_relative_poses(path, arm.base, arm.tip, &names, &full)
    }

    /// The joint vectors of an arm ([`N_SAMPLES`] from [`SEED`] in
    /// Pinocchio's ranges) and Pinocchio's placements at them.
    pub fn reference(
        bridge: &Bridge,
        arm: &Arm,
        path: &Path,
    ) -> Result<(Vec<Vec<f64>>, Vec<Placement>)> {
        let ranges = sampling_ranges(bridge, arm, path)?;
        let qs = joint_vectors(&ranges, N_SAMPLES, SEED);
        let poses = pinocchio_poses(bridge, arm, path, &qs)?;
        Ok((qs, poses))
    }

    /// An arm's fixture, from the installed package's file.
    pub fn make_fixture(bridge: &Bridge, arm: &Arm) -> Result<FkFixture> {
        let path = robots_dir(bridge)?.join(arm.urdf);
        let (qs, poses) = reference(bridge, arm, &path)?;
        FkFixture::new(arm, ERD_VERSION, bridge.versions().clone(), &qs, &poses)
    }

    /// Writes every arm's fixture into `dir/fk/` and copies the URDFs they
    /// read into `dir/`, unchanged; returns the paths written.
    pub fn regenerate(bridge: &Bridge, dir: &Path) -> Result<Vec<PathBuf>> {
        let robots = robots_dir(bridge)?;
        let fk = dir.join("fk");
        std::fs::create_dir_all(&fk)?;
        let mut written = Vec::new();
        for arm in ARMS.iter().filter(|a| a.coverage == Coverage::Fixture) {
            let f = make_fixture(bridge, arm)?;
            let path = fk.join(format!("{}.json", arm.name));
            std::fs::write(&path, f.to_json())?;
            written.push(path);
            let copy = dir.join(arm.fixture_urdf().expect("a fixture arm"));
            if !written.contains(&copy) {
                std::fs::copy(robots.join(arm.urdf), &copy)?;
                written.push(copy);
            }
        }
        Ok(written)
    }
}
