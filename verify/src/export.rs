//! The calibrated robot written back (issue #26) against Pinocchio: the
//! exported URDF, loaded by Pinocchio, composed with the measurement frame
//! and tool of the frames file, predicts what activecal's calibrated model
//! predicts.
//!
//! Each [`Case`] is a chain of a URDF (FIGAROH's UR10 and TIAGo, the arms of
//! [`crate::erd`]) or a built-in robot. Its calibrated table is the robot's
//! `real` one (every unknown perturbed, as a calibration moves them). For a
//! URDF chain, [`activecal::frames::decompose`] splits it into the
//! measurement frame `M`, the joint origins and the tool `T`, and
//! [`activecal::io::urdf_edit::with_origins`] writes the user's URDF with
//! only the chain's origins changed; Pinocchio's `oMf(base)⁻¹ · oMf(tip)` of
//! that file, `P(q)`, gives `M · P(q) · T`, to compare with
//! [`activecal::kinematics::pose`] (marker `k`: `M · P(q) · m_k` with the
//! split's offset `m_k` in the tip link, against `p + R o_k`). A built-in
//! robot has no URDF of its own: [`activecal::io::urdf::to_urdf`] writes
//! its chain (root link `measurement`, tip link `tip`), and `P(q)` is
//! compared directly.
//!
//! The live check (`verify/tests/live_export.rs`) runs every case at
//! [`N_RANDOM`] configurations and at the measured ones of the data files;
//! the fixtures `fixtures/export/<case>.json` keep, for the cases whose
//! files are in the repository, the split and Pinocchio's `P(q)` at
//! [`N_FIXTURE`] configurations, which `tests/export_fixtures.rs` (no
//! Python) compares with activecal's predictions.

use crate::erd::{ARMS, Coverage};
use crate::erd_fk::{Placement, joint_vectors, workspace};
use crate::fixture::Versions;
use activecal::frames::{CalibratedFrames, decompose};
use activecal::io::load_robot;
use activecal::io::urdf::{self, UrdfOptions};
use activecal::io::urdf_edit::with_origins;
use activecal::kinematics::pose;
use activecal::model::source::rpy;
use activecal::model::{MeasurementKind, ParamTable, Robot};
use anyhow::{Context, Result, bail};
use nalgebra::{Isometry3, Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Version of the fixture layout.
pub const FORMAT: u32 = 1;
/// Seed of the random configurations (live check and fixtures alike).
pub const SEED: u64 = 26_000_026;
/// Random configurations per case in the live check (the 100).
pub const N_RANDOM: usize = 100;
/// Configurations per case in a fixture.
pub const N_FIXTURE: usize = 20;
/// Largest deviation accepted (metres for positions, and on rotation
/// entries): the 1e-9 m. The two sides compose about 25 rigid
/// transforms of at most ~3 m each, and the URDF stores the origins as
/// shortest round-trip decimals, so rounding stays near 1e-14 m; a joint
/// origin off by a microradian moves the tip by 1e-7 m or more (checked
/// by the live test), a real export mistake by millimetres.
pub const TOLERANCE: f64 = 1e-9;
/// Marker offsets (metres, in the model's end frame) of the marker cases: a
/// cluster 5–20 cm from the flange, as the TIAGo's mocap markers are.
pub const MARKERS: [[f64; 3]; 3] = [[0.05, -0.12, 0.15], [0.2, 0.0, 0.05], [-0.08, 0.1, 0.18]];
/// What a fixture's samples are.
pub const REFERENCE: &str = "Pinocchio buildModelFromUrdf + framesForwardKinematics of the \
     exported URDF: oMf(base)^-1 * oMf(tip), rotation row-major, position in metres; \
     activecal's prediction is measurement_frame * that * tool (marker k: * markers[k])";

/// The robot description of a case.
#[derive(Clone, Debug, PartialEq)]
pub enum Description {
    /// A URDF file: relative to the workspace, or absolute (the installed
    /// `example-robot-data`).
    Urdf(String),
    /// A built-in robot, by name.
    Builtin(&'static str),
}

/// What the sensor measures in a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sensor {
    /// One point per pose.
    Point,
    /// A full pose.
    Pose,
    /// The three points of [`MARKERS`].
    Markers,
}

impl Sensor {
    /// `point`, `pose` or `markers`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Sensor::Point => "point",
            Sensor::Pose => "pose",
            Sensor::Markers => "markers",
        }
    }

    /// The sensor named `s`.
    pub fn parse(s: &str) -> Result<Sensor> {
        Ok(match s {
            "point" => Sensor::Point,
            "pose" => Sensor::Pose,
            "markers" => Sensor::Markers,
            _ => bail!("unknown sensor {s}"),
        })
    }
}

