//! Design files: the poses chosen for a calibration, as JSON that `select`
//! writes and `score`, `gap` and `calibrate` read.
//!
//! A design names the pool it was chosen from (`pool`, a [`PoolSpec`]) and
//! carries each pose's id in that pool (`poses`) and its joint values (`q`,
//! radians or metres), so it survives a change of pool: `score` and
//! `calibrate` use the stored joint values, and poses need not lie on any
//! lattice.
//!
//! Old files, `{"robot", "levels", "poses": [lattice indices]}`, still load:
//! their pool is the unfiltered `levels`-value lattice and their joint values
//! are the lattice's. Other keys written by `select` (algorithm, seed,
//! criterion values) are kept as extra information.

use crate::error::{Error, Result};
use crate::io::{ChainChoice, RobotRef};
use crate::model::ParamTable;
use crate::model::Robot;
use crate::pool::{Configurations, Lattice, Pool, PoolSource, PoolSpec};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Joint values of a stored pose and of a pool pose agree to this, absolute
/// (a JSON round trip of an `f64` is exact; this only absorbs hand edits
/// written with fewer digits).
const Q_TOL: f64 = 1e-9;

/// A design as stored on disk.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DesignFile {
    /// Robot name (built-in) or path of its description, with `:pose`
    /// for full poses (files of old also carry the chain here, as a `#…`
    /// fragment: see [`DesignFile::robot_ref`]).
    pub robot: String,
    /// The chain of a URDF tree the design is for (base, tip, locks,
    /// frames file); absent for a built-in robot or a description file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chain: Option<ChainChoice>,
    /// The pool the poses were chosen from (absent in old files: the
    /// unfiltered lattice of `levels`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pool: Option<PoolSpec>,
    /// Lattice values per joint, when the pool is a lattice (kept for old
    /// readers).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub levels: Option<usize>,
    /// The chain's joint names, in the order of the joint values (absent
    /// in files written before they were stored).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint_names: Option<Vec<String>>,
    /// Id of each pose in its pool (the lattice index for lattice poses).
    pub poses: Vec<usize>,
    /// Joint values of each pose (absent in old files: the lattice's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub q: Option<Vec<Vec<f64>>>,
    /// Every configuration of a file-sourced pool, before filtering, in id
    /// order: with it the design's pool is rebuilt without the original
    /// file (lattice and sampled pools are regenerated from their spec).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pool_qs: Option<Vec<Vec<f64>>>,
    /// Poses measured before the design was chosen (`select --existing`):
    /// their file and joint values, so that `gap` scores the design on top
    /// of the same prior information without the file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub existing: Option<ExistingPoses>,
    /// Whether the poses were refined off the pool (`select --refine`):
    /// their ids name the pool poses they started from, their joint values
    /// are the refined ones.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub refined: bool,
    /// The joints whose compliance the design was chosen to identify
    /// (`select --compliance`): `gap` and `score` give them their columns.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub compliance: Vec<String>,
    /// Via configurations of the visiting order: a move that collides
    /// straight goes through one (`select` with collision filters); the
    /// robot is not measured there.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub via: Vec<ViaPoint>,
    /// Anything else (algorithm, seed, ln_oid, ...), kept as written.
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

/// One named joint configuration as read back.
#[derive(Deserialize)]
struct NamedIn {
    #[allow(dead_code)]
    name: Option<String>,
    /// Absent on a via configuration.
    id: Option<usize>,
    /// A via configuration of the tour, not a pose.
    #[serde(default)]
    via: bool,
    joints: std::collections::BTreeMap<String, f64>,
}

/// A via configuration of a design's visiting order: the robot goes from
/// the pose at position `from` (`None`: home) through `q` to the pose at
/// position `to`, two straight joint-space moves, and is not measured at
/// `q`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ViaPoint {
    /// Position in the visiting order of the pose the move starts from
    /// (`None`: from home).
    pub from: Option<usize>,
    /// Position in the visiting order of the pose the move goes to.
    pub to: usize,
    /// The via configuration's joint values.
    pub q: Vec<f64>,
}

/// Poses measured before a design was chosen, as a design file stores them.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ExistingPoses {
    /// The file they were read from (informational).
    pub path: String,
    /// Their joint values.
    pub q: Vec<Vec<f64>>,
}

