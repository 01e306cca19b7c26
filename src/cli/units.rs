//! `--angle-unit` and `--length-unit`: the units of the joint values and
//! positions a command reads (measurement files, pool and `--existing`
//! files, `fk --q`), parsed once into the library's typed
//! [`activecal::units::Units`]; and the option a unit error calls for.

use activecal::error::UnitHint;
use activecal::experiment::error::IdentifyError;
use activecal::units::{AngleUnit, LengthUnit, Units};

/// The unit options of every command that reads joint values or positions.
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct UnitOpts {
    /// Unit of the revolute joint values read (files, --q): rad or deg.
    /// Roll, pitch and yaw columns stay radians.
    #[arg(long, value_parser = super::choice::<AngleUnit>(), default_value_t = AngleUnit::Rad)]
    pub angle_unit: AngleUnit,
    /// Unit of the lengths read: measured positions (x1, y1, z1, …) and
    /// prismatic joint values: m or mm.
    #[arg(long, value_parser = super::choice::<LengthUnit>(), default_value_t = LengthUnit::M)]
    pub length_unit: LengthUnit,
}

impl UnitOpts {
    /// The typed units.
    #[must_use]
    pub fn units(&self) -> Units {
        Units {
            angle: self.angle_unit,
            length: self.length_unit,
        }
    }
}

/// The input error inside an identification error, if it is one.
fn model_error(e: &IdentifyError) -> Option<&activecal::Error> {
    match e {
        IdentifyError::Model(m) => Some(m),
        _ => None,
    }
}

/// The option a unit error calls for, if the error (anywhere in its chain)
/// is one: a joint column out of its limits that fits in the other unit, or
/// positions beyond the robot's reach that fit in the other length unit.
#[must_use]
pub fn flag_hint(e: &anyhow::Error) -> Option<&'static str> {
    let hint = e.chain().find_map(|c| {
        let lib = c
            .downcast_ref::<activecal::Error>()
            .or_else(|| c.downcast_ref::<IdentifyError>().and_then(model_error))
            .or_else(|| {
                use activecal::experiment::paper::ExperimentError as E;
                match c.downcast_ref::<E>()? {
                    E::Input(m) => Some(m),
                    E::Identify(i) | E::InFile { error: i, .. } => model_error(i),
                    _ => None,
                }
            })?;
        match lib {
            activecal::Error::JointOutOfLimits { hint, .. }
            | activecal::Error::PositionsBeyondReach { hint, .. }
            | activecal::Error::PositionsTooSmall { hint, .. } => *hint,
            _ => None,
        }
    })?;
    Some(match hint {
        UnitHint::Degrees => "the joint values look like degrees: give --angle-unit deg",
        UnitHint::Radians => "the joint values look like radians: drop --angle-unit deg",
        UnitHint::Millimetres => "the lengths look like millimetres: give --length-unit mm",
        UnitHint::Metres => "the lengths look like metres: drop --length-unit mm",
    })
}
