//! The robot-description loader (`activecal::io::robot_toml`) and the URDF
//! importer (`activecal::io::urdf`) never panic: on arbitrary text, on random
//! edits of valid files, and on random robots written by `to_toml`, which
//! must read back to the same kinematics bit for bit when they load at all.
//! Whatever loads is valid and has identifiable unknowns.

use activecal::io::robot_toml as file;
use activecal::io::urdf::{self, UrdfOptions};
use activecal::kinematics::pose;
use activecal::model::{
    Convention, Frame, JointKind, MeasurementKind, ParamId, ParamTable, Robot, Symbol,
};
use proptest::prelude::*;
use std::sync::OnceLock;

fn puma_toml() -> &'static str {
    static T: OnceLock<String> = OnceLock::new();
    T.get_or_init(|| file::to_toml(&Robot::puma560()))
}

fn stanford_toml() -> &'static str {
    static T: OnceLock<String> = OnceLock::new();
    T.get_or_init(|| file::to_toml(&Robot::builtin("stanford:pose").unwrap()))
}

fn puma_urdf() -> &'static str {
    static T: OnceLock<String> = OnceLock::new();
    T.get_or_init(|| {
        let r = Robot::puma560();
        urdf::to_urdf(&r, &r.nominal).unwrap()
    })
}

/// Whatever loads must be a valid robot with identifiable unknowns.
fn check_loaded(r: &Robot) {
    r.validate().unwrap();
    assert!(r.n_unknowns() > 0);
    r.check_identifiable().unwrap();
}

