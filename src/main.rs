//! The `activecal` command line: robots, forward kinematics, pose pools,
//! scoring, selection, bounds and calibration.

use activecal::kinematics::{Evaluator, position_checked};
use activecal::pool::Lattice;
use activecal::robot::{ParamSet, Robot};
use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use serde_json::{Value, json};

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

#[derive(Args)]
struct RobotsArgs {
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct FkArgs {
    /// Robot name (built-in).
    #[arg(long, default_value = "puma560")]
    robot: String,
    /// Parameter set: nominal or real.
    #[arg(long, default_value = "nominal")]
    params: String,
    /// Joint angles, comma separated (radians, or degrees with --deg).
    #[arg(long, allow_hyphen_values = true)]
    q: String,
    /// Angles are in degrees.
    #[arg(long)]
    deg: bool,
    /// Also print the identification Jacobian (3 × p).
    #[arg(long)]
    jacobian: bool,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct PoolArgs {
    /// Robot name (built-in).
    #[arg(long, default_value = "puma560")]
    robot: String,
    /// Lattice values per joint.
    #[arg(long, default_value_t = 5)]
    levels: usize,
    /// Lattice digits of one pose (joint 1 first), comma separated.
    #[arg(long)]
    digits: Option<String>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

fn parse_list<T: std::str::FromStr>(s: &str, what: &str) -> Result<Vec<T>>
where
    T::Err: std::fmt::Display,
{
    s.split(',')
        .map(|x| {
            let x = x.trim();
            x.parse::<T>()
                .map_err(|e| anyhow::anyhow!("{what}: cannot parse '{x}': {e}"))
        })
        .collect()
}

fn load_robot(name: &str) -> Result<Robot> {
    let r = Robot::builtin(name)?;
    r.validate()?;
    Ok(r)
}

fn emit(json_out: bool, value: &Value, text: impl FnOnce() -> String) {
    if json_out {
        println!("{value}");
    } else {
        print!("{}", text());
    }
}

fn cmd_robots(a: RobotsArgs) -> Result<()> {
    let robots: Vec<Value> = activecal::robot::BUILTIN
        .iter()
        .map(|n| {
            let r = Robot::builtin(n).expect("built-in");
            json!({
                "name": r.name,
                "dof": r.dof(),
                "frames": r.frames,
                "real": r.real.rows,
                "nominal": r.nominal.rows,
                "unknowns": r.parameter_names(),
                "limits_deg": r.limits.iter().map(|l| [l[0].to_degrees(), l[1].to_degrees()]).collect::<Vec<_>>(),
                "measurement": r.measurement,
            })
        })
        .collect();
    let v = json!({ "robots": robots });
    emit(a.json, &v, || {
        let mut s = String::new();
        for n in activecal::robot::BUILTIN {
            let r = Robot::builtin(n).expect("built-in");
            s += &format!(
                "{} ({} joints, {} unknowns)\n",
                r.name,
                r.dof(),
                r.n_unknowns()
            );
            s += "frame  conv    joint       gamma       alpha           a           d        beta   (real | nominal)\n";
            for (i, f) in r.frames.iter().enumerate() {
                for (tag, t) in [("real", &r.real), ("nom ", &r.nominal)] {
                    let row = t.rows[i];
                    s += &format!(
                        "{:>5}  {:<6}  {:>5} {tag} {:>10.4}  {:>10.4}  {:>10.4}  {:>10.4}  {:>10.4}\n",
                        f.label,
                        format!("{:?}", f.convention),
                        f.joint.map_or("-".into(), |j| format!("q{}", j + 1)),
                        row[0],
                        row[1],
                        row[2],
                        row[3],
                        row[4]
                    );
                }
            }
            s += &format!("unknowns: {}\n", r.parameter_names().join(" "));
        }
        s
    });
    Ok(())
}

fn cmd_fk(a: FkArgs) -> Result<()> {
    let robot = load_robot(&a.robot)?;
    let set = ParamSet::parse(&a.params)?;
    let mut q: Vec<f64> = parse_list(&a.q, "--q")?;
    if a.deg {
        q.iter_mut().for_each(|v| *v = v.to_radians());
    }
    let table = robot.params(set);
    let p = position_checked(&robot, table, &q)?;
    let mut v = json!({ "robot": robot.name, "params": set, "q": q, "position": [p.x, p.y, p.z] });
    let mut jac = vec![0.0; 3 * robot.n_unknowns()];
    if a.jacobian {
        Evaluator::new(&robot, table).eval(&q, &mut jac);
        let n = robot.n_unknowns();
        v["jacobian"] = json!(jac.chunks(n).collect::<Vec<_>>());
        v["parameter_names"] = json!(robot.parameter_names());
    }
    emit(a.json, &v, || {
        let mut s = format!("position: {:.12} {:.12} {:.12}\n", p.x, p.y, p.z);
        if a.jacobian {
            let n = robot.n_unknowns();
            for (c, name) in robot.parameter_names().iter().enumerate() {
                s += &format!(
                    "{name:>8}: {:>14.8} {:>14.8} {:>14.8}\n",
                    jac[c],
                    jac[n + c],
                    jac[2 * n + c]
                );
            }
        }
        s
    });
    Ok(())
}

fn cmd_pool(a: PoolArgs) -> Result<()> {
    let robot = load_robot(&a.robot)?;
    let lattice = Lattice::new(&robot, a.levels)?;
    let mut v = json!({ "robot": robot.name, "levels": a.levels, "size": lattice.size() });
    if let Some(d) = &a.digits {
        let digits: Vec<usize> = parse_list(d, "--digits")?;
        let index = lattice.index_of(&digits)?;
        v["index"] = json!(index);
        v["digits"] = json!(digits);
        v["q"] = json!(lattice.q(index)?);
    }
    emit(a.json, &v, || {
        let mut s = format!(
            "lattice: {} levels per joint, {} poses\n",
            a.levels,
            lattice.size()
        );
        if let Some(i) = v.get("index") {
            s += &format!("index: {i}\nq (rad): {}\n", v["q"]);
        }
        s
    });
    Ok(())
}

fn main() {
    let cli = Cli::parse();
    let r = match cli.command {
        Command::Robots(a) => cmd_robots(a),
        Command::Fk(a) => cmd_fk(a),
        Command::Pool(a) => cmd_pool(a),
    };
    if let Err(e) = r {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
