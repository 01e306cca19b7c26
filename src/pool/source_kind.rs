//! A pool's source as a front end names it, before its sizes are given:
//! [`PoolKind`] (`lattice`, `random`, `sobol`, or a file of joint
//! configurations), and the [`PoolSource`] it makes with the sizes given
//! for it ([`PoolSource::of`]).

use super::PoolSource;
use crate::error::SettingError;

/// Samples of a random or Sobol pool when no count is given (2¹²: a whole
/// number of Sobol strata).
pub const DEFAULT_COUNT: usize = 4096;

/// Lattice values per joint when none are given.
pub const DEFAULT_LEVELS: usize = 5;

/// Where the candidate poses come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PoolKind {
    /// The joint-space lattice.
    Lattice,
    /// Uniform random samples inside the joint limits.
    Random,
    /// Sobol points inside the joint limits.
    Sobol,
    /// Joint configurations from a CSV or JSON file.
    File(std::path::PathBuf),
}

impl std::str::FromStr for PoolKind {
    type Err = String;

    /// `lattice`, `random`, `sobol`, `file:PATH`, or a path ending in
    /// `.csv` or `.json`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "lattice" => return Ok(PoolKind::Lattice),
            "random" => return Ok(PoolKind::Random),
            "sobol" => return Ok(PoolKind::Sobol),
            _ => {}
        }
        if let Some(p) = s.strip_prefix("file:") {
            if p.is_empty() {
                return Err("file: needs a path, e.g. file:poses.csv".into());
            }
            return Ok(PoolKind::File(p.into()));
        }
        let lower = s.to_ascii_lowercase();
        if lower.ends_with(".csv") || lower.ends_with(".json") {
            return Ok(PoolKind::File(s.into()));
        }
        Err(format!(
            "unknown pool '{s}': use lattice, random, sobol, or file:PATH (a CSV or JSON of joint configurations)"
        ))
    }
}

impl PoolSource {
    /// The source of `kind` with the sizes given: `levels` per joint for a
    /// lattice ([`DEFAULT_LEVELS`]), `count` samples for a random or Sobol
    /// pool ([`DEFAULT_COUNT`]) with `seed` (a random pool's stream, 0 by
    /// default; a Sobol pool's scramble, none by default). A size given
    /// for a source that takes none is refused, never ignored.
    pub fn of(
        kind: &PoolKind,
        levels: Option<usize>,
        count: Option<usize>,
        seed: Option<u64>,
    ) -> Result<Self, SettingError> {
        let sampled = matches!(kind, PoolKind::Random | PoolKind::Sobol);
        if levels.is_some() && *kind != PoolKind::Lattice {
            return Err(SettingError::because(
                "levels",
                "applies to `pool` lattice only",
            ));
        }
        for (key, given) in [("count", count.is_some()), ("pool_seed", seed.is_some())] {
            if given && !sampled {
                return Err(SettingError::because(
                    key,
                    "applies to `pool` random or sobol only",
                ));
            }
        }
        let count = count.unwrap_or(DEFAULT_COUNT);
        Ok(match kind {
            PoolKind::Lattice => PoolSource::Lattice {
                levels: levels.unwrap_or(DEFAULT_LEVELS),
            },
            PoolKind::Random => PoolSource::Random {
                count,
                seed: seed.unwrap_or(0),
            },
            PoolKind::Sobol => PoolSource::Sobol { count, seed },
            PoolKind::File(p) => PoolSource::File {
                path: p.display().to_string(),
            },
        })
    }
}
