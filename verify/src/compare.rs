//! End-point positions and joint Jacobians at a list of configurations, from
//! any source (activecal, Pinocchio, MuJoCo, a fixture), and their largest
//! deviations.

use activecal::measure::JacobianEvaluator;
use activecal::model::{ParamTable, Robot};
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

/// Positions and positional joint Jacobians at a list of configurations.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Kinematics {
    /// End-point position (metres) in the measurement frame, per configuration.
    pub position: Vec<[f64; 3]>,
    /// `∂position/∂q` (3 × dof, row-major: entry `r·dof + j`), per
    /// configuration. Column `j` is also the identification-Jacobian column
    /// of the γ of the frame driven by joint `j` if it is revolute (of its
    /// `d` if prismatic).
    pub jacobian: Vec<Vec<f64>>,
}

impl Kinematics {
    /// Number of configurations.
    #[must_use]
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there are no configurations.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }
}

/// activecal's own values: `measure::JacobianEvaluator::joint_jacobian`, which
/// also returns the position (for a full-pose robot, the positional rows of
/// its joint Jacobian).
#[must_use]
pub fn activecal_kinematics(robot: &Robot, table: &ParamTable, qs: &[Vec<f64>]) -> Kinematics {
    let dof = robot.dof();
    let mut ev = JacobianEvaluator::new(robot, table);
    let mut out = Kinematics::default();
    let mut jac = vec![0.0; robot.rows_per_pose() * dof];
    for q in qs {
        let p = ev.joint_jacobian(q, &mut jac);
        out.position.push([p.x, p.y, p.z]);
        out.jacobian.push(jac[..3 * dof].to_vec());
    }
    out
}

/// Largest deviations between two sets of values over all configurations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Deviation {
    /// `max_k |Δposition_k|` (Euclidean norm, metres).
    pub position: f64,
    /// `max_k max_ij |ΔJ_k,ij|` (metres per radian).
    pub jacobian: f64,
}

impl Deviation {
    /// Whether both deviations are at most `tol` (NaN never is).
    #[must_use]
    pub fn within(&self, tol: f64) -> bool {
        self.position <= tol && self.jacobian <= tol
    }
}

/// Largest deviations between `a` and `b`, which must cover the same
/// configurations. NaN anywhere gives a NaN deviation.
pub fn deviation(a: &Kinematics, b: &Kinematics) -> Result<Deviation> {
    if a.len() != b.len() || a.jacobian.len() != b.jacobian.len() {
        bail!("{} vs {} configurations", a.len(), b.len());
    }
    let mut dev = Deviation::default();
    let max = |acc: f64, x: f64| {
        if x.is_nan() || acc.is_nan() {
            f64::NAN
        } else {
            acc.max(x)
        }
    };
    for (pa, pb) in a.position.iter().zip(&b.position) {
        let d2: f64 = pa.iter().zip(pb).map(|(x, y)| (x - y) * (x - y)).sum();
        dev.position = max(dev.position, d2.sqrt());
    }
    for (ja, jb) in a.jacobian.iter().zip(&b.jacobian) {
        if ja.len() != jb.len() {
            bail!("Jacobians of {} vs {} entries", ja.len(), jb.len());
        }
        for (x, y) in ja.iter().zip(jb) {
            dev.jacobian = max(dev.jacobian, (x - y).abs());
        }
    }
    Ok(dev)
}
