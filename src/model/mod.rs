//! Robot models: a serial chain of DH or Hayati frames with named parameters,
//! real and nominal parameter tables, unknowns and joint limits.
//!
//! Each frame's transform is `Rz(q + γ) Tz(d) Tx(a) Rx(α)` (DH) or
//! `Rz(q + γ) Tx(a) Rx(α) Ry(β)` (Hayati; `d` is kept in the table and applied
//! as `Tz(d)` after `Rz`, so a Hayati frame with `d = 0` is exactly the
//! paper's). A frame driven by a prismatic joint moves along z instead:
//! `Rz(γ) Tz(q + d) …`. A fixed frame has no `q`. The measured point is the
//! origin of the last frame, expressed in the measurement frame ("coordinate
//! zero"); a full-pose measurement ([`MeasurementKind::Pose`]) adds the last
//! frame's orientation.
//!
//! The model imports no loader, no pool and no sensor: built-in arms are in
//! [`catalogue`]; robots from files come from [`crate::io`] (TOML
//! descriptions, URDF), which produces these types; the unknowns a
//! measurement can identify are chosen in [`crate::observability`].

pub mod catalogue;
pub mod frame;
pub mod gravity;
pub mod robot_ref;
pub mod source;

pub use frame::{FrameMotion, frame_transform};

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::fmt;

/// Parameterization of one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Convention {
    /// Denavit–Hartenberg: `Rz(q+γ) Tz(d) Tx(a) Rx(α)`; has no β.
    Dh,
    /// Hayati: `Rz(q+γ) Tx(a) Rx(α) Ry(β)`, for nearly parallel consecutive axes.
    Hayati,
}

/// The five parameter symbols of a frame, in the tables' column order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Symbol {
    /// Joint-angle offset γ (radians).
    Gamma,
    /// Twist α about x (radians).
    Alpha,
    /// Length a along x (metres).
    A,
    /// Offset d along z (metres).
    D,
    /// Hayati twist β about y (radians).
    Beta,
    /// Joint compliance `c` of the joint driving the frame (rad per N·m):
    /// the joint deflects by `c·τ(q)` under its gravity torque `τ`
    /// ([`gravity`]). Not a column of the frame tables: it lives in
    /// [`ParamTable::compliance`], and is an unknown only of a robot with a
    /// [`Robot::gravity`] model.
    C,
}

impl Symbol {
    /// All symbols in column order.
    pub const ALL: [Symbol; 5] = [
        Symbol::Gamma,
        Symbol::Alpha,
        Symbol::A,
        Symbol::D,
        Symbol::Beta,
    ];

    /// Column of this symbol in a parameter table ([`Symbol::C`], which has
    /// none, gives 5, past the table's columns).
    #[must_use]
    pub fn column(self) -> usize {
        self as usize
    }

    /// The name used in parameter names (`gamma`, `alpha`, `a`, `d`, `beta`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Symbol::Gamma => "gamma",
            Symbol::Alpha => "alpha",
            Symbol::A => "a",
            Symbol::D => "d",
            Symbol::Beta => "beta",
            Symbol::C => "c",
        }
    }

    /// Parses a symbol name.
    #[must_use]
    pub fn parse(s: &str) -> Option<Symbol> {
        Symbol::ALL.into_iter().find(|x| x.name() == s)
    }
}

impl fmt::Display for Symbol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How a joint drives its frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Rotation about the frame's base z axis: `Rz(q + γ)`; `q` in radians.
    #[default]
    Revolute,
    /// Translation along the frame's base z axis: `Tz(q + d)`; `q` in metres.
    Prismatic,
}

/// One frame of the chain.
#[derive(Clone, Debug, Serialize)]
pub struct Frame {
    /// Frame label used in parameter names (`a`, `0`, `1`, …).
    pub label: String,
    /// DH or Hayati.
    pub convention: Convention,
    /// Index (0-based) of the joint that drives this frame, or `None` if fixed.
    pub joint: Option<usize>,
    /// Revolute or prismatic; only meaningful when `joint` is `Some`
    /// (fixed frames keep the default, revolute).
    pub joint_kind: JointKind,
}

