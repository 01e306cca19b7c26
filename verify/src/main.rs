//! `verify`: Pinocchio / MuJoCo cross-checks of activecal (feature `live`).
//!
//! ```sh
//! cargo run -p verify --features live -- regen [--out DIR]   # rewrite fixtures/
//! cargo run -p verify --features live -- check [--json]      # print deviations
//! ```
//!
//! `regen` writes `fixtures/<robot>_<set>.json` (positions and joint
//! Jacobians) and `fixtures/idjac/<robot>.json` (Pinocchio's
//! finite-difference identification Jacobians, [`verify::idjac`]) and
//! `fixtures/example-robot-data/fk/<arm>.json` (Pinocchio's forward
//! kinematics of the `example-robot-data` arms, [`verify::erd_fk`]) with
//! copies of their URDFs in `fixtures/example-robot-data/`, and
//! `fixtures/export/<case>.json` (Pinocchio's forward kinematics of the
//! calibrated URDFs activecal writes, [`verify::export`]) and
//! `fixtures/gravity/<case>.json` (Pinocchio's gravity torques,
//! [`verify::gravity`]); with `--out DIR`
//! they go to `DIR/idjac/`, `DIR/example-robot-data/` and `DIR/export/`.
//!
//! Build with `PYO3_PYTHON=$PWD/.venv/bin/python` (scripts/test does).

use activecal::model::ParamSet;
use anyhow::{Result, bail};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use verify::bridge::Bridge;
use verify::check::{check_live, regenerate};
use verify::{TOLERANCE, builtin_robots, erd_fk, export, fixture, gravity, idjac, synthetic_robot};

/// Configurations of the identification-Jacobian check.
const IDJAC_CONFIGS: usize = 200;
/// Their seed.
const IDJAC_SEED: u64 = 20_251_117;

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
    let mut paths = regenerate(&bridge, &dir)?;
    paths.extend(idjac::live::regenerate(&bridge, &dir.join("idjac"))?);
    paths.extend(erd_fk::live::regenerate(
        &bridge,
        &dir.join("example-robot-data"),
    )?);
    paths.extend(export::live::regenerate(&bridge, &dir.join("export"))?);
    paths.extend(gravity::live::regenerate(&bridge, &dir.join("gravity"))?);
    for path in paths {
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
    let mut id_reports = Vec::new();
    for source in idjac::sources() {
        let robot = source.robot()?;
        id_reports.push(idjac::live::check(
            &bridge,
            &robot,
            IDJAC_CONFIGS,
            IDJAC_SEED,
        )?);
    }
    let ok = reports.iter().all(|r| r.passed(TOLERANCE))
        && id_reports.iter().all(|r| r.within(idjac::REL_TOL));
    if json {
        let out = serde_json::json!({
            "versions": bridge.versions(),
            "tolerance": TOLERANCE,
            "passed": ok,
            "reports": reports,
            "identification_jacobian_rel_tol": idjac::REL_TOL,
            "identification_jacobian": id_reports,
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
            "identification Jacobian, Pinocchio central differences (h = {:e}) vs activecal, \
             {IDJAC_CONFIGS} configurations, tolerance {:e}·L:",
            idjac::STEP,
            idjac::REL_TOL
        );
        for r in &id_reports {
            println!(
                "  {:<22} {}x{:<3} L {:6.2}  max|ΔJ| {:8.2e}  relative {:8.2e}  orientation rows {:8.2e}  (q#{} row {} {})",
                r.robot,
                r.shape[0],
                r.shape[1],
                r.size,
                r.absolute,
                r.relative,
                r.orientation,
                r.worst.0,
                r.worst.1,
                r.worst.2
            );
        }
        println!(
            "{} in {:.2} s",
            if ok { "PASSED" } else { "FAILED" },
            start.elapsed().as_secs_f64()
        );
    }
    Ok(ok)
}