/// One random edit of a text, by lines.
#[derive(Clone, Debug)]
enum Edit {
    Delete(usize),
    Duplicate(usize),
    Swap(usize, usize),
    /// Replace the k-th number-like token with a string.
    Number(usize, &'static str),
    Insert(usize, &'static str),
    Truncate(usize),
    Char(usize, char),
}

const NUMBERS: &[&str] = &[
    "nan", "inf", "-inf", "1e308", "-1e308", "0", "-0.0", "1e-320", "3", "\"x\"", "true", "[]",
    "[1.0]", "1e6", "-1e7", "0 0 0", "1 2", "",
];

const TOML_LINES: &[&str] = &[
    "unknowns = \"auto\"",
    "unknowns = \"all\"",
    "joint = \"prismatic\"",
    "joint = \"fixed\"",
    "limits = [1.0, -1.0]",
    "limits = [0.0, 0.0]",
    "limits_deg = [0, 360]",
    "convention = \"dh\"",
    "convention = \"hayati\"",
    "[[frame]]",
    "label = \"a\"",
    "label = \"\"",
    "measurement = \"pose\"",
    "urdf = \"nope.urdf\"",
    "tip = \"x\"",
    "[visibility]\nkind = \"box\"\nmin = [0.0, 0.0, 0.0]\nmax = [1.0, 1.0, 1.0]",
    "[visibility]\nkind = \"cone\"\napex = [0.0, 0.0, 0.0]\naxis = [0.0, 0.0, 0.0]\nhalf_angle = 0.1\nmax_range = 1.0",
    "unknowns = [\"beta\"]",
    "unknowns = [\"gamma\", \"alpha\", \"a\", \"d\", \"beta\"]",
    "real = [0.0, 0.0, 0.0, 0.0]",
    "bogus = 1",
    "name = 3",
];

const URDF_LINES: &[&str] = &[
    "<joint name=\"x\" type=\"floating\"><parent link=\"link6\"/><child link=\"z\"/></joint>",
    "<joint name=\"q1\" type=\"continuous\"><parent link=\"tip\"/><child link=\"link1\"/></joint>",
    "<axis xyz=\"0 0 0\"/>",
    "<limit lower=\"1\" upper=\"-1\" effort=\"0\" velocity=\"0\"/>",
    "<mimic joint=\"q1\"/>",
    "<link name=\"tip\"/>",
    "</robot>",
    "<robot>",
    "<origin xyz=\"nan 0 0\" rpy=\"0 0 1e308\"/>",
    "<!--",
];

fn edit(lines: &'static [&'static str]) -> impl Strategy<Value = Edit> {
    prop_oneof![
        (0..200usize).prop_map(Edit::Delete),
        (0..200usize).prop_map(Edit::Duplicate),
        (0..200usize, 0..200usize).prop_map(|(a, b)| Edit::Swap(a, b)),
        (0..300usize, prop::sample::select(NUMBERS)).prop_map(|(k, s)| Edit::Number(k, s)),
        (0..200usize, prop::sample::select(lines)).prop_map(|(k, s)| Edit::Insert(k, s)),
        (0..4000usize).prop_map(Edit::Truncate),
        (0..4000usize, any::<char>()).prop_map(|(k, c)| Edit::Char(k, c)),
    ]
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for e in edits {
        let n = lines.len().max(1);
        match e {
            Edit::Delete(k) => {
                if !lines.is_empty() {
                    lines.remove(k % n);
                }
            }
            Edit::Duplicate(k) => {
                if !lines.is_empty() {
                    let l = lines[k % n].clone();
                    lines.insert(k % n, l);
                }
            }
            Edit::Swap(a, b) => {
                if !lines.is_empty() {
                    lines.swap(a % n, b % n);
                }
            }
            Edit::Number(k, s) => {
                // The k-th maximal run of number characters, cyclically.
                let joined = lines.join("\n");
                let bytes = joined.as_bytes();
                let is_num = |c: u8| c.is_ascii_digit() || c == b'.' || c == b'-' || c == b'e';
                let mut runs = Vec::new();
                let mut i = 0;
                while i < bytes.len() {
                    if bytes[i].is_ascii_digit() {
                        let mut a = i;
                        while a > 0 && is_num(bytes[a - 1]) {
                            a -= 1;
                        }
                        let mut b = i;
                        while b < bytes.len() && is_num(bytes[b]) {
                            b += 1;
                        }
                        runs.push((a, b));
                        i = b;
                    } else {
                        i += 1;
                    }
                }
                if !runs.is_empty() {
                    let (a, b) = runs[k % runs.len()];
                    let t = format!("{}{}{}", &joined[..a], s, &joined[b..]);
                    lines = t.lines().map(str::to_string).collect();
                }
            }
            Edit::Insert(k, s) => lines.insert(k % (lines.len() + 1), s.to_string()),
            Edit::Truncate(k) => {
                let joined = lines.join("\n");
                let mut cut = k % (joined.len() + 1);
                while !joined.is_char_boundary(cut) {
                    cut -= 1;
                }
                lines = joined[..cut].lines().map(str::to_string).collect();
            }
            Edit::Char(k, c) => {
                let joined = lines.join("\n");
                let chars: Vec<char> = joined.chars().collect();
                if !chars.is_empty() {
                    let mut chars = chars;
                    let n = chars.len();
                    chars[k % n] = *c;
                    let t: String = chars.into_iter().collect();
                    lines = t.lines().map(str::to_string).collect();
                }
            }
        }
    }
    lines.join("\n") + "\n"
}

/// A random robot (possibly invalid: no joints, no unknowns, β on DH,
/// inverted limits…) with its frames, tables, unknowns and limits.
fn any_robot() -> impl Strategy<Value = Robot> {
    let frame = (
        any::<bool>(),
        0..3u8,
        prop::array::uniform5(-3.0f64..3.0),
        prop::array::uniform5(-0.01f64..0.01),
        any::<u8>(),
        (-3.0f64..3.0, -0.5f64..3.0),
    );
    (
        prop::collection::vec(frame, 1..7),
        any::<bool>(),
        prop::option::of(any::<bool>()),
    )
        .prop_map(|(frames, pose_m, extra)| {
            let mut fr = Vec::new();
            let (mut real, mut nominal, mut unknowns, mut limits) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for (i, (hayati, joint, row, dev, mask, (lo, w))) in frames.into_iter().enumerate() {
                let convention = if hayati {
                    Convention::Hayati
                } else {
                    Convention::Dh
                };
                let (joint, joint_kind) = match joint {
                    0 => (None, JointKind::Revolute),
                    1 => (Some(limits.len()), JointKind::Revolute),
                    _ => (Some(limits.len()), JointKind::Prismatic),
                };
                if joint.is_some() {
                    limits.push([lo, lo + w]);
                }
                fr.push(Frame {
                    label: format!("f{i}"),
                    convention,
                    joint,
                    joint_kind,
                });
                nominal.push(row);
                let mut r = row;
                r.iter_mut().zip(dev).for_each(|(x, d)| *x += d);
                real.push(r);
                for (k, s) in Symbol::ALL.into_iter().enumerate() {
                    if mask & (1 << k) != 0 && (s != Symbol::Beta || hayati) {
                        unknowns.push(ParamId {
                            frame: i,
                            symbol: s,
                        });
                    }
                }
            }
            let _ = extra;
            Robot {
                name: "random".into(),
                frames: fr,
                real: ParamTable::from_rows(real),
                nominal: ParamTable::from_rows(nominal),
                unknowns,
                limits,
                measurement: if pose_m {
                    MeasurementKind::Pose
                } else {
                    MeasurementKind::Point
                },
                orientation_scale: activecal::model::DEFAULT_ORIENTATION_SCALE,
                source: None,
                gravity: None,
            }
        })
}

// 256 cases per property (proptest's default; PROPTEST_CASES overrides).
proptest! {
    #[test]
    fn arbitrary_text_never_panics(text in ".{0,300}") {
        let _ = file::parse(&text, "fuzz.toml", None);
        let _ = urdf::parse(&text, "fuzz.urdf", &UrdfOptions::default());
    }

    #[test]
    fn toml_fragments_never_panic(
        parts in prop::collection::vec(prop::sample::select(TOML_LINES), 0..20)
    ) {
        let text = parts.join("\n");
        if let Ok(r) = file::parse(&text, "fuzz.toml", None) {
            check_loaded(&r);
        }
    }

    #[test]
    fn edited_descriptions_never_panic(
        edits in prop::collection::vec(edit(TOML_LINES), 1..4),
        which in any::<bool>(),
    ) {
        let base = if which { puma_toml() } else { stanford_toml() };
        let text = apply(base, &edits);
        match file::parse(&text, "fuzz.toml", None) {
            Ok(r) => check_loaded(&r),
            Err(e) => {
                // Every error names the file.
                prop_assert!(e.to_string().starts_with("fuzz.toml"), "{}", e);
            }
        }
    }

    #[test]
    fn edited_urdf_never_panics(edits in prop::collection::vec(edit(URDF_LINES), 1..4)) {
        let text = apply(puma_urdf(), &edits);
        for m in [MeasurementKind::Point, MeasurementKind::Pose] {
            let o = UrdfOptions { measurement: m, ..UrdfOptions::default() };
            if let Ok(r) = urdf::parse(&text, "fuzz.urdf", &o) {
                check_loaded(&r);
            }
        }
    }

    #[test]
    fn random_robots_round_trip_or_fail_cleanly(r in any_robot(), q in prop::collection::vec(0.0f64..1.0, 7)) {
        let text = file::to_toml(&r);
        match file::parse(&text, "random.toml", None) {
            Ok(back) => {
                check_loaded(&back);
                prop_assert_eq!(&back.real, &r.real);
                prop_assert_eq!(&back.nominal, &r.nominal);
                prop_assert_eq!(&back.unknowns, &r.unknowns);
                prop_assert_eq!(&back.limits, &r.limits);
                let q: Vec<f64> = r
                    .limits
                    .iter()
                    .zip(&q)
                    .map(|(&[lo, hi], f)| lo + (hi - lo) * f)
                    .collect();
                prop_assert_eq!(pose(&back, &back.real, &q), pose(&r, &r.real, &q));
            }
            Err(e) => prop_assert!(e.to_string().starts_with("random.toml"), "{}", e),
        }
        // The automatic choice on the same chain: never more unknowns than
        // the independent parameters of a serial chain (4R + 2P + 6 for a
        // pose; a point does not see the tool's 3 orientation parameters).
        let auto = text
            .lines()
            .filter(|l| !l.starts_with("unknowns"))
            .collect::<Vec<_>>()
            .join("\n")
            .replacen("\n", "\nunknowns = \"auto\"\n", 1);
        if let Ok(back) = file::parse(&auto, "random.toml", None) {
            check_loaded(&back);
            prop_assert!(
                back.n_unknowns() <= back.minimal_unknowns(),
                "{} unknowns > {}: {:?}",
                back.n_unknowns(),
                back.minimal_unknowns(),
                back.parameter_names()
            );
        }
    }
}
