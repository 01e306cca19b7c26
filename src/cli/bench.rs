//! `bench`: medians of the hot paths on the PUMA pool, identification, the
//! relaxation bound by both solvers, and the 10⁶-pose scale run (time and
//! peak memory). The work is in `activecal::experiment::bench`.

use activecal::experiment::bench::{BenchSettings, run};
use anyhow::Result;
use clap::Args;

/// Arguments of `bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Repetitions per measurement (the median is reported).
    #[arg(long, default_value_t = 7, allow_negative_numbers = true)]
    pub reps: usize,
    /// Also run the 10⁶-pose scale test (10 levels per joint, N = 145).
    #[arg(long)]
    pub scale: bool,
    /// Also compare the robots side by side: the certified bound, one EAE
    /// start and the default selection (multi-start with iterated local
    /// search) with its D-efficiency, and each robot's peak memory, on each
    /// robot's 5-level lattice (PUMA, UR5 full pose, and the FIGAROH UR10
    /// and example-robot-data Panda in full pose when run from the
    /// repository, where their URDFs are).
    #[arg(long)]
    pub robots: bool,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// Runs `bench`: each section's timings as rows of one table, in JSON or
/// as text.
pub fn cmd_bench(a: BenchArgs) -> Result<()> {
    if a.reps == 0 {
        anyhow::bail!("--reps 0: the median needs at least 1 repetition");
    }
    let r = run(BenchSettings {
        reps: a.reps,
        scale: a.scale,
        robots: a.robots,
    })?;
    for note in &r.skipped {
        super::diag(&format!("bench: {note}"));
    }
    super::emit_report(a.json, &r, || activecal::render::bench_text::text(&r))
}
