//! `reproduce`: the paper's §V experiment end to end — random baseline, EAE
//! with the determinant and with the eigenvalue OI, multi-start with Fedorov
//! polish, the relaxation bound, and the calibration simulation — written as
//! a Markdown report, a JSON summary and figures. The pipeline is
//! [`activecal::experiment::paper`]; this file parses the arguments, shows
//! progress and writes the staged folder.

use activecal::experiment::paper::{self, PaperSettings};
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
    let mut files = super::run_files::RunFiles::new();
    files.dir("--out", Some(a.out.as_path()));
    super::run_files::check(&files, a.force)?;
    let clock = Instant::now();
    paper::folder::reproduce_into(&a.out, &settings)?;
    let out = &a.out;
    super::print_out(&format!(
        "wrote {}/report.md, report.json and figures in {:.1} s\n",
        out.display(),
        clock.elapsed().as_secs_f64()
    ))
}
