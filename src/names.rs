//! Names a user may mistype (parameters, links, joints): the closest valid
//! ones, for a "did you mean" in the message.

/// Levenshtein distance between two names (characters).
#[must_use]
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The valid names nearest `name` by edit distance, when near enough to be
/// a typo (at most half the name's length plus one edits): all those at
/// the smallest distance, in the given order.
#[must_use]
pub fn closest<'a, S: AsRef<str>>(name: &str, valid: &'a [S]) -> Vec<&'a str> {
    let by: Vec<(usize, &str)> = valid
        .iter()
        .map(|v| (edit_distance(name, v.as_ref()), v.as_ref()))
        .collect();
    let best = by.iter().map(|b| b.0).min().unwrap_or(usize::MAX);
    by.into_iter()
        .filter(|(d, _)| *d == best && *d <= name.len().max(3) / 2 + 1)
        .map(|(_, v)| v)
        .collect()
}

/// `" (did you mean A or B?)"`, or nothing when no valid name is near.
#[must_use]
pub fn did_you_mean<S: AsRef<str>>(name: &str, valid: &[S]) -> String {
    let close = closest(name, valid);
    if close.is_empty() {
        String::new()
    } else {
        format!(" (did you mean {}?)", close.join(" or "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_typo_finds_its_name_and_nonsense_finds_none() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        let links = ["arm_tool_link", "arm_7_link", "base_link"];
        assert_eq!(closest("arm_tool_lnk", &links), vec!["arm_tool_link"]);
        assert!(did_you_mean("zzzzzzzzzzzzzzzzzz", &links).is_empty());
    }
}

/// A closed set of named values a user chooses from by name (a parameter
/// table, an algorithm, a solver): the names the command line offers and
/// parses, kept beside the type so that the library needs no command-line
/// crate.
pub trait Choice: Copy + Sized + 'static {
    /// Every value, in the order a listing shows them.
    const ALL: &'static [Self];

    /// The value's name (as serialised).
    fn name(self) -> &'static str;

    /// The value named `name`, if any.
    fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|v| v.name() == name)
    }
}

/// Implements [`Choice`] and [`std::fmt::Display`] for a field-less enum:
/// `choice!(Type { Variant => "name", … })`.
#[macro_export]
macro_rules! choice {
    ($t:ty { $($v:ident => $n:literal),+ $(,)? }) => {
        impl $crate::names::Choice for $t {
            const ALL: &'static [Self] = &[$(<$t>::$v),+];
            fn name(self) -> &'static str {
                match self { $(<$t>::$v => $n),+ }
            }
        }
        impl ::std::fmt::Display for $t {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str($crate::names::Choice::name(*self))
            }
        }
    };
}

/// Phrases the library's messages use for a setting that each front end
/// spells its own way: the command line's hint table (`cli/hints.rs`) and
/// the Python bindings' (`python/src/convert.rs`) map each to their
/// option, so the library never names a flag.
pub mod phrase {
    /// The gross-error screen (data snooping), which drops flagged poses.
    pub const OUTLIER_SCREEN: &str = "the gross-error screen";
    /// Switching the gross-error screen to keep every pose.
    pub const KEEP_GROSS_ERRORS: &str = "keeping gross errors keeps it";
    /// Joint compliance (sag under gravity) as unknowns of the fit.
    pub const COMPLIANCE: &str = "the joints' compliance as unknowns";
    /// The camera's intrinsics refined with the fit.
    pub const REFINE_INTRINSICS: &str = "refining the intrinsics";
    /// Position data with no tool point or marker given.
    pub const NO_TOOL_POINT: &str = "no tool point given";
    /// The stated position noise when none is given.
    pub const DEFAULT_NOISE: &str = "the default stated noise";
    /// The stated pixel noise when none is given.
    pub const DEFAULT_PIXEL_NOISE: &str = "the default stated pixel noise";
    /// A target error for the how-many curve: the fewest poses reaching it.
    pub const TARGET_ERROR: &str = "a target error gives the fewest poses reaching it";
    /// Overwriting an existing output, when asked for.
    pub const OVERWRITE_ASKED: &str = "even when overwriting is asked for";
}