impl Frame {
    /// A fixed frame (no joint).
    #[must_use]
    pub fn fixed(label: &str, convention: Convention) -> Frame {
        Frame {
            label: label.to_string(),
            convention,
            joint: None,
            joint_kind: JointKind::Revolute,
        }
    }

    /// A frame driven by joint `joint` (0-based) of the given kind.
    #[must_use]
    pub fn driven(label: &str, convention: Convention, joint: usize, kind: JointKind) -> Frame {
        Frame {
            label: label.to_string(),
            convention,
            joint: Some(joint),
            joint_kind: kind,
        }
    }

    /// Whether this frame is driven by a prismatic joint.
    #[must_use]
    pub fn is_prismatic(&self) -> bool {
        self.joint.is_some() && self.joint_kind == JointKind::Prismatic
    }
}

/// Values of all five parameters of every frame (`[γ, α, a, d, β]` per frame),
/// and the offsets of the markers a [`MeasurementKind::Markers`] sensor sees.
/// A DH frame's β entry is ignored by the kinematics (the paper's tables write 10).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ParamTable {
    /// One row per frame, columns in [`Symbol::ALL`] order.
    pub rows: Vec<[f64; 5]>,
    /// Marker offsets `o_k` in the last frame (metres), one per marker of a
    /// [`MeasurementKind::Markers`] robot, empty otherwise: marker `k` is at
    /// `p + R o_k`. They are always unknown (the sensor's own unknowns,
    /// after the robot's in the parameter vector).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub markers: Vec<[f64; 3]>,
    /// Joint compliances `c` (rad per N·m, [`Symbol::C`]), one per frame
    /// (meaningful on frames driven by a revolute joint), or empty: all 0.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub compliance: Vec<f64>,
}

impl ParamTable {
    /// A table of frame rows, without markers.
    #[must_use]
    pub fn from_rows(rows: Vec<[f64; 5]>) -> Self {
        Self {
            rows,
            markers: Vec::new(),
            compliance: Vec::new(),
        }
    }

    /// The marker offsets as one flat vector `[o_1x, o_1y, o_1z, o_2x, …]`
    /// (the sensor's own parameters, see [`crate::measure::Sensor::n_own_params`]).
    #[must_use]
    pub fn marker_values(&self) -> Vec<f64> {
        self.markers.iter().flatten().copied().collect()
    }

    /// Value of a parameter.
    #[must_use]
    pub fn get(&self, id: ParamId) -> f64 {
        match id.symbol {
            Symbol::C => self.compliance.get(id.frame).copied().unwrap_or(0.0),
            s => self.rows[id.frame][s.column()],
        }
    }

    /// Sets a parameter.
    pub fn set(&mut self, id: ParamId, v: f64) {
        match id.symbol {
            Symbol::C => {
                if self.compliance.len() != self.rows.len() {
                    self.compliance.resize(self.rows.len(), 0.0);
                }
                self.compliance[id.frame] = v;
            }
            s => self.rows[id.frame][s.column()] = v,
        }
    }

    /// Whether any joint compliance is non-zero.
    #[must_use]
    pub fn has_compliance(&self) -> bool {
        self.compliance.iter().any(|&c| c != 0.0)
    }
}

/// Identifies one parameter: a frame and a symbol.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct ParamId {
    /// Index of the frame in the chain.
    pub frame: usize,
    /// The symbol.
    pub symbol: Symbol,
}

/// Which of a robot's two parameter tables to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ParamSet {
    /// The nominal (design) model, used to compute Jacobians for pose selection.
    Nominal,
    /// The real robot, used to simulate measurements.
    Real,
}

crate::choice!(ParamSet { Nominal => "nominal", Real => "real" });

