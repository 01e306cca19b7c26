//! The fixture files in `fixtures/`: reference positions and joint Jacobians
//! from Pinocchio (cross-checked against MuJoCo when written), read by the
//! root crate's `tests/fixtures.rs` without Python.
//!
//! One file per robot and parameter set, `fixtures/<robot>_<set>.json`,
//! written deterministically: fixed seed, fixed key order, one sample per
//! line, every number as the shortest decimal that parses back to the same
//! `f64`, no timestamps.

use crate::compare::{Deviation, Kinematics};
use activecal::model::{ParamSet, Robot};
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Version of the file layout.
pub const FORMAT: u32 = 1;
/// Seed of the fixtures' random configurations.
pub const SEED: u64 = 560_001;
/// Random configurations per fixture; with the 64 corners of a 6-joint robot
/// that makes 200 samples per file.
pub const N_RANDOM: usize = 136;
/// The one command that rewrites every fixture.
pub const REGEN_COMMAND: &str = "cargo run -p verify --features live -- regen";
/// What the `jacobian` of a sample holds.
pub const JACOBIAN_LAYOUT: &str = "d position / d q, 3 x dof, row-major (entry r*dof + j); \
     column j = Pinocchio computeFrameJacobian(LOCAL_WORLD_ALIGNED) top rows";

/// Versions of the software that produced a fixture.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Versions {
    /// CPython (`platform.python_version()`).
    pub python: String,
    /// numpy.
    pub numpy: String,
    /// Pinocchio (`pin` on PyPI).
    pub pinocchio: String,
    /// MuJoCo.
    pub mujoco: String,
}

/// One joint configuration and its reference values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Joint angles (radians).
    pub q: Vec<f64>,
    /// End-point position (metres) in the measurement frame.
    pub position: [f64; 3],
    /// Joint Jacobian, see [`JACOBIAN_LAYOUT`].
    pub jacobian: Vec<f64>,
}

/// A fixture file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fixture {
    /// File layout version ([`FORMAT`]).
    pub format: u32,
    /// Robot name (`Robot::builtin` accepts it).
    pub robot: String,
    /// `nominal` or `real`.
    pub param_set: String,
    /// The parameter table the values were computed with, one `[γ, α, a, d, β]`
    /// row per frame; a test compares it with the robot's to tell a stale
    /// fixture from a kinematics bug.
    pub params: Vec<[f64; 5]>,
    /// The command that regenerates the file.
    pub regenerate: String,
    /// Seed of the random configurations.
    pub seed: u64,
    /// Number of random configurations (the first samples).
    pub n_random: usize,
    /// Number of limit-box corners (the last samples).
    pub n_corners: usize,
    /// Software that produced the values.
    pub versions: Versions,
    /// Library whose values are stored (`pinocchio`).
    pub reference: String,
    /// Largest deviation of MuJoCo's values from the stored ones.
    pub mujoco_deviation: Deviation,
    /// Layout of [`Sample::jacobian`].
    pub jacobian_layout: String,
    /// The configurations and their values.
    pub samples: Vec<Sample>,
}

/// One value as compact JSON (numbers as the shortest decimal that parses
/// back to the same `f64`): the unit every fixture file is written in.
#[must_use]
pub fn json_value<T: Serialize + ?Sized>(v: &T) -> String {
    serde_json::to_string(v).expect("fixture values serialize")
}

/// A list as a fixture writes it under a top-level key: one item a line.
#[must_use]
pub fn json_lines<T: Serialize>(items: &[T]) -> String {
    let body: Vec<String> = items
        .iter()
        .map(|x| format!("    {}", json_value(x)))
        .collect();
    format!("[\n{}\n  ]", body.join(",\n"))
}

/// A fixture file's text: the rendered values under their keys, in the
/// given order, one key a line, trailing newline (deterministic output).
#[must_use]
pub fn json_object(fields: &[(&str, String)]) -> String {
    let mut s = String::from("{\n");
    let n = fields.len();
    for (i, (k, v)) in fields.iter().enumerate() {
        let sep = if i + 1 < n { "," } else { "" };
        writeln!(s, "  {}: {v}{sep}", json_value(*k)).unwrap();
    }
    s.push_str("}\n");
    s
}

