//! Every option of `calibrate`, `evaluate` and `select`, as clap defines it, with every
//! sensor: the table decides it, and an option the table says does not act
//! on a sensor is refused before any work, naming the option (by clap, or
//! by the same check `main` runs). A new option without a row fails here.

use super::{CALIBRATE, EVALUATE, SELECT, Sensor, Table, check};
use crate::{Cli, Command};
use clap::{ArgAction, CommandFactory, FromArgMatches};

/// The command line of each sensor, without the options under test. A
/// camera's is without `--mounting` (`--camera-link` conflicts with it).
fn bases(contacts: &str) -> Vec<(&'static str, Sensor, Vec<String>)> {
    let v = |s: &[&str]| s.iter().map(|x| (*x).to_string()).collect::<Vec<_>>();
    let pose = "0,0,0,0,0,0";
    vec![
        ("calibrate", Sensor::Simulated, v(&["--design", "d.json"])),
        ("calibrate", Sensor::Points, v(&["--measurements", "m.csv"])),
        ("calibrate", Sensor::Poses, v(&["--measurements", "m.csv"])),
        (
            "calibrate",
            Sensor::Contacts,
            v(&["--measurements", contacts]),
        ),
        (
            "calibrate",
            Sensor::Pixels,
            v(&[
                "--observations",
                "o.csv",
                "--camera-info",
                "c.yaml",
                "--target",
                "t.yaml",
            ]),
        ),
        (
            "calibrate",
            Sensor::Images,
            v(&[
                "--images",
                "shots",
                "--joints",
                "j.csv",
                "--camera-info",
                "c.yaml",
                "--target",
                "t.yaml",
            ]),
        ),
        (
            "calibrate",
            Sensor::BagPoints,
            v(&["--bag", "b.mcap", "--points", "/tracker"]),
        ),
        (
            "calibrate",
            Sensor::BagPoses,
            v(&["--bag", "b.mcap", "--poses", "/mocap"]),
        ),
        (
            "calibrate",
            Sensor::BagImages,
            v(&[
                "--bag",
                "b.mcap",
                "--images",
                "/camera/image",
                "--camera-info",
                "/camera/camera_info",
                "--target",
                "t.yaml",
            ]),
        ),
        (
            "evaluate",
            Sensor::Points,
            v(&["--robot", "puma560", "--measurements", "m.csv"]),
        ),
        (
            "evaluate",
            Sensor::Contacts,
            v(&["--robot", "puma560", "--measurements", contacts]),
        ),
        ("select", Sensor::Pool, v(&[])),
        ("select", Sensor::Sockets, v(&["--point", "a=0.4,0,0.3"])),
        (
            "select",
            Sensor::Camera,
            v(&[
                "--camera-info",
                "c.yaml",
                "--target",
                "t.yaml",
                "--camera-pose",
                pose,
                "--target-pose",
                pose,
            ]),
        ),
    ]
}

