//! Memory budget: every large structure (a pool's Jacobian, its variances,
//! an identifiability check) is estimated before it is allocated, and
//! refused with the figure and the limit when it would exceed the budget —
//! never a panic inside an allocator or a visit from the OOM killer. The
//! largest buffers are then reserved fallibly ([`try_zeroed`]), so a
//! refusal by the system is an error too.
//!
//! The budget is the smallest of what every source allows:
//! - `ACTIVECAL_MAX_MEMORY` when set (bytes, or with a `K`, `M`, `G`
//!   suffix, powers of 1024);
//! - 75 % of the machine's memory (`MemTotal` of `/proc/meminfo`);
//! - the memory limit of the process's cgroup and of its ancestors
//!   (v2 `memory.max`, v1 `memory.limit_in_bytes`; found through
//!   `/proc/self/cgroup` and `/proc/self/mountinfo`, else at the usual
//!   `/sys/fs/cgroup` paths; `max` or v1's page-counter maximum is none);
//! - the address-space and data-segment limits (`RLIMIT_AS`, `ulimit -v`;
//!   `RLIMIT_DATA`, `ulimit -d`; from `/proc/self/limits`) less what the
//!   process already maps (`VmSize`, `VmData` of `/proc/self/status`).
//!
//! 8 GiB where none of them is known. Every file is read under a root
//! directory ([`MemoryBudget::from_sources`]), so tests feed fake ones.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// Environment variable that lowers the budget.
pub const MEMORY_ENV: &str = "ACTIVECAL_MAX_MEMORY";

/// Share of the machine's memory one run may take by default.
pub const DEFAULT_SHARE: f64 = 0.75;

/// A cgroup v1 limit at or above this is "no limit" (the kernel writes its
/// page-counter maximum, 2⁶³ rounded down to a page).
const V1_UNLIMITED: u64 = 1 << 62;

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

/// Reads `path` (absolute, as on the real system) under `root`.
fn read_under(root: &Path, path: &str) -> Option<String> {
    std::fs::read_to_string(root.join(path.trim_start_matches('/'))).ok()
}

/// The value of `key` in a `/proc` text of `Key:   value kB` lines, in bytes.
fn kb_field(text: &str, key: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    let kb: u64 = line[key.len()..]
        .trim_start_matches(':')
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    Some(kb.saturating_mul(1024))
}

/// 75 % of `MemTotal`.
fn physical(root: &Path) -> Option<MemoryBudget> {
    let total = kb_field(&read_under(root, "/proc/meminfo")?, "MemTotal")?;
    Some(MemoryBudget {
        limit: (total as f64 * DEFAULT_SHARE) as u64,
        source: format!(
            "{:.0} % of this machine's {}; set {MEMORY_ENV} to lower it",
            DEFAULT_SHARE * 100.0,
            format_bytes(total)
        ),
    })
}

/// A cgroup hierarchy: where it is mounted (under the root), the cgroup
/// path its mount shows as `/`, the process's cgroup in it, and the name of
/// its limit file.
struct Hierarchy {
    mount_point: PathBuf,
    mount_root: String,
    cgroup: String,
    file: &'static str,
}

/// The process's memory hierarchies from `/proc/self/cgroup` and
/// `/proc/self/mountinfo`: v2 (`0::/path`, a `cgroup2` mount) and v1 (the
/// `memory` controller's line and mount).
fn hierarchies(root: &Path) -> Vec<Hierarchy> {
    let (Some(cgroups), Some(mounts)) = (
        read_under(root, "/proc/self/cgroup"),
        read_under(root, "/proc/self/mountinfo"),
    ) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for line in cgroups.lines() {
        let mut f = line.splitn(3, ':');
        let (Some(id), Some(controllers), Some(path)) = (f.next(), f.next(), f.next()) else {
            continue;
        };
        let v2 = id == "0" && controllers.is_empty();
        if !v2 && !controllers.split(',').any(|c| c == "memory") {
            continue;
        }
        let mount = mounts.lines().find_map(|m| {
            let (pre, post) = m.split_once(" - ")?;
            let pre: Vec<&str> = pre.split_whitespace().collect();
            let post: Vec<&str> = post.split_whitespace().collect();
            let fits = if v2 {
                post.first() == Some(&"cgroup2")
            } else {
                post.first() == Some(&"cgroup")
                    && post
                        .get(2)
                        .is_some_and(|o| o.split(',').any(|o| o == "memory"))
            };
            fits.then(|| (pre.get(3).copied(), pre.get(4).copied()))
        });
        if let Some((Some(mount_root), Some(mount_point))) = mount {
            out.push(Hierarchy {
                mount_point: root.join(mount_point.trim_start_matches('/')),
                mount_root: mount_root.to_string(),
                cgroup: path.to_string(),
                file: if v2 {
                    "memory.max"
                } else {
                    "memory.limit_in_bytes"
                },
            });
        }
    }
    out
}

