//! `verify`: Pinocchio / MuJoCo cross-checks of activecal (feature `live`).
//!
//! ```sh
//! cargo run -p verify --features live -- regen [--out DIR]   # rewrite fixtures/
//! cargo run -p verify --features live -- check [--json]      # print deviations
//! ```
//!
//! Build with `PYO3_PYTHON=$PWD/.venv/bin/python` (scripts/test does).

use activecal::model::ParamSet;
use anyhow::{Result, bail};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use verify::bridge::Bridge;
use verify::check::{check_live, regenerate};
use verify::{TOLERANCE, builtin_robots, fixture, synthetic_robot};

const USAGE: &str = "usage: verify regen [--out DIR] | verify check [--json]";

fn main() -> ExitCode {
    match run(std::env::args().skip(1).collect()) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("verify: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: Vec<String>) -> Result<bool> {
    let Some((cmd, rest)) = args.split_first() else {
        bail!("{USAGE}");
    };
    match (cmd.as_str(), rest) {
        ("regen", []) => regen(fixture::default_dir()),
        ("regen", [flag, dir]) if flag == "--out" => regen(PathBuf::from(dir)),
        ("check", []) => check(false),
        ("check", [flag]) if flag == "--json" => check(true),
        _ => bail!("{USAGE}"),
    }
}

fn regen(dir: PathBuf) -> Result<bool> {
    let bridge = Bridge::new()?;
    for path in regenerate(&bridge, &dir)? {
        let size = std::fs::metadata(&path)?.len();
        println!("wrote {} ({size} bytes)", path.display());
    }
    Ok(true)
}

fn check(json: bool) -> Result<bool> {
    let start = Instant::now();
    let bridge = Bridge::new()?;
    let mut robots = builtin_robots()?;
    robots.push(synthetic_robot());
    let mut reports = Vec::new();
    for robot in &robots {
        for set in [ParamSet::Nominal, ParamSet::Real] {
            reports.push(check_live(&bridge, robot, set)?);
        }
    }
    let ok = reports.iter().all(|r| r.passed(TOLERANCE));
    if json {
        let out = serde_json::json!({
            "versions": bridge.versions(),
            "tolerance": TOLERANCE,
            "passed": ok,
            "reports": reports,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        let v = bridge.versions();
        println!(
            "Python {}, numpy {}, Pinocchio {}, MuJoCo {}; tolerance {TOLERANCE:e}",
            v.python, v.numpy, v.pinocchio, v.mujoco
        );
        for r in &reports {
            print!("{r}");
        }
        println!(
            "{} in {:.2} s",
            if ok { "PASSED" } else { "FAILED" },
            start.elapsed().as_secs_f64()
        );
    }
    Ok(ok)
}
