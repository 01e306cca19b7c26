//! Loader fuzz: 10,000 generated inputs for each file loader — robot
//! descriptions (`io::robot_toml`), URDF (`io::urdf`), design files
//! (`io::design`) and measurement files (`data::Measurements`) — made by
//! mutating valid seeds (the fixtures, and files the library writes): bit
//! flips, random bytes, truncation, numbers replaced by NaN, infinities,
//! 1e300, -0, huge or negative integers and values of the wrong type, and
//! elements duplicated, removed or swapped (on the text, and for JSON on the
//! parsed tree). Every input is loaded in process under `catch_unwind`:
//!
//! - no loader may panic (the failing input is printed);
//! - an error must carry a non-empty message;
//! - whatever loads must be usable: a robot passes `Robot::validate`, a
//!   measurement file that passes `Measurements::check` holds finite values
//!   of the robot's shape, and a design's joint values are finite and of the
//!   robot's joint count.
//!
//! A fixed seed (ChaCha8) makes every run the same; each loader also has to
//! see both outcomes (some inputs load, most do not), or the mutations
//! would be testing nothing.

use activecal::data::Measurements;
use activecal::identify::{simulate, trial_rng};
use activecal::io::design::DesignFile;
use activecal::io::robot_toml;
use activecal::io::urdf::{self, UrdfOptions};
use activecal::model::Robot;
use activecal::pool::Pool;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

/// Inputs per loader.
const CASES: usize = 10_000;

/// Replacements for a number (or any value) in the text.
const SPECIALS: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "Infinity",
    "1e300",
    "-1e300",
    "1e-320",
    "-0",
    "-0.0",
    "0",
    "18446744073709551616",
    "18446744073709551615",
    "-9223372036854775809",
    "99999999999999999999999999",
    "4294967296",
    "-1",
    "2.5",
    "1e6",
    "1e7",
    "\"x\"",
    "true",
    "null",
    "[]",
    "{}",
    "\"\"",
];

fn fixture(path: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(path);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

// ------------------------------------------------------------------ mutation

/// Spans of number-like tokens (`[-+0-9.eE]` runs holding a digit).
fn number_spans(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() || b[i] == b'-' || b[i] == b'.' {
            let s = i;
            while i < b.len() && matches!(b[i], b'0'..=b'9' | b'-' | b'+' | b'.' | b'e' | b'E') {
                i += 1;
            }
            if b[s..i].iter().any(u8::is_ascii_digit) {
                out.push((s, i));
            }
        } else {
            i += 1;
        }
    }
    out
}

/// Positions of element separators (line ends and commas).
fn separators(b: &[u8]) -> Vec<usize> {
    (0..b.len())
        .filter(|&i| b[i] == b'\n' || b[i] == b',')
        .collect()
}

/// A random value to put in a JSON tree.
fn special_value(rng: &mut ChaCha8Rng) -> Value {
    match rng.random_range(0..12) {
        0 => Value::from(1e300),
        1 => Value::from(-0.0),
        2 => Value::from(u64::MAX),
        3 => Value::from(i64::MIN),
        4 => Value::from(1e308),
        5 => Value::Null,
        6 => Value::from(""),
        7 => Value::Array(Vec::new()),
        8 => Value::Object(serde_json::Map::new()),
        9 => Value::from(true),
        10 => Value::from(1.5),
        _ => Value::from(-7),
    }
}

/// Every node of a JSON tree, as paths of keys and indices.
fn paths(v: &Value, here: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    out.push(here.clone());
    match v {
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                here.push(Value::from(i));
                paths(x, here, out);
                here.pop();
            }
        }
        Value::Object(m) => {
            for (k, x) in m {
                here.push(Value::from(k.clone()));
                paths(x, here, out);
                here.pop();
            }
        }
        _ => {}
    }
}

fn node_mut<'a>(v: &'a mut Value, path: &[Value]) -> &'a mut Value {
    path.iter().fold(v, |v, k| match k {
        Value::String(s) => &mut v[s.as_str()],
        k => &mut v[k.as_u64().unwrap() as usize],
    })
}

