//! The binary's progress sink ([`activecal::progress::Sink`]): always on
//! stderr, never on stdout.
//!
//! * On a terminal: one bar (`indicatif`) showing the innermost open task,
//!   its count, what it is doing and the elapsed time, and the time left
//!   as estimated by the outermost task with a count ([`time_left`]);
//!   cleared when the last task ends.
//! * Not a terminal, when asked with `--progress`: plain lines, one when a
//!   task starts, at most one every half second while it runs, and one when
//!   it ends (with its time), so that a log file or a CI job shows them.
//! * Otherwise, and with `--json` unless `--progress` is given: nothing.

use activecal::progress::{Sink, install};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How progress is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// A bar on stderr (a terminal).
    Bar,
    /// Lines on stderr.
    Lines,
    /// Nothing.
    Off,
}

/// The mode for a command: `forced` by `--progress`, `json` when the
/// command writes JSON, `terminal` when stderr is one.
#[must_use]
pub fn mode(forced: bool, json: bool, terminal: bool) -> Mode {
    match (forced, json, terminal) {
        (_, _, true) if forced || !json => Mode::Bar,
        (true, _, false) => Mode::Lines,
        _ => Mode::Off,
    }
}

/// Installs the sink of `mode` for the rest of the process.
pub fn install_for(forced: bool, json: bool) {
    let m = mode(forced, json, std::io::stderr().is_terminal());
    if m != Mode::Off {
        install(Box::new(Stderr::new(m)));
    }
}

struct Entry {
    id: u64,
    name: String,
    total: Option<u64>,
    done: u64,
    note: String,
    started: Instant,
}

struct State {
    open: Vec<Entry>,
    bar: Option<ProgressBar>,
    last_line: Instant,
}

/// The stderr sink.
struct Stderr {
    mode: Mode,
    state: Mutex<State>,
}

/// Least time between two progress lines of a running task.
const LINE_EVERY: Duration = Duration::from_millis(500);

impl Stderr {
    fn new(mode: Mode) -> Self {
        Self {
            mode,
            state: Mutex::new(State {
                open: Vec::new(),
                bar: None,
                last_line: Instant::now(),
            }),
        }
    }

    fn line(e: &Entry, what: &str, left: &str) {
        let count = match e.total {
            Some(t) => format!(" {}/{t}", e.done),
            None if e.done > 0 => format!(" {}", e.done),
            None => String::new(),
        };
        let note = if e.note.is_empty() {
            String::new()
        } else {
            format!(" ({})", e.note)
        };
        let head = format!("progress: {}{count}{note}", e.name);
        let line = [head.as_str(), what, left.trim_start()]
            .iter()
            .filter(|p| !p.is_empty())
            .copied()
            .collect::<Vec<_>>()
            .join(" ");
        let _ = writeln!(std::io::stderr().lock(), "{line}");
    }

    fn draw(st: &mut State) {
        let Some(top) = st.open.last() else {
            if let Some(b) = st.bar.take() {
                b.finish_and_clear();
            }
            return;
        };
        let bar = st.bar.get_or_insert_with(|| {
            let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            b.enable_steady_tick(Duration::from_millis(200));
            b
        });
        let template = if top.total.is_some() {
            "{prefix} {bar:25} {pos}/{len} {msg} ({elapsed})"
        } else {
            "{prefix} {spinner} {msg} ({elapsed})"
        };
        bar.set_style(ProgressStyle::with_template(template).expect("a valid template"));
        bar.set_prefix(top.name.clone());
        bar.set_length(top.total.unwrap_or(0));
        bar.set_position(top.done);
        bar.set_message(format!("{}{}", top.note, time_left(&st.open)));
    }
}

/// The time left as the outermost open task with a count estimates it
/// (its elapsed time over its share done, once a unit is done): ` · about
/// 6 s left (how many poses 3/12)`, or empty while nothing can be said.
fn time_left(open: &[Entry]) -> String {
    let Some((e, total)) = open.iter().find_map(|e| {
        e.total
            .filter(|&t| t > e.done && e.done > 0)
            .map(|t| (e, t))
    }) else {
        return String::new();
    };
    let seconds = e.started.elapsed().as_secs_f64() * (total - e.done) as f64 / e.done as f64;
    format!(
        " · about {} left ({} {}/{total})",
        human_seconds(seconds),
        e.name,
        e.done
    )
}

