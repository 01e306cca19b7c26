//! A run's files in one place: every file (or directory) a run reads and
//! every file or directory it writes, each with the words its caller names
//! it by (a command line's option, a Python argument), checked together,
//! once, before any work ([`RunFiles::check`]). Paths are compared by their
//! canonical identity ([`super::atomic::output_over_input`],
//! [`super::atomic::output_dir_conflict`], [`super::atomic::check_outputs`]):
//! overwriting never replaces an input of the same run, two outputs never
//! name one file, and a directory replaced whole (a report folder) holds no
//! input and no other output.

use super::RobotRef;
use super::atomic::{Output, check_outputs, output_dir_conflict, output_over_input};
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// The files of one run: its inputs, its output files and its output
/// directories, each with the label that named it.
#[derive(Debug, Default)]
pub struct RunFiles {
    inputs: Vec<(String, PathBuf)>,
    outputs: Vec<(String, PathBuf)>,
    dirs: Vec<(String, PathBuf)>,
}

impl RunFiles {
    /// No files yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// An input file or directory, named by `label`.
    pub fn input(&mut self, label: &str, path: Option<&Path>) -> &mut Self {
        if let Some(p) = path {
            self.inputs.push((label.to_string(), p.to_path_buf()));
        }
        self
    }

    /// Several inputs under one label (a repeatable option).
    pub fn inputs(&mut self, label: &str, paths: &[PathBuf]) -> &mut Self {
        for p in paths {
            self.input(label, Some(p.as_path()));
        }
        self
    }

    /// An output file, named by `label`.
    pub fn output(&mut self, label: &str, path: Option<&Path>) -> &mut Self {
        if let Some(p) = path {
            self.outputs.push((label.to_string(), p.to_path_buf()));
        }
        self
    }

    /// Several output files under one label.
    pub fn outputs(&mut self, label: &str, paths: &[PathBuf]) -> &mut Self {
        for p in paths {
            self.output(label, Some(p.as_path()));
        }
        self
    }

    /// An output directory replaced whole (a report folder).
    pub fn dir(&mut self, label: &str, path: Option<&Path>) -> &mut Self {
        if let Some(p) = path {
            self.dirs.push((label.to_string(), p.to_path_buf()));
        }
        self
    }

    /// The robot's files, `r` named by `label`: its description (when `r`
    /// names a file, not a built-in robot) and the chain's frames file,
    /// named by `frames_label`.
    pub fn robot(&mut self, label: &str, r: &RobotRef, frames_label: &str) -> &mut Self {
        if r.path().is_file() {
            self.input(label, Some(r.path()));
        }
        let frames = r.chain.frames.as_deref().map(Path::new);
        self.input(frames_label, frames)
    }

    /// Checks every output against every input and every other output,
    /// by canonical identity, before any work: an output that is an input
    /// (even when overwriting is asked for), two outputs naming one file,
    /// an output file inside (or naming) an output directory, an output
    /// directory holding an input ([`Error::Invalid`]); then each output
    /// file as [`check_outputs`] does (an existing file needs `overwrite`:
    /// [`Error::OutputExists`]; its directory must exist) and each output
    /// directory as [`check_output_dir`] does.
    pub fn check(&self, overwrite: bool) -> Result<()> {
        let (inputs, files, dirs) = (view(&self.inputs), view(&self.outputs), view(&self.dirs));
        let over_input = files.iter().find_map(|o| output_over_input(o, &inputs));
        if let Some(why) = over_input.or_else(|| output_dir_conflict(&dirs, &files, &inputs)) {
            return Err(Error::Invalid(why));
        }
        let paths: Vec<&Path> = inputs.iter().map(|i| i.path).collect();
        check_outputs(&files, &paths, overwrite)?;
        for d in &dirs {
            check_output_dir(d.label, d.path, overwrite)?;
        }
        Ok(())
    }
}

/// Labelled paths as [`Output`]s.
fn view(v: &[(String, PathBuf)]) -> Vec<Output<'_>> {
    v.iter()
        .map(|(label, path)| Output { label, path })
        .collect()
}

/// Refuses an output directory `dir` (named by `label`) that is a file
/// ([`Error::Invalid`]), a non-empty directory unless `overwrite` (it is
/// replaced whole: [`Error::OutputDirNotEmpty`]), or whose parent does not
/// exist ([`Error::Invalid`]).
pub fn check_output_dir(label: &str, dir: &Path, overwrite: bool) -> Result<()> {
    if dir.exists() {
        if !dir.is_dir() {
            return Err(Error::Invalid(format!(
                "{label} {}: exists and is not a directory",
                dir.display()
            )));
        }
        let non_empty = std::fs::read_dir(dir).map_or(true, |mut d| d.next().is_some());
        if non_empty && !overwrite {
            return Err(Error::OutputDirNotEmpty {
                label: label.to_string(),
                path: dir.display().to_string(),
            });
        }
    }
    if let Some(parent) = dir
        .parent()
        .filter(|p| !p.as_os_str().is_empty() && !p.is_dir())
    {
        return Err(Error::Invalid(format!(
            "{label} {}: the directory {} does not exist",
            dir.display(),
            parent.display()
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("run_files_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn an_output_over_an_input_is_refused_even_when_overwriting() {
        let d = scratch("over");
        let input = d.join("in.csv");
        std::fs::write(&input, "x").unwrap();
        let mut f = RunFiles::new();
        f.input("--measurements", Some(&input))
            .output("--out", Some(&input));
        let e = f.check(true).unwrap_err().to_string();
        assert!(e.contains("--out") && e.contains("--measurements"), "{e}");
    }

    #[test]
    fn a_non_empty_report_folder_needs_overwrite_and_a_file_is_no_folder() {
        let d = scratch("dir");
        std::fs::write(d.join("old.txt"), "x").unwrap();
        let mut f = RunFiles::new();
        f.dir("--report", Some(&d));
        assert!(matches!(
            f.check(false),
            Err(Error::OutputDirNotEmpty { .. })
        ));
        f.check(true).unwrap();
        let file = d.join("old.txt");
        let e = check_output_dir("path", &file, true)
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("exists and is not a directory"), "{e}");
        let e = check_output_dir("path", &d.join("no/such"), true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("does not exist"), "{e}");
    }
}