/// The names of the joints with a compliance unknown.
fn compliant_joints(robot: &Robot) -> Vec<String> {
    let names = crate::pool::file::joint_names(robot);
    robot
        .unknowns
        .iter()
        .filter(|u| u.symbol == crate::model::Symbol::C)
        .filter_map(|u| robot.frames[u.frame].joint.map(|j| names[j].clone()))
        .collect()
}

impl DesignFile {
    /// The design made of pool positions `positions` of `pool`, for `robot`.
    #[must_use]
    pub fn from_pool(robot: &Robot, pool: &Pool, positions: &[usize]) -> Self {
        let (name, chain) = match RobotRef::parse(&robot.name) {
            Ok(r) if !r.chain.is_empty() => (r.head(), Some(r.chain)),
            _ => (robot.name.clone(), None),
        };
        Self {
            robot: name,
            chain,
            pool: Some(pool.spec.clone()),
            levels: pool.spec.levels(),
            joint_names: Some(crate::pool::file::joint_names(robot)),
            poses: pool.ids_of(positions),
            q: Some(positions.iter().map(|&k| pool.q(k)).collect()),
            pool_qs: pool.listed().map(<[Vec<f64>]>::to_vec),
            existing: None,
            refined: false,
            compliance: compliant_joints(robot),
            via: Vec::new(),
            extra: serde_json::Map::new(),
        }
    }

    /// An old-style design: lattice indices of a `levels`-value lattice, no
    /// stored joint values.
    #[must_use]
    pub fn new(robot: &str, levels: usize, poses: Vec<usize>) -> Self {
        Self {
            robot: robot.to_string(),
            chain: None,
            pool: None,
            levels: Some(levels),
            joint_names: None,
            poses,
            q: None,
            pool_qs: None,
            existing: None,
            refined: false,
            compliance: Vec::new(),
            via: Vec::new(),
            extra: serde_json::Map::new(),
        }
    }

    /// Reads and parses a design file: JSON ([`DesignFile::parse`]), or
    /// the YAML form `select --out d.yaml` writes
    /// ([`DesignFile::parse_yaml`]) when the name ends in
    /// `.yaml` or `.yml`. A `.csv` (joint values, no robot or pool) is
    /// refused saying so.
    pub fn read(path: &Path) -> Result<DesignFile> {
        let text = crate::io::read::read_text(path)?;
        let origin = path.display().to_string();
        let yaml = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"));
        if yaml {
            return Self::parse_yaml(&text, &origin);
        }
        let csv = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"));
        if csv {
            return Err(Error::Parse {
                path: origin,
                message: "a .csv design holds only joint values (a pool file, or poses measured before); the design file is the .json or .yaml of the same selection (it names the robot and pool)".into(),
            });
        }
        Self::parse(&text, &origin)
    }

    /// Parses the YAML form back into a design file (`origin` names it in
    /// errors): the configurations' joint values become `q`, in the order of
    /// `joint_names`; a configuration missing a joint, or naming one the design
    /// does not list, is an error naming it.
    pub fn parse_yaml(text: &str, origin: &str) -> Result<DesignFile> {
        let perr = |message: String| Error::Parse {
            path: origin.to_string(),
            message,
        };
        let mut v: serde_json::Value =
            serde_saphyr::from_str(text).map_err(|e| perr(e.to_string()))?;
        let confs = v
            .as_object_mut()
            .and_then(|o| o.remove("configurations"))
            .ok_or_else(|| perr("no 'configurations' list of named joint configurations".into()))?;
        let confs: Vec<NamedIn> =
            serde_json::from_value(confs).map_err(|e| perr(format!("configurations: {e}")))?;
        let names: Vec<String> = v
            .get("joint_names")
            .cloned()
            .map(serde_json::from_value)
            .transpose()
            .map_err(|e| perr(format!("joint_names: {e}")))?
            .ok_or_else(|| perr("no 'joint_names' list".into()))?;
        let mut ids = Vec::with_capacity(confs.len());
        let mut qs = Vec::with_capacity(confs.len());
        for (k, c) in confs.iter().enumerate() {
            if c.via {
                continue;
            }
            let id = c.id.ok_or_else(|| {
                perr(format!(
                    "configurations[{k}]: no 'id' (the pose's id in its pool)"
                ))
            })?;
            if let Some(extra) = c.joints.keys().find(|n| !names.contains(n)) {
                return Err(perr(format!(
                    "configurations[{k}]: joint '{extra}' is not one of the design's joints ({})",
                    names.join(", ")
                )));
            }
            let q = names
                .iter()
                .map(|n| {
                    c.joints.get(n).copied().ok_or_else(|| {
                        perr(format!("configurations[{k}]: no value for joint '{n}'"))
                    })
                })
                .collect::<Result<Vec<f64>>>()?;
            ids.push(id);
            qs.push(q);
        }
        let o = v.as_object_mut().expect("an object: it had configurations");
        o.insert("poses".into(), serde_json::json!(ids));
        o.insert("q".into(), serde_json::json!(qs));
        DesignFile::parse(&v.to_string(), origin)
    }

