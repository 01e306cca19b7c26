//! The `activecal` command line: robots, forward kinematics, pose pools,
//! scoring, selection, bounds and calibration.

mod cli;

use clap::{Parser, Subcommand};
use cli::basic::{FkArgs, PoolArgs, RobotsArgs};

#[derive(Parser)]
#[command(
    name = "activecal",
    version,
    about = "Pose selection and kinematic calibration for serial robots"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in robots with their parameter tables.
    Robots(RobotsArgs),
    /// Forward kinematics (and identification Jacobian) at one joint vector.
    Fk(FkArgs),
    /// Size of a pose lattice, or the index and angles of one lattice pose.
    Pool(PoolArgs),
}

fn main() {
    let cli = Cli::parse();
    let r = match cli.command {
        Command::Robots(a) => cli::basic::cmd_robots(a),
        Command::Fk(a) => cli::basic::cmd_fk(a),
        Command::Pool(a) => cli::basic::cmd_pool(a),
    };
    if let Err(e) = r {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
