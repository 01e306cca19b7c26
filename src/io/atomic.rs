//! Outputs that are never half-written and never overwrite without asking.
//!
//! A file is written to a temporary file in the target's own directory,
//! flushed to disk, and renamed over the target: a reader (or a crash, or a
//! `SIGKILL`) sees either the old file or the new one, never a mixture, and
//! the old file is not lost until the new one is complete. A directory of
//! outputs (`reproduce`) is built aside and swapped in ([`replace_dir`]).
//!
//! [`check_outputs`] refuses, before any work is done, an output that exists
//! (without `force`), that is a directory, whose directory does not exist,
//! that is one of the command's inputs, or that two outputs share;
//! [`output_dir_conflict`] finds an output directory (replaced whole) that
//! holds an input or another output.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// One output of a command, for [`check_outputs`].
#[derive(Clone, Copy, Debug)]
pub struct Output<'a> {
    /// What the output is, as the caller names it (`design file`, or the
    /// option that named it on a command line), for
    /// messages.
    pub label: &'a str,
    /// The path given.
    pub path: &'a Path,
}

fn invalid(msg: String) -> Error {
    Error::Invalid(msg)
}

/// A path's identity for comparisons: canonical when it exists, else its
/// nearest existing ancestor made canonical and joined with the rest (so
/// `./x/new.json`, `x/new.json` and a symbolic link to `x` agree, and a
/// file inside a directory yet to be made is still inside it), else as
/// given.
fn identity(path: &Path) -> PathBuf {
    if let Ok(c) = path.canonicalize() {
        return c;
    }
    let mut rest = Vec::new();
    let mut at = path;
    loop {
        let (Some(name), Some(parent)) = (at.file_name(), at.parent()) else {
            return path.to_path_buf();
        };
        rest.push(name);
        at = parent;
        let base = if at.as_os_str().is_empty() {
            Path::new(".")
        } else {
            at
        };
        if let Ok(c) = base.canonicalize() {
            return rest.iter().rev().fold(c, |p, n| p.join(n));
        }
    }
}

