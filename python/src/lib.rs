//! `activecal` for Python: thin wrappers over the library's public API that
//! convert arguments (NumPy arrays, validated and named in errors), call the
//! library with the GIL released, and convert results. No algorithm lives
//! here: what a wrapper needs that the command line also does is in the
//! library.

use pyo3::prelude::*;

mod bound;
mod calibrate;
mod camera;
mod camera_select;
mod contacts;
mod convert;
mod pool;
mod progress;
mod robot;
mod select;

pyo3::create_exception!(
    activecal,
    Error,
    pyo3::exceptions::PyException,
    "Bad input or a failed computation, with the library's message (naming the argument when one is wrong). Every error activecal raises is one of its subclasses."
);
pyo3::create_exception!(
    activecal,
    InputError,
    Error,
    "A wrong argument (the message starts with its name) or a wrong value in an input file (the message names the file and the place)."
);
pyo3::create_exception!(
    activecal,
    FileError,
    Error,
    "A file that could not be read or written, or an output that exists (pass overwrite=True)."
);
pyo3::create_exception!(
    activecal,
    ResourceError,
    Error,
    "Work too large for the memory or size limits, with the figure."
);
pyo3::create_exception!(
    activecal,
    ComputationError,
    Error,
    "A computation that cannot be done on these (valid) inputs: a design that cannot identify the robot, a bound that fails."
);
pyo3::create_exception!(
    activecal,
    InternalError,
    Error,
    "A defect in activecal (please report it with the message)."
);

/// The extension module `activecal._activecal` (re-exported by `activecal`).
#[pymodule]
fn _activecal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<Error>())?;
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add("FileError", m.py().get_type::<FileError>())?;
    m.add("ResourceError", m.py().get_type::<ResourceError>())?;
    m.add("ComputationError", m.py().get_type::<ComputationError>())?;
    m.add("InternalError", m.py().get_type::<InternalError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<robot::Robot>()?;
    m.add_class::<select::Design>()?;
    m.add_class::<pool::Pool>()?;
    m.add_function(wrap_pyfunction!(pool::pool, m)?)?;
    m.add_class::<calibrate::Calibration>()?;
    m.add_function(wrap_pyfunction!(select::select, m)?)?;
    m.add_function(wrap_pyfunction!(bound::bound, m)?)?;
    m.add_function(wrap_pyfunction!(bound::gap, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate::evaluate, m)?)?;
    m.add_class::<camera::CameraCalibration>()?;
    m.add_function(wrap_pyfunction!(camera::calibrate_camera, m)?)?;
    m.add_class::<camera_select::CameraDesign>()?;
    m.add_function(wrap_pyfunction!(camera_select::select_camera, m)?)?;
    m.add_class::<contacts::ContactCalibration>()?;
    m.add_function(wrap_pyfunction!(contacts::calibrate_contacts, m)?)?;
    Ok(())
}
