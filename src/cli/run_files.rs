//! A command's files in one place: every file (or directory) it reads and
//! every file or directory it writes, collected by the command and checked
//! together, once, before any work ([`RunFiles::check`]). Paths are
//! compared by their canonical identity
//! ([`activecal::io::atomic::output_over_input`],
//! [`activecal::io::atomic::output_dir_conflict`],
//! [`activecal::io::atomic::check_outputs`]): `--force` never replaces
//! an input of the same run, two outputs never name one file, and a
//! directory replaced whole (`--report DIR`) holds no input and no other
//! output.

use activecal::io::RobotRef;
use activecal::io::atomic::{Output, output_dir_conflict, output_over_input};
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};

/// The files of one run of a command: its inputs, its output files and its
/// output directories, each with the option that named it.
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

    /// An input file or directory, named by the option `label` that gave it.
    pub fn input(&mut self, label: &str, path: Option<&Path>) -> &mut Self {
        if let Some(p) = path {
            self.inputs.push((label.to_string(), p.to_path_buf()));
        }
        self
    }

    /// Several inputs of one option (a repeatable one).
    pub fn inputs(&mut self, label: &str, paths: &[PathBuf]) -> &mut Self {
        for p in paths {
            self.input(label, Some(p.as_path()));
        }
        self
    }

    /// An output file, named by the option `label` that gave it.
    pub fn output(&mut self, label: &str, path: Option<&Path>) -> &mut Self {
        if let Some(p) = path {
            self.outputs.push((label.to_string(), p.to_path_buf()));
        }
        self
    }

    /// Several output files of one option (a repeatable `--out`).
    pub fn outputs(&mut self, label: &str, paths: &[PathBuf]) -> &mut Self {
        for p in paths {
            self.output(label, Some(p.as_path()));
        }
        self
    }

    /// An output directory replaced whole (`--report DIR`, `reproduce
    /// --out DIR`).
    pub fn dir(&mut self, label: &str, path: Option<&Path>) -> &mut Self {
        if let Some(p) = path {
            self.dirs.push((label.to_string(), p.to_path_buf()));
        }
        self
    }

    /// The robot's files: its description (when `--robot` names a file,
    /// not a built-in robot) and the chain's frames file (`--frames`).
    pub fn robot(&mut self, r: &RobotRef) -> &mut Self {
        self.robot_as("--robot", r)
    }

    /// As [`Self::robot`], the robot given by option `label` (`robots
    /// --export`).
    pub fn robot_as(&mut self, label: &str, r: &RobotRef) -> &mut Self {
        if r.path().is_file() {
            self.input(label, Some(r.path()));
        }
        let frames = r.chain.frames.as_deref().map(Path::new);
        self.input("--frames", frames)
    }

    /// The files of the pool options: the robot's ([`Self::robot`]),
    /// `--pool file:`, `--srdf` and the `--package-dir` mesh directories.
    pub fn pool(&mut self, p: &super::PoolOpts) -> &mut Self {
        self.robot(&p.robot);
        if let super::PoolKind::File(f) = &p.pool {
            self.input("--pool file:", Some(f.as_path()));
        }
        self.input("--srdf", p.srdf.as_deref())
            .inputs("--package-dir", &p.package_dirs)
    }

    /// Checks every output against every input and every other output,
    /// by canonical identity, before any work: an output that is an input
    /// (even with `force`), two outputs naming one file, an output file
    /// inside (or naming) an output directory, an output directory holding
    /// an input; then each output file as
    /// [`activecal::io::atomic::check_outputs`] does (an existing file
    /// needs `force`, its directory must exist) and each output directory
    /// ([`check_dir`]).
    pub fn check(&self, force: bool) -> Result<()> {
        let (inputs, files, dirs) = (view(&self.inputs), view(&self.outputs), view(&self.dirs));
        let over_input = files.iter().find_map(|o| output_over_input(o, &inputs));
        if let Some(why) = over_input.or_else(|| output_dir_conflict(&dirs, &files, &inputs)) {
            bail!(why);
        }
        let paths: Vec<&Path> = inputs.iter().map(|i| i.path).collect();
        let pairs: Vec<(&str, &Path)> = files.iter().map(|o| (o.label, o.path)).collect();
        super::check_outputs(&pairs, &paths, force)?;
        for d in &dirs {
            check_dir(d.label, d.path, force)?;
        }
        Ok(())
    }
}

/// Labelled paths as the library's [`Output`]s.
fn view(v: &[(String, PathBuf)]) -> Vec<Output<'_>> {
    v.iter()
        .map(|(label, path)| Output { label, path })
        .collect()
}

/// Refuses an output directory `dir` (named by option `label`) that is a
/// file, is a non-empty directory (without `force`: it is replaced whole),
/// or whose parent does not exist.
pub fn check_dir(label: &str, dir: &Path, force: bool) -> Result<()> {
    if dir.exists() {
        if !dir.is_dir() {
            bail!("{label} {}: exists and is not a directory", dir.display());
        }
        let non_empty = std::fs::read_dir(dir)
            .map(|mut d| d.next().is_some())
            .unwrap_or(true);
        if non_empty && !force {
            bail!(
                "{label} {}: exists and is not empty; pass --force to replace it",
                dir.display()
            );
        }
    }
    if let Some(parent) = dir
        .parent()
        .filter(|p| !p.as_os_str().is_empty() && !p.is_dir())
    {
        bail!(
            "{label} {}: the directory {} does not exist",
            dir.display(),
            parent.display()
        );
    }
    Ok(())
}