/// One robot chain whose export is checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// A unique name (the fixture's file stem).
    pub name: String,
    /// The description.
    pub description: Description,
    /// Base link (`None`: the URDF's root).
    pub base: Option<String>,
    /// Tip link.
    pub tip: Option<String>,
    /// Locked joints and their values.
    pub lock: Vec<(String, f64)>,
    /// The sensor.
    pub sensor: Sensor,
    /// A CSV of measured poses (relative to the workspace) whose joint
    /// columns are checked too.
    pub measured: Option<&'static str>,
    /// Whether the case has a fixture (its file is in the repository).
    pub fixture: bool,
}

const TIAGO: &str = "fixtures/figaroh/tiago.urdf";
const TIAGO_CSV: &str = "fixtures/figaroh/tiago_mocap_4markers.csv";

fn urdf_case(name: &str, path: &str, base: Option<&str>, tip: &str, sensor: Sensor) -> Case {
    Case {
        name: name.into(),
        description: Description::Urdf(path.into()),
        base: base.map(str::to_string),
        tip: Some(tip.into()),
        lock: Vec::new(),
        sensor,
        measured: None,
        fixture: true,
    }
}

/// The cases: FIGAROH's UR10 (full pose) and TIAGo (full pose; torso
/// locked at 0.15 m; three markers), the built-ins in point and full pose,
/// and every arm of [`ARMS`] in full pose — from the repository's copy when
/// it has one, else (with `erd_dir`, the installed package's `robots/`)
/// from the installed file, without a fixture.
#[must_use]
pub fn cases(erd_dir: Option<&Path>) -> Vec<Case> {
    let mut v = vec![
        Case {
            measured: Some("fixtures/figaroh/ur10_full_pose.csv"),
            ..urdf_case(
                "figaroh_ur10",
                "fixtures/figaroh/ur10_robot.urdf",
                None,
                "wrist_3_link",
                Sensor::Pose,
            )
        },
        Case {
            measured: Some(TIAGO_CSV),
            ..urdf_case("figaroh_tiago", TIAGO, None, "arm_tool_link", Sensor::Pose)
        },
        Case {
            lock: vec![("torso_lift_joint".into(), 0.15)],
            measured: Some(TIAGO_CSV),
            ..urdf_case(
                "figaroh_tiago_torso_locked",
                TIAGO,
                None,
                "arm_tool_link",
                Sensor::Pose,
            )
        },
        Case {
            measured: Some(TIAGO_CSV),
            ..urdf_case(
                "figaroh_tiago_markers",
                TIAGO,
                None,
                "arm_tool_link",
                Sensor::Markers,
            )
        },
    ];
    for name in activecal::model::BUILTIN {
        for sensor in [Sensor::Point, Sensor::Pose] {
            v.push(Case {
                name: format!("builtin_{name}_{}", sensor.name()),
                description: Description::Builtin(name),
                base: None,
                tip: None,
                lock: Vec::new(),
                sensor,
                measured: None,
                fixture: true,
            });
        }
    }
    for arm in ARMS {
        let path = match (arm.fixture_urdf(), erd_dir) {
            (Some(file), _) => format!("fixtures/example-robot-data/{file}"),
            (None, Some(dir)) => dir.join(arm.urdf).display().to_string(),
            (None, None) => continue,
        };
        v.push(Case {
            lock: arm.lock.iter().map(|&(n, x)| (n.to_string(), x)).collect(),
            fixture: arm.coverage == Coverage::Fixture,
            ..urdf_case(
                &format!("erd_{}", arm.name),
                &path,
                arm.base,
                arm.tip,
                Sensor::Pose,
            )
        });
    }
    v
}

