//! `reproduce`: the paper's §V experiment end to end — random baseline, EAE
//! with the determinant and with the eigenvalue OI, multi-start with Fedorov
//! polish, the relaxation bound, and the calibration simulation — written as
//! a Markdown report, a JSON summary and figures. The pipeline is
//! [`activecal::experiment::paper`]; this file parses the arguments, shows
//! progress and draws the figures.

use activecal::experiment::paper::{self, PaperReport, PaperSettings};
use activecal::progress::Task;
use activecal::render::paper_figures as figures;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `reproduce`.
#[derive(Args)]
pub struct ReproduceArgs {
    /// Directory for report.md, report.json and the figures.
    #[arg(long, default_value = "reproduce")]
    pub out: PathBuf,
    /// Replace the files of an existing --out directory.
    #[arg(long)]
    pub force: bool,
    /// Lattice values per joint (the paper: 5).
    #[arg(long, default_value_t = 5, allow_negative_numbers = true)]
    pub levels: usize,
    /// Poses per design (the paper: 30).
    #[arg(long, default_value_t = 30, allow_negative_numbers = true)]
    pub n: usize,
    /// Initial EAE poses (the paper: 12).
    #[arg(long, default_value_t = 12, allow_negative_numbers = true)]
    pub initial: usize,
    /// Random designs of the baseline (the paper: 5,000).
    #[arg(long, default_value_t = 5000, allow_negative_numbers = true)]
    pub designs: usize,
    /// Starts of the multi-start EAE.
    #[arg(long, default_value_t = 20, allow_negative_numbers = true)]
    pub starts: usize,
    /// Monte-Carlo calibration trials per design.
    #[arg(long, default_value_t = 200, allow_negative_numbers = true)]
    pub trials: usize,
    /// Measurement noise σ per coordinate, metres (the paper: 1 cm).
    #[arg(long, default_value_t = 0.01, allow_negative_numbers = true)]
    pub noise: f64,
    /// Seed of every random choice.
    #[arg(
        long,
        default_value_t = 1,
        value_parser = super::parse_seed,
        allow_negative_numbers = true
    )]
    pub seed: u64,
    /// Skip the eigenvalue-OI run (slow: an eigen-decomposition per candidate).
    #[arg(long)]
    pub skip_oi: bool,
}

/// The experiment's steps as one progress task ([`activecal::progress`]).
struct Steps {
    task: Task,
}

impl Steps {
    fn new(n: u64) -> Self {
        Self {
            task: Task::start("reproduce", Some(n)),
        }
    }
    fn step(&self, msg: &'static str) {
        self.task.note(|| msg.to_string());
        self.task.inc(1);
    }
}

impl ReproduceArgs {
    fn settings(&self) -> PaperSettings {
        PaperSettings {
            levels: self.levels,
            n: self.n,
            initial: self.initial,
            designs: self.designs,
            starts: self.starts,
            trials: self.trials,
            noise: self.noise,
            seed: self.seed,
            skip_oi: self.skip_oi,
        }
    }
}

/// Runs `reproduce`.
pub fn cmd_reproduce(a: ReproduceArgs) -> Result<()> {
    // Every input is checked before any work or any file is made.
    let settings = a.settings();
    settings.validate()?;
    super::run_files::RunFiles::new()
        .dir("--out", Some(a.out.as_path()))
        .check(a.force)?;
    // Built aside and swapped in whole: an interrupted run leaves the old
    // report as it was, never new figures beside an old report.
    let staged = activecal::io::atomic::StagedDir::new(&a.out)?;
    let clock = Instant::now();
    let steps = Steps::new(paper::STEPS + 2);
    let report = paper::run(&settings, |msg| steps.step(msg))?;
    steps.step("figures");
    let out = staged.path();
    draw_figures(out, &report, a.levels)?;
    steps.step("report");
    std::fs::write(
        out.join("report.json"),
        serde_json::to_string_pretty(&report)? + "\n",
    )?;
    std::fs::write(out.join("report.md"), report.markdown())?;
    staged.commit()?;
    let out = &a.out;
    drop(steps);
    super::print_out(&format!(
        "wrote {}/report.md, report.json and figures in {:.1} s\n",
        out.display(),
        clock.elapsed().as_secs_f64()
    ))
}

/// Figures 2 to 6 of the paper, from the report.
fn draw_figures(out: &std::path::Path, r: &PaperReport, levels: usize) -> Result<()> {
    let f = &r.figures;
    figures::random_designs(&out.join("fig2_random_designs"), &f.random_oi, f.eae_oi)?;
    figures::trace(
        &out.join("fig4_log10_oid"),
        "log10 OI_D per EAE iteration (Fig. 4)",
        "log10 OI_D",
        &[("EAE, det criterion", r.eae.trace_log10_oid.clone())],
    )?;
    let mut oi_series = vec![("EAE, det criterion", f.eae_trace_oi.clone())];
    if let Some(o) = &f.eae_oi_trace_oi {
        oi_series.push(("EAE, eigenvalue-OI criterion", o.clone()));
    }
    figures::trace(
        &out.join("fig5_oi"),
        "OI per EAE iteration (Fig. 5)",
        "OI, eq. (1)",
        &oi_series,
    )?;
    // 1/OI_D spans 20 decades: plotted as its log10 on a linear axis (a log
    // scale with every decade labelled).
    let inv: Vec<f64> = r.eae.trace_log10_oid.iter().map(|v| -v).collect();
    figures::trace(
        &out.join("fig6_inverse_oid"),
        "1/OI_D per EAE iteration, log scale (Fig. 6)",
        "log10 (1/OI_D)",
        &[("EAE", inv)],
    )?;
    figures::poses(
        &out.join("fig3_initial_poses"),
        "the initial EAE poses (Fig. 3)",
        &f.initial_digits,
        levels,
    )?;
    figures::poses(
        &out.join("fig4a_selected_poses"),
        "poses selected by EAE (Fig. 4 A)",
        &f.selected_digits,
        levels,
    )?;
    Ok(())
}
