//! Progress of long work reported to a Python callable: the library's
//! progress sink ([`activecal::progress`]) forwarding each task's start,
//! advance (at most every [`MIN_INTERVAL`]) and end to the callback of the
//! call that started it.
//!
//! The library has one sink per process; this module installs it once. A
//! call with `progress=f` runs its work with `f` as the calling thread's
//! callback: a task started on that thread reports to `f`, a task started
//! on a worker thread reports to the callback of the task that is running
//! (the innermost live one), so that nested work reaches the caller too.
//! The first exception the callback raises is raised by the call when its
//! work ends (the work itself cannot be interrupted midway).

use pyo3::prelude::*;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// Shortest time between two advances forwarded to a callback.
pub const MIN_INTERVAL: Duration = Duration::from_millis(100);

/// One call's callback and the first exception it raised.
struct Call {
    callback: Py<PyAny>,
    error: Mutex<Option<PyErr>>,
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

/// The sink that forwards to callbacks.
struct PySink;

impl PySink {
    /// Calls `call`'s callback with `(task, done, total, note)`, keeping
    /// its first exception.
    fn forward(call: &Call, name: &str, done: u64, total: Option<u64>, note: Option<&str>) {
        Python::attach(|py| {
            if let Err(e) = call.callback.call1(py, (name, done, total, note))
                && let Ok(mut slot) = call.error.lock()
                && slot.is_none()
            {
                *slot = Some(e);
            }
        });
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
        let now = Instant::now();
        if l.last.is_some_and(|t| now.duration_since(t) < MIN_INTERVAL) && note.is_none() {
            return;
        }
        l.last = Some(now);
        let (call, name, total) = (l.call.clone(), l.name.clone(), l.total);
        drop(map);
        Self::forward(&call, &name, done, total, note);
    }

    fn finish(&self, id: u64) {
        let Ok(mut map) = live().lock() else { return };
        let Some(l) = map.remove(&id) else { return };
        drop(map);
        Self::forward(&l.call, &l.name, l.done, l.total, Some("done"));
    }
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
    static INSTALLED: OnceLock<bool> = OnceLock::new();
    INSTALLED.get_or_init(|| activecal::progress::install(Box::new(PySink)));
    let call = Arc::new(Call {
        callback: cb.clone().unbind(),
        error: Mutex::new(None),
    });
    let before = CURRENT.with(|c| c.replace(Some(call.clone())));
    let out = work();
    CURRENT.with(|c| *c.borrow_mut() = before);
    let raised = call.error.lock().ok().and_then(|mut e| e.take());
    match raised {
        Some(e) => Err(e),
        None => out,
    }
}
