//! Memory budget: every large structure (a pool's Jacobian, its variances,
//! a random-design store, an identifiability check) is estimated before it
//! is allocated, and refused with the figure and the limit when it would
//! exceed the budget — never a panic inside an allocator or a visit from the
//! OOM killer.
//!
//! The budget is `ACTIVECAL_MAX_MEMORY` when set (bytes, or with a `K`, `M`,
//! `G` suffix, powers of 1024), else 75 % of the machine's memory
//! (`MemTotal` of `/proc/meminfo`), else 8 GiB where that file is missing.

use crate::error::{Error, Result};

/// Environment variable that overrides the budget.
pub const MEMORY_ENV: &str = "ACTIVECAL_MAX_MEMORY";

/// Share of the machine's memory one run may take by default.
pub const DEFAULT_SHARE: f64 = 0.75;

/// The memory one run may allocate for its large structures.
#[derive(Clone, Debug, PartialEq)]
pub struct MemoryBudget {
    /// Bytes.
    pub limit: u64,
    /// Where the figure comes from (for messages).
    pub source: String,
}

/// Parses `123`, `64K`, `512M`, `4G` (powers of 1024; a trailing `B` or
/// `iB` is accepted).
pub fn parse_bytes(s: &str) -> Option<u64> {
    let t = s.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(t);
    let (num, mult) = match t.chars().last()? {
        'k' | 'K' => (&t[..t.len() - 1], 1u64 << 10),
        'm' | 'M' => (&t[..t.len() - 1], 1 << 20),
        'g' | 'G' => (&t[..t.len() - 1], 1 << 30),
        't' | 'T' => (&t[..t.len() - 1], 1 << 40),
        _ => (t, 1),
    };
    let v: f64 = num.trim().parse().ok()?;
    (v.is_finite() && v > 0.0).then_some((v * mult as f64) as u64)
}

/// A byte count for people: `41.0 GB` (decimal units, three figures).
#[must_use]
pub fn format_bytes(b: u64) -> String {
    let b = b as f64;
    for (unit, scale) in [("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)] {
        if b >= scale {
            return format!("{:.1} {unit}", b / scale);
        }
    }
    format!("{b:.0} B")
}

fn mem_total() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

impl MemoryBudget {
    /// The budget of this process (see the module docs). A malformed
    /// `ACTIVECAL_MAX_MEMORY` is an error naming it.
    pub fn from_env() -> Result<MemoryBudget> {
        if let Ok(v) = std::env::var(MEMORY_ENV) {
            return parse_bytes(&v)
                .map(|limit| MemoryBudget {
                    limit,
                    source: format!("{MEMORY_ENV}={v}"),
                })
                .ok_or_else(|| {
                    Error::Invalid(format!(
                        "{MEMORY_ENV}={v}: expected a size such as 4G, 512M or 1000000"
                    ))
                });
        }
        Ok(match mem_total() {
            Some(total) => MemoryBudget {
                limit: (total as f64 * DEFAULT_SHARE) as u64,
                source: format!(
                    "{:.0} % of this machine's {}; set {MEMORY_ENV} to change it",
                    DEFAULT_SHARE * 100.0,
                    format_bytes(total)
                ),
            },
            None => MemoryBudget {
                limit: 8 << 30,
                source: format!("the default 8 GiB; set {MEMORY_ENV} to change it"),
            },
        })
    }

    /// Refuses `what` needing `bytes` (an estimate made before allocating)
    /// when it exceeds the budget.
    pub fn check(&self, what: &str, bytes: u64) -> Result<()> {
        if bytes > self.limit {
            return Err(Error::TooLarge {
                what: what.to_string(),
                needed: format_bytes(bytes),
                limit: format_bytes(self.limit),
                source_of_limit: self.source.clone(),
            });
        }
        Ok(())
    }
}

/// Bytes of `count` values of `size` bytes each, saturating (an estimate
/// that overflows is simply too large).
#[must_use]
pub fn bytes_of(count: usize, size: usize) -> u64 {
    (count as u64).saturating_mul(size as u64)
}

/// Checks `what`, `count` values of type `T`, against this process's budget.
pub fn check_alloc<T>(what: &str, count: usize) -> Result<()> {
    MemoryBudget::from_env()?.check(what, bytes_of(count, std::mem::size_of::<T>()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_print() {
        assert_eq!(parse_bytes("4G"), Some(4 << 30));
        assert_eq!(parse_bytes("512MiB"), Some(512 << 20));
        assert_eq!(parse_bytes("1000"), Some(1000));
        assert_eq!(parse_bytes("1.5k"), Some(1536));
        for bad in ["", "G", "-1G", "abc", "NaN", "0"] {
            assert_eq!(parse_bytes(bad), None, "{bad}");
        }
        assert_eq!(format_bytes(41_000_000_000), "41.0 GB");
        assert_eq!(format_bytes(999), "999 B");
    }

    #[test]
    fn the_budget_refuses_with_both_figures() {
        let b = MemoryBudget {
            limit: 1 << 30,
            source: "test".into(),
        };
        b.check("a pool Jacobian", 1 << 29).unwrap();
        let e = b
            .check("a pool Jacobian", 41 << 30)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a pool Jacobian") && e.contains("44.0 GB") && e.contains("1.1 GB"),
            "{e}"
        );
        assert_eq!(bytes_of(usize::MAX, 8), u64::MAX);
    }
}