/// Why a command's output directories (each replaced whole, as a report
/// directory is) conflict with its output files or its inputs, by
/// canonical identity, or `None`; checked before any work: a directory
/// that is or holds an input (replacing it would delete the input), that
/// names the same path as an output file or another output directory, or
/// that holds an output file or another output directory. The reason
/// names both options and the paths.
#[must_use]
pub fn output_dir_conflict(
    dirs: &[Output<'_>],
    files: &[Output<'_>],
    inputs: &[Output<'_>],
) -> Option<String> {
    for (k, d) in dirs.iter().enumerate() {
        let shown = d.path.display();
        let id = identity(d.path);
        if let Some(i) = inputs.iter().find(|i| identity(i.path).starts_with(&id)) {
            return Some(format!(
                "{} {shown}: is or holds an input of this command ({} {}), and the directory is replaced whole; choose another directory",
                d.label,
                i.label,
                i.path.display()
            ));
        }
        if let Some(other) = dirs[..k]
            .iter()
            .chain(files)
            .find(|o| identity(o.path) == id)
        {
            return Some(format!(
                "{} and {} name the same file {shown}",
                other.label, d.label
            ));
        }
        if let Some(o) = files.iter().find(|o| identity(o.path).starts_with(&id)) {
            return Some(format!(
                "{} {}: is inside the {} directory {shown}, which is replaced whole; write it outside that directory",
                o.label,
                o.path.display(),
                d.label
            ));
        }
        if let Some(other) = dirs[..k]
            .iter()
            .find(|o| identity(o.path).starts_with(&id) || id.starts_with(identity(o.path)))
        {
            return Some(format!(
                "{} {shown} and {} {}: one directory inside the other; choose separate directories",
                d.label,
                other.label,
                other.path.display()
            ));
        }
    }
    None
}

/// Why output `output` (one of a command's) cannot be written, or `None`:
/// it is one of the command's `inputs` by canonical identity (another
/// spelling, a symbolic link), which `--force` never replaces. The reason
/// names the output's option and path and the input's.
#[must_use]
pub fn output_over_input(output: &Output<'_>, inputs: &[Output<'_>]) -> Option<String> {
    let id = identity(output.path);
    inputs.iter().find(|i| identity(i.path) == id).map(|i| {
        format!(
            "{} {}: is an input of this command ({} {}); an input is never overwritten, {}: choose another file",
            output.label,
            output.path.display(),
            i.label,
            i.path.display(),
            crate::names::phrase::OVERWRITE_ASKED
        )
    })
}

/// Checks a command's output files before it does any work: each must name
/// a file (not a directory) in an existing directory, must not exist unless
/// `force`, must not be one of `inputs`, and no two outputs may be the same
/// file. The error names the output (its label) and the path.
pub fn check_outputs(outputs: &[Output<'_>], inputs: &[&Path], force: bool) -> Result<()> {
    for (k, o) in outputs.iter().enumerate() {
        let shown = o.path.display();
        if o.path.is_dir() {
            return Err(invalid(format!(
                "{} {shown}: is a directory; give a file name",
                o.label
            )));
        }
        if o.path.file_name().is_none() {
            return Err(invalid(format!("{} {shown}: not a file name", o.label)));
        }
        let parent = match o.path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        if !parent.is_dir() {
            return Err(invalid(format!(
                "{} {shown}: the directory {} does not exist",
                o.label,
                parent.display()
            )));
        }
        let id = identity(o.path);
        if let Some(i) = inputs.iter().find(|i| identity(i) == id) {
            return Err(invalid(format!(
                "{} {shown}: is an input of this command ({}); choose another file",
                o.label,
                i.display()
            )));
        }
        if let Some(other) = outputs[..k].iter().find(|p| identity(p.path) == id) {
            return Err(invalid(format!(
                "{} and {} name the same file {shown}",
                other.label, o.label
            )));
        }
        if o.path.exists() && !force {
            return Err(Error::OutputExists {
                label: o.label.to_string(),
                path: shown.to_string(),
            });
        }
    }
    Ok(())
}

/// A temporary path beside `path`, unique to this process and call.
fn temporary_beside(path: &Path) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map_or_else(|| "output".into(), |f| f.to_string_lossy().into_owned());
    path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()))
}

fn io_error(path: &Path, cause: std::io::Error) -> Error {
    Error::Io {
        path: path.display().to_string(),
        cause,
    }
}

/// Whether process `pid` is running, when the system can tell (Linux's
/// `/proc`); `None` where it cannot.
fn process_alive(pid: u32) -> Option<bool> {
    if !Path::new("/proc/self").exists() {
        return None;
    }
    Some(Path::new(&format!("/proc/{pid}")).exists())
}

/// Removes the temporaries a killed write left beside `path`
/// (`.NAME.tmp-PID-N` whose process is no longer running: they are never
/// renamed into place; and `.NAME.old-PID`, a replaced directory, when
/// `path` exists again). Those of running processes (a concurrent write) and
/// any other file are kept; where the system cannot tell whether a process
/// runs, nothing is removed. Failures are ignored (the write goes on).
pub fn remove_stale_temporaries(path: &Path) {
    let Some(name) = path.file_name().map(|f| f.to_string_lossy().into_owned()) else {
        return;
    };
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    let prefix = format!(".{name}.tmp-");
    let old = format!(".{name}.old-");
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        // A replaced directory left aside by a kill between the two renames
        // of `replace_dir`: stale once the target is back in place.
        let aside = file.strip_prefix(&old).map(|pid| (pid, "0"));
        let aside = aside.filter(|_| path.exists());
        let Some((pid, n)) = file
            .strip_prefix(&prefix)
            .and_then(|r| r.split_once('-'))
            .or(aside)
        else {
            continue;
        };
        let (Ok(pid), true) = (pid.parse::<u32>(), n.bytes().all(|b| b.is_ascii_digit())) else {
            continue;
        };
        if n.is_empty() || pid == std::process::id() || process_alive(pid) != Some(false) {
            continue;
        }
        let stale = e.path();
        let _ = if stale.is_dir() && !stale.is_symlink() {
            std::fs::remove_dir_all(&stale)
        } else {
            std::fs::remove_file(&stale)
        };
    }
}

