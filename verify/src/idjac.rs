//! Identification Jacobians from outside: central differences of Pinocchio's
//! end frame over every DH/Hayati unknown, against activecal's analytic
//! identification Jacobian (`activecal::blocks::jacobian_of`), and the
//! fixtures `fixtures/idjac/<robot>.json` that let plain `cargo test` gate
//! every column without Python (`tests/identification_jacobian_fixtures.rs`).
//!
//! For an unknown `θ` the parameter table is perturbed to `θ ± h`, the
//! Pinocchio model is rebuilt from each perturbed table by
//! [`crate::model::pinocchio_model_spec`] (independent of activecal's
//! kinematics), and at each configuration
//!
//! * position rows: `(p(θ+h) − p(θ−h)) / 2h`,
//! * orientation rows (full-pose robots): `log3(R(θ+h) R(θ−h)ᵀ) / 2h`
//!   (`pin.log3`), an angular velocity in the measurement frame, times the
//!   robot's `orientation_scale`,
//!
//! which is activecal's column layout: `t` rows per pose (3 position rows,
//! then 3 orientation rows for a pose robot), one column per unknown in
//! `robot.unknowns` order.
//!
//! # Step and tolerance
//!
//! Every DH/Hayati parameter enters the chain as one elementary motion
//! (`Rz(γ)`, `Tz(d)`, `Tx(a)`, `Rx(α)`, `Ry(β)`) between fixed transforms, so
//! changing it by `s` moves everything downstream by a fixed screw: a
//! translation along a fixed unit vector (`a`, `d`) or a rotation about a fixed
//! line (`γ`, `α`, `β`). Hence
//!
//! * for `a`, `d`: `p` is affine in `s` and `R` constant, so central
//!   differences have no truncation error;
//! * for `γ`, `α`, `β`: `p(s) = c + exp(s·û)(p − c)`, whose third derivative
//!   has norm `r = dist(p, axis) ≤ L` (the reach, see below), so the position
//!   truncation error is at most `h²/6 · r`; and `R(θ+h) R(θ−h)ᵀ =
//!   exp(2h·û)` exactly, so `log3 / 2h = u` with no truncation error.
//!
//! Rounding: Pinocchio composes ≲ 12 rigid transforms, each coordinate of `p`
//! carrying an error of at most ~30 ε |L| (ε = 1.1e-16), so the difference of
//! two evaluations is off by ≤ 60 ε L and the quotient by ≤ 60 ε L / 2h =
//! 30 ε L / h. The entries of `R` (size ≤ 1) likewise give log3 rows off by
//! ≤ 30 ε / h per radian, times the orientation scale `w`. With
//! h = [`STEP`] = 1e-5 (rad or m; near the optimum `(3 ε)^{1/3} ≈ 7e-6` for
//! central differences):
//!
//! `|error| ≤ (h²/6 + 30 ε / h) · L ≈ (1.7e-11 + 3.3e-10) · L ≈ 3.5e-10 · L`,
//!
//! with `L = max(1 m, max |p|, max |J_fd|)` over the samples — `max |p|`
//! bounds the rounding of positions, and `max |J_fd|` covers the distance
//! `r` of every rotation column and the scale `w` of the orientation rows.
//! For the PUMA (tracker 20 m away) `L ≈ 21 m` and the bound is ≈ 7e-9.
//! The tolerance is [`REL_TOL`] · L = 1e-8 · L, about 30× the bound.
//! Observed deviations are ~1e-10 · L. Any real mistake in a column — a
//! wrong axis, a sign, a missing orientation scale, a column in the wrong
//! place, a lever arm off by 1 mm — is ≥ 1e-3 · L, five orders larger.