/// A case exported: the calibrated model, its split and the URDF text that
/// Pinocchio reads.
#[derive(Clone, Debug)]
pub struct Export {
    /// The imported robot.
    pub robot: Robot,
    /// The calibrated table (the robot's `real` one).
    pub table: ParamTable,
    /// The split (`None` for a built-in: identity frames).
    pub frames: Option<CalibratedFrames>,
    /// The exported URDF.
    pub text: String,
    /// Pinocchio's base and tip links.
    pub base: String,
    /// See `base`.
    pub tip: String,
    /// The chain's driven joints (the order of `q`), then the locked ones.
    pub names: Vec<String>,
    /// The locked joints' values (after the driven ones in `names`).
    pub locked: Vec<f64>,
}

impl Case {
    /// The description's path (URDF cases).
    #[must_use]
    pub fn path(&self) -> Option<PathBuf> {
        match &self.description {
            Description::Urdf(p) => Some(workspace().join(p)),
            Description::Builtin(_) => None,
        }
    }

    /// The description as a fixture names it: the workspace-relative path
    /// or `builtin:NAME`.
    #[must_use]
    pub fn description_name(&self) -> String {
        match &self.description {
            Description::Urdf(p) => p.clone(),
            Description::Builtin(n) => format!("builtin:{n}"),
        }
    }

    /// The robot as activecal imports it.
    pub fn import(&self) -> Result<Robot> {
        let measurement = match self.sensor {
            Sensor::Pose => MeasurementKind::Pose,
            Sensor::Point | Sensor::Markers => MeasurementKind::Point,
        };
        let robot = match &self.description {
            Description::Builtin(name) => {
                let suffix = if self.sensor == Sensor::Pose {
                    ":pose"
                } else {
                    ""
                };
                load_robot(&format!("{name}{suffix}"))?
            }
            Description::Urdf(p) => {
                let path = workspace().join(p);
                let text =
                    std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
                let opts = UrdfOptions {
                    base: self.base.clone(),
                    tip: self.tip.clone(),
                    lock: self.lock.clone(),
                    measurement,
                    ..UrdfOptions::default()
                };
                urdf::parse(&text, p, &opts).with_context(|| format!("importing {p}"))?
            }
        };
        Ok(match self.sensor {
            Sensor::Markers => robot.with_markers(&MARKERS)?,
            _ => robot,
        })
    }

    /// The case exported at the robot's `real` table, with the chain's
    /// origins changed by `tweak` (the identity for the export itself).
    pub fn export_with(&self, tweak: &dyn Fn(usize, &mut Isometry3<f64>)) -> Result<Export> {
        let robot = self.import()?;
        let table = robot.real.clone();
        let Some(src) = robot.source.as_deref() else {
            let text = urdf::to_urdf(&robot, &table)?;
            let names = (1..=robot.dof()).map(|k| format!("q{k}")).collect();
            return Ok(Export {
                robot,
                table,
                frames: None,
                text,
                base: "measurement".into(),
                tip: "tip".into(),
                names,
                locked: Vec::new(),
            });
        };
        let frames = decompose(&robot, &table)?;
        let origins: Vec<(String, Isometry3<f64>)> = frames
            .joints
            .iter()
            .enumerate()
            .map(|(k, j)| {
                let mut t = j.calibrated;
                tweak(k, &mut t);
                (j.name.clone(), t)
            })
            .collect();
        let text = with_origins(&src.text, &src.path, &origins)?;
        let mut names = src.driven_names();
        let mut locked = Vec::new();
        for j in &src.joints {
            if let Some(v) = j.locked {
                names.push(j.name.clone());
                locked.push(v);
            }
        }
        let (base, tip) = (src.base.clone(), src.tip.clone());
        Ok(Export {
            robot,
            table,
            frames: Some(frames),
            text,
            base,
            tip,
            names,
            locked,
        })
    }

    /// The case exported at the robot's `real` table.
    pub fn export(&self) -> Result<Export> {
        self.export_with(&|_, _| {})
    }

