//! Identification as a problem apart from its solver (argmin's
//! `core/problem.rs`): a [`Residuals`] is anything with a residual vector and
//! its Jacobian at a parameter vector θ; [`super::lm`] minimises `½‖r(θ)‖²`
//! for any of them, and a robust loss ([`super::loss`]) wraps one without
//! touching the solver.
//!
//! [`Calibration`] is the kinematic calibration problem: a robot, its sensor
//! ([`crate::measure::Sensor`]) and measurements, with residuals
//! `r_i(θ) = pred(θ, q_i) ⊖ y_i` (Sun & Hollerbach §V-E; for full poses the
//! weighted orientation rows of [`crate::measure::pose`]).

use super::{Measurements, Result};
use crate::kinematics::{Evaluator, Motion};
use crate::measure::{Sensor, sensor_for};
use crate::model::{ParamTable, Robot};
use faer::Mat;

/// A least-squares problem: `m` residuals of `n` parameters.
pub trait Residuals {
    /// Number of residuals `m`.
    fn n_residuals(&self) -> usize;

    /// Number of parameters `n`.
    fn n_params(&self) -> usize;

    /// Residuals come in consecutive blocks of this many rows that a robust
    /// loss treats as one (the rows of one measured pose). Default 1.
    fn block_rows(&self) -> usize {
        1
    }

    /// Writes `r(θ)` into `r` (`m` entries) and, if `jac` is given, the
    /// Jacobian `∂r/∂θ` into it (`m × n`). Returns whether every value
    /// written is finite.
    fn eval(&mut self, theta: &[f64], r: &mut [f64], jac: Option<&mut Mat<f64>>) -> bool;
}

/// The calibration problem: residuals of a robot's sensor at measured poses,
/// as functions of the robot's unknowns (then the sensor's own unknowns, see
/// [`Sensor::n_own_params`]); the parameters that are not unknown keep their
/// values in the base table.
pub struct Calibration<'a> {
    robot: &'a Robot,
    base: &'a ParamTable,
    qs: &'a [Vec<f64>],
    sensor: Box<dyn Sensor>,
    /// Measured values in the sensor's layout, `value_len` per pose (encoded
    /// once: a measured rotation is projected here, not per evaluation).
    measured: Vec<f64>,
    /// Per-unknown motions of one pose.
    motions: Vec<Motion>,
    /// Predicted value of one pose.
    pred: Vec<f64>,
    /// Row-major `t × n` Jacobian block of one pose.
    block: Vec<f64>,
}

impl<'a> Calibration<'a> {
    /// The problem of identifying `robot`'s unknowns from `meas` (checked
    /// against the robot), other parameters from `base`.
    pub fn new(robot: &'a Robot, base: &'a ParamTable, meas: &'a Measurements) -> Result<Self> {
        meas.check(robot)?;
        let sensor = sensor_for(robot);
        let vl = sensor.value_len();
        let mut measured = vec![0.0; vl * meas.len()];
        for (i, out) in measured.chunks_mut(vl).enumerate() {
            sensor.encode(&meas.observation(i), out);
        }
        let n = robot.n_params();
        Ok(Self {
            robot,
            base,
            qs: meas.qs(),
            motions: vec![Motion::default(); robot.n_unknowns()],
            pred: vec![0.0; vl],
            block: vec![0.0; sensor.rows() * n],
            measured,
            sensor,
        })
    }

    /// The sensor.
    #[must_use]
    pub fn sensor(&self) -> &dyn Sensor {
        self.sensor.as_ref()
    }
}

impl Residuals for Calibration<'_> {
    fn n_residuals(&self) -> usize {
        self.sensor.rows() * self.qs.len()
    }

    fn n_params(&self) -> usize {
        self.robot.n_params()
    }

    fn block_rows(&self) -> usize {
        self.sensor.rows()
    }

    fn eval(&mut self, theta: &[f64], r: &mut [f64], mut jac: Option<&mut Mat<f64>>) -> bool {
        let n = theta.len();
        let p = self.robot.n_unknowns();
        let t = self.sensor.rows();
        let vl = self.sensor.value_len();
        let table = self.robot.with_unknowns(self.base, theta);
        let own = &theta[p..];
        let mut ev = Evaluator::new(self.robot, &table);
        let mut finite = true;
        for (i, q) in self.qs.iter().enumerate() {
            let y = &self.measured[vl * i..vl * (i + 1)];
            let ri = &mut r[t * i..t * (i + 1)];
            let end = if jac.is_some() {
                ev.motions(q, &mut self.motions)
            } else {
                ev.end_frame(q)
            };
            self.sensor.predict(&end, own, &mut self.pred);
            self.sensor.residual(&self.pred, y, ri);
            finite &= ri.iter().all(|v| v.is_finite());
            if let Some(j) = jac.as_deref_mut() {
                self.sensor
                    .residual_rows(&end, own, &self.motions, y, &mut self.block, n);
                self.sensor.own_rows(&end, own, &mut self.block[p..], n);
                for c in 0..t {
                    for k in 0..n {
                        let x = self.block[c * n + k];
                        finite &= x.is_finite();
                        j[(t * i + c, k)] = x;
                    }
                }
            }
        }
        finite
    }
}
