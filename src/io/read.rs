//! Reading input files: the one function every loader of `io` reads a file
//! through, counting reads per file, so that a process can show (and a
//! test can check) that each input is read from disk once.

use crate::error::{Error, Result};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Reads per file, by canonical path (the path as given when it has none).
static READS: Mutex<BTreeMap<PathBuf, usize>> = Mutex::new(BTreeMap::new());

/// The file's text; an error names the file.
pub fn read_text(path: &Path) -> Result<String> {
    let text = std::fs::read_to_string(path).map_err(|cause| Error::Io {
        path: path.display().to_string(),
        cause,
    })?;
    let key = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    if let Ok(mut reads) = READS.lock() {
        *reads.entry(key).or_insert(0) += 1;
    }
    Ok(text)
}

/// How many times each file has been read by [`read_text`] in this
/// process, by canonical path.
#[must_use]
pub fn reads() -> Vec<(PathBuf, usize)> {
    READS
        .lock()
        .map(|r| r.iter().map(|(p, n)| (p.clone(), *n)).collect())
        .unwrap_or_default()
}