    /// Parses the text of a design file, `origin` naming it in errors
    /// ([`Error::Parse`]: JSON syntax and types with line and column, a
    /// repeated pose, ids and joint vectors of different counts, no pool).
    pub fn parse(text: &str, origin: &str) -> Result<DesignFile> {
        let d: DesignFile = serde_json::from_str(text).map_err(|e| Error::Parse {
            path: origin.to_string(),
            message: e.to_string(),
        })?;
        d.check_shape().map_err(|e| Error::Parse {
            path: origin.to_string(),
            message: e.to_string(),
        })?;
        Ok(d)
    }

    /// Writes the design as pretty JSON. An existing file is only replaced
    /// when `overwrite` is set: nothing the user has is lost without asking.
    pub fn write(&self, path: &Path, overwrite: bool) -> Result<()> {
        let text = serde_json::to_string_pretty(self).expect("a design serializes");
        write_design_text(path, &(text + "\n"), overwrite)
    }

    /// The pool the design was chosen from.
    pub fn spec(&self) -> Result<PoolSpec> {
        match (&self.pool, self.levels) {
            (Some(s), _) => Ok(s.clone()),
            (None, Some(levels)) => Ok(PoolSpec::lattice(levels)),
            (None, None) => Err(Error::Invalid(
                "the design names no pool (neither 'pool' nor 'levels')".into(),
            )),
        }
    }

    /// Builds `spec` (the design's pool, [`spec`](Self::spec), possibly with
    /// other filters) for `robot`: a file-sourced pool from the
    /// configurations stored in the design when it has them (the original
    /// file is then not read), any other pool from its spec.
    pub fn build_pool(&self, spec: &PoolSpec, robot: &Robot, table: &ParamTable) -> Result<Pool> {
        match (&spec.source, &self.pool_qs) {
            (PoolSource::File { path }, Some(qs)) => spec.build_listed(
                robot,
                table,
                Configurations {
                    qs: qs.clone(),
                    notes: vec![format!(
                        "the configurations of {path} as stored in the design file"
                    )],
                },
            ),
            _ => spec.build(robot, table),
        }
    }

    /// Errors on a file whose parts disagree: a repeated id, or a joint
    /// value list of another length than the ids.
    fn check_shape(&self) -> Result<()> {
        check_unique(&self.poses)?;
        if let Some(q) = &self.q
            && q.len() != self.poses.len()
        {
            return Err(Error::Invalid(format!(
                "the design has {} pose ids but {} joint vectors",
                self.poses.len(),
                q.len()
            )));
        }
        if self.pool.is_none() && self.levels.is_none() {
            return Err(Error::Invalid(
                "the design names no pool (neither 'pool' nor 'levels')".into(),
            ));
        }
        Ok(())
    }

    /// The robot the design is for: its name, with the chain stored apart
    /// or, in files of old, as the name's `#…` fragment (a file giving both
    /// must give the same chain).
    pub fn robot_ref(&self) -> Result<RobotRef> {
        let mut r = RobotRef::parse(&self.robot)?;
        if let Some(c) = &self.chain {
            if !r.chain.is_empty() && r.chain != *c {
                return Err(Error::Invalid(format!(
                    "the design's robot '{}' names a chain ({}) other than its `chain` ({})",
                    self.robot,
                    r.chain.fragment(),
                    c.fragment()
                )));
            }
            r.chain = c.clone();
        }
        Ok(r)
    }

    /// Errors unless the design is for `robot`.
    pub fn check_robot(&self, robot: &Robot) -> Result<()> {
        let mine = self.robot_ref()?;
        if RobotRef::parse(&robot.name).ok().as_ref() != Some(&mine) {
            return Err(Error::Invalid(format!(
                "the design is for robot '{mine}', not '{}'",
                robot.name
            )));
        }
        Ok(())
    }