use crate::fixture::Versions;
use activecal::blocks::{Blocks, jacobian_of};
use activecal::io::urdf::{UrdfOptions, load};
use activecal::model::{MeasurementKind, ParamTable, Robot};
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Finite-difference step (radians for angles, metres for lengths); see the
/// module docs.
pub const STEP: f64 = 1e-5;
/// Relative tolerance: deviations must stay below `REL_TOL · L` with `L` the
/// size of the values (see the module docs for the derivation).
pub const REL_TOL: f64 = 1e-8;
/// Version of the `fixtures/idjac/` layout.
pub const FORMAT: u32 = 1;
/// Seed of the fixtures' configurations.
pub const SEED: u64 = 170_003;
/// Configurations per fixture.
pub const N_SAMPLES: usize = 20;
/// Orientation scale (m/rad) given to the URDF arms' full-pose variants: not
/// 1, so that a missing or misplaced scale shows.
pub const URDF_ORIENTATION_SCALE: f64 = 0.29;
/// What the `jacobian` of a sample holds.
pub const LAYOUT: &str = "identification Jacobian, t x p row-major (entry r*p + c): rows 0-2 \
     (p(θ+h) - p(θ-h))/2h, rows 3-5 (pose) orientation_scale * pin.log3(R(θ+h) R(θ-h)^T)/2h, \
     columns in the order of `unknowns`, from Pinocchio models rebuilt from the perturbed table";

/// Where a robot comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Source {
    /// A built-in robot by name (`Robot::builtin`), e.g. `ur5:pose`.
    Builtin {
        /// The name.
        name: String,
    },
    /// A URDF import (`activecal::io::urdf::load`).
    Urdf {
        /// Path relative to the workspace root.
        path: String,
        /// The tip link.
        tip: String,
        /// `point` or `pose`.
        measurement: MeasurementKind,
        /// The orientation scale set on the imported robot.
        orientation_scale: f64,
    },
}

impl Source {
    /// Builds the robot.
    pub fn robot(&self) -> Result<Robot> {
        match self {
            Source::Builtin { name } => Ok(Robot::builtin(name)?),
            Source::Urdf {
                path,
                tip,
                measurement,
                orientation_scale,
            } => {
                let opts = UrdfOptions {
                    tip: Some(tip.clone()),
                    measurement: *measurement,
                    ..UrdfOptions::default()
                };
                let full = workspace().join(path);
                let mut robot =
                    load(&full, &opts).with_context(|| format!("importing {}", full.display()))?;
                robot.orientation_scale = *orientation_scale;
                Ok(robot)
            }
        }
    }

    /// The fixture's file stem: `puma560`, `puma560_pose`, `panda_pose`, …
    #[must_use]
    pub fn file_stem(&self) -> String {
        match self {
            Source::Builtin { name } => name.replace(':', "_"),
            Source::Urdf {
                path, measurement, ..
            } => {
                let stem = Path::new(path)
                    .file_stem()
                    .map_or_else(|| "urdf".into(), |s| s.to_string_lossy().into_owned());
                match measurement {
                    MeasurementKind::Point => stem,
                    MeasurementKind::Pose => format!("{stem}_pose"),
                    MeasurementKind::Markers(k) => format!("{stem}_markers{k}"),
                    MeasurementKind::Registered(key) => format!("{stem}_{}", key.name),
                }
            }
        }
    }
}

/// The workspace root (the parent of `verify/`).
#[must_use]
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `fixtures/idjac/`.
#[must_use]
pub fn default_dir() -> PathBuf {
    workspace().join("fixtures").join("idjac")
}

/// The robots checked: the built-ins in point and pose form, and two
/// `example-robot-data` arms (Panda, Kinova Jaco; copied into
/// `fixtures/example-robot-data/`) in point and pose form.
#[must_use]
pub fn sources() -> Vec<Source> {
    let mut out = Vec::new();
    for name in activecal::model::BUILTIN {
        out.push(Source::Builtin {
            name: (*name).into(),
        });
        out.push(Source::Builtin {
            name: format!("{name}:pose"),
        });
    }
    for (file, tip) in [
        ("panda.urdf", "panda_hand_tcp"),
        ("kinova.urdf", "j2s6s200_end_effector"),
    ] {
        for m in [MeasurementKind::Point, MeasurementKind::Pose] {
            out.push(Source::Urdf {
                path: format!("fixtures/example-robot-data/{file}"),
                tip: tip.into(),
                measurement: m,
                orientation_scale: if m == MeasurementKind::Pose {
                    URDF_ORIENTATION_SCALE
                } else {
                    activecal::model::DEFAULT_ORIENTATION_SCALE
                },
            });
        }
    }
    out
}

