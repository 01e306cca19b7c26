//! activecal's Python exceptions: `activecal.Error`, the base of every
//! error it raises, and its kinds, each also a subclass of the built-in
//! exception that fits, so that `except ValueError` or `except OSError`
//! catches them as it does NumPy's and pandas' errors.

use activecal::names::phrase;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

pyo3::create_exception!(
    activecal,
    Error,
    pyo3::exceptions::PyException,
    "Bad input or a failed computation, with the library's message (naming the argument when one is wrong). Every error activecal raises is one of its subclasses."
);

/// What failed, naming the exception class raised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `InputError(Error, ValueError)`.
    Input,
    /// `FileError(Error, OSError)`.
    File,
    /// `ResourceError(Error, RuntimeError)`.
    Resource,
    /// `ComputationError(Error, RuntimeError)`.
    Computation,
    /// `InternalError(Error, RuntimeError)`.
    Internal,
}

/// Each kind: its class name, the built-in it also subclasses, its doc.
const KINDS: [(Kind, &str, &str, &str); 5] = [
    (
        Kind::Input,
        "InputError",
        "ValueError",
        "A wrong argument (the message starts with its name) or a wrong value in an input file (the message names the file and the place). Also a ValueError.",
    ),
    (
        Kind::File,
        "FileError",
        "OSError",
        "A file that could not be read or written, or an output that exists when a writer is given overwrite=False. Also an OSError.",
    ),
    (
        Kind::Resource,
        "ResourceError",
        "RuntimeError",
        "Work too large for the memory or size limits, with the figure. Also a RuntimeError.",
    ),
    (
        Kind::Computation,
        "ComputationError",
        "RuntimeError",
        "A computation that cannot be done on these (valid) inputs: a design that cannot identify the robot, a bound that fails. Also a RuntimeError.",
    ),
    (
        Kind::Internal,
        "InternalError",
        "RuntimeError",
        "A defect in activecal (please report it with the message). Also a RuntimeError.",
    ),
];

/// The kinds' classes, made once (`type(name, (Error, builtin), ...)`:
/// pyo3's `create_exception!` takes one base).
static CLASSES: PyOnceLock<Vec<Py<PyType>>> = PyOnceLock::new();

fn classes(py: Python<'_>) -> PyResult<&Vec<Py<PyType>>> {
    CLASSES.get_or_try_init(py, || {
        let builtins = py.import("builtins")?;
        let make = builtins.getattr("type")?;
        KINDS
            .iter()
            .map(|(_, name, base, doc)| {
                let bases = PyTuple::new(
                    py,
                    [py.get_type::<Error>().into_any(), builtins.getattr(*base)?],
                )?;
                let ns = PyDict::new(py);
                ns.set_item("__doc__", *doc)?;
                ns.set_item("__module__", "activecal")?;
                Ok(make
                    .call1((*name, bases, ns))?
                    .cast_into::<PyType>()?
                    .unbind())
            })
            .collect()
    })
}

/// The class of `kind`.
pub fn class(py: Python<'_>, kind: Kind) -> PyResult<Bound<'_, PyType>> {
    let k = KINDS.iter().position(|(k, ..)| *k == kind).unwrap_or(0);
    Ok(classes(py)?[k].bind(py).clone())
}

/// How Python spells the library's phrases for a setting
/// (`activecal::names::phrase`): as the keyword argument that sets it.
const SPELLING: &[(&str, &str)] = &[
    (phrase::KEEP_GROSS_ERRORS, "outliers=\"keep\" keeps it"),
    (phrase::OUTLIER_SCREEN, "outliers="),
    (phrase::COMPLIANCE, "compliance=True"),
    (phrase::REFINE_INTRINSICS, "refine_intrinsics=True"),
    (phrase::NO_TOOL_POINT, "no tool point given (marker=)"),
    (phrase::DEFAULT_PIXEL_NOISE, "the default of pixel_noise="),
    (phrase::DEFAULT_NOISE, "the default of noise="),
    (
        phrase::TARGET_ERROR,
        "target_error=: the fewest reaching an error",
    ),
    (phrase::OVERWRITE_ASKED, "even with overwrite=True"),
];

/// `text` with the library's phrases for settings spelled as this
/// package's keyword arguments (every message and warning goes through it).
#[must_use]
pub fn spell(text: &str) -> String {
    SPELLING
        .iter()
        .fold(text.to_string(), |t, (phrase, kw)| t.replace(phrase, kw))
}

/// The exception of `kind` with `msg`.
pub fn new_err(kind: Kind, msg: impl Into<String>) -> PyErr {
    let msg = spell(&msg.into());
    Python::attach(|py| match class(py, kind) {
        Ok(ty) => PyErr::from_type(ty, msg),
        Err(e) => e,
    })
}

/// Adds `Error` and its kinds to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    for (kind, name, ..) in KINDS {
        m.add(name, class(py, kind)?)?;
    }
    Ok(())
}

/// What the command line prints as a warning reaches Python as one.
pub(crate) fn warn_all(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    for w in warnings {
        let cat = py.get_type::<pyo3::exceptions::PyUserWarning>();
        pyo3::PyErr::warn(
            py,
            cat.as_any(),
            &std::ffi::CString::new(spell(w)).unwrap_or_default(),
            1,
        )?;
    }
    Ok(())
}