    /// The joint columns of the measured CSV for the chain's driven joints
    /// (named in `names`), one vector per row; empty without a CSV.
    pub fn measured_configurations(&self, names: &[String]) -> Result<Vec<Vec<f64>>> {
        let Some(csv) = self.measured else {
            return Ok(Vec::new());
        };
        let path = workspace().join(csv);
        let text = std::fs::read_to_string(&path).with_context(|| path.display().to_string())?;
        let mut lines = text.lines().filter(|l| !l.trim().is_empty());
        let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
        let cols: Vec<usize> = names
            .iter()
            .map(|n| {
                header
                    .iter()
                    .position(|h| h.trim() == n)
                    .with_context(|| format!("{csv}: no column {n}"))
            })
            .collect::<Result<_>>()?;
        lines
            .map(|l| {
                let cells: Vec<&str> = l.split(',').collect();
                cols.iter()
                    .map(|&c| {
                        cells[c]
                            .trim()
                            .parse::<f64>()
                            .with_context(|| format!("{csv}: {l}"))
                    })
                    .collect()
            })
            .collect()
    }
}

/// A rotation and position as a placement.
#[must_use]
pub fn placement(r: &Matrix3<f64>, p: &Vector3<f64>) -> Placement {
    Placement {
        rotation: std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)])),
        position: [p.x, p.y, p.z],
    }
}

/// Composes `M · P · T` (and `M · P · m_k` per marker) in full precision:
/// the rotation matrices are multiplied as given (no quaternion round
/// trip), so the composition adds only the products' rounding.
#[must_use]
pub fn compose(frames: Option<&CalibratedFrames>, p: &Placement) -> Vec<Placement> {
    let pr = Matrix3::from_fn(|i, j| p.rotation[i][j]);
    let pp = Vector3::from(p.position);
    let Some(f) = frames else {
        return vec![*p];
    };
    let (mr, mp) = (
        *f.measurement.rotation.to_rotation_matrix().matrix(),
        f.measurement.translation.vector,
    );
    let (tr, tp) = (
        *f.tool.rotation.to_rotation_matrix().matrix(),
        f.tool.translation.vector,
    );
    let r = mr * pr * tr;
    let at = |o: &Vector3<f64>| mr * (pr * o + pp) + mp;
    if f.markers.is_empty() {
        vec![placement(&r, &at(&tp))]
    } else {
        f.markers.iter().map(|m| placement(&r, &at(m))).collect()
    }
}

/// activecal's calibrated prediction at `q`: the end frame, or one
/// placement per marker (`p + R o_k`, rotation `R`).
#[must_use]
pub fn activecal_prediction(robot: &Robot, table: &ParamTable, q: &[f64]) -> Vec<Placement> {
    let (r, p) = pose(robot, table, q);
    if table.markers.is_empty() {
        vec![placement(&r, &p)]
    } else {
        table
            .markers
            .iter()
            .map(|o| placement(&r, &(r * Vector3::from(*o) + p)))
            .collect()
    }
}

/// The largest `|Δ|` over positions (metres) and rotation entries of two
/// lists of predictions; NaN if either holds one.
#[must_use]
pub fn deviation(a: &[Vec<Placement>], b: &[Vec<Placement>]) -> (f64, f64) {
    let (mut dp, mut dr) = (0.0f64, 0.0f64);
    let mut nan = a.len() != b.len();
    for (x, y) in a.iter().zip(b) {
        nan |= x.len() != y.len();
        for (p, q) in x.iter().zip(y) {
            for i in 0..3 {
                let e = (p.position[i] - q.position[i]).abs();
                nan |= e.is_nan();
                dp = dp.max(e);
                for j in 0..3 {
                    let e = (p.rotation[i][j] - q.rotation[i][j]).abs();
                    nan |= e.is_nan();
                    dr = dr.max(e);
                }
            }
        }
    }
    if nan { (f64::NAN, f64::NAN) } else { (dp, dr) }
}

/// A frame as a frames file writes it: xyz (metres), rpy (radians, as URDF).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct XyzRpy {
    /// Whose frame (a joint's name, `measurement_frame`, `tool`).
    pub name: String,
    /// Translation.
    pub xyz: [f64; 3],
    /// Rotation, `R = Rz(yaw) Ry(pitch) Rx(roll)`.
    pub rpy: [f64; 3],
}

