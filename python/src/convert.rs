//! Arguments in (any array-like, as float64, shape and finiteness checked,
//! errors naming the argument), results out (NumPy arrays, dicts), library
//! errors and panics as `activecal.Error`.

use crate::errors::{Kind, new_err};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::fmt::Display;

/// A wrong argument as `activecal.InputError`, the message starting with
/// its name.
pub fn arg_err(name: &str, msg: impl Display) -> PyErr {
    new_err(Kind::Input, format!("{name}: {msg}"))
}

/// Why library work failed, as the Python exception it becomes: the
/// `activecal.Error` subclass and the library's message.
#[derive(Debug)]
pub enum Fail {
    /// Wrong input (a value, a file's content): `InputError`.
    Input(String),
    /// A file could not be read or written, or exists: `FileError`.
    File(String),
    /// Too large for the memory or size limits: `ResourceError`.
    Resource(String),
    /// The computation could not be done on valid input: `ComputationError`.
    Compute(String),
}

impl Fail {
    /// Wrong input (any error type) with its message.
    pub fn input(e: impl Display) -> Self {
        Fail::Input(e.to_string())
    }

    /// The Python exception.
    pub fn into_py(self) -> PyErr {
        match self {
            Fail::Input(m) => new_err(Kind::Input, m),
            Fail::File(m) => new_err(Kind::File, m),
            Fail::Resource(m) => new_err(Kind::Resource, m),
            Fail::Compute(m) => new_err(Kind::Computation, m),
        }
    }
}

impl From<activecal::Error> for Fail {
    fn from(e: activecal::Error) -> Self {
        use activecal::Error as E;
        let m = e.to_string();
        match e {
            E::Io { .. } | E::OutputExists { .. } | E::OutputDirNotEmpty { .. } => Fail::File(m),
            E::TooLarge { .. } | E::OutOfMemory { .. } => Fail::Resource(m),
            E::Unidentifiable { .. } => Fail::Compute(m),
            E::Setting(s) => Fail::from(s),
            _ => Fail::Input(m),
        }
    }
}

impl From<activecal::error::SettingError> for Fail {
    /// A setting's value refused: `key value: why`, keys as Python's
    /// keywords.
    fn from(e: activecal::error::SettingError) -> Self {
        Fail::Input(e.spelled(str::to_string))
    }
}

impl From<activecal::experiment::error::IdentifyError> for Fail {
    /// Bad input to identification (its own description).
    fn from(e: activecal::experiment::error::IdentifyError) -> Self {
        Fail::Input(e.to_string())
    }
}

impl From<activecal::data::DataError> for Fail {
    /// Bad measured data (its own description).
    fn from(e: activecal::data::DataError) -> Self {
        Fail::Input(e.to_string())
    }
}

impl From<activecal::experiment::error::LsqError> for Fail {
    /// A solver setting out of range (an argument) or a problem it cannot
    /// take.
    fn from(e: activecal::experiment::error::LsqError) -> Self {
        Fail::Input(e.to_string())
    }
}

impl From<activecal::experiment::error::BoundError> for Fail {
    fn from(e: activecal::experiment::error::BoundError) -> Self {
        Fail::Compute(e.to_string())
    }
}

impl From<activecal::experiment::ExperimentError> for Fail {
    fn from(e: activecal::experiment::ExperimentError) -> Self {
        use activecal::experiment::ExperimentError as E;
        match e {
            E::Input(e) => e.into(),
            E::Bound(e) => e.into(),
            E::Identify(_) | E::InFile { .. } => Fail::Input(e.to_string()),
            E::Frames(_) => Fail::Compute(e.to_string()),
        }
    }
}

impl From<serde_json::Error> for Fail {
    /// A report that does not serialise: a defect.
    fn from(e: serde_json::Error) -> Self {
        Fail::Compute(format!(
            "internal error in activecal (please report it): {e}"
        ))
    }
}

impl From<String> for Fail {
    fn from(m: String) -> Self {
        Fail::Compute(m)
    }
}

/// How often a call waiting for its work checks for Ctrl-C.
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// Stack of the thread that does a call's work (a process's main thread's).
const WORK_STACK: usize = 8 << 20;

