//! Temporary harness: compiles src/cli/bound.rs outside main.rs.
#![allow(dead_code, unused_imports)]
#[path = "../src/cli/mod.rs"]
mod cli;
#[path = "../src/cli/bound.rs"]
mod bound_cli;
use clap::{Parser, Subcommand};
use cli::{PoolOpts, emit};

#[derive(Parser)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}
#[derive(Subcommand)]
enum Command {
    Bound(bound_cli::BoundArgs),
    Gap(bound_cli::GapArgs),
}
fn main() {
    let r = match Cli::parse().command {
        Command::Bound(a) => bound_cli::cmd_bound(a),
        Command::Gap(a) => bound_cli::cmd_gap(a),
    };
    if let Err(e) = r {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