impl XyzRpy {
    /// `t` named `name`.
    #[must_use]
    pub fn of(name: &str, t: &Isometry3<f64>) -> XyzRpy {
        let v = t.translation.vector;
        XyzRpy {
            name: name.into(),
            xyz: [v.x, v.y, v.z],
            rpy: rpy(&t.rotation.to_rotation_matrix()),
        }
    }
}

/// One configuration and Pinocchio's `oMf(base)⁻¹ · oMf(tip)` of the
/// exported URDF.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExportSample {
    /// The chain's driven joints (radians, metres), locked ones excluded.
    pub q: Vec<f64>,
    /// Position (metres).
    pub position: [f64; 3],
    /// Rotation, row-major.
    pub rotation: [[f64; 3]; 3],
}

/// A `fixtures/export/<case>.json` file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExportFixture {
    /// [`FORMAT`].
    pub format: u32,
    /// The case's name.
    pub case: String,
    /// The URDF (workspace-relative) or `builtin:NAME`.
    pub description: String,
    /// Base link (`null`: the URDF's root).
    pub base: Option<String>,
    /// Tip link.
    pub tip: Option<String>,
    /// Locked joints.
    pub lock: Vec<(String, f64)>,
    /// `point`, `pose` or `markers` ([`MARKERS`]).
    pub sensor: String,
    /// Pinocchio's base and tip links in the exported URDF.
    pub links: [String; 2],
    /// The order of `q`.
    pub joints: Vec<String>,
    /// The command that regenerates the file.
    pub regenerate: String,
    /// Seed of the configurations.
    pub seed: u64,
    /// Software that produced the values.
    pub versions: Versions,
    /// [`REFERENCE`].
    pub reference: String,
    /// The split as the frames file holds it: the measurement frame, the
    /// tool (identity for a built-in), the markers in the tip link, and the
    /// calibrated origin of every chain joint the exported URDF holds.
    pub measurement_frame: XyzRpy,
    /// See `measurement_frame`.
    pub tool: XyzRpy,
    /// See `measurement_frame`.
    pub markers: Vec<[f64; 3]>,
    /// See `measurement_frame`.
    pub origins: Vec<XyzRpy>,
    /// The configurations and Pinocchio's placements.
    pub samples: Vec<ExportSample>,
}

impl ExportFixture {
    /// A fixture of `case` from Pinocchio's placements `poses` of the
    /// export `e` at `qs`.
    pub fn new(
        case: &Case,
        e: &Export,
        versions: Versions,
        qs: &[Vec<f64>],
        poses: &[Placement],
    ) -> Result<ExportFixture> {
        if qs.len() != poses.len() {
            bail!("{} configurations, {} placements", qs.len(), poses.len());
        }
        let id = Isometry3::identity();
        let f = e.frames.as_ref();
        Ok(ExportFixture {
            format: FORMAT,
            case: case.name.clone(),
            description: case.description_name(),
            base: case.base.clone(),
            tip: case.tip.clone(),
            lock: case.lock.clone(),
            sensor: case.sensor.name().into(),
            links: [e.base.clone(), e.tip.clone()],
            joints: e.names[..qs.first().map_or(0, Vec::len)].to_vec(),
            regenerate: crate::fixture::REGEN_COMMAND.into(),
            seed: SEED,
            versions,
            reference: REFERENCE.into(),
            measurement_frame: XyzRpy::of("measurement_frame", f.map_or(&id, |f| &f.measurement)),
            tool: XyzRpy::of("tool", f.map_or(&id, |f| &f.tool)),
            markers: f.map_or(Vec::new(), |f| {
                f.markers.iter().map(|m| [m.x, m.y, m.z]).collect()
            }),
            origins: f.map_or(Vec::new(), |f| {
                f.joints
                    .iter()
                    .map(|j| XyzRpy::of(&j.name, &j.calibrated))
                    .collect()
            }),
            samples: qs
                .iter()
                .zip(poses)
                .map(|(q, p)| ExportSample {
                    q: q.clone(),
                    position: p.position,
                    rotation: p.rotation,
                })
                .collect(),
        })
    }