/// Runs library work with the GIL released, on a thread of its own while
/// the calling thread waits and checks Python's signals every
/// [`SIGNAL_POLL`]: a signal whose handler raises (Ctrl-C's
/// `KeyboardInterrupt`) cancels the work, which stops at its next progress
/// advance ([`crate::progress`]), and the call raises that exception. The
/// work's failure becomes the `activecal.Error` subclass of its [`Fail`], a
/// panic `activecal.InternalError` (never unwinds into Python).
pub fn detached<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> Result<T, Fail> + Send,
) -> PyResult<T> {
    let call = crate::progress::current_or_new();
    let (out, interrupt) = py.detach(|| {
        std::thread::scope(|s| {
            let (tx, rx) = std::sync::mpsc::channel::<()>();
            let worker = call.clone();
            let spawned = std::thread::Builder::new()
                .name("activecal".into())
                .stack_size(WORK_STACK)
                .spawn_scoped(s, move || {
                    let out = crate::progress::within(worker, || {
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(work))
                    });
                    let _ = tx.send(());
                    out
                });
            let handle = match spawned {
                Ok(h) => h,
                Err(e) => {
                    return (
                        Err(Box::new(format!("no thread for the work: {e}")) as _),
                        None,
                    );
                }
            };
            let mut interrupt = None;
            while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) = rx.recv_timeout(SIGNAL_POLL)
            {
                if interrupt.is_none()
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    call.cancel();
                    interrupt = Some(e);
                }
            }
            (handle.join().unwrap_or_else(Err), interrupt)
        })
    });
    if let Some(e) = interrupt {
        return Err(e);
    }
    match out {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(f)) => Err(f.into_py()),
        Err(p) if p.is::<crate::progress::Cancelled>() => Err(new_err(
            Kind::Internal,
            "the work was cancelled by its progress callback",
        )),
        Err(p) => {
            let what = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| (*s).to_string()))
                .unwrap_or_else(|| "a panic".into());
            Err(new_err(
                Kind::Internal,
                format!("internal error in activecal (please report it): {what}"),
            ))
        }
    }
}

/// The text of a shape, `(n, 6)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// An array argument read as float64: its values (row-major) and shape.
/// `want` is the expected shape, `None` for any length along an axis; `what`
/// says what it holds (with units) for messages. Every value must be finite.
pub fn float_array(
    py: Python<'_>,
    obj: &Bound<'_, PyAny>,
    name: &str,
    want: &[Option<usize>],
    what: &str,
) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let np = py.import("numpy")?;
    let kw = PyDict::new(py);
    kw.set_item("dtype", "float64")?;
    let a = np
        .call_method("asarray", (obj,), Some(&kw))
        .map_err(|e| arg_err(name, format!("not an array of numbers ({e})")))?;
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    let fits = shape.len() == want.len()
        && shape
            .iter()
            .zip(want)
            .all(|(s, w)| w.is_none_or(|w| *s == w));
    if !fits {
        let expected: Vec<String> = want
            .iter()
            .zip(["n", "m", "k"].iter().cycle())
            .map(|(w, v)| w.map_or_else(|| (*v).to_string(), |w| w.to_string()))
            .collect();
        let expected = if expected.len() == 1 {
            format!("({},)", expected[0])
        } else {
            format!("({})", expected.join(", "))
        };
        return Err(arg_err(
            name,
            format!(
                "expected shape {expected} ({what}), got {}",
                shape_text(&shape)
            ),
        ));
    }
    let values: Vec<f64> = a.call_method0("ravel")?.call_method0("tolist")?.extract()?;
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        let mut idx = Vec::with_capacity(shape.len());
        let mut rest = k;
        for d in (0..shape.len()).rev() {
            idx.push(rest % shape[d].max(1));
            rest /= shape[d].max(1);
        }
        idx.reverse();
        let idx: Vec<String> = idx.iter().map(ToString::to_string).collect();
        return Err(arg_err(
            name,
            format!(
                "{name}[{}] is {}, not a finite number ({what})",
                idx.join(", "),
                values[k]
            ),
        ));
    }
    Ok((values, shape))
}

