//! The paper's Tables III (estimates) and IV (residuals) for a design: one
//! simulated calibration, laid out one row per frame and one column per symbol.

use super::Result;
use super::lm::{Identification, LmSettings, identify};
use super::simulate::{simulate, trial_rng};
use crate::data::Measurements;
use crate::model::{ParamId, Robot, Symbol};
use serde::Serialize;

/// Values laid out like the paper's parameter tables: one row per frame that
/// has an unknown, columns `γ α a d β`; `None` where the frame's symbol is not
/// an unknown.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamGrid {
    /// Frame labels, one per row.
    pub frames: Vec<String>,
    /// Column names (`gamma`, `alpha`, `a`, `d`, `beta`).
    pub symbols: Vec<String>,
    /// One row per frame.
    pub rows: Vec<[Option<f64>; 5]>,
}

impl ParamGrid {
    /// Lays out one value per unknown (in the robot's order; the values of
    /// marker offsets that may follow are not part of the grid).
    #[must_use]
    pub fn from_unknowns(robot: &Robot, values: &[f64]) -> ParamGrid {
        assert!(values.len() == robot.n_unknowns() || values.len() == robot.n_params());
        let frames: Vec<usize> = {
            let mut f: Vec<usize> = robot.unknowns.iter().map(|u| u.frame).collect();
            f.dedup();
            f
        };
        let rows = frames
            .iter()
            .map(|&f| {
                let mut row = [None; 5];
                for s in Symbol::ALL {
                    let id = ParamId {
                        frame: f,
                        symbol: s,
                    };
                    if let Some(k) = robot.unknowns.iter().position(|&u| u == id) {
                        row[s.column()] = Some(values[k]);
                    }
                }
                row
            })
            .collect();
        ParamGrid {
            frames: frames
                .iter()
                .map(|&f| robot.frames[f].label.clone())
                .collect(),
            symbols: Symbol::ALL.iter().map(|s| s.name().to_string()).collect(),
            rows,
        }
    }

    /// The grid as an aligned text table with `decimals` decimals; cells that
    /// are not unknowns print as `-`.
    #[must_use]
    pub fn to_text(&self, decimals: usize) -> String {
        let w = decimals + 6;
        let lw = self
            .frames
            .iter()
            .map(|l| l.chars().count())
            .fold(5, usize::max);
        let mut s = format!("{:>lw$}", "frame");
        for sym in &self.symbols {
            s += &format!(" {sym:>w$}");
        }
        s.push('\n');
        for (label, row) in self.frames.iter().zip(&self.rows) {
            s += &format!("{label:>lw$}");
            for v in row {
                match v {
                    Some(v) => s += &format!(" {v:>w$.decimals$}"),
                    None => s += &format!(" {:>w$}", "-"),
                }
            }
            s.push('\n');
        }
        s
    }
}

/// Tables III and IV (and the standard deviations) of one simulated calibration.
#[derive(Clone, Debug, Serialize)]
pub struct PaperTables {
    /// Noise σ, metres.
    pub sigma: f64,
    /// Seed of the noise (trial 0 of [`trial_rng`]).
    pub seed: u64,
    /// Table III: the estimated unknowns.
    pub estimate: ParamGrid,
    /// Table IV: residuals `real − estimate`.
    pub residual: ParamGrid,
    /// Standard deviations `√(σ̂² (XᵀX)⁻¹)_jj`, when the design has full rank.
    pub std: Option<ParamGrid>,
    /// The full identification result.
    pub identification: Identification,
    /// The simulated measurements it was identified from.
    #[serde(skip)]
    pub measurements: Measurements,
}

/// Simulates measurements of the real robot at `qs` with noise σ = `sigma`
/// (seeded: trial 0 of `seed`), identifies from the nominal parameters, and
/// lays out the estimate (Table III), the residuals `real − estimate`
/// (Table IV; the paper's own Table IV mixes signs and absolute values) and
/// the standard deviations.
pub fn paper_tables(
    robot: &Robot,
    qs: &[Vec<f64>],
    sigma: f64,
    seed: u64,
    lm: &LmSettings,
) -> Result<PaperTables> {
    let meas = simulate(robot, &robot.real, qs, sigma, &mut trial_rng(seed, 0))?;
    let id = identify(robot, &robot.nominal, &meas, lm)?;
    let truth = robot.unknown_values(&robot.real);
    let residual: Vec<f64> = truth.iter().zip(&id.estimate).map(|(t, e)| t - e).collect();
    Ok(PaperTables {
        sigma,
        seed,
        estimate: ParamGrid::from_unknowns(robot, &id.estimate),
        residual: ParamGrid::from_unknowns(robot, &residual),
        std: id
            .covariance
            .as_ref()
            .map(|c| ParamGrid::from_unknowns(robot, &c.std)),
        identification: id,
        measurements: meas,
    })
}