/// Seconds as a person reads them: `4 s`, `2 min 5 s`.
fn human_seconds(s: f64) -> String {
    let s = s.round() as u64;
    if s == 0 {
        "under 1 s".into()
    } else if s < 60 {
        format!("{s} s")
    } else {
        format!("{} min {} s", s / 60, s % 60)
    }
}

impl Sink for Stderr {
    fn start(&self, id: u64, name: &str, total: Option<u64>) {
        let Ok(mut st) = self.state.lock() else {
            return;
        };
        st.open.push(Entry {
            id,
            name: name.to_string(),
            total,
            done: 0,
            note: String::new(),
            started: Instant::now(),
        });
        match self.mode {
            Mode::Bar => Self::draw(&mut st),
            Mode::Lines => Self::line(st.open.last().expect("just pushed"), "started", ""),
            Mode::Off => {}
        }
    }

    fn update(&self, id: u64, done: u64, note: Option<&str>) {
        let Ok(mut st) = self.state.lock() else {
            return;
        };
        let Some(k) = st.open.iter().position(|e| e.id == id) else {
            return;
        };
        let e = &mut st.open[k];
        e.done = e.done.max(done);
        if let Some(n) = note {
            e.note = n.to_string();
        }
        let top = k + 1 == st.open.len();
        match self.mode {
            Mode::Bar => {
                let shown = st.open.last().expect("an open task");
                let message = format!("{}{}", shown.note, time_left(&st.open));
                if let Some(b) = &st.bar {
                    b.set_position(shown.done);
                    b.set_message(message);
                }
            }
            Mode::Lines if top && st.last_line.elapsed() >= LINE_EVERY => {
                st.last_line = Instant::now();
                Self::line(&st.open[k], "", &time_left(&st.open));
            }
            _ => {}
        }
    }

    fn finish(&self, id: u64) {
        let Ok(mut st) = self.state.lock() else {
            return;
        };
        let Some(k) = st.open.iter().position(|e| e.id == id) else {
            return;
        };
        let e = st.open.remove(k);
        match self.mode {
            Mode::Bar => Self::draw(&mut st),
            Mode::Lines => Self::line(
                &e,
                &format!("done in {:.2} s", e.started.elapsed().as_secs_f64()),
                "",
            ),
            Mode::Off => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(name: &str, total: Option<u64>, done: u64, ago: u64) -> Entry {
        Entry {
            id: 0,
            name: name.into(),
            total,
            done,
            note: String::new(),
            started: Instant::now() - Duration::from_secs(ago),
        }
    }

    /// The outermost task with a count and a unit done speaks: 2 of 8
    /// sizes in 10 s leave 30 s; an inner task's count does not.
    #[test]
    fn time_left_is_the_outermost_counted_task_s() {
        let open = [
            entry("select", None, 0, 12),
            entry("how many poses", Some(8), 2, 10),
            entry("jacobian", Some(100), 99, 1),
        ];
        assert_eq!(time_left(&open), " · about 30 s left (how many poses 2/8)");
        let starting = [entry("how many poses", Some(8), 0, 3)];
        assert_eq!(time_left(&starting), "");
        assert_eq!(human_seconds(125.2), "2 min 5 s");
        assert_eq!(human_seconds(0.3), "under 1 s");
    }

    #[test]
    fn json_is_silent_unless_asked_and_pipes_get_lines_only_when_asked() {
        assert_eq!(mode(false, false, true), Mode::Bar);
        assert_eq!(mode(false, true, true), Mode::Off);
        assert_eq!(mode(true, true, true), Mode::Bar);
        assert_eq!(mode(false, false, false), Mode::Off);
        assert_eq!(mode(true, true, false), Mode::Lines);
        assert_eq!(mode(true, false, false), Mode::Lines);
    }
}