/// A pandas DataFrame argument (anything with `columns` and `to_numpy`)
/// cut to `columns`, in that order, as a NumPy array; any other object as
/// it is. A frame without one of them is refused naming the column
/// (`what`: what the columns are, for the message).
pub fn named_columns<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    columns: &[String],
    what: &str,
) -> PyResult<Bound<'py, PyAny>> {
    if !(obj.hasattr("columns")? && obj.hasattr("to_numpy")?) {
        return Ok(obj.clone());
    }
    let have: Vec<String> = obj
        .getattr("columns")?
        .try_iter()?
        .map(|c| c.and_then(|c| c.str().map(|s| s.to_string())))
        .collect::<PyResult<_>>()?;
    if let Some(m) = columns.iter().find(|c| !have.contains(c)) {
        return Err(arg_err(
            name,
            format!(
                "a DataFrame needs a column per {what} ({}): no column '{m}' among {}",
                columns.join(", "),
                have.join(", ")
            ),
        ));
    }
    let cut = obj.get_item(PyList::new(obj.py(), columns)?)?;
    cut.call_method0("to_numpy")
}

/// Rows of `cols` values each from a row-major buffer.
pub fn rows(values: &[f64], cols: usize) -> Vec<Vec<f64>> {
    values.chunks(cols.max(1)).map(<[f64]>::to_vec).collect()
}

/// A float64 NumPy array of `shape` from row-major values.
pub fn ndarray<'py>(
    py: Python<'py>,
    values: &[f64],
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let np = py.import("numpy")?;
    let kw = PyDict::new(py);
    kw.set_item("dtype", "float64")?;
    let a = np.call_method("array", (PyList::new(py, values)?,), Some(&kw))?;
    a.call_method1("reshape", (shape.to_vec(),))
}

/// A JSON value as Python objects (dict, list, str, int, float, bool, None).
pub fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any()
            } else {
                n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any()
            }
        }
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let l = PyList::empty(py);
            for x in a {
                l.append(json_to_py(py, x)?)?;
            }
            l.into_any()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// A non-negative integer argument that fits `u64` (a seed, a count).
pub fn non_negative(name: &str, v: i128) -> PyResult<u64> {
    u64::try_from(v).map_err(|_| {
        arg_err(
            name,
            format!("{v}: must be an integer from 0 to {}", u64::MAX),
        )
    })
}

/// A count argument: an integer >= `min`.
pub fn count(name: &str, v: i64, min: usize) -> PyResult<usize> {
    usize::try_from(v)
        .ok()
        .filter(|&n| n >= min)
        .ok_or_else(|| arg_err(name, format!("{v}: must be an integer >= {min}")))
}

/// Emits `text` as a Python `UserWarning` (what the command line prints as
/// a note or warning reaches Python as one).
pub fn warn(py: Python<'_>, text: &str) -> PyResult<()> {
    let cat = py.get_type::<pyo3::exceptions::PyUserWarning>();
    pyo3::PyErr::warn(
        py,
        cat.as_any(),
        &std::ffi::CString::new(crate::errors::spell(text)).unwrap_or_default(),
        1,
    )
}

/// `other` in the row order of `q` when both are pandas objects with an
/// index: as given when the indexes are equal, reordered by `q`'s index
/// when they hold the same unique labels in another order, and refused when
/// their labels differ (rows are never matched by position behind the
/// user's back). Anything without an index (NumPy arrays, lists) is taken
/// as given, row for row.
pub(crate) fn aligned<'py>(
    q: &Bound<'py, PyAny>,
    other: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<Bound<'py, PyAny>> {
    // A pandas index (a list's `index` is a method: not one).
    let index = |x: &Bound<'py, PyAny>| {
        x.getattr("index")
            .ok()
            .filter(|i| i.hasattr("equals").unwrap_or(false))
    };
    let (Some(qi), Some(oi)) = (index(q), index(other)) else {
        return Ok(other.clone());
    };
    if qi.call_method1("equals", (&oi,))?.is_truthy()? {
        return Ok(other.clone());
    }
    let sorted = |i: &Bound<'py, PyAny>| i.call_method0("sort_values");
    let same = sorted(&qi)?
        .call_method1("equals", (sorted(&oi)?,))?
        .is_truthy()?;
    let unique = qi.getattr("is_unique")?.is_truthy()? && oi.getattr("is_unique")?.is_truthy()?;
    if same && unique {
        return other.getattr("loc")?.get_item(&qi);
    }
    Err(pyo3::exceptions::PyValueError::new_err(format!(
        "{name}: its index does not hold q's row labels (q {}, {name} {}): give both with the same labels, or plain arrays matched row by row",
        qi.repr()?,
        oi.repr()?
    )))
}