/// A valid value of an option that takes one and offers no list of
/// values, and the options it needs given with it (`requires`).
fn sample(command: &str, id: &str) -> Option<(&'static [&'static str], &'static str)> {
    Some(match (command, id) {
        (_, "base") => (&[], "base_link"),
        (_, "tip") => (&[], "tool0"),
        (_, "lock") => (&[], "j=0"),
        (_, "frames") => (&[], "f.yaml"),
        (_, "kinematics") => (&[], "k.yaml"),
        (_, "markers") => (&[], "tool0@0,0,0.1"),
        (_, "robot") => (&[], "puma560"),
        (_, "out") => (&[], "o.json"),
        (_, "seed") => (&[], "2"),
        (_, "noise") => (&[], "0.001"),
        (_, "report") => (&[], "rep"),
        (_, "point_distance") => (&[], "a,b=0.1"),
        (_, "target") => (&[], "t.yaml"),
        (_, "camera_info") => (&[], "c.yaml"),
        (_, "camera_link") => (&[], "head"),
        (_, "camera_pose" | "target_pose") => (&[], "0,0,0,0,0,0"),
        ("calibrate", "design") => (&[], "d.json"),
        ("calibrate", "measurements" | "observations") => (&[], "m.csv"),
        ("calibrate", "images") => (&["--joints", "j.csv"], "shots"),
        // --images needs --joints, --bag not: given alone, it is refused
        // by clap for the sensors other than these two.
        ("calibrate", "joints") => (&[], "j.csv"),
        ("calibrate", "bag") => (&["--points", "/tracker"], "b.mcap"),
        ("calibrate", "points" | "poses") => (&["--bag", "b.mcap"], "/t"),
        ("calibrate", "tf") => (&["--bag", "b.mcap"], "world:marker"),
        ("calibrate", "time_offset" | "max_offset" | "rest_speed" | "rest_min" | "settle") => {
            (&["--bag", "b.mcap"], "0.1")
        }
        ("calibrate", "bag_design") => (&["--bag", "b.mcap"], "d.csv"),
        ("calibrate", "design_tolerance") => {
            (&["--bag", "b.mcap", "--bag-design", "d.csv"], "0.02")
        }
        ("calibrate", "save_observations") => (&[], "s.csv"),
        ("calibrate", "save_measurements") => (&[], "s.json"),
        ("calibrate", "trials" | "validation" | "max_iterations") => (&[], "3"),
        ("calibrate", "loss_scale") => (&[], "0.01"),
        ("calibrate", "outlier_rate") => (&[], "0.05"),
        ("calibrate", "orientation_noise") => (&[], "0.001"),
        ("calibrate", "pixel_noise") => (&[], "0.3"),
        ("calibrate", "fix" | "free") => (&[], "d_2"),
        ("calibrate", "holdout") => (&[], "0.2"),
        ("calibrate", "splits") => (&["--holdout", "0.2"], "3"),
        ("calibrate", "orientation_scale") => (&[], "0.5"),
        (_, "plane") => (&[], "p=0,0,1,0"),
        ("calibrate", "train_on") => (&[], "left"),
        ("calibrate", "inertia") => (&[], "i.urdf"),
        ("calibrate", "payload") => (&[], "1.5"),
        ("calibrate", "out_camera_info") => (&["--refine-intrinsics"], "r.yaml"),
        ("select", "pool") => (&[], "random"),
        ("select", "levels" | "initial" | "kick" | "ils" | "starts") => (&[], "3"),
        ("select", "count" | "designs" | "n" | "pool_seed") => (&[], "40"),
        ("select", "visibility") => (&[], r#"{"kind":"box","min":[-9,-9,-9],"max":[9,9,9]}"#),
        ("select", "srdf") => (&[], "s.srdf"),
        ("select", "package_dirs") => (&[], "pkg"),
        ("select", "obstacles") => (&[], "box:0,0,-1,1,1,0.1"),
        ("select", "floor" | "margin" | "clearance") => (&[], "0.5"),
        ("select", "fixed") => (&[], "1,2"),
        ("select", "existing") => (&[], "e.csv"),
        ("select", "refine_sweeps") => (&["--refine"], "2"),
        ("select", "home") => (&[], "0,0,0,0,0,0"),
        ("select", "target_error") => (&["--report", "rep"], "0.5"),
        ("select", "orientation_noise") => (&[], "0.01"),
        ("select", "points") => (&[], "a=0.4,0,0.3"),
        ("select", "min_visible") => (&[], "0.5"),
        ("select", "image_margin" | "max_view_angle" | "pixel_noise") => (&[], "5"),
        ("select", "distance") => (&[], "0.2,2"),
        _ => return None,
    })
}

