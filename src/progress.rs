//! Progress of long computations: the library reports it, the binary draws
//! it.
//!
//! Library code that can run for more than a second (pool building, the
//! bound's rounds, multi-start selection, Monte-Carlo calibration) opens a
//! [`Task`], advances it and says what it is doing; nothing is drawn unless a
//! [`Sink`] has been installed with [`install`] (once per process, by the
//! binary, which draws on stderr). The same pattern as the `log` crate:
//! reporting costs an atomic add when no sink is installed, needs no
//! argument threaded through every signature, and never touches stdout or
//! the results: the numbers a computation returns do not depend on whether,
//! or how, its progress is shown.
//!
//! Tasks nest (a `select` start inside a multi-start, the bound inside
//! `reproduce`): a sink sees every start and finish with the task's id and
//! shows the innermost open one.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};

/// Where progress goes: implemented by the binary (a bar or lines on stderr).
/// Calls may come from several threads at once.
pub trait Sink: Send + Sync {
    /// Task `id` named `name` started, with `total` units of work if known.
    fn start(&self, id: u64, name: &str, total: Option<u64>);
    /// Task `id` has done `done` units (monotone), with an optional note
    /// of what it is doing now.
    fn update(&self, id: u64, done: u64, note: Option<&str>);
    /// Task `id` ended (normally or not).
    fn finish(&self, id: u64);
    /// A point between two steps of long work where it may be stopped
    /// ([`checkpoint`]): a sink that cancels work (Python's Ctrl-C) unwinds
    /// from here; the default does nothing.
    fn checkpoint(&self) {}
}

static SINK: OnceLock<Box<dyn Sink>> = OnceLock::new();
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// Installs the process's sink. Returns `false` (and drops `sink`) if one is
/// already installed.
pub fn install(sink: Box<dyn Sink>) -> bool {
    SINK.set(sink).is_ok()
}

/// Whether a sink is installed (so that a note worth formatting is shown).
#[must_use]
pub fn enabled() -> bool {
    SINK.get().is_some()
}

/// Marks a point between two steps of long work (a round of an exchange
/// loop) where the installed sink may stop it, so that work that advances
/// no task for a long time can still be cancelled at once. Costs an atomic
/// load without a sink.
pub fn checkpoint() {
    if let Some(s) = SINK.get() {
        s.checkpoint();
    }
}

/// One unit of long work: started by [`Task::start`], finished when dropped.
/// Shared by reference between threads ([`Task::inc`] is atomic).
pub struct Task {
    id: u64,
    done: AtomicU64,
}

impl Task {
    /// Starts a task called `name` of `total` units (`None`: unknown).
    #[must_use]
    pub fn start(name: &str, total: Option<u64>) -> Task {
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        if let Some(s) = SINK.get() {
            s.start(id, name, total);
        }
        Task {
            id,
            done: AtomicU64::new(0),
        }
    }

    /// Advances the task by `n` units.
    pub fn inc(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        if let Some(s) = SINK.get() {
            s.update(self.id, done, None);
        }
    }

    /// Says what the task is doing now; `note` is only called when a sink
    /// is installed.
    pub fn note(&self, note: impl FnOnce() -> String) {
        if let Some(s) = SINK.get() {
            s.update(self.id, self.done.load(Ordering::Relaxed), Some(&note()));
        }
    }

    /// A guard that advances the task by one unit when dropped (whichever
    /// way the unit of work ends, an early error return included).
    #[must_use]
    pub fn tick(&self) -> Tick<'_> {
        Tick(self)
    }

    /// Units done so far.
    #[must_use]
    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }
}

/// See [`Task::tick`].
pub struct Tick<'a>(&'a Task);

impl Drop for Tick<'_> {
    fn drop(&mut self) {
        self.0.inc(1);
    }
}

impl Drop for Task {
    fn drop(&mut self) {
        if let Some(s) = SINK.get() {
            s.finish(self.id);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_task_counts_its_units_from_any_thread() {
        let t = Task::start("count", Some(1000));
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| (0..250).for_each(|_| t.inc(1)));
            }
        });
        assert_eq!(t.done(), 1000);
        let u = Task::start("other", None);
        assert_ne!(u.id, t.id, "every task has its own id");
    }
}