/// Writes `bytes` to `path` atomically: a temporary file in the same
/// directory, flushed to disk, then renamed over `path`. On any error the
/// temporary file is removed and `path` is untouched. Temporaries an
/// earlier, killed write left beside `path` are removed
/// ([`remove_stale_temporaries`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    remove_stale_temporaries(path);
    let tmp = temporary_beside(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|cause| {
        let _ = std::fs::remove_file(&tmp);
        io_error(path, cause)
    })
}

/// A directory being built aside for [`replace_dir`]: `.NAME.tmp-PID-N`
/// beside the target.
#[derive(Debug)]
pub struct StagedDir {
    staging: PathBuf,
    target: PathBuf,
}

impl StagedDir {
    /// Creates an empty staging directory beside `target`.
    pub fn new(target: &Path) -> Result<StagedDir> {
        remove_stale_temporaries(target);
        let staging = temporary_beside(target);
        std::fs::create_dir(&staging).map_err(|e| io_error(&staging, e))?;
        Ok(StagedDir {
            staging,
            target: target.to_path_buf(),
        })
    }

    /// Where to write the outputs.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Swaps the staged directory in for the target (see [`replace_dir`]).
    pub fn commit(self) -> Result<()> {
        let r = replace_dir(&self.staging, &self.target);
        std::mem::forget(self);
        r
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        // Not committed (an error on the way): nothing half-built remains.
        let _ = std::fs::remove_dir_all(&self.staging);
    }
}