    /// The file's text: keys in declaration order, one sample per line,
    /// shortest round-trip decimals, trailing newline.
    #[must_use]
    pub fn to_json(&self) -> String {
        use crate::fixture::{json_lines as lines, json_value as j};
        let fields: [(&str, String); 18] = [
            ("format", j(&self.format)),
            ("case", j(&self.case)),
            ("description", j(&self.description)),
            ("base", j(&self.base)),
            ("tip", j(&self.tip)),
            ("lock", j(&self.lock)),
            ("sensor", j(&self.sensor)),
            ("links", j(&self.links)),
            ("joints", j(&self.joints)),
            ("regenerate", j(&self.regenerate)),
            ("seed", j(&self.seed)),
            ("versions", j(&self.versions)),
            ("reference", j(&self.reference)),
            ("measurement_frame", j(&self.measurement_frame)),
            ("tool", j(&self.tool)),
            ("markers", j(&self.markers)),
            ("origins", lines(&self.origins)),
            ("samples", lines(&self.samples)),
        ];
        crate::fixture::json_object(&fields)
    }

    /// Reads a fixture file.
    pub fn read(path: &Path) -> Result<ExportFixture> {
        crate::fixture::read_versioned(path, FORMAT, |f: &ExportFixture| f.format)
    }
}

/// `fixtures/export/`.
#[must_use]
pub fn default_dir() -> PathBuf {
    workspace().join("fixtures").join("export")
}

/// The random configurations of a robot: `n` from [`SEED`], uniform in its
/// joint limits (locked joints are not in them).
#[must_use]
pub fn random_configurations(robot: &Robot, n: usize) -> Vec<Vec<f64>> {
    joint_vectors(&robot.limits, n, SEED)
}

/// The live part (feature `live`): Pinocchio's placements of an export and
/// the fixtures' regeneration.
#[cfg(feature = "live")]
pub mod live {
    use super::*;
    use crate::bridge::Bridge;

    /// Writes the export's URDF to a file of its own (Pinocchio's models are
    /// cached by path: a new name per text) and returns Pinocchio's
    /// `oMf(base)⁻¹ · oMf(tip)` at `qs` (driven joints; locked ones at their
    /// values, other joints neutral).
    pub fn pinocchio_poses(
        bridge: &Bridge,
        e: &Export,
        file: &str,
        qs: &[Vec<f64>],
    ) -> Result<Vec<Placement>> {
        let dir = std::env::temp_dir().join(format!("activecal-export-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let path = dir.join(format!("{file}.urdf"));
        if path.exists() {
            bail!(
                "{}: already written (Pinocchio caches models by path)",
                path.display()
            );
        }
        std::fs::write(&path, &e.text)?;
        let full: Vec<Vec<f64>> = qs
            .iter()
            .map(|q| q.iter().chain(&e.locked).copied().collect())
            .collect();
        bridge.urdf_relative_poses(&path, Some(&e.base), &e.tip, &e.names, &full)
    }

    /// A case's fixture: its export and Pinocchio's placements at
    /// [`N_FIXTURE`] random configurations.
    pub fn make_fixture(bridge: &Bridge, case: &Case, file: &str) -> Result<ExportFixture> {
        let e = case.export()?;
        let qs = random_configurations(&e.robot, N_FIXTURE);
        let poses = pinocchio_poses(bridge, &e, file, &qs)?;
        ExportFixture::new(case, &e, bridge.versions().clone(), &qs, &poses)
    }

    /// Writes the fixture of every case that has one into `dir`; returns
    /// the paths written.
    pub fn regenerate(bridge: &Bridge, dir: &Path) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir)?;
        let mut written = Vec::new();
        for case in cases(None).iter().filter(|c| c.fixture) {
            let f = make_fixture(bridge, case, &format!("regen-{}", case.name))?;
            let path = dir.join(format!("{}.json", case.name));
            std::fs::write(&path, f.to_json())?;
            written.push(path);
        }
        Ok(written)
    }
}
