//! Progress of long work reported to a Python callable, and Ctrl-C: the
//! library's progress sink ([`activecal::progress`]) forwarding each task's
//! start, advance (at most every [`MIN_INTERVAL`]) and end to the callback
//! of the call that started it, and stopping the call's work at its next
//! advance once the call is cancelled.
//!
//! The library has one sink per process; this module installs it on the
//! first call. Each call runs its work with a [`Call`] as the working
//! thread's current one: a task started on that thread belongs to it, a
//! task started on a worker thread belongs to the call of the task that is
//! running (the innermost live one), so that nested work reaches the caller
//! too. The library also marks checkpoints between the steps of loops that
//! advance no task for long ([`activecal::progress::checkpoint`]), where a
//! cancelled call's work stops as well. The first exception the callback
//! raises stops the work (as a
//! cancellation does) and is raised by the call. A cancelled call (Ctrl-C: see [`crate::convert::detached`])
//! unwinds its work from the next advance of any of its tasks, on any
//! thread, with a [`Cancelled`] payload (no panic message is printed).

use pyo3::prelude::*;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// Shortest time between two advances forwarded to a callback.
pub const MIN_INTERVAL: Duration = Duration::from_millis(100);

/// The unwinding payload of cancelled work.
pub struct Cancelled;

/// One call: its callback (if any), the first exception it raised, and
/// whether the call is cancelled.
pub struct Call {
    callback: Option<Py<PyAny>>,
    error: Mutex<Option<PyErr>>,
    cancelled: AtomicBool,
}

/// How many cancelled calls are still alive: the library's checkpoints
/// cost one atomic load while there are none.
static CANCELLED: AtomicUsize = AtomicUsize::new(0);

impl Call {
    /// Stops the call's work at its next advance or checkpoint.
    pub fn cancel(&self) {
        if !self.cancelled.swap(true, Ordering::SeqCst) {
            CANCELLED.fetch_add(1, Ordering::SeqCst);
        }
    }
}

impl Drop for Call {
    fn drop(&mut self) {
        if self.cancelled.load(Ordering::SeqCst) {
            CANCELLED.fetch_sub(1, Ordering::SeqCst);
        }
    }
}

/// A live task: its call, name, size and when it last reported.
struct Live {
    call: Arc<Call>,
    name: String,
    total: Option<u64>,
    last: Option<Instant>,
    /// Units done at the last update.
    done: u64,
}

thread_local! {
    static CURRENT: RefCell<Option<Arc<Call>>> = const { RefCell::new(None) };
}

fn live() -> &'static Mutex<HashMap<u64, Live>> {
    static LIVE: OnceLock<Mutex<HashMap<u64, Live>>> = OnceLock::new();
    LIVE.get_or_init(|| Mutex::new(HashMap::new()))
}

/// The sink that forwards to callbacks and stops cancelled work.
struct PySink;

impl PySink {
    /// Calls `call`'s callback (if any) with `(task, done, total, note)`,
    /// keeping its first exception.
    fn forward(call: &Call, name: &str, done: u64, total: Option<u64>, note: Option<&str>) {
        let Some(cb) = call.callback.as_ref() else {
            return;
        };
        Python::attach(|py| {
            if let Err(e) = cb.call1(py, (name, done, total, note))
                && let Ok(mut slot) = call.error.lock()
                && slot.is_none()
            {
                *slot = Some(e);
                // The work stops: its result would be discarded anyway.
                call.cancel();
            }
        });
    }

    /// Unwinds the work of a cancelled call (not while already unwinding:
    /// a task's tick advances it from a destructor).
    fn stop_if_cancelled(call: &Call) {
        if call.cancelled.load(Ordering::SeqCst) && !std::thread::panicking() {
            std::panic::resume_unwind(Box::new(Cancelled));
        }
    }
}

impl activecal::progress::Sink for PySink {
    fn start(&self, id: u64, name: &str, total: Option<u64>) {
        let Ok(mut map) = live().lock() else { return };
        let call = CURRENT.with(|c| c.borrow().clone()).or_else(|| {
            map.iter()
                .max_by_key(|(k, _)| **k)
                .map(|(_, l)| l.call.clone())
        });
        let Some(call) = call else { return };
        map.insert(
            id,
            Live {
                call: call.clone(),
                name: name.to_string(),
                total,
                last: None,
                done: 0,
            },
        );
        drop(map);
        Self::forward(&call, name, 0, total, None);
    }

    fn update(&self, id: u64, done: u64, note: Option<&str>) {
        let Ok(mut map) = live().lock() else { return };
        let Some(l) = map.get_mut(&id) else { return };
        l.done = done;
        let call = l.call.clone();
        let now = Instant::now();
        if l.last.is_some_and(|t| now.duration_since(t) < MIN_INTERVAL) && note.is_none() {
            drop(map);
            Self::stop_if_cancelled(&call);
            return;
        }
        l.last = Some(now);
        let (name, total) = (l.name.clone(), l.total);
        drop(map);
        Self::stop_if_cancelled(&call);
        Self::forward(&call, &name, done, total, note);
    }

    fn checkpoint(&self) {
        if CANCELLED.load(Ordering::Relaxed) == 0 {
            return;
        }
        // This thread's call, or (a worker thread) the innermost live task's.
        let call = CURRENT.with(|c| c.borrow().clone()).or_else(|| {
            let map = live().lock().ok()?;
            map.iter()
                .max_by_key(|(k, _)| **k)
                .map(|(_, l)| l.call.clone())
        });
        if let Some(call) = call {
            Self::stop_if_cancelled(&call);
        }
    }

    fn finish(&self, id: u64) {
        let Ok(mut map) = live().lock() else { return };
        let Some(l) = map.remove(&id) else { return };
        drop(map);
        if !l.call.cancelled.load(Ordering::SeqCst) {
            Self::forward(&l.call, &l.name, l.done, l.total, Some("done"));
        }
    }
}

/// Installs the sink, once per process.
fn install() {
    static INSTALLED: OnceLock<bool> = OnceLock::new();
    INSTALLED.get_or_init(|| activecal::progress::install(Box::new(PySink)));
}

/// The call of this thread: the one [`with_callback`] set, or a new one
/// without a callback.
pub fn current_or_new() -> Arc<Call> {
    install();
    CURRENT.with(|c| c.borrow().clone()).unwrap_or_else(|| {
        Arc::new(Call {
            callback: None,
            error: Mutex::new(None),
            cancelled: AtomicBool::new(false),
        })
    })
}

/// Runs `work` with `call` as this thread's current call (the thread that
/// does a call's work).
pub fn within<T>(call: Arc<Call>, work: impl FnOnce() -> T) -> T {
    let before = CURRENT.with(|c| c.replace(Some(call)));
    let out = work();
    CURRENT.with(|c| *c.borrow_mut() = before);
    out
}

/// Runs `work` with `callback` receiving its progress (none without one);
/// the callback's first exception is returned after the work.
pub fn with_callback<T>(
    callback: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce() -> PyResult<T>,
) -> PyResult<T> {
    let Some(cb) = callback else {
        return work();
    };
    if !cb.is_callable() {
        return Err(crate::convert::arg_err(
            "progress",
            "a callable progress(task, done, total, note)",
        ));
    }
    install();
    let call = Arc::new(Call {
        callback: Some(cb.clone().unbind()),
        error: Mutex::new(None),
        cancelled: AtomicBool::new(false),
    });
    let out = within(call.clone(), work);
    let raised = call.error.lock().ok().and_then(|mut e| e.take());
    match raised {
        Some(e) => Err(e),
        None => out,
    }
}