/// A limit file's figure: `max` (v2) or the page-counter maximum (v1) is
/// none.
fn limit_in(path: &Path) -> Option<u64> {
    let text = std::fs::read_to_string(path).ok()?;
    let v: u64 = text.trim().parse().ok()?;
    (v < V1_UNLIMITED).then_some(v)
}

/// The smallest limit of the process's cgroup and its ancestors, in every
/// memory hierarchy; without `/proc/self/cgroup`, the usual root files.
fn cgroup(root: &Path) -> Option<MemoryBudget> {
    let mut found: Vec<(u64, PathBuf)> = Vec::new();
    let hs = hierarchies(root);
    for h in &hs {
        let rel = h
            .cgroup
            .strip_prefix(h.mount_root.trim_end_matches('/'))
            .unwrap_or("");
        let mut dir = h.mount_point.join(rel.trim_start_matches('/'));
        loop {
            let f = dir.join(h.file);
            if let Some(v) = limit_in(&f) {
                found.push((v, f));
            }
            if dir == h.mount_point || !dir.pop() || !dir.starts_with(&h.mount_point) {
                break;
            }
        }
    }
    if hs.is_empty() {
        for usual in [
            "/sys/fs/cgroup/memory.max",
            "/sys/fs/cgroup/memory/memory.limit_in_bytes",
        ] {
            let f = root.join(usual.trim_start_matches('/'));
            if let Some(v) = limit_in(&f) {
                found.push((v, f));
            }
        }
    }
    let (limit, file) = found.into_iter().min_by_key(|(v, _)| *v)?;
    let shown = Path::new("/").join(file.strip_prefix(root).unwrap_or(&file));
    Some(MemoryBudget {
        limit,
        source: format!(
            "the cgroup limit {} in {}",
            format_bytes(limit),
            shown.display()
        ),
    })
}

/// The soft limit of `name` (`Max address space`) in `/proc/self/limits`.
fn soft_limit(limits: &str, name: &str) -> Option<u64> {
    let line = limits.lines().find(|l| l.starts_with(name))?;
    line[name.len()..].split_whitespace().next()?.parse().ok()
}

/// `RLIMIT_AS` less `VmSize` and `RLIMIT_DATA` less `VmData`, the smaller.
fn rlimits(root: &Path) -> Option<MemoryBudget> {
    let limits = read_under(root, "/proc/self/limits")?;
    let status = read_under(root, "/proc/self/status").unwrap_or_default();
    [
        ("Max address space", "ulimit -v", "VmSize"),
        ("Max data size", "ulimit -d", "VmData"),
    ]
    .into_iter()
    .filter_map(|(line, name, used_key)| {
        let limit = soft_limit(&limits, line)?;
        let used = kb_field(&status, used_key).unwrap_or(0);
        Some(MemoryBudget {
            limit: limit.saturating_sub(used),
            source: format!(
                "{name} of {} less {} mapped",
                format_bytes(limit),
                format_bytes(used)
            ),
        })
    })
    .min_by_key(|b| b.limit)
}

impl MemoryBudget {
    /// The budget of this process (see the module docs). A malformed
    /// `ACTIVECAL_MAX_MEMORY` is an error naming it.
    pub fn from_env() -> Result<MemoryBudget> {
        Self::from_sources(Path::new("/"), std::env::var(MEMORY_ENV).ok().as_deref())
    }