/// Identification Jacobians at a list of configurations: per configuration,
/// `t × p` row-major, plus the end point.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IdJacobians {
    /// Rows per pose.
    pub t: usize,
    /// Columns (unknowns).
    pub p: usize,
    /// End point per configuration (metres).
    pub position: Vec<[f64; 3]>,
    /// `t·p` entries per configuration, row-major.
    pub jacobian: Vec<Vec<f64>>,
}

/// activecal's analytic identification Jacobian
/// (`activecal::blocks::jacobian_of`) at `qs`, as row-major blocks
/// (positions left empty).
#[must_use]
pub fn activecal_jacobians(robot: &Robot, table: &ParamTable, qs: &[Vec<f64>]) -> IdJacobians {
    let x: Blocks = jacobian_of(robot, table, qs.len(), |k, q| q.copy_from_slice(&qs[k]));
    let (t, p) = (x.t(), x.p());
    IdJacobians {
        t,
        p,
        position: Vec::new(),
        jacobian: (0..qs.len())
            .map(|k| {
                let b = x.block(k);
                (0..t * p).map(|e| b[(e / p, e % p)]).collect()
            })
            .collect(),
    }
}

/// The parameter tables at `θ ± h` for every unknown, in column order.
#[must_use]
pub fn perturbed_tables(
    robot: &Robot,
    table: &ParamTable,
    h: f64,
) -> Vec<(ParamTable, ParamTable)> {
    robot
        .unknowns
        .iter()
        .map(|&id| {
            let (mut plus, mut minus) = (table.clone(), table.clone());
            plus.set(id, table.get(id) + h);
            minus.set(id, table.get(id) - h);
            (plus, minus)
        })
        .collect()
}

/// The size `L = max(1, max |p|, max |J|)` of a set of values, the scale of
/// the tolerance (see the module docs).
#[must_use]
pub fn size(reference: &IdJacobians) -> f64 {
    let p = reference
        .position
        .iter()
        .map(|p| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt())
        .fold(0.0, f64::max);
    let j = reference
        .jacobian
        .iter()
        .flatten()
        .map(|v| v.abs())
        .fold(0.0, f64::max);
    1.0f64.max(p).max(j)
}

/// Largest deviation between a reference (finite differences) and activecal.
#[derive(Clone, Debug, Default, Serialize)]
pub struct IdDeviation {
    /// Robot (`Robot::name`) and measurement (`point`, `pose`).
    pub robot: String,
    /// Configurations compared.
    pub configurations: usize,
    /// Rows per pose × unknowns.
    pub shape: [usize; 2],
    /// `L` of the reference values.
    pub size: f64,
    /// `max |ΔJ|` (m or m/rad).
    pub absolute: f64,
    /// `absolute / L`.
    pub relative: f64,
    /// `max |ΔJ|` over the orientation rows alone (0 for point robots).
    pub orientation: f64,
    /// Where the worst entry is: `(configuration, row, unknown name)`.
    pub worst: (usize, usize, String),
}

impl IdDeviation {
    /// Whether `relative ≤ tol` (NaN never is).
    #[must_use]
    pub fn within(&self, tol: f64) -> bool {
        self.relative <= tol
    }
}

