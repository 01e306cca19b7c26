//! `select`'s visiting order and design outputs: the poses in the order to
//! measure them, written in the robot's terms (.json, .csv, .yaml).

use activecal::io::design::DesignFile;
use activecal::io::design_formats;
use activecal::model::Robot;
use anyhow::{Result, bail};

/// Parses `--home`: one finite value per joint of `robot`.
pub fn parse_home(text: Option<&str>, robot: &Robot) -> Result<Option<Vec<f64>>> {
    let Some(t) = text else { return Ok(None) };
    let q: Vec<f64> = super::parse_list(t, "--home")?;
    if q.len() != robot.dof() {
        bail!(
            "--home {t}: {} joint values, the robot has {} joints ({})",
            q.len(),
            robot.dof(),
            activecal::io::configurations::joint_names(robot).join(", ")
        );
    }
    if let Some(j) = q.iter().position(|v| !v.is_finite()) {
        bail!("--home {t}: joint {} value {} is not finite", j + 1, q[j]);
    }
    Ok(Some(q))
}

/// Writes the design in the format its extension names (checked before the
/// search too).
pub fn write_design(d: &DesignFile, out: &std::path::Path, force: bool) -> Result<()> {
    // The command's own message for an existing file ("pass --force").
    super::refuse_overwrite(out, force)?;
    design_formats::write(d, out, true)?;
    Ok(())
}
