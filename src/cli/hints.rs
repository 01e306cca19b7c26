//! The command line's words for what the library's errors name.
//!
//! The library names an input by what it is (the chain's tip, a locked
//! joint, an obstacle, a fixed parameter), never by a flag; this table is
//! the one place that maps those names to this command line's options, so
//! that an error ends with the option to change.

use activecal::names::phrase;

/// A phrase the library uses for an input, and the option that gives it.
const OPTIONS: &[(&str, &str)] = &[
    ("the chain's tip", "--tip LINK names the chain's tip"),
    ("the chain's base", "--base LINK names the chain's base"),
    ("locked joint", "--lock NAME=VALUE holds a joint still"),
    (
        "obstacle '",
        "--obstacle box:cx,cy,cz,sx,sy,sz adds an obstacle (metres, base frame)",
    ),
    (
        "floor height",
        "--floor Z sets the floor's height (metres, base frame)",
    ),
    (
        "name the package directory",
        "--package-dir DIR names a package directory (repeatable)",
    ),
    ("SRDF file", "--srdf FILE names the SRDF"),
    (
        "no rest period on",
        "--rest-speed SPEED and --rest-min S set what counts as a rest",
    ),
    (
        "of the robot is in no message of",
        "--joints TOPIC names the JointState topic; --base, --tip and --lock choose the chain",
    ),
    (
        "reached no pose of the design",
        "--design-tolerance RAD sets how near a rest must be to a design pose",
    ),
    (
        "fixed parameter",
        "--fix NAME holds an unknown at its nominal value",
    ),
    (
        "freed parameter",
        "--free NAME adds a parameter to the unknowns",
    ),
    (
        "held-out fraction",
        "--holdout FRACTION sets the share of poses held out",
    ),
    (
        "held-out splits",
        "--splits N sets the number of held-out splits",
    ),
    (
        "fewer lattice levels",
        "--levels N sets the lattice's levels per joint",
    ),
    (
        "overwriting it was not asked for",
        "pass --force to overwrite it",
    ),
];

/// The chain's phrases as a description file gives them: a robot read
/// from a `.toml` description takes its chain from the file's keys, not
/// from the command line's options.
const IN_DESCRIPTION: &[(&str, &str)] = &[
    (
        "the chain's tip",
        "tip = \"LINK\" in the description names the chain's tip",
    ),
    (
        "the chain's base",
        "base = \"LINK\" in the description names the chain's base",
    ),
    (
        "locked joint",
        "a [lock] table (NAME = VALUE) in the description holds a joint still",
    ),
];

/// How this command line spells the library's phrases for a setting
/// ([`activecal::names::phrase`]): the phrase is replaced where a message
/// is printed, so the library's text reads with this command line's flags.
const SPELLING: &[(&str, &str)] = &[
    (phrase::KEEP_GROSS_ERRORS, "--outliers keep keeps it"),
    (phrase::OUTLIER_SCREEN, "--outliers"),
    (phrase::COMPLIANCE, "--compliance"),
    (phrase::REFINE_INTRINSICS, "--refine-intrinsics"),
    (phrase::NO_TOOL_POINT, "no tool point given (--marker)"),
    (phrase::DEFAULT_PIXEL_NOISE, "the default of --pixel-noise"),
    (phrase::DEFAULT_NOISE, "the default of --noise"),
    (
        phrase::TARGET_ERROR,
        "--target-error MM: the fewest reaching an error",
    ),
    (phrase::OVERWRITE_ASKED, "even with --force"),
];

/// `text` with the library's phrases for settings spelled as this command
/// line's flags (applied to the text printed and to stderr, not to
/// `--json`, which keeps the library's words as Python's reports do).
#[must_use]
pub fn spell(text: &str) -> String {
    let text = spell_keys(text);
    SPELLING
        .iter()
        .fold(text, |t, (phrase, flag)| t.replace(phrase, flag))
}