/// Compares `ours` with `reference` entry by entry; NaN gives a NaN deviation.
pub fn id_deviation(
    robot: &Robot,
    reference: &IdJacobians,
    ours: &IdJacobians,
) -> Result<IdDeviation> {
    if (reference.t, reference.p) != (ours.t, ours.p)
        || reference.jacobian.len() != ours.jacobian.len()
    {
        bail!(
            "{} configurations of {}×{} vs {} of {}×{}",
            reference.jacobian.len(),
            reference.t,
            reference.p,
            ours.jacobian.len(),
            ours.t,
            ours.p
        );
    }
    let l = size(reference);
    let mut dev = IdDeviation {
        robot: format!("{} ({})", robot.name, robot.measurement.name()),
        configurations: ours.jacobian.len(),
        shape: [ours.t, ours.p],
        size: l,
        ..IdDeviation::default()
    };
    for (k, (a, b)) in reference.jacobian.iter().zip(&ours.jacobian).enumerate() {
        if a.len() != b.len() || a.len() != ours.t * ours.p {
            bail!("configuration {k}: {} vs {} entries", a.len(), b.len());
        }
        for (e, (x, y)) in a.iter().zip(b).enumerate() {
            let d = (x - y).abs();
            if e / ours.p >= 3 {
                dev.orientation = dev.orientation.max(d);
            }
            if d.is_nan() || d > dev.absolute {
                dev.absolute = if d.is_nan() { f64::NAN } else { d };
                dev.worst = (k, e / ours.p, robot.param_name(robot.unknowns[e % ours.p]));
                if d.is_nan() {
                    dev.relative = f64::NAN;
                    return Ok(dev);
                }
            }
        }
    }
    dev.relative = dev.absolute / l;
    Ok(dev)
}

/// One configuration of a fixture.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IdSample {
    /// Joint values.
    pub q: Vec<f64>,
    /// End point from Pinocchio at the fixture's table (metres).
    pub position: [f64; 3],
    /// See [`LAYOUT`].
    pub jacobian: Vec<f64>,
}

/// A `fixtures/idjac/<robot>.json` file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IdFixture {
    /// [`FORMAT`].
    pub format: u32,
    /// `Robot::name` of the robot built from `source`.
    pub robot: String,
    /// How to build the robot.
    pub source: Source,
    /// Rows per pose (3 point, 6 pose).
    pub rows: usize,
    /// The robot's orientation scale (m/rad).
    pub orientation_scale: f64,
    /// Unknown names (`Robot::param_name`), the column order.
    pub unknowns: Vec<String>,
    /// The table the derivatives are taken at (the nominal one).
    pub params: Vec<[f64; 5]>,
    /// Finite-difference step.
    pub step: f64,
    /// Relative tolerance ([`REL_TOL`]).
    pub rel_tol: f64,
    /// The command that regenerates the file.
    pub regenerate: String,
    /// Seed of the configurations.
    pub seed: u64,
    /// Software that produced the values.
    pub versions: Versions,
    /// [`LAYOUT`].
    pub layout: String,
    /// The configurations and their values.
    pub samples: Vec<IdSample>,
}

impl IdFixture {
    /// A fixture from Pinocchio's values.
    pub fn new(
        source: &Source,
        robot: &Robot,
        versions: Versions,
        qs: &[Vec<f64>],
        fd: &IdJacobians,
    ) -> Result<IdFixture> {
        if fd.jacobian.len() != qs.len() || fd.position.len() != qs.len() {
            bail!("{} configurations, {} values", qs.len(), fd.jacobian.len());
        }
        Ok(IdFixture {
            format: FORMAT,
            robot: robot.name.clone(),
            source: source.clone(),
            rows: fd.t,
            orientation_scale: robot.orientation_scale,
            unknowns: robot.parameter_names(),
            params: robot.nominal.rows.clone(),
            step: STEP,
            rel_tol: REL_TOL,
            regenerate: crate::fixture::REGEN_COMMAND.into(),
            seed: SEED,
            versions,
            layout: LAYOUT.into(),
            samples: qs
                .iter()
                .zip(&fd.position)
                .zip(&fd.jacobian)
                .map(|((q, p), j)| IdSample {
                    q: q.clone(),
                    position: *p,
                    jacobian: j.clone(),
                })
                .collect(),
        })
    }

    /// The stored values.
    #[must_use]
    pub fn jacobians(&self) -> IdJacobians {
        IdJacobians {
            t: self.rows,
            p: self.unknowns.len(),
            position: self.samples.iter().map(|s| s.position).collect(),
            jacobian: self.samples.iter().map(|s| s.jacobian.clone()).collect(),
        }
    }

    /// The configurations.
    #[must_use]
    pub fn configurations(&self) -> Vec<Vec<f64>> {
        self.samples.iter().map(|s| s.q.clone()).collect()
    }

