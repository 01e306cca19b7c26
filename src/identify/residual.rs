//! Identification as a problem apart from its solver (argmin's
//! `core/problem.rs`): a [`Residuals`] is anything with a residual vector and
//! its Jacobian at a parameter vector θ; [`super::lm`] minimises `½‖r(θ)‖²`
//! for any of them, and a robust loss ([`crate::lsq::loss`]) wraps one without
//! touching the solver.
//!
//! [`Calibration`] is the kinematic calibration problem: a robot, its sensor
//! ([`crate::measure::Sensor`]) and measurements, with residuals
//! `r_i(θ) = pred(θ, q_i) ⊖ y_i` (Sun & Hollerbach §V-E; for full poses the
//! weighted orientation rows of [`crate::measure::pose`]).

pub use crate::lsq::Residuals;

use super::Result;
use crate::data::Measurements;
use crate::kinematics::{Evaluator, Motion};
use crate::measure::{Sensor, sensor_for};
use crate::model::{ParamTable, Robot};
use faer::Mat;

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
    /// Parameters: the robot's unknowns, then the sensor's own.
    n_params: usize,
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
        Ok(Self::with_sensor(robot, base, meas.qs(), sensor, measured))
    }

    /// The problem of identifying `robot`'s unknowns and `sensor`'s own from
    /// poses `qs` whose measured values (in the sensor's layout,
    /// `value_len` each, already checked) are `measured`: for sensors that
    /// are not the robot's own ([`crate::measure::contact`]).
    #[must_use]
    pub fn with_sensor(
        robot: &'a Robot,
        base: &'a ParamTable,
        qs: &'a [Vec<f64>],
        sensor: Box<dyn Sensor>,
        measured: Vec<f64>,
    ) -> Self {
        let n = robot.n_unknowns() + sensor.n_own_params();
        Self {
            robot,
            base,
            qs,
            motions: vec![Motion::default(); robot.n_unknowns()],
            pred: vec![0.0; sensor.value_len()],
            block: vec![0.0; sensor.rows().max(sensor.constraint_rows()) * n],
            measured,
            sensor,
            n_params: n,
        }
    }

    /// The sensor.
    #[must_use]
    pub fn sensor(&self) -> &dyn Sensor {
        self.sensor.as_ref()
    }
}

impl Residuals for Calibration<'_> {
    fn n_residuals(&self) -> usize {
        self.sensor.rows() * self.qs.len() + self.sensor.constraint_rows()
    }

    fn n_params(&self) -> usize {
        self.n_params
    }

    fn block_rows(&self) -> usize {
        self.sensor.rows()
    }

    fn eval(&mut self, theta: &[f64], r: &mut [f64], mut jac: Option<&mut Mat<f64>>) -> bool {
        let n = theta.len();
        let p = self.robot.n_unknowns();
        let t = self.sensor.rows();
        let vl = self.sensor.value_len();
        // The robot's own sensor (markers) keeps its offsets in the table
        // too; another sensor's unknowns are its own only.
        let robot_part = if n == self.robot.n_params() {
            theta
        } else {
            &theta[..p]
        };
        let table = self.robot.with_unknowns(self.base, robot_part);
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
            self.sensor.residual_own(&self.pred, y, own, ri);
            finite &= ri.iter().all(|v| v.is_finite());
            if let Some(j) = jac.as_deref_mut() {
                self.sensor
                    .residual_rows(&end, own, &self.motions, y, &mut self.block, n);
                self.sensor
                    .own_rows_of(&end, own, y, &mut self.block[p..], n);
                for c in 0..t {
                    for k in 0..n {
                        let x = self.block[c * n + k];
                        finite &= x.is_finite();
                        j[(t * i + c, k)] = x;
                    }
                }
            }
        }
        finite & self.constraints(own, p, r, jac)
    }
}

impl Calibration<'_> {
    /// The sensor's constraint rows after the poses' (own columns only).
    fn constraints(
        &mut self,
        own: &[f64],
        p: usize,
        r: &mut [f64],
        jac: Option<&mut Mat<f64>>,
    ) -> bool {
        let c = self.sensor.constraint_rows();
        if c == 0 {
            return true;
        }
        let n = self.n_params;
        let first = self.sensor.rows() * self.qs.len();
        let rc = &mut r[first..first + c];
        let Some(j) = jac else {
            self.sensor.constraints(own, rc, None, n);
            return rc.iter().all(|v| v.is_finite());
        };
        self.block[..c * n].fill(0.0);
        self.sensor
            .constraints(own, rc, Some(&mut self.block[p..c * n]), n);
        let mut finite = rc.iter().all(|v| v.is_finite());
        for i in 0..c {
            for k in 0..n {
                let x = self.block[i * n + k];
                finite &= x.is_finite();
                j[(first + i, k)] = x;
            }
        }
        finite
    }
}