/// Extra options (`requires`) of flags.
fn flag_needs(command: &str, id: &str) -> &'static [&'static str] {
    match (command, id) {
        ("calibrate", "compare_pruned" | "compare_compliance") => &["--holdout", "0.2"],
        ("calibrate", "refine_intrinsics") => &[],
        ("select", "gap_solver") => &["--gap"],
        _ => &[],
    }
}

/// The options of a subcommand as clap defines them (global ones
/// included), but `--help` and `--version`.
fn options(root: &clap::Command, command: &str) -> Vec<clap::Arg> {
    root.find_subcommand(command)
        .unwrap()
        .get_arguments()
        .filter(|a| !matches!(a.get_id().as_str(), "help" | "version"))
        .cloned()
        .collect()
}

/// The arguments that give `arg` a valid value (and what it requires).
fn argv_of(command: &str, arg: &clap::Arg) -> Vec<String> {
    let id = arg.get_id().as_str();
    let long = format!("--{}", arg.get_long().unwrap());
    let (needs, value): (&[&str], Option<String>) =
        if matches!(arg.get_action(), ArgAction::SetTrue) {
            (flag_needs(command, id), None)
        } else if let Some((needs, v)) = sample(command, id) {
            (needs, Some(v.to_string()))
        } else {
            let values = arg.get_possible_values();
            let v = values
                .last()
                .unwrap_or_else(|| panic!("{command} {long}: give it a sample value in sample()"));
            (flag_needs(command, id), Some(v.get_name().to_string()))
        };
    let mut argv: Vec<String> = needs.iter().map(|s| (*s).to_string()).collect();
    argv.push(long);
    argv.extend(value);
    argv
}

/// `extra` without the options (and their values) `base` gives already
/// (an option's needs that the base line holds).
fn without_given(base: &[String], extra: Vec<String>) -> Vec<String> {
    let mut out = Vec::new();
    let mut it = extra.into_iter().peekable();
    while let Some(w) = it.next() {
        if w.starts_with("--") && base.contains(&w) {
            if it.peek().is_some_and(|v| !v.starts_with("--")) {
                it.next();
            }
            continue;
        }
        out.push(w);
    }
    out
}

fn table(command: &str) -> &'static Table {
    match command {
        "calibrate" => CALIBRATE,
        "evaluate" => EVALUATE,
        _ => SELECT,
    }
}

#[test]
fn every_option_of_calibrate_evaluate_and_select_has_a_row_and_every_row_an_option() {
    let mut root = Cli::command();
    root.build();
    for command in ["calibrate", "evaluate", "select"] {
        let args = options(&root, command);
        for a in &args {
            let id = a.get_id().as_str();
            assert!(
                table(command).iter().any(|r| r.id == id),
                "{command} --{}: no row in acts_on's table (decide which sensors it acts on)",
                a.get_long().unwrap_or(id)
            );
        }
        for r in table(command).iter() {
            assert!(
                args.iter().any(|a| a.get_id() == r.id),
                "{command}: the row '{}' names no option",
                r.id
            );
            assert!(!r.acts_on.is_empty(), "{command} {}: acts on nothing", r.id);
        }
    }
}

/// Parses `argv` and runs the checks `main` runs before any work (for
/// points and full poses, the one `calibrate` runs on the file's data).
fn refusal(argv: &[String], sensor: Sensor) -> Option<String> {
    let m = match Cli::command().try_get_matches_from(argv) {
        Ok(m) => m,
        Err(e) => return Some(e.render().to_string()),
    };
    let mut cli = Cli::from_arg_matches(&m).unwrap();
    cli.command.record_given(&m);
    if let Err(e) = cli.command.refuse_unused_options() {
        return Some(format!("{e:#}"));
    }
    match (&cli.command, sensor) {
        (Command::Calibrate(a), Sensor::Points | Sensor::Poses) => {
            check(CALIBRATE, &a.given, &[sensor])
                .err()
                .map(|e| e.to_string())
        }
        _ => None,
    }
}