/// One structural edit of a JSON tree: remove, duplicate or replace a node.
fn mutate_tree(text: &[u8], rng: &mut ChaCha8Rng) -> Option<Vec<u8>> {
    let mut v: Value = serde_json::from_slice(text).ok()?;
    let mut all = Vec::new();
    paths(&v, &mut Vec::new(), &mut all);
    let path = all[rng.random_range(0..all.len())].clone();
    match (path.split_last(), rng.random_range(0..3)) {
        (Some((last, parent)), 0) => match node_mut(&mut v, parent) {
            Value::Array(a) => {
                a.remove(last.as_u64().unwrap() as usize);
            }
            Value::Object(m) => {
                m.remove(last.as_str().unwrap());
            }
            _ => unreachable!("a parent is a container"),
        },
        (Some((last, parent)), 1) => {
            if let Value::Array(a) = node_mut(&mut v, parent) {
                let i = last.as_u64().unwrap() as usize;
                let x = a[i].clone();
                a.insert(i, x);
            }
        }
        _ => *node_mut(&mut v, &path) = special_value(rng),
    }
    Some(serde_json::to_vec(&v).unwrap())
}

/// One to three random edits of `seed`.
fn mutate(seed: &str, rng: &mut ChaCha8Rng, json: bool) -> Vec<u8> {
    let mut b = seed.as_bytes().to_vec();
    for _ in 0..rng.random_range(1..=3) {
        let len = b.len();
        match rng.random_range(0..9) {
            0 if len > 0 => {
                let i = rng.random_range(0..len);
                b[i] ^= 1 << rng.random_range(0..8);
            }
            1 if len > 0 => {
                let i = rng.random_range(0..len);
                b[i] = rng.random::<u8>();
            }
            2 => b.truncate(rng.random_range(0..=len)),
            3 | 4 => {
                let spans = number_spans(&b);
                if !spans.is_empty() {
                    let (s, e) = spans[rng.random_range(0..spans.len())];
                    let with = SPECIALS[rng.random_range(0..SPECIALS.len())];
                    b.splice(s..e, with.bytes());
                }
            }
            5 | 6 => {
                // Duplicate (5) or remove (6) the element between two
                // consecutive separators.
                let seps = separators(&b);
                if seps.len() >= 2 {
                    let k = rng.random_range(0..seps.len() - 1);
                    let (s, e) = (seps[k], seps[k + 1]);
                    if rng.random_range(0..2) == 0 {
                        let part = b[s..e].to_vec();
                        b.splice(e..e, part);
                    } else {
                        b.drain(s..e);
                    }
                }
            }
            7 if json => {
                if let Some(t) = mutate_tree(&b, rng) {
                    b = t;
                }
            }
            7 => {
                // Swap two lines.
                let mut lines: Vec<Vec<u8>> =
                    b.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
                let n = lines.len();
                lines.swap(rng.random_range(0..n), rng.random_range(0..n));
                b = lines.join(&b'\n');
            }
            _ => {
                let i = rng.random_range(0..=len);
                let with = SPECIALS[rng.random_range(0..SPECIALS.len())];
                b.splice(i..i, with.bytes());
            }
        }
    }
    b
}

// ------------------------------------------------------------------ harness

thread_local! {
    /// Set while a fuzz input runs: its panics are caught and reported
    /// with the input, not printed as they happen.
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

fn quiet_panics() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let prev = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                prev(info);
            }
        }));
    });
}

/// What a loader did with one input: loaded it, or refused it with a
/// message; `Err` is a broken promise (described).
type Outcome = Result<bool, String>;

/// A refusal must say something.
fn refused(e: impl std::fmt::Display) -> Outcome {
    let m = e.to_string();
    if m.trim().is_empty() {
        Err("an error with an empty message".into())
    } else {
        Ok(false)
    }
}