    /// The budget read from the files under `root` (`/` for this process)
    /// and the value `env` of `ACTIVECAL_MAX_MEMORY`: the smallest of the
    /// sources, named in [`source`](Self::source).
    pub fn from_sources(root: &Path, env: Option<&str>) -> Result<MemoryBudget> {
        let mut all = Vec::new();
        if let Some(v) = env {
            let limit = parse_bytes(v).ok_or_else(|| {
                Error::Invalid(format!(
                    "{MEMORY_ENV}={v}: expected a size such as 4G, 512M or 1000000"
                ))
            })?;
            all.push(MemoryBudget {
                limit,
                source: format!("{MEMORY_ENV}={v}"),
            });
        }
        all.extend(physical(root));
        all.extend(cgroup(root));
        all.extend(rlimits(root));
        Ok(all
            .into_iter()
            .min_by_key(|b| b.limit)
            .unwrap_or_else(|| MemoryBudget {
                limit: 8 << 30,
                source: format!("the default 8 GiB; set {MEMORY_ENV} to lower it"),
            }))
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

/// The L3 cache as `/sys` gives it for the first CPU under `root` (the
/// figure the linear-algebra backend sizes its buffers by), or the
/// backend's default of 2 MiB when none is found.
fn l3_bytes(root: &Path) -> u64 {
    (0..8)
        .filter_map(|k| {
            let dir = format!("/sys/devices/system/cpu/cpu0/cache/index{k}");
            let level = read_under(root, &format!("{dir}/level"))?;
            (level.trim() == "3").then_some(())?;
            parse_bytes(read_under(root, &format!("{dir}/size"))?.trim())
        })
        .max()
        .unwrap_or(2 << 20)
}

/// Bytes the linear-algebra backend keeps on each thread that multiplies
/// matrices larger than 16×16×16: faer's x86 kernel (`private-gemm-x86`)
/// allocates twice the L3 cache per thread on its first product, outside
/// any budget, and the process aborts when that allocation fails.
#[must_use]
pub fn backend_buffer_bytes() -> u64 {
    2 * l3_bytes(Path::new("/"))
}

/// The share of the budget the backend's per-thread buffers may take.
pub const BACKEND_SHARE: f64 = 0.25;

/// How many worker threads to run (at most `wanted`, at least 1) so that
/// the backend's buffers — one per worker and one for the main thread,
/// `buffer` bytes each ([`backend_buffer_bytes`]) — fit in
/// [`BACKEND_SHARE`] of the budget: with 150 MiB of L3 and `ulimit -v
/// 2000000`, one worker, where four aborted.
#[must_use]
pub fn threads_within(budget: &MemoryBudget, buffer: u64, wanted: usize) -> usize {
    let share = (budget.limit as f64 * BACKEND_SHARE) as u64;
    let fit = (share / buffer.max(1)).saturating_sub(1);
    usize::try_from(fit)
        .unwrap_or(usize::MAX)
        .clamp(1, wanted.max(1))
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

/// A vector of `n` copies of `value`, reserved fallibly: when the system
/// refuses the memory (a limit the budget could not see), an error naming
/// `what` and the figure instead of an abort.
pub fn try_zeroed<T: Clone>(what: &str, n: usize, value: T) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| refused(what, bytes_of(n, std::mem::size_of::<T>())))?;
    v.resize(n, value);
    Ok(v)
}

/// A `rows × cols` matrix of zeros, reserved fallibly (see [`try_zeroed`]).
pub fn try_zeros_mat(what: &str, rows: usize, cols: usize) -> Result<faer::Mat<f64>> {
    let mut m = faer::Mat::<f64>::new();
    m.try_reserve(rows, cols)
        .map_err(|_| refused(what, bytes_of(rows.saturating_mul(cols), 8)))?;
    m.resize_with(rows, cols, |_, _| 0.0);
    Ok(m)
}

/// The error of an allocation of `bytes` for `what` that the system refused.
fn refused(what: &str, bytes: u64) -> Error {
    Error::OutOfMemory {
        what: what.to_string(),
        needed: format_bytes(bytes),
    }
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
    fn backend_buffers_cap_the_threads_and_the_l3_is_read_from_sys() {
        let root = fake_root(
            "l3",
            &[
                ("sys/devices/system/cpu/cpu0/cache/index2/level", "2\n"),
                ("sys/devices/system/cpu/cpu0/cache/index2/size", "1024K\n"),
                ("sys/devices/system/cpu/cpu0/cache/index3/level", "3\n"),
                ("sys/devices/system/cpu/cpu0/cache/index3/size", "153600K\n"),
            ],
        );
        assert_eq!(l3_bytes(&root), 150 << 20);
        assert_eq!(l3_bytes(Path::new("/no/such/root")), 2 << 20);
        let b = |limit| MemoryBudget {
            limit,
            source: String::new(),
        };
        // The VM: 300 MiB a thread, 1.9 GB of budget: one worker.
        assert_eq!(threads_within(&b(1_900_000_000), 300 << 20, 4), 1);
        // 64 MiB a thread: 7 buffers in a quarter of 1.9 GB, 6 workers.
        assert_eq!(threads_within(&b(1_900_000_000), 64 << 20, 20), 6);
        assert_eq!(threads_within(&b(64 << 30), 64 << 20, 8), 8);
        assert_eq!(threads_within(&b(0), 64 << 20, 8), 1);
        let _ = std::fs::remove_dir_all(&root);
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

    /// A fake root: `files` (absolute paths as on the system) written
    /// under a fresh directory.
    fn fake_root(name: &str, files: &[(&str, &str)]) -> PathBuf {
        let root =
            std::env::temp_dir().join(format!("activecal-budget-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        for (path, text) in files {
            let f = root.join(path.trim_start_matches('/'));
            std::fs::create_dir_all(f.parent().unwrap()).unwrap();
            std::fs::write(f, text).unwrap();
        }
        root
    }

    const MEMINFO: (&str, &str) = (
        "/proc/meminfo",
        "MemTotal:       16000000 kB\nMemFree: 1 kB\n",
    );
    const MOUNTS: &str = "31 23 0:28 / /sys/fs/cgroup rw - cgroup2 cgroup2 rw\n\
        35 31 0:32 / /sys/fs/cgroup/memory rw - cgroup cgroup rw,memory\n";
    const LIMITS: &str = "Limit                     Soft Limit           Hard Limit           Units\n\
        Max data size             unlimited            unlimited            bytes\n\
        Max address space         2048000000           unlimited            bytes\n";
    const STATUS: &str = "Name: x\nVmSize:\t   48000 kB\nVmData:\t    1000 kB\n";

    fn budget(name: &str, files: &[(&str, &str)], env: Option<&str>) -> MemoryBudget {
        let root = fake_root(name, files);
        let b = MemoryBudget::from_sources(&root, env).unwrap();
        let _ = std::fs::remove_dir_all(&root);
        b
    }

    #[test]
    fn physical_memory_alone_gives_three_quarters() {
        let b = budget("meminfo", &[MEMINFO], None);
        assert_eq!(b.limit, 16_000_000 * 1024 / 4 * 3);
        assert!(
            b.source.contains("75 % of this machine's 16.4 GB"),
            "{}",
            b.source
        );
        // Nothing known: the default.
        assert_eq!(budget("none", &[], None).limit, 8 << 30);
    }

    #[test]
    fn a_cgroup_v2_limit_is_found_through_proc_self_cgroup() {
        let files = [
            MEMINFO,
            ("/proc/self/cgroup", "0::/kubepods/pod1/box\n"),
            ("/proc/self/mountinfo", MOUNTS),
            ("/sys/fs/cgroup/kubepods/memory.max", "4000000000\n"),
            ("/sys/fs/cgroup/kubepods/pod1/memory.max", "max\n"),
            (
                "/sys/fs/cgroup/kubepods/pod1/box/memory.max",
                "2000000000\n",
            ),
        ];
        let b = budget("v2", &files, None);
        assert_eq!(b.limit, 2_000_000_000);
        assert_eq!(
            b.source,
            "the cgroup limit 2.0 GB in /sys/fs/cgroup/kubepods/pod1/box/memory.max"
        );
        // "max" everywhere is no limit: physical memory decides.
        let unlimited = [
            MEMINFO,
            ("/proc/self/cgroup", "0::/a\n"),
            ("/proc/self/mountinfo", MOUNTS),
            ("/sys/fs/cgroup/a/memory.max", "max\n"),
        ];
        assert!(budget("v2max", &unlimited, None).source.contains("75 %"));
        // An ancestor's smaller limit binds its descendants.
        let ancestor = [
            MEMINFO,
            ("/proc/self/cgroup", "0::/a/b\n"),
            ("/proc/self/mountinfo", MOUNTS),
            ("/sys/fs/cgroup/a/memory.max", "1000000000\n"),
            ("/sys/fs/cgroup/a/b/memory.max", "max\n"),
        ];
        assert_eq!(budget("v2up", &ancestor, None).limit, 1_000_000_000);
    }

    #[test]
    fn a_cgroup_v1_limit_is_found_and_its_maximum_means_none() {
        let v1 = |value: &'static str| {
            [
                MEMINFO,
                ("/proc/self/cgroup", "4:memory:/docker/abc\n1:cpu:/\n0::/\n"),
                ("/proc/self/mountinfo", MOUNTS),
                (
                    "/sys/fs/cgroup/memory/docker/abc/memory.limit_in_bytes",
                    value,
                ),
            ]
        };
        let b = budget("v1", &v1("3000000000\n"), None);
        assert_eq!(b.limit, 3_000_000_000);
        assert!(b.source.contains("memory.limit_in_bytes"), "{}", b.source);
        let b = budget("v1max", &v1("9223372036854771712\n"), None);
        assert!(b.source.contains("75 %"), "{}", b.source);
        // Without /proc/self/cgroup: the usual paths.
        let usual = [
            MEMINFO,
            ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "1500000000"),
        ];
        assert_eq!(budget("v1usual", &usual, None).limit, 1_500_000_000);
    }

    #[test]
    fn an_address_space_limit_counts_what_is_already_mapped() {
        let files = [
            MEMINFO,
            ("/proc/self/limits", LIMITS),
            ("/proc/self/status", STATUS),
        ];
        let b = budget("rlimit", &files, None);
        assert_eq!(b.limit, 2_048_000_000 - 48_000 * 1024);
        assert_eq!(b.source, "ulimit -v of 2.0 GB less 49.2 MB mapped");
        // A data limit smaller still wins, less VmData.
        let data = LIMITS.replace(
            "Max data size             unlimited",
            "Max data size             1000000000",
        );
        let files = [
            MEMINFO,
            ("/proc/self/limits", data.as_str()),
            ("/proc/self/status", STATUS),
        ];
        let b = budget("rdata", &files, None);
        assert_eq!(b.limit, 1_000_000_000 - 1_000 * 1024);
        assert!(b.source.starts_with("ulimit -d of"), "{}", b.source);
    }

    #[test]
    fn the_smallest_source_wins_and_is_named() {
        let files = [
            MEMINFO,
            ("/proc/self/cgroup", "0::/a\n"),
            ("/proc/self/mountinfo", MOUNTS),
            ("/sys/fs/cgroup/a/memory.max", "1900000000"),
            ("/proc/self/limits", LIMITS),
            ("/proc/self/status", STATUS),
        ];
        // cgroup 1.9 GB < RLIMIT_AS room 2.0 GB < 75 % of 16.4 GB.
        let b = budget("min1", &files, None);
        assert!(
            b.source.starts_with("the cgroup limit 1.9 GB"),
            "{}",
            b.source
        );
        // The variable, when smaller, wins; when larger, it does not raise.
        let b = budget("min2", &files, Some("1G"));
        assert_eq!(
            (b.limit, b.source.as_str()),
            (1 << 30, "ACTIVECAL_MAX_MEMORY=1G")
        );
        assert_eq!(budget("min3", &files, Some("8G")).limit, 1_900_000_000);
        // A refusal names the source that set the figure.
        let e = budget("min4", &files, None)
            .check("a pool Jacobian", 4 << 30)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("4.3 GB") && e.contains("1.9 GB") && e.contains("memory.max"),
            "{e}"
        );
        assert!(MemoryBudget::from_sources(Path::new("/nonexistent"), Some("lots")).is_err());
    }

    #[test]
    fn a_refused_reservation_is_an_error_naming_the_figure() {
        let e = try_zeroed("the pool variances", usize::MAX / 2, 0.0f64)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("the pool variances") && e.contains("allocating"),
            "{e}"
        );
        assert_eq!(try_zeroed("x", 3, 1u8).unwrap(), vec![1, 1, 1]);
        let m = try_zeros_mat("x", 4, 3).unwrap();
        assert_eq!((m.nrows(), m.ncols(), m[(3, 2)]), (4, 3, 0.0));
        assert!(try_zeros_mat("a Jacobian", usize::MAX / 4, 4).is_err());
    }
}
