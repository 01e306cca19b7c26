//! `activecal` for Python: thin wrappers over the library's public API that
//! convert arguments (NumPy arrays, validated and named in errors), call the
//! library with the GIL released, and convert results. No algorithm lives
//! here: what a wrapper needs that the command line also does is in the
//! library.

use pyo3::prelude::*;

mod calibrate;
mod convert;
mod pool;
mod robot;
mod select;

pyo3::create_exception!(
    activecal,
    Error,
    pyo3::exceptions::PyException,
    "Bad input or a failed computation, with the library's message (naming the argument when one is wrong)."
);

/// The extension module `activecal._activecal` (re-exported by `activecal`).
#[pymodule]
fn _activecal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<Error>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<robot::Robot>()?;
    m.add_class::<select::Design>()?;
    m.add_class::<pool::Pool>()?;
    m.add_function(wrap_pyfunction!(pool::pool, m)?)?;
    m.add_class::<calibrate::Calibration>()?;
    m.add_function(wrap_pyfunction!(select::select, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate, m)?)?;
    Ok(())
}