/// Reads a JSON fixture whose layout version (`version` of the parsed
/// value) must be `format`; errors name the file.
pub fn read_versioned<T: serde::de::DeserializeOwned>(
    path: &Path,
    format: u32,
    version: impl Fn(&T) -> u32,
) -> Result<T> {
    use anyhow::Context;
    let text = std::fs::read_to_string(path).with_context(|| path.display().to_string())?;
    let f: T = serde_json::from_str(&text).with_context(|| path.display().to_string())?;
    if version(&f) != format {
        bail!(
            "{}: format {} (this build reads {format})",
            path.display(),
            version(&f)
        );
    }
    Ok(f)
}

/// `nominal` or `real`.
#[must_use]
pub fn set_name(set: ParamSet) -> &'static str {
    match set {
        ParamSet::Nominal => "nominal",
        ParamSet::Real => "real",
    }
}

/// File name of a robot's fixture for one parameter set.
#[must_use]
pub fn file_name(robot: &str, set: ParamSet) -> String {
    format!("{robot}_{}.json", set_name(set))
}

/// The workspace's `fixtures/` directory.
#[must_use]
pub fn default_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("fixtures")
}

impl Fixture {
    /// A fixture from Pinocchio's values at `qs` (the first `n_random`
    /// random, the rest corners) and MuJoCo's deviation from them.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        robot: &Robot,
        set: ParamSet,
        versions: Versions,
        qs: &[Vec<f64>],
        n_random: usize,
        pinocchio: &Kinematics,
        mujoco_deviation: Deviation,
    ) -> Result<Fixture> {
        if pinocchio.len() != qs.len() || n_random > qs.len() {
            bail!(
                "{} configurations, {} random, {} values",
                qs.len(),
                n_random,
                pinocchio.len()
            );
        }
        let samples = qs
            .iter()
            .zip(&pinocchio.position)
            .zip(&pinocchio.jacobian)
            .map(|((q, p), j)| Sample {
                q: q.clone(),
                position: *p,
                jacobian: j.clone(),
            })
            .collect();
        Ok(Fixture {
            format: FORMAT,
            robot: robot.name.clone(),
            param_set: set_name(set).into(),
            params: robot.params(set).rows.clone(),
            regenerate: REGEN_COMMAND.into(),
            seed: SEED,
            n_random,
            n_corners: qs.len() - n_random,
            versions,
            reference: "pinocchio".into(),
            mujoco_deviation,
            jacobian_layout: JACOBIAN_LAYOUT.into(),
            samples,
        })
    }

    /// The configurations of the samples.
    #[must_use]
    pub fn configurations(&self) -> Vec<Vec<f64>> {
        self.samples.iter().map(|s| s.q.clone()).collect()
    }

    /// The stored values as [`Kinematics`].
    #[must_use]
    pub fn kinematics(&self) -> Kinematics {
        Kinematics {
            position: self.samples.iter().map(|s| s.position).collect(),
            jacobian: self.samples.iter().map(|s| s.jacobian.clone()).collect(),
        }
    }

    /// The file's text: keys in declaration order, one parameter row and one
    /// sample per line, numbers as serde_json prints them (shortest
    /// round-trip decimal), trailing newline.
    #[must_use]
    pub fn to_json(&self) -> String {
        use json_value as j;
        let fields: [(&str, String); 13] = [
            ("format", j(&self.format)),
            ("robot", j(&self.robot)),
            ("param_set", j(&self.param_set)),
            ("params", json_lines(&self.params)),
            ("regenerate", j(&self.regenerate)),
            ("seed", j(&self.seed)),
            ("n_random", j(&self.n_random)),
            ("n_corners", j(&self.n_corners)),
            ("versions", j(&self.versions)),
            ("reference", j(&self.reference)),
            ("mujoco_deviation", j(&self.mujoco_deviation)),
            ("jacobian_layout", j(&self.jacobian_layout)),
            ("samples", json_lines(&self.samples)),
        ];
        json_object(&fields)
    }

    /// Parses a fixture file's text.
    pub fn from_json(text: &str) -> Result<Fixture> {
        let f: Fixture = serde_json::from_str(text)?;
        if f.format != FORMAT {
            bail!(
                "fixture format {} (this build reads {FORMAT}); run `{REGEN_COMMAND}`",
                f.format
            );
        }
        Ok(f)
    }

    /// Reads a fixture file.
    pub fn read(path: &Path) -> Result<Fixture> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        Fixture::from_json(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
    }
}
