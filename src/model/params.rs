//! Parameters: the five symbols of a frame (and the joint compliance), the
//! tables of their values, the id of one parameter, and which table to use.

use serde::{Deserialize, Serialize};
use std::fmt;

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
    /// ([`gravity`](super::gravity)). Not a column of the frame tables: it lives in
    /// [`ParamTable::compliance`], and is an unknown only of a robot with a
    /// [`Robot::gravity`](super::Robot::gravity) model.
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

/// Values of all five parameters of every frame (`[γ, α, a, d, β]` per frame),
/// and the offsets of the markers a [`MeasurementKind::Markers`](super::MeasurementKind::Markers) sensor sees.
/// A DH frame's β entry is ignored by the kinematics (the paper's tables write 10).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ParamTable {
    /// One row per frame, columns in [`Symbol::ALL`] order.
    pub rows: Vec<[f64; 5]>,
    /// Marker offsets `o_k` in the last frame (metres), one per marker of a
    /// [`MeasurementKind::Markers`](super::MeasurementKind::Markers) robot, empty otherwise: marker `k` is at
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
