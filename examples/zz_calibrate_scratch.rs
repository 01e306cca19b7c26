// Scratch driver for src/cli/calibrate.rs until it is wired into main.rs. Not for commit.
#[path = "../src/cli/calibrate.rs"]
mod calibrate;
use activecal::robot::Robot;
use anyhow::Result;
use clap::Parser;
use serde_json::Value;
pub fn load_robot(name: &str) -> Result<Robot> {
    let r = Robot::builtin(name)?;
    r.validate()?;
    Ok(r)
}
pub fn emit(json_out: bool, value: &Value, text: impl FnOnce() -> String) {
    if json_out {
        println!("{value}");
    } else {
        print!("{}", text());
    }
}
#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    a: calibrate::CalibrateArgs,
}
fn main() {
    if let Err(e) =
        calibrate::cmd_calibrate(Cli::parse_from(std::env::args().filter(|a| a != "calibrate")).a)
    {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