    /// Joint values of the design's poses: the stored ones, else (old files)
    /// the lattice's. Checked against the robot: one value per joint, all
    /// finite.
    pub fn joint_values(&self, robot: &Robot) -> Result<Vec<Vec<f64>>> {
        self.check_robot(robot)?;
        self.check_shape()?;
        if let Some(names) = &self.joint_names {
            let chain = crate::pool::file::joint_names(robot);
            if let Some(n) = names.iter().find(|n| !chain.contains(n)) {
                return Err(Error::Invalid(format!(
                    "the design's joint '{n}' is not a joint of the robot's chain ({})",
                    chain.join(", ")
                )));
            }
            if names != &chain {
                return Err(Error::Invalid(format!(
                    "the design's joints ({}) are not the chain's, in its order ({})",
                    names.join(", "),
                    chain.join(", ")
                )));
            }
        }
        let qs = match &self.q {
            Some(q) => q.clone(),
            None => {
                // An old file: its lattice gives the joint values.
                let Some(levels) = self.spec()?.levels() else {
                    return Err(Error::Invalid(
                        "the design stores no joint values ('q') and its pool is not a lattice: there is no way to know its poses".into(),
                    ));
                };
                let lattice = Lattice::new(robot, levels)?;
                self.poses
                    .iter()
                    .map(|&i| lattice.q(i))
                    .collect::<Result<_>>()?
            }
        };
        for q in &qs {
            if q.len() != robot.dof() {
                return Err(Error::JointCount {
                    expected: robot.dof(),
                    got: q.len(),
                });
            }
            if let Some(j) = q.iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFiniteAngle {
                    joint: j + 1,
                    value: q[j],
                });
            }
        }
        // Design files hold radians and metres (`select` writes them); the
        // limits are checked by the rule of every joint-value reader.
        let mut qs = qs;
        let rows: Vec<String> = self
            .poses
            .iter()
            .enumerate()
            .map(|(k, id)| format!("q[{k}] (pose {id})"))
            .collect();
        let columns = crate::units::joint_names(robot);
        let source = crate::units::JointSource {
            file: "the design file",
            rows: &rows,
            columns: &columns,
        };
        crate::units::joint_values_to_model_units(
            robot,
            crate::units::Units::default(),
            &source,
            &mut qs,
        )?;
        Ok(qs)
    }

    /// Checks the design against a robot and its pool, returning the pool
    /// positions of its poses: the robot name must match, every id must be
    /// in the pool with the stored joint values (to whole turns of a joint that
    /// turns all the way round), and no pose may repeat.
    pub fn positions_in(&self, robot: &Robot, pool: &Pool) -> Result<Vec<usize>> {
        let qs = self.joint_values(robot)?;
        let turning = crate::pool::turn::turning_joints(robot);
        if let (Some(mine), Some(theirs)) = (self.spec()?.levels(), pool.spec.levels())
            && mine != theirs
        {
            return Err(Error::Invalid(format!(
                "the design refers to a {mine}-level lattice, the pool has {theirs} levels"
            )));
        }
        self.poses
            .iter()
            .zip(&qs)
            .map(|(&id, q)| {
                let k = pool.position_of(id)?;
                if !same_q(&turning, pool.config(k), q) {
                    return Err(Error::PoseNotInPool {
                        index: id,
                        reason: "the pool's pose of this id has other joint values".into(),
                    });
                }
                Ok(k)
            })
            .collect()
    }

    /// Pool positions of the design poses that are in `pool` (same id, same
    /// joint values); poses outside it are skipped.
    pub fn positions_found_in(&self, robot: &Robot, pool: &Pool) -> Result<Vec<usize>> {
        let qs = self.joint_values(robot)?;
        let turning = crate::pool::turn::turning_joints(robot);
        Ok(self
            .poses
            .iter()
            .zip(&qs)
            .filter_map(|(&id, q)| {
                let k = pool.position_of(id).ok()?;
                same_q(&turning, pool.config(k), q).then_some(k)
            })
            .collect())
    }
}

/// The same pose to [`Q_TOL`]: a joint that turns all the way round may be
/// stored a whole turn away (a visiting order reaches poses so).
fn same_q(turning: &[bool], a: &[f64], b: &[f64]) -> bool {
    crate::pool::turn::same_place(turning, a, b, Q_TOL)
}