/// Runs `load` on [`CASES`] mutations of the seeds (chosen in turn) and
/// fails with the first broken promises, inputs included.
fn fuzz(
    name: &str,
    seeds: &[String],
    rng_seed: u64,
    json: bool,
    load: impl Fn(usize, &str) -> Outcome,
) {
    quiet_panics();
    let mut rng = ChaCha8Rng::seed_from_u64(rng_seed);
    let (mut loaded, mut errors) = (0, 0);
    let mut failures = Vec::new();
    for k in 0..CASES {
        let s = k % seeds.len();
        let text = String::from_utf8_lossy(&mutate(&seeds[s], &mut rng, json)).into_owned();
        QUIET.with(|q| q.set(true));
        let r = catch_unwind(AssertUnwindSafe(|| load(s, &text)));
        QUIET.with(|q| q.set(false));
        let problem = match r {
            Ok(Ok(true)) => {
                loaded += 1;
                None
            }
            Ok(Ok(false)) => {
                errors += 1;
                None
            }
            Ok(Err(m)) => Some(m),
            Err(p) => Some(format!(
                "panicked: {}",
                p.downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| (*s).to_string()))
                    .unwrap_or_default()
            )),
        };
        if let Some(m) = problem {
            failures.push(format!(
                "case {k} (seed {s}): {m}\n--- input ---\n{}\n---",
                text.chars().take(3000).collect::<String>()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{name}: {} of {CASES} inputs broke a promise; the first:\n{}",
        failures.len(),
        failures
            .iter()
            .take(3)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
    // Both outcomes happen: mutations that load prove the seeds are valid
    // and the edits are small; refusals prove the edits reach the checks.
    assert!(
        loaded > 0 && errors > CASES / 10,
        "{name}: {loaded} loaded, {errors} refused"
    );
}

// ------------------------------------------------------------------ loaders

/// A loaded robot must be valid.
fn robot_outcome(r: activecal::Result<Robot>) -> Outcome {
    match r {
        Ok(robot) => match robot.validate() {
            Ok(()) if robot.n_unknowns() > 0 => Ok(true),
            Ok(()) => Err("loaded a robot without unknowns".into()),
            Err(e) => Err(format!("loaded an invalid robot: {e}")),
        },
        Err(e) => refused(e),
    }
}

#[test]
fn robot_descriptions() {
    let mut puma_box = Robot::puma560();
    puma_box.name = "boxed".into();
    let boxed = robot_toml::description_to_toml(
        &puma_box,
        Some(
            &serde_json::from_str(r#"{"kind":"box","min":[-30,-30,-30],"max":[30,30,30]}"#)
                .unwrap(),
        ),
    );
    let seeds = vec![
        fixture("puma560.toml"),
        fixture("scara.toml"),
        fixture("ur5_pose.toml"),
        robot_toml::to_toml(&Robot::builtin("stanford:pose").unwrap()),
        boxed,
    ];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    fuzz("robot TOML", &seeds, 0x5eed_0001, false, |_, text| {
        robot_outcome(robot_toml::parse_description(text, "fuzz.toml", Some(&dir)).map(|d| d.robot))
    });
}

#[test]
fn urdf_files() {
    let seeds = vec![
        fixture("ur5.urdf"),
        fixture("puma560.urdf"),
        fixture("stanford.urdf"),
        fixture("example-robot-data/panda.urdf"),
        fixture("example-robot-data/kinova.urdf"),
        fixture("figaroh/ur10_robot.urdf"),
        fixture("figaroh/tiago.urdf"),
    ];
    let tiago = UrdfOptions {
        tip: Some("arm_tool_link".into()),
        ..UrdfOptions::default()
    };
    let panda = UrdfOptions {
        tip: Some("panda_link8".into()),
        ..UrdfOptions::default()
    };
    fuzz("URDF", &seeds, 0x5eed_0002, false, |s, text| {
        let opts = match s {
            3 => panda.clone(),
            6 => tiago.clone(),
            _ => UrdfOptions::default(),
        };
        robot_outcome(urdf::parse(text, "fuzz.urdf", &opts))
    });
}

#[test]
fn design_files() {
    let puma = Robot::puma560();
    let pool = Pool::full(&puma, 3).unwrap();
    let positions: Vec<usize> = (0..30).map(|k| k * 24).collect();
    let new =
        serde_json::to_string_pretty(&DesignFile::from_pool(&puma, &pool, &positions)).unwrap();
    let mut filtered: Value = serde_json::from_str(&new).unwrap();
    filtered["pool"]["filters"] = serde_json::from_str(
        r#"[{"visibility":{"kind":"cone","apex":[0,0,0],"axis":[0,1,0],"half_angle":0.5,"max_range":40}}]"#,
    )
    .unwrap();
    filtered["algorithm"] = "eae".into();
    // A pool without stored joint values (the lattice gives them): one
    // removal away from a design that names neither.
    let mut no_q: Value = serde_json::from_str(&new).unwrap();
    no_q.as_object_mut().unwrap().remove("q");
    let seeds = vec![
        fixture("designs/puma560_levels3_v0.json"),
        new,
        serde_json::to_string(&filtered).unwrap(),
        serde_json::to_string(&no_q).unwrap(),
    ];
    let small = Pool::full(&puma, 2).unwrap();
    fuzz("design JSON", &seeds, 0x5eed_0003, true, |_, text| {
        let d = match DesignFile::parse(text, "fuzz.json") {
            Ok(d) => d,
            Err(e) => return refused(e),
        };
        if let Err(e) = d.spec() {
            return refused(e);
        }
        match d.joint_values(&puma) {
            Ok(qs) => {
                if qs.len() != d.poses.len()
                    || qs
                        .iter()
                        .any(|q| q.len() != 6 || q.iter().any(|v| !v.is_finite()))
                {
                    return Err("joint values of the wrong shape or not finite".into());
                }
            }
            Err(e) => return refused(e),
        }
        match d.positions_found_in(&puma, &small) {
            Ok(p) if p.iter().all(|&k| k < small.len()) => Ok(true),
            Ok(_) => Err("a position outside the pool".into()),
            Err(e) => refused(e),
        }
    });
}

#[test]
fn measurement_files() {
    let puma = Robot::puma560();
    let ur5 = Robot::builtin("ur5:pose").unwrap();
    let qs = |r: &Robot, n: usize| -> Vec<Vec<f64>> {
        (0..n)
            .map(|k| {
                r.limits
                    .iter()
                    .enumerate()
                    .map(|(j, &[lo, hi])| lo + (hi - lo) * (((k * 7 + j * 3) % 11) as f64 / 10.0))
                    .collect()
            })
            .collect()
    };
    let m_puma = simulate(&puma, &puma.real, &qs(&puma, 8), 0.01, &mut trial_rng(1, 0))
        .unwrap()
        .of_robot("puma560");
    let m_ur5 = simulate(&ur5, &ur5.real, &qs(&ur5, 6), 0.01, &mut trial_rng(1, 0)).unwrap();
    let mut quats: Value = serde_json::to_value(&m_ur5).unwrap();
    quats.as_object_mut().unwrap().remove("orientations");
    quats["quaternions"] = serde_json::to_value([[1.0, 0.0, 0.0, 0.0]; 6]).unwrap();
    let seeds = vec![
        serde_json::to_string(&m_puma).unwrap(),
        serde_json::to_string_pretty(&m_ur5).unwrap(),
        serde_json::to_string(&quats).unwrap(),
    ];
    fuzz("measurements JSON", &seeds, 0x5eed_0004, true, |s, text| {
        let m: Measurements = match serde_json::from_str(text) {
            Ok(m) => m,
            Err(e) => return refused(e),
        };
        let robot = if s == 0 { &puma } else { &ur5 };
        match m.check(robot) {
            Ok(()) => {
                let dof = robot.dof();
                let finite = m
                    .qs()
                    .iter()
                    .all(|q| q.len() == dof && q.iter().all(|v| v.is_finite()))
                    && m.points().iter().flatten().all(|v| v.is_finite())
                    && m.orientations()
                        .iter()
                        .flatten()
                        .flatten()
                        .all(|v| v.is_finite());
                if finite && m.points().len() == m.markers() * m.len() {
                    Ok(true)
                } else {
                    Err("checked measurements hold non-finite values or the wrong shape".into())
                }
            }
            Err(e) => refused(e),
        }
    });
}

#[test]
fn measurement_csv_files() {
    use activecal::io::measurements::parse_csv_measurements;
    let load = |name: &str| activecal::io::load_robot(name).unwrap();
    let tiago = load("fixtures/figaroh/tiago.urdf#tip=arm_tool_link")
        .with_markers(&[
            [0.3, -0.1, 0.0],
            [0.35, -0.15, -0.2],
            [0.45, -0.15, -0.17],
            [0.45, -0.15, -0.17],
        ])
        .unwrap();
    let ur10 = load("fixtures/figaroh/ur10_robot.urdf:pose#tip=wrist_3_link");
    // The first rows of the two real files (a header and 6 postures each).
    let head = |path: &str| -> String {
        fixture(path).lines().take(7).collect::<Vec<_>>().join("\n") + "\n"
    };
    let seeds = vec![
        head("figaroh/tiago_mocap_4markers.csv"),
        head("figaroh/ur10_full_pose.csv"),
    ];
    fuzz("measurements CSV", &seeds, 0x5eed_0005, false, |s, text| {
        let robot = if s == 0 { &tiago } else { &ur10 };
        let f = match parse_csv_measurements(text, "m.csv", robot) {
            Ok(f) => f,
            Err(e) => return refused(e),
        };
        let m = f.measurements;
        let finite = m
            .qs()
            .iter()
            .all(|q| q.len() == robot.dof() && q.iter().all(|v| v.is_finite()))
            && m.points().iter().flatten().all(|v| v.is_finite())
            && m.points().len() == m.markers() * m.len();
        if !finite {
            return Err("a read CSV holds non-finite values or the wrong shape".into());
        }
        // What the reader accepts, the sensor check either accepts or
        // refuses with a message (a marker column lost, say).
        match m.check(robot) {
            Ok(()) => Ok(true),
            Err(e) => refused(e),
        }
    });
}