    /// The file's text: keys in declaration order, one sample per line,
    /// shortest round-trip decimals, trailing newline.
    #[must_use]
    pub fn to_json(&self) -> String {
        use crate::fixture::{json_lines as lines, json_value as j};
        let fields: [(&str, String); 14] = [
            ("format", j(&self.format)),
            ("robot", j(&self.robot)),
            ("source", j(&self.source)),
            ("rows", j(&self.rows)),
            ("orientation_scale", j(&self.orientation_scale)),
            ("unknowns", j(&self.unknowns)),
            ("params", lines(&self.params)),
            ("step", j(&self.step)),
            ("rel_tol", j(&self.rel_tol)),
            ("regenerate", j(&self.regenerate)),
            ("seed", j(&self.seed)),
            ("versions", j(&self.versions)),
            ("layout", j(&self.layout)),
            ("samples", lines(&self.samples)),
        ];
        crate::fixture::json_object(&fields)
    }

    /// Reads a fixture file.
    pub fn read(path: &Path) -> Result<IdFixture> {
        crate::fixture::read_versioned(path, FORMAT, |f: &IdFixture| f.format)
    }
}

/// The live part (feature `live`): Pinocchio's central differences.
#[cfg(feature = "live")]
pub mod live {
    use super::*;
    use crate::bridge::Bridge;
    use crate::model::pinocchio_model_spec;
    use crate::sample::random_configurations;

    /// Pinocchio's finite-difference identification Jacobian of `robot` at
    /// `table` and `qs` (step `h`), with the end point at `table`.
    pub fn pinocchio_jacobians(
        bridge: &Bridge,
        robot: &Robot,
        table: &ParamTable,
        qs: &[Vec<f64>],
        h: f64,
    ) -> Result<IdJacobians> {
        let (mut plus, mut minus) = (Vec::new(), Vec::new());
        for (tp, tm) in perturbed_tables(robot, table, h) {
            plus.push(pinocchio_model_spec(robot, &tp)?);
            minus.push(pinocchio_model_spec(robot, &tm)?);
        }
        let cd = bridge.pinocchio_central_differences(&plus, &minus, qs, h)?;
        let position = bridge
            .pinocchio(&pinocchio_model_spec(robot, table)?, qs)?
            .position;
        let t = robot.rows_per_pose();
        let p = robot.n_unknowns();
        let w = robot.orientation_scale;
        let jacobian = cd
            .iter()
            .map(|cols| {
                (0..t * p)
                    .map(|e| {
                        let (r, c) = (e / p, e % p);
                        if r < 3 { cols[c][r] } else { w * cols[c][r] }
                    })
                    .collect()
            })
            .collect();
        Ok(IdJacobians {
            t,
            p,
            position,
            jacobian,
        })
    }

    /// Pinocchio's finite differences vs activecal at `n` random
    /// configurations (seed `seed`), at the nominal table.
    pub fn check(bridge: &Bridge, robot: &Robot, n: usize, seed: u64) -> Result<IdDeviation> {
        let qs = random_configurations(robot, n, seed);
        let fd = pinocchio_jacobians(bridge, robot, &robot.nominal, &qs, STEP)?;
        let ours = activecal_jacobians(robot, &robot.nominal, &qs);
        id_deviation(robot, &fd, &ours)
    }

    /// The fixture of one source: Pinocchio's values at [`N_SAMPLES`]
    /// configurations. Independent of activecal's kinematics and Jacobians.
    pub fn make_fixture(bridge: &Bridge, source: &Source) -> Result<IdFixture> {
        let robot = source.robot()?;
        let qs = random_configurations(&robot, N_SAMPLES, SEED);
        let fd = pinocchio_jacobians(bridge, &robot, &robot.nominal, &qs, STEP)?;
        IdFixture::new(source, &robot, bridge.versions().clone(), &qs, &fd)
    }

    /// Writes every source's fixture into `dir` and returns the paths.
    pub fn regenerate(bridge: &Bridge, dir: &Path) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir)?;
        let mut written = Vec::new();
        for source in sources() {
            let f = make_fixture(bridge, &source)?;
            let path = dir.join(format!("{}.json", source.file_stem()));
            std::fs::write(&path, f.to_json())?;
            written.push(path);
        }
        Ok(written)
    }
}