/// What is measured at each pose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MeasurementKind {
    /// The position of the end point: 3 rows per pose.
    Point,
    /// The position and orientation of the end frame: 6 rows per pose,
    /// position first, then the orientation (an angular velocity: the rows of
    /// a rotation parameter about unit axis `u` are `u`, those of a
    /// translation parameter are 0).
    Pose,
    /// `K ≥ 1` markers fixed to the last frame, each measured as a point:
    /// `3K` rows per pose. Marker `k` sits at `p + R o_k` with its own offset
    /// `o_k` ([`ParamTable::markers`]), three unknowns per marker after the
    /// robot's.
    Markers(usize),
}

impl MeasurementKind {
    /// Rows of the identification Jacobian per pose.
    #[must_use]
    pub fn rows(self) -> usize {
        match self {
            MeasurementKind::Point => 3,
            MeasurementKind::Pose => 6,
            MeasurementKind::Markers(k) => 3 * k,
        }
    }

    /// `point`, `pose` or `markers`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MeasurementKind::Point => "point",
            MeasurementKind::Pose => "pose",
            MeasurementKind::Markers(_) => "markers",
        }
    }

    /// Markers per pose: `K` for [`MeasurementKind::Markers`], else 0
    /// (the end point itself is measured, with no offset unknowns).
    #[must_use]
    pub fn markers(self) -> usize {
        match self {
            MeasurementKind::Markers(k) => k,
            _ => 0,
        }
    }
}

/// An immutable serial-chain robot model.
#[derive(Clone, Debug, Serialize)]
pub struct Robot {
    /// Name (`puma560` for the built-in PUMA).
    pub name: String,
    /// Frames from the measurement frame to the end point.
    pub frames: Vec<Frame>,
    /// Parameters of the real robot (simulation truth).
    pub real: ParamTable,
    /// Nominal parameters (the model the Jacobians are computed with).
    pub nominal: ParamTable,
    /// The unknown parameters, frame-major, in column order.
    pub unknowns: Vec<ParamId>,
    /// Joint limits `[lo, hi]`, one per joint: radians for a revolute joint,
    /// metres for a prismatic one.
    pub limits: Vec<[f64; 2]>,
    /// What is measured.
    pub measurement: MeasurementKind,
    /// Metres per radian that make an orientation error comparable to a
    /// position error (full-pose robots): the orientation rows of the
    /// identification Jacobian and the orientation residuals of
    /// identification are multiplied by it. Set it to `σ_position /
    /// σ_orientation` of the sensor (e.g. 0.05 mm / 0.01° ≈ 0.29 m/rad for a
    /// laser tracker with a 6-DoF probe), so that every weighted row carries
    /// the same noise σ_position and `XᵀX` is the Fisher information up to
    /// `σ²`. Default [`DEFAULT_ORIENTATION_SCALE`]; unused for points.
    pub orientation_scale: f64,
    /// The URDF the chain was imported from, when it was (see
    /// [`source::UrdfSource`]): what writing a calibrated URDF back needs.
    #[serde(skip)]
    pub source: Option<std::sync::Arc<source::UrdfSource>>,
    /// Gravity torques of the joints, when the robot's joints deflect under
    /// them: the kinematics then evaluate `q + c∘τ(q)` with the table's
    /// [`ParamTable::compliance`] (see [`gravity`]).
    #[serde(skip)]
    pub gravity: Option<std::sync::Arc<gravity::GravityModel>>,
}

/// Default [`Robot::orientation_scale`]: 1 m/rad, i.e. an orientation noise
/// in radians equal to the position noise in metres (0.01 rad ≈ 0.57° beside
/// 1 cm).
pub const DEFAULT_ORIENTATION_SCALE: f64 = 1.0;

/// Names of the built-in robots (point measurements; append `:pose` for the
/// full-pose variant, see [`Robot::builtin`]).
pub const BUILTIN: &[&str] = &["puma560", "ur5", "stanford"];

