//! Every shell example of `README.md` and `docs/*.md` runs here, and prints
//! what the page says it prints.
//!
//! An example is a fenced block tagged `console`:
//!
//! ````text
//! ```console
//! $ activecal select --robot puma560 --n 30 --levels 3
//! log10 OI_D 25.1... OI ...
//! ```
//! ````
//!
//! - A line starting with `$ ` is a command (a line ending in `\` goes on to
//!   the next). It runs in `sh`, with the freshly built `activecal` first
//!   on `PATH`, in a scratch directory of its page: every example of one
//!   page shares it, in page order (a later command reads what an earlier
//!   one wrote), and `fixtures/` there is the repository's.
//! - The lines after it, up to the next command, are the lines of its
//!   output (stdout and stderr together) that matter: each must match an
//!   output line, in this order; output lines between them are skipped.
//!   Runs of spaces count as one space.
//! - Within a line, `...` stands for any text (spaces beside it too). A number matches a printed
//!   number within 1e-3 relative or one unit of its last printed digit
//!   (`2.598` matches 2.597–2.599), an integer (no decimal point) exactly.
//!   All other text matches exactly.
//! - A command that exits with a status other than 0 must say so: its
//!   output ends with the line `[exit status: N]`.
//!
//! A block tagged `sh`, `bash` or `shell` is not run, and is allowed only
//! right after a line `<!-- not run: REASON -->`: every shell example is
//! either run or says why not. `DOCS_EXAMPLES_ONLY=docs/x.md` runs one
//! page; `DOCS_EXAMPLES_SHOW=1` prints every command's whole output.
//!
//! Beyond the lines a page promises, every command's *whole* output is
//! kept in `tests/golden/docs/<page>.txt` and must stay the same (a
//! refactoring of the front ends changes no output): text byte for byte,
//! a number within one unit of its last printed digit (another CPU's BLAS
//! kernels may round the last digit the other way), a duration (a number
//! followed by ` s` or ` ms`) free. `DOCS_GOLDEN_UPDATE=1` rewrites the
//! files after an intended change of output (review the diff).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// One command of a page, with the output lines it promises.
#[derive(Debug, Clone, PartialEq)]
pub struct Example {
    /// The page's 1-based line of the `$ ` line.
    pub line: usize,
    /// The command, continuation lines joined.
    pub command: String,
    /// The output lines that matter, in order.
    pub expected: Vec<String>,
}

/// What a page holds: its examples, and its shell blocks that are not run
/// without a reason (by line).
#[derive(Debug, Default)]
pub struct Page {
    pub examples: Vec<Example>,
    pub unexplained: Vec<usize>,
}

/// The examples and the unexplained shell blocks of a Markdown page.
pub fn parse_page(text: &str) -> Page {
    let lines: Vec<&str> = text.lines().collect();
    let mut page = Page::default();
    let mut i = 0;
    while i < lines.len() {
        let fence = lines[i].trim_start();
        let Some(lang) = fence.strip_prefix("```") else {
            i += 1;
            continue;
        };
        let lang = lang.trim();
        let end = (i + 1..lines.len())
            .find(|&k| lines[k].trim_start().starts_with("```"))
            .unwrap_or(lines.len());
        if lang == "console" {
            page.examples
                .extend(parse_console(&lines[i + 1..end], i + 2));
        } else if matches!(lang, "sh" | "bash" | "shell" | "zsh") {
            let reason = lines[..i]
                .iter()
                .rev()
                .find(|l| !l.trim().is_empty())
                .is_some_and(|l| l.trim().starts_with("<!-- not run:"));
            if !reason {
                page.unexplained.push(i + 1);
            }
        }
        i = end + 1;
    }
    page
}