#[test]
fn every_option_acts_on_a_sensor_or_is_refused_naming_it() {
    let dir = std::env::temp_dir().join(format!("activecal_acts_on_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let contacts = dir.join("contacts.csv");
    std::fs::write(&contacts, "point,q1,q2,q3,q4,q5,q6\na,0,0,0,0,0,0\n").unwrap();
    let mut root = Cli::command();
    root.build();
    let (mut acting, mut refused) = (0, 0);
    for (command, sensor, base) in bases(contacts.to_str().unwrap()) {
        let line = |extra: &[String]| -> Vec<String> {
            let mut v = vec!["activecal".to_string(), command.to_string()];
            v.extend(base.iter().cloned());
            v.extend(extra.iter().cloned());
            v
        };
        assert_eq!(refusal(&line(&[]), sensor), None, "{command} {base:?}");
        for arg in options(&root, command) {
            let long = format!("--{}", arg.get_long().unwrap());
            // The option that gives the sensor; on a pool's line, one that
            // gives another (the line is then that sensor's).
            let defines = matches!(arg.get_id().as_str(), "points" | "camera_info");
            // A bag's measurement options give its sensor (their conflicts
            // are clap's).
            let bag_defines = matches!(arg.get_id().as_str(), "points" | "poses" | "tf")
                && matches!(sensor, Sensor::BagPoints | Sensor::BagPoses);
            // --bag on an --images line brings a bag's measurement
            // (--points): a bag's images line is its own base's.
            let bag_on_images = arg.get_id() == "bag" && sensor == Sensor::Images;
            if base.contains(&long)
                || (defines && sensor == Sensor::Pool)
                || bag_defines
                || bag_on_images
            {
                continue;
            }
            let extra = without_given(&base, argv_of(command, &arg));
            let rule = table(command)
                .iter()
                .find(|r| r.id == arg.get_id().as_str())
                .unwrap();
            // A bag's option on an --images line brings its --bag: the line
            // is then a bag's images.
            let sensor = if sensor == Sensor::Images && extra.iter().any(|w| w == "--bag") {
                Sensor::BagImages
            } else {
                sensor
            };
            let got = refusal(&line(&extra), sensor);
            if rule.acts_on.contains(&sensor) {
                acting += 1;
                assert_eq!(got, None, "{command} {long} acts on {sensor:?}: {extra:?}");
            } else {
                refused += 1;
                let msg = got.unwrap_or_else(|| {
                    panic!("{command} {base:?} {extra:?}: accepted, but {long} does not act on {sensor:?}")
                });
                // The option, or the option it needs (refused too).
                let named = extra.iter().filter(|w| w.starts_with("--"));
                assert!(
                    named.clone().any(|w| [":", " ", "\n"]
                        .iter()
                        .any(|end| msg.contains(&format!("{w}{end}")))
                        || msg.contains(&format!("'{w}"))),
                    "{command} {long} with {sensor:?}: the refusal names none of {extra:?}: {msg}"
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    // Both kinds occur: the loop is not vacuous.
    assert!(
        acting > 100 && refused > 100,
        "{acting} acting, {refused} refused"
    );
}

#[test]
fn a_refusal_names_the_option_and_the_sensor() {
    let given = super::Given(vec![
        ("loss".into(), "--loss".into()),
        ("json".into(), "--json".into()),
        ("fix".into(), "--fix".into()),
    ]);
    let e = check(CALIBRATE, &given, &[Sensor::Pixels])
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("--loss: not used with --observations (a camera's pixels); the camera fit is least squares"),
        "{e}"
    );
    assert!(e.contains("\n--fix: not used with --observations"), "{e}");
    assert!(!e.contains("--json"), "{e}");
    let unknown = super::Given(vec![("nothing".into(), "--nothing".into())]);
    let e = check(SELECT, &unknown, &[Sensor::Pool])
        .unwrap_err()
        .to_string();
    assert!(e.contains("--nothing: not decided"), "{e}");
}