impl Robot {
    /// A built-in robot by name: `puma560` (or `puma`), `ur5`, `stanford`.
    /// A name with the suffix `:pose` (`ur5:pose`) gives the same robot with
    /// full-pose measurements and the three orientation unknowns more that
    /// they identify (see [`catalogue`]).
    pub fn builtin(name: &str) -> Result<Robot> {
        let (base, m) = match name.strip_suffix(":pose") {
            Some(b) => (b, MeasurementKind::Pose),
            None => (name, MeasurementKind::Point),
        };
        match (base, m) {
            ("puma560" | "puma", MeasurementKind::Point) => Ok(Robot::puma560()),
            ("puma560" | "puma", MeasurementKind::Pose) => Ok(catalogue::puma560_pose()),
            ("ur5", m) => Ok(catalogue::ur5_with(m)),
            ("stanford", m) => Ok(catalogue::stanford_with(m)),
            _ => Err(Error::UnknownRobot {
                name: name.to_string(),
                known: BUILTIN.join(", "),
            }),
        }
    }

    /// The PUMA 560 of Sun & Hollerbach §V-A: Tables I (real) and II
    /// (nominal), joint limits eq. (25), 27 unknowns.
    ///
    /// Frame `a` is a fixed Hayati frame from the measurement frame to the
    /// base (20 m away), frame 0 is joint 1 (DH), frame 1 joint 2 (Hayati),
    /// frames 2–5 joints 3–6 (DH), frame 6 the identity.
    #[must_use]
    pub fn puma560() -> Robot {
        use Convention::{Dh, Hayati};
        let frames: Vec<Frame> = [
            ("a", Hayati, None),
            ("0", Dh, Some(0)),
            ("1", Hayati, Some(1)),
            ("2", Dh, Some(2)),
            ("3", Dh, Some(3)),
            ("4", Dh, Some(4)),
            ("5", Dh, Some(5)),
            ("6", Dh, None),
        ]
        .into_iter()
        .map(|(l, c, j)| Frame {
            label: l.to_string(),
            convention: c,
            joint: j,
            joint_kind: JointKind::Revolute,
        })
        .collect();
        // Table I (β = 10 marks "no β" in the paper; kept for display, ignored for DH).
        let real = ParamTable::from_rows(vec![
            [PI / 2.0, PI / 100.0, 20.0, 0.0, PI / 100.0],
            [0.0, -PI / 2.0, 0.0, 0.6858, 10.0],
            [0.0, PI / 100.0, 0.4318, 0.0, PI / 100.0],
            [0.0, PI / 2.0, -0.0203, 0.1491, 10.0],
            [0.0, -PI / 2.0, 0.0, 0.4331, 10.0],
            [0.0, PI / 2.0, 0.0, 0.0, 10.0],
            [0.0, 0.0, 0.2, 0.1655, 10.0],
            [0.0, 0.0, 0.0, 0.0, 10.0],
        ]);
        // Table II.
        let nominal = ParamTable::from_rows(vec![
            [1.6360, 0.1572, 19.8820, 0.0, -0.0123],
            [-0.0367, -1.4524, 0.0603, 0.6713, 10.0],
            [-0.1455, -0.2622, 0.3411, 0.0, -0.1963],
            [0.0128, 1.6374, -0.1214, 0.0074, 10.0],
            [0.0024, -1.3948, -0.1029, 0.3002, 10.0],
            [0.1207, 1.6151, -0.0468, -0.0747, 10.0],
            [0.0938, 0.0, 0.1322, 0.3083, 10.0],
            [0.0, 0.0, 0.0, 0.0, 10.0],
        ]);
        use Symbol::{A, Alpha, Beta, D, Gamma};
        let per_frame: [&[Symbol]; 7] = [
            &[Gamma, Alpha, A, Beta],
            &[Gamma, Alpha, A, D],
            &[Gamma, Alpha, A, Beta],
            &[Gamma, Alpha, A, D],
            &[Gamma, Alpha, A, D],
            &[Gamma, Alpha, A, D],
            &[Gamma, A, D],
        ];
        let unknowns = per_frame
            .iter()
            .enumerate()
            .flat_map(|(f, syms)| {
                syms.iter().map(move |&s| ParamId {
                    frame: f,
                    symbol: s,
                })
            })
            .collect();
        let deg = PI / 180.0;
        let limits = [
            [-250.0, 70.0],
            [-110.0, 170.0],
            [-133.0, 133.0],
            [-100.0, 100.0],
            [-142.0, 142.0],
            [-176.0, 356.0],
        ]
        .iter()
        .map(|[lo, hi]| [lo * deg, hi * deg])
        .collect();
        Robot {
            name: "puma560".into(),
            frames,
            real,
            nominal,
            unknowns,
            limits,
            measurement: MeasurementKind::Point,
            orientation_scale: DEFAULT_ORIENTATION_SCALE,
            source: None,
            gravity: None,
        }
    }

