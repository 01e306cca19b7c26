//! `--existing FILE`: poses measured before a selection, read (joint
//! configurations, measurements or a design) into their prior information.

use activecal::model::{ParamSet, Robot};
use anyhow::Result;

/// Poses measured before a selection (`--existing`): their prior
/// information `M0` and its report.
pub struct Existing {
    /// `M0 = Σ XᵢᵀXᵢ` of the poses, at the pool's parameters.
    pub prior: activecal::criterion::Prior,
    /// What the file held.
    pub report: activecal::report::ExistingReport,
    /// Their joint values (a design file stores them).
    pub qs: Vec<Vec<f64>>,
}

/// Reads the poses of `--existing FILE` (a CSV or JSON of joint
/// configurations, a JSON measurement file or a design file: the same
/// reader as `--pool file:…`; or a design written as YAML) and makes their
/// prior information at `params`.
pub fn load_existing(
    path: &std::path::Path,
    robot: &Robot,
    params: ParamSet,
    units: activecal::units::Units,
) -> Result<Existing> {
    use activecal::io::design_formats::DesignFormat;
    use anyhow::Context;
    if DesignFormat::of(path).ok() == Some(DesignFormat::Yaml) {
        // A design written as YAML: its joint values.
        let d = activecal::io::design::DesignFile::read(path)
            .and_then(|d| d.joint_values(robot))
            .map_err(|e| anyhow::anyhow!("--existing {}: {e}", path.display()))?;
        return existing_from(path.display().to_string(), d, Vec::new(), robot, params);
    }
    let c = activecal::pool::read_configurations_in(path, robot, units).context("--existing")?;
    existing_from(path.display().to_string(), c.qs, c.notes, robot, params)
}

/// The prior information of poses `qs` (from `file`) at `params`.
pub fn existing_from(
    file: String,
    qs: Vec<Vec<f64>>,
    notes: Vec<String>,
    robot: &Robot,
    params: ParamSet,
) -> Result<Existing> {
    activecal::resources::MemoryBudget::from_env()?.check(
        &format!("the Jacobian of {} existing poses", qs.len()),
        activecal::pool::memory_estimate(robot, qs.len()),
    )?;
    if let Some(k) = qs.iter().position(|q| q.len() != robot.dof()) {
        anyhow::bail!(
            "{file}: existing pose {} has {} joint values, the robot {}",
            k + 1,
            qs[k].len(),
            robot.dof()
        );
    }
    let x = activecal::blocks::jacobian_of(robot, robot.params(params), qs.len(), |k, q| {
        q.copy_from_slice(&qs[k]);
    });
    let prior = activecal::criterion::Prior::from_blocks(&x)
        .map_err(|e| anyhow::anyhow!("{file}: the existing poses' Jacobian: {e}"))?;
    let report = activecal::report::ExistingReport::new(file, &x, &prior, notes);
    Ok(Existing { prior, report, qs })
}

/// Text lines about the existing poses of a report.
pub fn existing_text(e: &activecal::report::ExistingReport) -> String {
    let mut s = format!(
        "existing: {} poses from {} (rank {}), log10 det M0 {}\n",
        e.poses,
        e.file,
        e.rank,
        e.log10_det
            .map_or("singular (-inf)".to_string(), |v| format!("{v:.4}"))
    );
    for n in &e.notes {
        s += &format!("note: {n}\n");
    }
    s
}