/// Errors on a repeated pose index.
pub fn check_unique(poses: &[usize]) -> Result<()> {
    let mut sorted = poses.to_vec();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(Error::Invalid(format!(
            "pose {} appears more than once",
            w[0]
        )));
    }
    Ok(())
}

/// Writes a design file's text atomically; an existing file is only
/// replaced when `overwrite` is set.
pub(crate) fn write_design_text(path: &Path, text: &str, overwrite: bool) -> Result<()> {
    super::atomic::check_outputs(
        &[super::atomic::Output {
            label: "design file",
            path,
        }],
        &[],
        overwrite,
    )?;
    super::atomic::write_atomic(path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimal_file_is_accepted_and_checked() {
        let d: DesignFile =
            serde_json::from_str(r#"{"robot":"puma560","levels":5,"poses":[1982, 0]}"#).unwrap();
        let r = Robot::puma560();
        let pool = Pool::full(&r, 5).unwrap();
        assert_eq!(d.positions_in(&r, &pool).unwrap(), vec![1982, 0]);
        assert_eq!(d.joint_values(&r).unwrap()[0], pool.q(1982));
        let bad: DesignFile =
            serde_json::from_str(r#"{"robot":"puma560","levels":5,"poses":[15625]}"#).unwrap();
        assert!(bad.positions_in(&r, &pool).is_err());
        let dup: DesignFile =
            serde_json::from_str(r#"{"robot":"puma560","levels":5,"poses":[3,3]}"#).unwrap();
        assert!(
            dup.positions_in(&r, &pool)
                .unwrap_err()
                .to_string()
                .contains("more than once")
        );
        let other: DesignFile =
            serde_json::from_str(r#"{"robot":"ur5","levels":5,"poses":[3]}"#).unwrap();
        assert!(other.positions_in(&r, &pool).is_err());
    }

    #[test]
    fn stored_joint_values_are_used_and_checked() {
        let r = Robot::puma560();
        let pool = Pool::full(&r, 3).unwrap();
        let mut d = DesignFile::from_pool(&r, &pool, &[5, 7]);
        assert_eq!(d.poses, vec![5, 7]);
        assert_eq!(d.levels, Some(3));
        // A pose in no lattice: its stored values are what counts.
        let off = vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6];
        d.q.as_mut().unwrap()[1] = off.clone();
        assert_eq!(d.joint_values(&r).unwrap()[1], off);
        assert!(d.positions_in(&r, &pool).is_err());
        assert_eq!(d.positions_found_in(&r, &pool).unwrap(), vec![5]);
        d.q.as_mut().unwrap()[1] = vec![0.0; 5];
        assert!(d.joint_values(&r).is_err());
        d.q.as_mut().unwrap().pop();
        assert!(d.joint_values(&r).is_err());
    }

    #[test]
    fn sampled_sources_round_trip_through_a_design_file() {
        let r = Robot::puma560();
        for source in [
            PoolSource::Random {
                count: 200,
                seed: 5,
            },
            PoolSource::Sobol {
                count: 128,
                seed: Some(3),
            },
            PoolSource::Sobol {
                count: 128,
                seed: None,
            },
        ] {
            let pool = PoolSpec::of(source.clone()).build(&r, &r.nominal).unwrap();
            let d = DesignFile::from_pool(&r, &pool, &[3, 77, 101]);
            let text = serde_json::to_string(&d).unwrap();
            let back: DesignFile = serde_json::from_str(&text).unwrap();
            assert_eq!(back.spec().unwrap().source, source);
            assert!(back.pool_qs.is_none());
            let again = back
                .build_pool(&back.spec().unwrap(), &r, &r.nominal)
                .unwrap();
            assert_eq!(back.positions_in(&r, &again).unwrap(), vec![3, 77, 101]);
        }
    }

    #[test]
    fn write_refuses_to_overwrite() {
        let dir = std::env::temp_dir().join(format!("activecal-design-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("d.json");
        let r = Robot::puma560();
        let pool = Pool::full(&r, 3).unwrap();
        let d = DesignFile::from_pool(&r, &pool, &[1, 2, 3]);
        d.write(&path, true).unwrap();
        assert!(d.write(&path, false).is_err());
        let back = DesignFile::read(&path).unwrap();
        assert_eq!(back.poses, d.poses);
        assert_eq!(back.q, d.q);
        assert_eq!(back.spec().unwrap().levels(), Some(3));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
