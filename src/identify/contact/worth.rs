//! Which weakly determined unknowns a contact fit estimates: the rule that
//! depends on what the noise makes them worth.
//!
//! An unknown whose column is nearly a combination of the others (a pivot
//! above the exact-dependence floor [`crate::identify::undetermined::PIVOT_TOL`]
//! but at or below [`super::fit::CONTACT_PIVOT_TOL`]) is determined by the
//! data, but poorly: its estimate's σ grows as the noise does. Estimating
//! it predicts better than fixing it at nominal when its σ is below the
//! error a URDF's origin is expected to carry — [`PRIOR_LENGTH`] and
//! [`PRIOR_ANGLE`], the tolerances of a machined link — since fixing it
//! leaves that error and estimating it leaves σ. Noise-free data make σ
//! vanish, so every determined unknown is estimated and the truth is
//! recovered; on real contacts (σ ≈ 0.2 mm) a wrist's γ with σ of tenths
//! of a radian is fixed, as the constant pivot bar did.

use crate::identify::undetermined::FixedParameter;
use crate::model::{Robot, Symbol};

/// The error a URDF joint origin's length is expected to carry (metres): the
/// upper end of a machined link's tolerance.
pub const PRIOR_LENGTH: f64 = 2e-3;

/// The error a URDF joint origin's angle is expected to carry (radians,
/// 0.3°).
pub const PRIOR_ANGLE: f64 = 5.235_987_755_982_989e-3;

/// The prior error of a parameter of `robot` named `name`: [`PRIOR_ANGLE`]
/// for γ, α, β, [`PRIOR_LENGTH`] for a, d; `None` for another (a
/// compliance, a sensor's own unknown).
#[must_use]
pub fn prior_of(robot: &Robot, name: &str) -> Option<f64> {
    match robot.param_id(name).ok()?.symbol {
        Symbol::Gamma | Symbol::Alpha | Symbol::Beta => Some(PRIOR_ANGLE),
        Symbol::A | Symbol::D => Some(PRIOR_LENGTH),
        Symbol::C => None,
    }
}

/// The weak unknowns (by name) to fix, each with its value at `start` and
/// why, given the estimate's names, start values and σ's of a fit that
/// estimated them all: those whose σ is at or above their prior error, or
/// has none.
#[must_use]
pub fn weak_to_fix(
    robot: &Robot,
    weak: &[String],
    names: &[String],
    start: &[f64],
    std: Option<&[f64]>,
) -> Vec<FixedParameter> {
    weak.iter()
        .filter_map(|w| {
            let k = names.iter().position(|n| n == w)?;
            let prior = prior_of(robot, w)?;
            let sigma = std.map(|s| s[k]);
            let (unit, scale) = if prior == PRIOR_ANGLE {
                ("°", 180.0 / std::f64::consts::PI)
            } else {
                (" mm", 1e3)
            };
            let reason = match sigma {
                Some(s) if s < prior => return None,
                Some(s) => format!(
                    "weakly determined by these data: its σ {:.3}{unit} would exceed the {:.3}{unit} a joint origin is expected to be off by, so nominal predicts better",
                    s * scale,
                    prior * scale
                ),
                None => "weakly determined by these data (no covariance with it estimated)".into(),
            };
            Some(FixedParameter {
                name: w.clone(),
                value: start[k],
                reason,
            })
        })
        .collect()
}