/// The commands of one `console` block whose first line is `first_line`.
fn parse_console(block: &[&str], first_line: usize) -> Vec<Example> {
    let mut out: Vec<Example> = Vec::new();
    let mut k = 0;
    while k < block.len() {
        let line = block[k];
        if let Some(cmd) = line.strip_prefix("$ ") {
            let start = k;
            let mut command = String::new();
            let mut part = cmd;
            loop {
                match part.trim_end().strip_suffix('\\') {
                    Some(head) if k + 1 < block.len() => {
                        command.push_str(head.trim_end());
                        command.push(' ');
                        k += 1;
                        part = block[k].trim_start().trim_start_matches("> ");
                    }
                    _ => {
                        command.push_str(part.trim_end());
                        break;
                    }
                }
            }
            out.push(Example {
                line: first_line + start,
                command,
                expected: Vec::new(),
            });
        } else if let Some(ex) = out.last_mut()
            && !line.trim().is_empty()
        {
            ex.expected.push(line.to_string());
        }
        k += 1;
    }
    out
}

/// Runs of whitespace as one space, ends trimmed.
fn squeeze(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A number printed at the start of `s`: its value, its length in bytes
/// and its decimals (`None` for an integer). A sign is part of it only
/// where a digit follows.
fn number_at(s: &str) -> Option<(f64, usize, Option<usize>)> {
    let b = s.as_bytes();
    let mut k = usize::from(b.first() == Some(&b'-'));
    let digits = |k: &mut usize| {
        let s = *k;
        while *k < b.len() && b[*k].is_ascii_digit() {
            *k += 1;
        }
        *k - s
    };
    if digits(&mut k) == 0 {
        return None;
    }
    let mut decimals = None;
    if k + 1 < b.len() && b[k] == b'.' && b[k + 1].is_ascii_digit() {
        k += 1;
        decimals = Some(digits(&mut k));
    }
    if k + 1 < b.len() && matches!(b[k], b'e' | b'E') {
        let mut e = k + 1;
        if e < b.len() && matches!(b[e], b'-' | b'+') {
            e += 1;
        }
        if digits(&mut e) > 0 {
            k = e;
            decimals = decimals.or(Some(0));
        }
    }
    let v: f64 = s[..k].parse().ok()?;
    Some((v, k, decimals))
}

/// Whether a printed `actual` number is the expected one within the
/// tolerance of the module's documentation.
fn numbers_agree(expected: f64, decimals: Option<usize>, actual: f64) -> bool {
    match decimals {
        None => expected == actual,
        Some(d) => {
            let unit = 10f64.powi(-(d as i32));
            let tol = (1e-3 * expected.abs()).max(unit * (1.0 + 1e-9));
            (actual - expected).abs() <= tol
        }
    }
}

/// Whether the whole of `actual` matches the whole of `expected` (both
/// squeezed): `...` any text, numbers within tolerance, the rest exact.
pub fn line_matches(expected: &str, actual: &str) -> bool {
    if expected.is_empty() {
        return actual.is_empty();
    }
    if let Some(rest) = expected.strip_prefix("...") {
        return actual
            .char_indices()
            .map(|(k, _)| k)
            .chain([actual.len()])
            .any(|k| line_matches(rest, &actual[k..]));
    }
    if let Some((ev, elen, decimals)) = number_at(expected) {
        return number_at(actual).is_some_and(|(av, alen, _)| {
            numbers_agree(ev, decimals, av) && line_matches(&expected[elen..], &actual[alen..])
        });
    }
    let c = expected.chars().next().expect("not empty");
    actual.starts_with(c) && line_matches(&expected[c.len_utf8()..], &actual[c.len_utf8()..])
}

/// The first expected line no output line matches (in order), if any:
/// its index in `expected` and the output index where the search began.
pub fn first_unmatched(expected: &[String], output: &str) -> Option<(usize, usize)> {
    let out: Vec<String> = output.lines().map(squeeze).collect();
    let mut from = 0;
    for (i, e) in expected.iter().enumerate() {
        // A space beside `...` is part of what it stands for.
        let e = squeeze(e).replace(" ...", "...").replace("... ", "...");
        match (from..out.len()).find(|&k| line_matches(&e, &out[k])) {
            Some(k) => from = k + 1,
            None => return Some((i, from)),
        }
    }
    None
}

/// The relative links of a page (`](path)` or `](path#anchor)`) whose
/// file does not exist, from the page's directory.
fn broken_links(page: &Path, text: &str) -> Vec<String> {
    let dir = page.parent().expect("a page is in a directory");
    text.split("](")
        .skip(1)
        .filter_map(|rest| rest.split(')').next())
        .filter(|t| !t.starts_with("http") && !t.starts_with('#') && !t.contains(' '))
        .filter(|t| {
            let file = t.split('#').next().unwrap_or(t);
            !dir.join(file).exists()
        })
        .map(str::to_string)
        .collect()
}

/// The pages whose examples run: the README and every chapter of `docs/`.
fn pages(root: &Path) -> Vec<PathBuf> {
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .map(|d| {
            d.filter_map(|e| Some(e.ok()?.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "md"))
                .collect()
        })
        .unwrap_or_default();
    docs.sort();
    let mut all = vec![root.join("README.md")];
    all.extend(docs);
    if let Ok(only) = std::env::var("DOCS_EXAMPLES_ONLY") {
        all.retain(|p| p.ends_with(&only));
    }
    all
}

/// A fresh scratch directory for one page, with the repository's fixtures.
fn scratch(root: &Path, page: &Path) -> PathBuf {
    let stem = page.file_stem().expect("a file name").to_string_lossy();
    let dir = std::env::temp_dir().join(format!("activecal-docs-{}-{stem}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a scratch directory");
    std::os::unix::fs::symlink(root.join("fixtures"), dir.join("fixtures"))
        .expect("fixtures linked");
    dir
}

/// Runs one command in `dir`: its stdout and stderr together, and
/// `[exit status: N]` at the end when it did not exit with 0.
fn run_example(dir: &Path, command: &str) -> String {
    let bin = Path::new(env!("CARGO_BIN_EXE_activecal"));
    let path = format!(
        "{}:{}",
        bin.parent().expect("the binary's directory").display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!("exec 2>&1\n{command}"))
        .current_dir(dir)
        .env("PATH", path)
        .env("NO_COLOR", "1")
        .output()
        .expect("sh runs");
    let mut text = String::from_utf8_lossy(&out.stdout).into_owned();
    match out.status.code() {
        Some(0) => {}
        Some(c) => text.push_str(&format!("\n[exit status: {c}]\n")),
        None => text.push_str("\n[killed by a signal]\n"),
    }
    text
}

/// The whole outputs of one page's commands, as kept in its golden file:
/// each command after a `$ ` line, its output after it.
fn transcript(runs: &[(String, String)]) -> String {
    let mut t = String::new();
    for (command, output) in runs {
        t.push_str("$ ");
        t.push_str(command);
        t.push('\n');
        t.push_str(output);
        if !output.ends_with('\n') {
            t.push('\n');
        }
    }
    t
}

/// Whether a printed number `actual` is `expected` within one unit of the
/// last digit `expected` prints (the same text always agrees).
fn same_number(expected: &str, actual: &str) -> bool {
    if expected == actual {
        return true;
    }
    match (number_at(expected), number_at(actual)) {
        (Some((e, _, Some(d))), Some((a, _, Some(da)))) if d == da => {
            (a - e).abs() <= 10f64.powi(-(d as i32)) * (1.0 + 1e-9) * scale_of(expected)
        }
        _ => false,
    }
}

/// The power of ten a number in exponent notation carries (1 otherwise):
/// `1.25e-7`'s last digit is a unit of 1e-9.
fn scale_of(s: &str) -> f64 {
    s.find(['e', 'E'])
        .and_then(|k| s[k + 1..].parse::<i32>().ok())
        .map_or(1.0, |x| 10f64.powi(x))
}

/// The tokens of a line: runs of a number (as [`number_at`] reads it),
/// and single other characters.
fn tokens(line: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < line.len() {
        let at_boundary = k == 0 || !line.as_bytes()[k - 1].is_ascii_alphanumeric();
        let n = if at_boundary {
            number_at(&line[k..]).map(|(_, n, _)| n)
        } else {
            None
        };
        let len = n.unwrap_or_else(|| line[k..].chars().next().map_or(1, char::len_utf8));
        out.push(&line[k..k + len]);
        k += len;
    }
    out
}

/// Whether an output line equals its golden line (see the module
/// documentation: numbers to one unit of the last digit, durations free).
pub fn golden_line_matches(golden: &str, actual: &str) -> bool {
    let (g, a) = (tokens(golden), tokens(actual));
    if g.len() != a.len() {
        return false;
    }
    let duration = |t: &[&str], i: usize| {
        let rest: String = t[i + 1..].iter().take(3).copied().collect();
        rest.starts_with(" s") && !rest[2..].starts_with(|c: char| c.is_alphanumeric())
            || rest.starts_with(" ms")
            || rest.starts_with("s)")
    };
    g.iter().zip(&a).enumerate().all(|(i, (x, y))| {
        x == y
            || number_at(x).is_some()
                && number_at(y).is_some()
                && (duration(&g, i) || same_number(x, y))
    })
}

/// Where a page's whole output first differs from its golden file, if it
/// does (or why the file cannot be read).
fn golden_difference(root: &Path, page: &Path, transcript: &str) -> Option<String> {
    let stem = page
        .file_stem()
        .expect("a page has a name")
        .to_string_lossy();
    let file = root.join("tests/golden/docs").join(format!("{stem}.txt"));
    if std::env::var_os("DOCS_GOLDEN_UPDATE").is_some() {
        std::fs::create_dir_all(file.parent().expect("a folder")).expect("the golden folder");
        std::fs::write(&file, transcript).expect("the golden file written");
        return None;
    }
    let Ok(golden) = std::fs::read_to_string(&file) else {
        return Some(format!(
            "{}: no golden output {} (DOCS_GOLDEN_UPDATE=1 writes it)",
            page.display(),
            file.display()
        ));
    };
    let (g, a): (Vec<&str>, Vec<&str>) = (golden.lines().collect(), transcript.lines().collect());
    let at = (0..g.len().max(a.len())).find(
        |&k| !matches!((g.get(k), a.get(k)), (Some(x), Some(y)) if golden_line_matches(x, y)),
    )?;
    let command = g[..at.min(g.len())]
        .iter()
        .rev()
        .find(|l| l.starts_with("$ "))
        .copied()
        .unwrap_or("");
    Some(format!(
        "{}: the whole output differs from {} at its line {} (in `{}`):\n  golden: {}\n  now:    {}\n  (an intended change: DOCS_GOLDEN_UPDATE=1, then review the diff)",
        page.display(),
        file.display(),
        at + 1,
        command.trim_start_matches("$ "),
        g.get(at).copied().unwrap_or("<end of file>"),
        a.get(at).copied().unwrap_or("<end of output>")
    ))
}

/// Why an example's output is not what its page says, if it is not.
fn check(page: &Path, ex: &Example, output: &str) -> Option<String> {
    let (i, from) = first_unmatched(&ex.expected, output)?;
    let tail: Vec<&str> = output.lines().skip(from).take(40).collect();
    Some(format!(
        "{}:{}: `{}`\n  expected line {} of the example (page line {}), found in no output line from line {} on:\n    {}\n  the output from there:\n    {}",
        page.display(),
        ex.line,
        ex.command,
        i + 1,
        ex.line + 1 + i,
        from + 1,
        ex.expected[i],
        tail.join("\n    ")
    ))
}

#[test]
fn every_shell_example_in_the_readme_and_docs_runs_and_prints_what_it_says() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let show = std::env::var_os("DOCS_EXAMPLES_SHOW").is_some();
    let (mut failures, mut count) = (Vec::new(), 0);
    let start = Instant::now();
    for page in pages(root) {
        let text = std::fs::read_to_string(&page).expect("the page is readable");
        for link in broken_links(&page, &text) {
            failures.push(format!("{}: the link {link} leads nowhere", page.display()));
        }
        let page = page.strip_prefix(root).unwrap_or(&page).to_path_buf();
        let parsed = parse_page(&text);
        for line in parsed.unexplained {
            failures.push(format!(
                "{}:{line}: a shell block that is not run: tag it `console` with its output, or say why after `<!-- not run: `",
                page.display()
            ));
        }
        let dir = scratch(root, &page);
        let mut runs = Vec::new();
        for ex in &parsed.examples {
            let t = Instant::now();
            let output = run_example(&dir, &ex.command);
            count += 1;
            eprintln!(
                "{}:{} ({:.2} s): {}",
                page.display(),
                ex.line,
                t.elapsed().as_secs_f64(),
                ex.command
            );
            if show {
                eprintln!("{output}");
            }
            failures.extend(check(&page, ex, &output));
            runs.push((
                ex.command.clone(),
                output.replace(&dir.display().to_string(), "SCRATCH"),
            ));
        }
        if !parsed.examples.is_empty() && std::env::var_os("DOCS_EXAMPLES_ONLY").is_none() {
            failures.extend(golden_difference(root, &page, &transcript(&runs)));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    eprintln!("{count} examples in {:.1} s", start.elapsed().as_secs_f64());
    assert!(count > 0, "no example ran");
    assert!(
        failures.is_empty(),
        "{} of {count} examples differ:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

#[test]
fn a_figure_outside_its_tolerance_fails_and_elisions_match_anything() {
    assert!(line_matches(
        "fitted: position RMS 0.085 mm",
        "fitted: position RMS 0.0851 mm"
    ));
    assert!(line_matches("RMS 2.598 mm", "RMS 2.599 mm"));
    assert!(!line_matches("RMS 2.598 mm", "RMS 2.601 mm"));
    assert!(!line_matches("RMS 0.085 mm", "RMS 0.095 mm"));
    assert!(line_matches("rss 2.18e-7", "rss 2.182822e-7"));
    assert!(!line_matches("30 poses", "31 poses"));
    assert!(!line_matches("RMS 2.598 mm", "RMS 2.598 m"));
    assert!(line_matches("poses in ... s", "poses in 0.105 s"));
    assert!(line_matches("a ... b ... c", "a x b y c"));
    assert!(!line_matches("a ... b", "a x c"));
    assert!(line_matches("tool0@0.03,-0.02,0.1", "tool0@0.03,-0.02,0.1"));
    assert!(!line_matches("x-1", "x-2"));
    // In order, lines between skipped; a missing one is named.
    let out = "one 1.0\ntwo  2.0\nthree 3.0\n";
    assert_eq!(
        first_unmatched(&["one 1.0".into(), "three 3.0".into()], out),
        None
    );
    assert_eq!(
        first_unmatched(&["two 2.0".into(), "one 1.0".into()], out),
        Some((1, 2))
    );
}

#[test]
fn golden_lines_allow_the_last_digit_and_durations_only() {
    assert!(golden_line_matches(
        "RMS 0.085 mm in 0.32 s",
        "RMS 0.085 mm in 1.70 s"
    ));
    assert!(golden_line_matches("RMS 0.085 mm", "RMS 0.086 mm"));
    assert!(!golden_line_matches("RMS 0.085 mm", "RMS 0.087 mm"));
    assert!(!golden_line_matches("RMS 0.085 mm", "RMS 0.0850 mm"));
    assert!(!golden_line_matches("RMS 0.085 mm", "RMS  0.085 mm"));
    assert!(golden_line_matches("rss 2.18e-7 m", "rss 2.19e-7 m"));
    assert!(!golden_line_matches("rss 2.18e-7 m", "rss 2.20e-7 m"));
    assert!(!golden_line_matches("30 poses", "31 poses"));
    assert!(!golden_line_matches("0.5 mm", "0.5 m"));
    assert!(golden_line_matches("took 12 ms", "took 80 ms"));
    assert!(golden_line_matches("a (0.21 s)", "a (1.30 s)"));
    assert!(!golden_line_matches("0.21 sigma", "0.31 sigma"));
    assert!(golden_line_matches("joint_2 x", "joint_2 x"));
    assert!(!golden_line_matches("joint_2 x", "joint_3 x"));
}

#[test]
fn pages_are_parsed_into_commands_their_output_and_unexplained_shell_blocks() {
    let page = "text\n```console\n$ activecal a \\\n    --b 1\nout 1\n\n$ activecal c\nout 2\n```\n```sh\nrm -rf /\n```\n<!-- not run: needs a robot -->\n```sh\nmove\n```\n";
    let p = parse_page(page);
    assert_eq!(p.examples.len(), 2);
    assert_eq!(p.examples[0].command, "activecal a --b 1");
    assert_eq!(p.examples[0].line, 3);
    assert_eq!(p.examples[0].expected, vec!["out 1".to_string()]);
    assert_eq!(p.examples[1].expected, vec!["out 2".to_string()]);
    assert_eq!(p.unexplained, vec![10]);
}