    /// Number of joints.
    #[must_use]
    pub fn dof(&self) -> usize {
        self.limits.len()
    }

    /// Number of unknown kinematic parameters (the robot's, without the
    /// sensor's own marker offsets; see [`Robot::n_params`]).
    #[must_use]
    pub fn n_unknowns(&self) -> usize {
        self.unknowns.len()
    }

    /// Number of parameters identified, `p`: the robot's unknowns, then three
    /// offset coordinates per marker of a [`MeasurementKind::Markers`]
    /// sensor. The width of every identification Jacobian.
    #[must_use]
    pub fn n_params(&self) -> usize {
        self.unknowns.len() + 3 * self.measurement.markers()
    }

    /// Rows of the identification Jacobian per pose.
    #[must_use]
    pub fn rows_per_pose(&self) -> usize {
        self.measurement.rows()
    }

    /// The parameter table of a set.
    #[must_use]
    pub fn params(&self, set: ParamSet) -> &ParamTable {
        match set {
            ParamSet::Nominal => &self.nominal,
            ParamSet::Real => &self.real,
        }
    }

    /// Name of a parameter, `<symbol>_<frame>` (e.g. `gamma_a`, `d_3`).
    #[must_use]
    pub fn param_name(&self, id: ParamId) -> String {
        format!("{}_{}", id.symbol.name(), self.frames[id.frame].label)
    }