/// Replaces directory `target` by `staging`: the old target (if any) is
/// renamed aside, `staging` renamed to `target`, then the old one removed.
/// At every moment one complete directory exists: the old one (under its
/// name or, for the instant between the two renames, as `.NAME.old-PID`) or
/// the new one.
pub fn replace_dir(staging: &Path, target: &Path) -> Result<()> {
    let old = if target.exists() {
        let name = target
            .file_name()
            .map_or_else(|| "output".into(), |f| f.to_string_lossy().into_owned());
        let old = target.with_file_name(format!(".{name}.old-{}", std::process::id()));
        std::fs::rename(target, &old).map_err(|e| io_error(target, e))?;
        Some(old)
    } else {
        None
    };
    if let Err(e) = std::fs::rename(staging, target) {
        if let Some(o) = &old {
            let _ = std::fs::rename(o, target);
        }
        return Err(io_error(target, e));
    }
    if let Some(o) = old {
        let _ = std::fs::remove_dir_all(o);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("activecal-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn writes_replace_and_leave_no_temporary() {
        let d = scratch("write");
        let f = d.join("a.json");
        write_atomic(&f, b"one").unwrap();
        write_atomic(&f, b"two").unwrap();
        assert_eq!(std::fs::read(&f).unwrap(), b"two");
        let names: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
        // A write into a missing directory fails and creates nothing.
        assert!(write_atomic(&d.join("no/such/dir.json"), b"x").is_err());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_killed_writes_temporaries_go_with_the_next_write() {
        let d = scratch("stale");
        let f = d.join("cal.yaml");
        // PID 0 never names a process that can be a writer; our own PID runs.
        let dead = d.join(".cal.yaml.tmp-0-3");
        let ours = d.join(format!(".cal.yaml.tmp-{}-99", std::process::id()));
        let other = d.join(".other.yaml.tmp-0-1");
        let staged = d.join(".cal.yaml.tmp-0-4");
        for p in [&dead, &ours, &other] {
            std::fs::write(p, "half").unwrap();
        }
        std::fs::create_dir(&staged).unwrap();
        std::fs::write(staged.join("x"), "x").unwrap();
        write_atomic(&f, b"new").unwrap();
        if process_alive(0).is_some() {
            assert!(!dead.exists() && !staged.exists(), "stale temporaries kept");
        }
        // A directory replaced aside by a killed `replace_dir`: removed once
        // the target is in place, kept while it is the only copy.
        let report = d.join("report");
        let aside = d.join(".report.old-0");
        std::fs::create_dir(&aside).unwrap();
        remove_stale_temporaries(&report);
        assert!(aside.exists(), "the only copy was removed");
        std::fs::create_dir(&report).unwrap();
        remove_stale_temporaries(&report);
        if process_alive(0).is_some() {
            assert!(!aside.exists(), "a stale aside directory kept");
        }
        assert!(
            ours.exists() && other.exists(),
            "a live or other temporary removed"
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn outputs_are_checked_before_work() {
        let d = scratch("check");
        let input = d.join("in.json");
        std::fs::write(&input, "{}").unwrap();
        fn out(p: &Path) -> Output<'_> {
            Output {
                label: "--out",
                path: p,
            }
        }
        let e =
            |o: &[Output<'_>], force| check_outputs(o, &[&input], force).unwrap_err().to_string();
        assert!(e(&[out(&d)], true).contains("is a directory"));
        assert!(e(&[out(&d.join("missing/x.json"))], false).contains("does not exist"));
        assert!(e(&[out(&input)], true).contains("is an input"));
        // The same file by another spelling is still the input.
        let other = d.join(".").join("in.json");
        assert!(e(&[out(&other)], true).contains("is an input"));
        assert!(e(&[out(&input)], false).contains("is an input"));
        let new = d.join("new.json");
        let second = Output {
            label: "--save-measurements",
            path: &new,
        };
        assert!(e(&[out(&new), second], true).contains("name the same file"));
        std::fs::write(&new, "old").unwrap();
        assert!(e(&[out(&new)], false).contains("overwriting it was not asked for"));
        check_outputs(&[out(&new)], &[&input], true).unwrap();
        check_outputs(&[out(&d.join("fresh.json"))], &[&input], false).unwrap();
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn output_directories_hold_no_input_and_no_other_output() {
        let d = scratch("dirs");
        let input = d.join("in.json");
        std::fs::write(&input, "{}").unwrap();
        let report = d.join("report");
        let o = |label, path| Output { label, path };
        let inputs = [o("--pool file:", &input)];
        let e = |dirs: &[Output<'_>], files: &[Output<'_>]| {
            output_dir_conflict(dirs, files, &inputs).expect("a conflict")
        };
        // The directory holding the input, by another spelling.
        let here = d.join(".");
        assert!(
            e(&[o("--report", &here)], &[])
                .contains("holds an input of this command (--pool file:")
        );
        // An output over an input, by another spelling, names both.
        let dotted = d.join(".").join("in.json");
        let over = output_over_input(&o("--out", &dotted), &inputs);
        assert!(over.is_some_and(|w| w.contains("--out") && w.contains("(--pool file:")));
        assert_eq!(output_over_input(&o("--out", &report), &inputs), None);
        // A file named like the directory, a file inside it (not yet made).
        let inside = report.join("x.json");
        assert!(e(&[o("--report", &report)], &[o("--out", &report)]).contains("name the same"));
        assert!(e(&[o("--report", &report)], &[o("--out", &inside)]).contains("is inside"));
        let elsewhere = d.join("x.json");
        let apart = [o("--report", &report)];
        assert_eq!(
            output_dir_conflict(&apart, &[o("--out", &elsewhere)], &inputs),
            None
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_staged_directory_replaces_the_old_one_whole() {
        let d = scratch("dir");
        let target = d.join("report");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("old.txt"), "old").unwrap();
        let staged = StagedDir::new(&target).unwrap();
        std::fs::write(staged.path().join("new.txt"), "new").unwrap();
        staged.commit().unwrap();
        assert!(target.join("new.txt").exists());
        assert!(
            !target.join("old.txt").exists(),
            "no old file beside the new ones"
        );
        // An abandoned staging directory is removed and the target kept.
        let staged = StagedDir::new(&target).unwrap();
        let path = staged.path().to_path_buf();
        drop(staged);
        assert!(!path.exists());
        assert!(target.join("new.txt").exists());
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