/// `text` with each setting's key written in backticks by the library
/// ([`activecal::error::SettingError`]: `` `loss_scale` ``) spelled as this
/// command line's option (`--loss-scale`); backticked words that are no
/// option of any command are kept as they are.
fn spell_keys(text: &str) -> String {
    use clap::CommandFactory;
    static IDS: std::sync::OnceLock<std::collections::BTreeSet<String>> =
        std::sync::OnceLock::new();
    let ids = IDS.get_or_init(|| {
        let cli = crate::Cli::command();
        cli.get_subcommands()
            .flat_map(|c| {
                c.get_arguments()
                    .filter_map(|a| a.get_long().map(str::to_string))
            })
            .collect()
    });
    let mut out = String::with_capacity(text.len());
    let mut parts = text.split('`');
    out.push_str(parts.next().unwrap_or(""));
    let mut open = false;
    for part in parts {
        let flag = part.replace('_', "-");
        if !open && ids.contains(&flag) && text.contains(&format!("`{part}`")) {
            out.push_str("--");
            out.push_str(&flag);
            open = true;
            continue;
        }
        if open {
            open = false;
        } else {
            out.push('`');
        }
        out.push_str(part);
    }
    out
}

/// The options an error's message (its whole chain) calls for, in the
/// table's order, each once: the description's keys instead of the chain
/// options when the robot came from a description file, and the package
/// a missing mesh belongs to.
#[must_use]
pub fn option_hints(e: &anyhow::Error) -> Vec<String> {
    let text = format!("{e:#}");
    let description = text.contains(".toml: ");
    OPTIONS
        .iter()
        .filter(|(phrase, _)| text.contains(phrase))
        .map(|&(phrase, hint)| {
            let key = IN_DESCRIPTION.iter().find(|(p, _)| *p == phrase);
            match key {
                Some((_, in_file)) if description => (*in_file).to_string(),
                _ if phrase == "name the package directory" => package_hint(&text, hint),
                _ => hint.to_string(),
            }
        })
        .collect()
}

/// `--package-dir`'s hint, naming the directory to give when the message
/// names the package (`… holds package 'PKG'`).
fn package_hint(text: &str, hint: &str) -> String {
    let pkg = text
        .split("holds package '")
        .nth(1)
        .and_then(|r| r.split('\'').next());
    match pkg {
        Some(pkg) => format!("{hint}: the directory that holds {pkg}/ (or {pkg} itself)"),
        None => hint.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_phrase_is_spelled_as_a_flag() {
        for (p, flag) in SPELLING {
            let s = spell(&format!("a message naming {p}."));
            assert!(s.contains("--") && s.contains(flag), "{p}: {s}");
        }
        assert_eq!(spell("no phrase here"), "no phrase here");
    }

    #[test]
    fn setting_keys_become_flags_and_other_backticks_stay() {
        let e = activecal::error::SettingError::because("loss_scale", "is for `loss` huber");
        assert_eq!(spell(&e.to_string()), "--loss-scale: is for --loss huber");
        assert_eq!(
            spell("measurements `m.csv`, `no_such_option` and `pixel_noise`"),
            "measurements `m.csv`, `no_such_option` and --pixel-noise"
        );
    }

    #[test]
    fn a_library_phrase_gets_its_option_and_others_get_none() {
        let e = anyhow::anyhow!("locked joint 'j9': there is no joint 'j9' in the URDF");
        assert_eq!(
            option_hints(&e),
            vec!["--lock NAME=VALUE holds a joint still"]
        );
        let e = anyhow::anyhow!("expected 6 joint angles, got 5");
        assert!(option_hints(&e).is_empty());
    }

    #[test]
    fn a_description_s_chain_is_named_by_its_keys_and_a_package_by_its_directory() {
        let tree = "the URDF is a tree with 26 branches below 'base_footprint': choose the measured link as the chain's tip; candidate tips: a, b";
        let e = anyhow::anyhow!("{tree}").context("tiago.urdf");
        assert_eq!(option_hints(&e), vec!["--tip LINK names the chain's tip"]);
        let e = anyhow::anyhow!("{tree}").context("setup.toml: line 1, column 8: tiago.urdf");
        assert_eq!(
            option_hints(&e),
            vec!["tip = \"LINK\" in the description names the chain's tip"]
        );
        let e = anyhow::anyhow!(
            "link 'arm_1_link': mesh 'package://tiago_description/meshes/arm/arm_1.dae' not found (searched the URDF's directory . and its ancestors; name the package directory that holds package 'tiago_description')"
        );
        assert_eq!(
            option_hints(&e),
            vec![
                "--package-dir DIR names a package directory (repeatable): the directory that holds tiago_description/ (or tiago_description itself)"
            ]
        );
    }
}
