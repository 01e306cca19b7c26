//! The command line's words for what the library's errors name.
//!
//! The library names an input by what it is (the chain's tip, a locked
//! joint, an obstacle, a fixed parameter), never by a flag; this table is
//! the one place that maps those names to this command line's options, so
//! that an error ends with the option to change.

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

/// The options an error's message (its whole chain) calls for, in the
/// table's order, each once.
#[must_use]
pub fn option_hints(e: &anyhow::Error) -> Vec<&'static str> {
    let text = format!("{e:#}");
    OPTIONS
        .iter()
        .filter(|(phrase, _)| text.contains(phrase))
        .map(|&(_, hint)| hint)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
