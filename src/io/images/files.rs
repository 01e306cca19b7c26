//! The image files a `DIR|GLOB` names: every `.png`, `.jpg` or `.jpeg`
//! (in any case) in a directory, or
//! the files whose names match a pattern (`*` any run of characters, `?`
//! one character, in the file name only: `shots/pose_*.png`), or one
//! file; sorted by name.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// The image files `spec` names (see the module documentation); an error
/// when it names none.
pub fn image_files(spec: &Path) -> Result<Vec<PathBuf>> {
    let err = |message: String| Error::Parse {
        path: spec.display().to_string(),
        message,
    };
    let name = spec
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if spec.is_dir() {
        let files = listed(spec, |n| {
            Path::new(n).extension().is_some_and(|e| {
                ["png", "jpg", "jpeg"]
                    .iter()
                    .any(|k| e.eq_ignore_ascii_case(k))
            })
        })?;
        if files.is_empty() {
            return Err(err(
                "the directory holds no .png, .jpg or .jpeg image".into()
            ));
        }
        return Ok(files);
    }
    if name.contains(['*', '?']) {
        let dir = match spec.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if dir.to_string_lossy().contains(['*', '?']) {
            return Err(err(
                "a pattern may only match file names, not directories".into()
            ));
        }
        if !dir.is_dir() {
            return Err(err(format!("no directory {}", dir.display())));
        }
        let files = listed(&dir, |n| matches(&name, n))?;
        if files.is_empty() {
            return Err(err(format!(
                "no file in {} matches '{name}'",
                dir.display()
            )));
        }
        return Ok(files);
    }
    if spec.is_file() {
        return Ok(vec![spec.to_path_buf()]);
    }
    Err(err(
        "no such directory or file (give a directory of .png or .jpg images, a pattern such as 'dir/*.png', or one image)".into(),
    ))
}

/// The files of `dir` whose names `keep` accepts, sorted by name.
fn listed(dir: &Path, keep: impl Fn(&str) -> bool) -> Result<Vec<PathBuf>> {
    let io = |cause| Error::Io {
        path: dir.display().to_string(),
        cause,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let entry = entry.map_err(io)?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if entry.path().is_file() && keep(&name) {
            files.push(entry.path());
        }
    }
    files.sort();
    Ok(files)
}

/// Whether `name` matches `pattern` (`*` any run, `?` one character).
#[must_use]
pub fn matches(pattern: &str, name: &str) -> bool {
    let (p, n): (Vec<char>, Vec<char>) = (pattern.chars().collect(), name.chars().collect());
    // Greedy matching with one backtrack point: the last `*`.
    let (mut i, mut j, mut star, mut mark) = (0, 0, None, 0);
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some(i);
            mark = j;
            i += 1;
        } else if let Some(s) = star {
            i = s + 1;
            mark += 1;
            j = mark;
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_match_as_a_shell_does() {
        assert!(matches("*.png", "img_000.png"));
        assert!(matches("img_??.png", "img_01.png"));
        assert!(!matches("img_??.png", "img_001.png"));
        assert!(matches("a*b*c", "aXXbYYc"));
        assert!(!matches("a*b*c", "aXXbYY"));
        assert!(matches("*", ""));
        assert!(!matches("*.png", "img.PNG.txt"));
    }

    #[test]
    fn a_directory_a_pattern_and_a_file_name_their_images() {
        let d = std::env::temp_dir().join(format!("activecal-image-files-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        for f in ["b.png", "a.png", "notes.txt", "c.PNG", "d.jpg", "e.JPEG"] {
            std::fs::write(d.join(f), b"x").unwrap();
        }
        let names = |v: Vec<PathBuf>| -> Vec<String> {
            v.iter()
                .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
                .collect()
        };
        assert_eq!(
            names(image_files(&d).unwrap()),
            ["a.png", "b.png", "c.PNG", "d.jpg", "e.JPEG"]
        );
        assert_eq!(
            names(image_files(&d.join("?.png")).unwrap()),
            ["a.png", "b.png"]
        );
        assert_eq!(names(image_files(&d.join("a.png")).unwrap()), ["a.png"]);
        let e = image_files(&d.join("z*.png")).unwrap_err().to_string();
        assert!(e.contains("no file in") && e.contains("'z*.png'"), "{e}");
        let e = image_files(&d.join("missing")).unwrap_err().to_string();
        assert!(e.contains("no such directory or file"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