    /// Names of the identified parameters, in parameter-vector order: the
    /// unknowns, then the marker offsets (`marker1_x`, `marker1_y`, …).
    #[must_use]
    pub fn parameter_names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.unknowns.iter().map(|&u| self.param_name(u)).collect();
        for k in 1..=self.measurement.markers() {
            v.extend(["x", "y", "z"].map(|c| format!("marker{k}_{c}")));
        }
        v
    }

    /// Looks a parameter up by name.
    pub fn param_id(&self, name: &str) -> Result<ParamId> {
        let bad = || Error::UnknownParameter(name.to_string());
        let (sym, frame) = name.split_once('_').ok_or_else(bad)?;
        let symbol = match sym {
            "c" => Symbol::C,
            _ => Symbol::parse(sym).ok_or_else(bad)?,
        };
        let frame = self
            .frames
            .iter()
            .position(|f| f.label == frame)
            .ok_or_else(bad)?;
        if symbol == Symbol::Beta && self.frames[frame].convention == Convention::Dh {
            return Err(bad());
        }
        if symbol == Symbol::C && !self.is_compliant_frame(frame) {
            return Err(bad());
        }
        Ok(ParamId { frame, symbol })
    }

    /// Whether frame `frame` can carry a compliance unknown: the robot has a
    /// gravity model and a revolute joint drives the frame.
    #[must_use]
    pub fn is_compliant_frame(&self, frame: usize) -> bool {
        self.gravity.is_some()
            && self.frames[frame].joint.is_some()
            && self.frames[frame].joint_kind == JointKind::Revolute
    }

    /// The identified parameters' values in a table, in parameter-vector
    /// order ([`Robot::n_params`] of them: unknowns, then marker offsets).
    #[must_use]
    pub fn unknown_values(&self, table: &ParamTable) -> Vec<f64> {
        let mut v: Vec<f64> = self.unknowns.iter().map(|&u| table.get(u)).collect();
        v.extend(table.marker_values());
        v
    }

    /// A copy of `table` with the identified parameters set from `values`
    /// ([`Robot::n_params`] entries, or just the robot's unknowns: the
    /// markers then keep their values).
    #[must_use]
    pub fn with_unknowns(&self, table: &ParamTable, values: &[f64]) -> ParamTable {
        let p = self.unknowns.len();
        assert!(values.len() == p || values.len() == self.n_params());
        let mut t = table.clone();
        for (&u, &v) in self.unknowns.iter().zip(values) {
            t.set(u, v);
        }
        for (o, c) in t.markers.iter_mut().zip(values[p..].chunks_exact(3)) {
            o.copy_from_slice(c);
        }
        t
    }

    /// A copy of this robot with a different set of unknowns (validated).
    pub fn with_unknown_names(&self, names: &[&str]) -> Result<Robot> {
        let mut ids = names
            .iter()
            .map(|n| self.param_id(n))
            .collect::<Result<Vec<_>>>()?;
        ids.sort();
        ids.dedup();
        let mut r = self.clone();
        r.unknowns = ids;
        r.validate()?;
        Ok(r)
    }

    /// Checks internal consistency: unique non-empty frame labels, joints
    /// numbered 0..dof once each, prismatic only on driven frames, finite
    /// parameters, valid limits, no β unknown on a DH frame, unknowns sorted
    /// and naming existing frames.
    pub fn validate(&self) -> Result<()> {
        if !(self.orientation_scale.is_finite() && self.orientation_scale > 0.0) {
            return Err(Error::Invalid(format!(
                "orientation_scale = {}: must be a finite number > 0 (metres per radian)",
                crate::error::Compact(self.orientation_scale)
            )));
        }
        self.validate_frames()?;
        self.validate_limits()?;
        self.validate_tables()?;
        self.validate_unknowns()
    }

    /// Labels unique and well formed, prismatic only on driven frames,
    /// joints numbered 0..dof once each.
    fn validate_frames(&self) -> Result<()> {
        let mut seen = vec![false; self.dof()];
        for (i, f) in self.frames.iter().enumerate() {
            if f.label.is_empty() || f.label.chars().any(|c| c.is_whitespace() || c == ',') {
                return Err(Error::Invalid(format!(
                    "frame {i}: label '{}' must be non-empty, without spaces or commas",
                    f.label
                )));
            }
            if self.frames[..i].iter().any(|g| g.label == f.label) {
                return Err(Error::Invalid(format!(
                    "frame {}: the label is used by two frames",
                    f.label
                )));
            }
            if f.joint.is_none() && f.joint_kind == JointKind::Prismatic {
                return Err(Error::Invalid(format!(
                    "frame {}: a fixed frame cannot be prismatic",
                    f.label
                )));
            }
        }
        for f in &self.frames {
            if let Some(j) = f.joint {
                if j >= seen.len() || seen[j] {
                    return Err(Error::Invalid(format!(
                        "frame {}: joint index {j} is out of range or used twice",
                        f.label
                    )));
                }
                seen[j] = true;
            }
        }
        if let Some(j) = seen.iter().position(|s| !s) {
            return Err(Error::Invalid(format!("joint q{} drives no frame", j + 1)));
        }
        Ok(())
    }

    /// Every joint's limits finite, ordered and not empty.
    fn validate_limits(&self) -> Result<()> {
        for (j, &[lo, hi]) in self.limits.iter().enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(Error::InvalidLimits {
                    joint: j + 1,
                    lo,
                    hi,
                });
            }
            if lo == hi {
                let frame = self
                    .frames
                    .iter()
                    .find(|f| f.joint == Some(j))
                    .map_or("?", |f| f.label.as_str());
                return Err(Error::Invalid(format!(
                    "joint q{} (frame {frame}) has an empty range [{}, {}]: a joint that never moves leaves its frame's unknowns unidentifiable; give it a range, or make the frame fixed",
                    j + 1,
                    crate::error::Compact(lo),
                    crate::error::Compact(hi)
                )));
            }
        }
        Ok(())
    }

    /// Both tables: a row per frame, finite parameters, the sensor's
    /// number of finite marker offsets.
    fn validate_tables(&self) -> Result<()> {
        for table in [&self.real, &self.nominal] {
            if table.rows.len() != self.frames.len() {
                return Err(Error::Invalid(format!(
                    "parameter table has {} rows for {} frames",
                    table.rows.len(),
                    self.frames.len()
                )));
            }
            for (fi, row) in table.rows.iter().enumerate() {
                for s in Symbol::ALL {
                    let used = !(s == Symbol::Beta && self.frames[fi].convention == Convention::Dh);
                    if used && !row[s.column()].is_finite() {
                        return Err(Error::NonFiniteParameter {
                            name: self.param_name(ParamId {
                                frame: fi,
                                symbol: s,
                            }),
                            value: row[s.column()],
                        });
                    }
                }
            }
        }
        for (which, table) in [("real", &self.real), ("nominal", &self.nominal)] {
            let k = self.measurement.markers();
            if table.markers.len() != k {
                return Err(Error::Invalid(format!(
                    "the {which} table has {} marker offsets for a sensor of {k} markers",
                    table.markers.len()
                )));
            }
            if let Some(i) = table
                .markers
                .iter()
                .position(|o| o.iter().any(|v| !v.is_finite()))
            {
                return Err(Error::Invalid(format!(
                    "{which} marker {}: the offset {:?} is not finite",
                    i + 1,
                    table.markers[i]
                )));
            }
        }
        Ok(())
    }

    /// Unknowns present, sorted, unique, naming existing frames and
    /// parameters their frames have.
    fn validate_unknowns(&self) -> Result<()> {
        if self.unknowns.is_empty() {
            return Err(Error::Invalid("the robot has no unknown parameters".into()));
        }
        for w in self.unknowns.windows(2) {
            if w[0] >= w[1] {
                return Err(Error::Invalid(
                    "unknowns must be unique and frame-major".into(),
                ));
            }
        }
        for &u in &self.unknowns {
            if u.frame >= self.frames.len() {
                return Err(Error::Invalid(format!(
                    "unknown parameter {:?} refers to frame {} of {}",
                    u.symbol,
                    u.frame,
                    self.frames.len()
                )));
            }
            if u.symbol == Symbol::C && !self.is_compliant_frame(u.frame) {
                return Err(Error::Invalid(format!(
                    "{} is not a parameter: a compliance needs a revolute joint and the robot's gravity model",
                    self.param_name(u)
                )));
            }
            if u.symbol == Symbol::Beta && self.frames[u.frame].convention == Convention::Dh {
                return Err(Error::Invalid(format!(
                    "{} is not a parameter: frame {} is DH",
                    self.param_name(u),
                    self.frames[u.frame].label
                )));
            }
        }
        Ok(())
    }

    /// Validates a joint vector: length and finiteness (limits are not enforced:
    /// kinematics is defined everywhere).
    pub fn check_q(&self, q: &[f64]) -> Result<()> {
        if q.len() != self.dof() {
            return Err(Error::JointCount {
                expected: self.dof(),
                got: q.len(),
            });
        }
        if let Some((j, &v)) = q.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFiniteAngle {
                joint: j + 1,
                value: v,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn puma_has_27_unknowns_in_table_order() {
        let r = Robot::puma560();
        r.validate().unwrap();
        let names = r.parameter_names();
        assert_eq!(names.len(), 27);
        assert_eq!(
            &names[..5],
            ["gamma_a", "alpha_a", "a_a", "beta_a", "gamma_0"]
        );
        assert_eq!(&names[24..], ["gamma_5", "a_5", "d_5"]);
    }

    #[test]
    fn names_round_trip_and_bad_names_fail() {
        let r = Robot::puma560();
        for &u in &r.unknowns {
            assert_eq!(r.param_id(&r.param_name(u)).unwrap(), u);
        }
        assert!(r.param_id("beta_2").is_err()); // frame 2 is DH
        assert!(r.param_id("foo_1").is_err());
        assert!(r.param_id("gamma_9").is_err());
    }

    #[test]
    fn inverted_limits_are_rejected() {
        let mut r = Robot::puma560();
        r.limits[2] = [1.0, -1.0];
        assert!(matches!(
            r.validate(),
            Err(Error::InvalidLimits { joint: 3, .. })
        ));
    }
}
