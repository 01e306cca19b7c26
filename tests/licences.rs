//! Licences: the workspace's licence files exist, and every file under
//! `fixtures/` is named, with its licence, by the nearest `NOTICE.md` above
//! it (its own folder's, or an ancestor's up to `fixtures/`).
//!
//! A NOTICE names a file by a backticked path relative to the NOTICE's
//! folder: the path itself, a glob (`*` within one path segment) or a
//! folder (`dir/`). The entry that names it — a table row, a list item or a
//! paragraph — must also name a licence. Reading a few dozen small files:
//! cheap.

use std::path::{Path, PathBuf};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Words that name a licence in an entry.
const LICENCES: &[&str] = &["MIT", "Apache-2.0", "BSD", "MPL-2.0", "CC BY"];

/// Every file under `dir`, recursively.
fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let path = e.unwrap().path();
        if path.is_dir() {
            files_under(&path, out);
        } else {
            out.push(path);
        }
    }
}

/// The entries of a NOTICE: each table row and list item on its own, any
/// other paragraph whole.
fn entries(text: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut para = String::new();
    let flush = |para: &mut String, out: &mut Vec<String>| {
        if !para.trim().is_empty() {
            out.push(std::mem::take(para));
        }
        para.clear();
    };
    for line in text.lines() {
        let starts_item = line.starts_with('|') || line.starts_with("- ");
        if line.trim().is_empty() || starts_item {
            flush(&mut para, &mut out);
        }
        para.push_str(line);
        para.push('\n');
        if line.starts_with('|') {
            flush(&mut para, &mut out);
        }
    }
    flush(&mut para, &mut out);
    out
}

/// The backticked tokens of an entry.
fn tokens(entry: &str) -> Vec<&str> {
    entry.split('`').skip(1).step_by(2).collect()
}

/// `pattern` matches `name`, `*` standing for any run of characters
/// other than `/`.
fn glob(pattern: &str, name: &str) -> bool {
    match pattern.split_once('*') {
        None => pattern == name,
        Some((head, tail)) => {
            let Some(rest) = name.strip_prefix(head) else {
                return false;
            };
            (0..=rest.len())
                .take_while(|&k| !rest[..k].contains('/'))
                .filter(|&k| rest.is_char_boundary(k))
                .any(|k| glob(tail, &rest[k..]))
        }
    }
}

/// Whether token `t` of a NOTICE names the file at `rel` (relative to the
/// NOTICE's folder).
fn names(t: &str, rel: &str) -> bool {
    glob(t, rel) || (t.ends_with('/') && rel.starts_with(t))
}

/// The nearest `NOTICE.md` above `file`, not above `top`.
fn nearest_notice(file: &Path, top: &Path) -> Option<PathBuf> {
    let mut dir = file.parent()?;
    loop {
        let n = dir.join("NOTICE.md");
        if n.is_file() {
            return Some(n);
        }
        if dir == top {
            return None;
        }
        dir = dir.parent()?;
    }
}

/// What is wrong with `file`'s licence entry, if anything.
fn uncovered(file: &Path, top: &Path) -> Option<String> {
    let shown = file
        .strip_prefix(ROOT)
        .unwrap_or(file)
        .display()
        .to_string();
    let Some(notice) = nearest_notice(file, top) else {
        return Some(format!("{shown}: no NOTICE.md above it"));
    };
    let rel = file
        .strip_prefix(notice.parent().unwrap())
        .unwrap()
        .to_string_lossy()
        .replace('\\', "/");
    let text = std::fs::read_to_string(&notice).unwrap();
    let named: Vec<String> = entries(&text)
        .into_iter()
        .filter(|e| tokens(e).iter().any(|t| names(t, &rel)))
        .collect();
    if named.is_empty() {
        return Some(format!("{shown}: not named in {}", notice.display()));
    }
    if !named.iter().any(|e| LICENCES.iter().any(|l| e.contains(l))) {
        return Some(format!(
            "{shown}: named in {} without a licence",
            notice.display()
        ));
    }
    None
}

#[test]
fn the_matcher_reads_paths_globs_and_folders() {
    assert!(glob("fk/*.json", "fk/panda.json"));
    assert!(!glob("fk/*.json", "fk/sub/panda.json"));
    assert!(!glob("fk/*.json", "idjac/panda.json"));
    assert!(glob("a.urdf", "a.urdf") && !glob("a.urdf", "b.urdf"));
    assert!(names("robots/", "robots/x/y.stl"));
    let e = entries("intro `a`\nMIT\n\n| `b` | BSD |\n| `c` | none |\n- `d` is\n  Apache-2.0\n");
    assert_eq!(e.len(), 4, "{e:?}");
    assert_eq!(tokens(&e[3]), ["d"]);
    assert!(e[3].contains("Apache-2.0"));
}

#[test]
fn every_fixture_is_named_with_its_licence() {
    let top = Path::new(ROOT).join("fixtures");
    let mut files = Vec::new();
    files_under(&top, &mut files);
    files.retain(|f| f.file_name().is_some_and(|n| n != "NOTICE.md"));
    assert!(files.len() > 50, "{} files under fixtures/", files.len());
    let missing: Vec<String> = files.iter().filter_map(|f| uncovered(f, &top)).collect();
    assert!(
        missing.is_empty(),
        "{} of {} fixtures lack a NOTICE entry with a licence:\n{}",
        missing.len(),
        files.len(),
        missing.join("\n")
    );
    // A file that is not named fails: the check can fail.
    let ghost = top.join("figaroh/ghost.urdf");
    assert!(uncovered(&ghost, &top).is_some());
}

#[test]
fn the_workspace_states_its_licence() {
    for f in ["LICENSE-MIT", "LICENSE-APACHE"] {
        let text = std::fs::read_to_string(Path::new(ROOT).join(f)).unwrap();
        assert!(text.len() > 1000, "{f} is not a full licence text");
    }
    for manifest in [
        "Cargo.toml",
        "proptests/Cargo.toml",
        "verify/Cargo.toml",
        "crates/aprilgrid/Cargo.toml",
    ] {
        let text = std::fs::read_to_string(Path::new(ROOT).join(manifest)).unwrap();
        assert!(
            text.contains("license = \"MIT OR Apache-2.0\""),
            "{manifest} lacks the licence"
        );
    }
}

#[test]
fn vendored_code_keeps_its_authors_licence_and_says_where_it_came_from() {
    let dir = Path::new(ROOT).join("crates/aprilgrid");
    let licence = std::fs::read_to_string(dir.join("LICENSE")).unwrap();
    assert!(
        licence.starts_with("MIT License") && licence.contains("Copyright (c) 2024 Powei Lin"),
        "crates/aprilgrid/LICENSE is not aprilgrid-rs's MIT text"
    );
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    for needed in [
        "aprilgrid-rs 0.8.0",
        "github.com/powei-lin/aprilgrid-rs",
        "Changed",
    ] {
        assert!(
            readme.contains(needed),
            "crates/aprilgrid/README.md lacks {needed:?}"
        );
    }
}
