//! `reproduce`'s folder: the experiment run ([`super::run`]) and written
//! whole — `report.md`, `report.json` and the figures — into a folder
//! built aside and swapped in at the end, so that an interrupted run leaves
//! the old folder as it was, never new figures beside an old report. Its
//! stages are one progress task ([`crate::progress`]).

use super::{PaperReport, PaperSettings, STEPS, run};
use crate::experiment::ExperimentError;
use crate::io::atomic::StagedDir;
use crate::progress::Task;
use std::path::Path;

/// Runs the experiment of `settings` and writes its folder into `dir`
/// (replaced whole; the caller has checked that it may be); returns the
/// report.
pub fn reproduce_into(
    dir: &Path,
    settings: &PaperSettings,
) -> Result<PaperReport, ExperimentError> {
    settings.validate()?;
    let staged = StagedDir::new(dir)?;
    let task = Task::start("reproduce", Some(STEPS + 2));
    let step = |msg: &'static str| {
        task.note(|| msg.to_string());
        task.inc(1);
    };
    let report = run(settings, step)?;
    step("figures");
    let out = staged.path();
    super::figures::draw_figures(out, &report, settings.levels)?;
    step("report");
    let json = serde_json::to_string_pretty(&report)
        .map_err(|e| crate::Error::Invalid(format!("report.json: {e}")))?;
    crate::io::atomic::write_atomic(&out.join("report.json"), (json + "\n").as_bytes())?;
    crate::io::atomic::write_atomic(&out.join("report.md"), report.markdown().as_bytes())?;
    staged.commit()?;
    Ok(report)
}
