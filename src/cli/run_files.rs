//! A command's files, collected by the command with the options that named
//! them and checked together, once, before any work: the library's
//! [`RunFiles`], with the pool options' files ([`pool`]) and its refusals
//! said with `--force` ([`check`]).

pub use activecal::io::run_files::RunFiles;
use anyhow::Result;

/// The robot's files: `--robot` (a file, not a built-in name) and `--frames`.
pub fn robot<'a>(f: &'a mut RunFiles, r: &activecal::io::RobotRef) -> &'a mut RunFiles {
    f.robot("--robot", r, "--frames")
}

/// The files of the pool options: the robot's ([`robot`]), `--pool file:`,
/// `--srdf` and the `--package-dir` mesh directories.
pub fn pool<'a>(f: &'a mut RunFiles, p: &super::PoolOpts) -> &'a mut RunFiles {
    robot(f, &p.robot);
    if let super::PoolKind::File(file) = &p.pool {
        f.input("--pool file:", Some(file.as_path()));
    }
    f.input("--srdf", p.srdf.as_deref())
        .inputs("--package-dir", &p.package_dirs)
}

/// [`RunFiles::check`], its refusals of an existing output said with
/// `--force`.
pub fn check(f: &RunFiles, force: bool) -> Result<()> {
    f.check(force).map_err(|e| match e {
        activecal::Error::OutputExists { label, path } => {
            anyhow::anyhow!("{label} {path}: exists; pass --force to overwrite it")
        }
        activecal::Error::OutputDirNotEmpty { label, path } => {
            anyhow::anyhow!("{label} {path}: exists and is not empty; pass --force to replace it")
        }
        e => e.into(),
    })
}
