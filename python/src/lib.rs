//! `activecal` for Python: thin wrappers over the library's public API that
//! convert arguments (NumPy arrays, validated and named in errors), call the
//! library with the GIL released, and convert results. No algorithm lives
//! here: what a wrapper needs that the command line also does is in the
//! library.

use pyo3::prelude::*;

mod bag;
mod bound;
mod calibrate;
mod camera;
mod camera_select;
mod contacts;
mod convert;
mod errors;
mod fit_args;
mod images;
mod page;
mod pickling;
mod pool;
mod progress;
mod robot;
mod select;

/// The extension module `activecal._activecal` (re-exported by `activecal`).
#[pymodule]
fn _activecal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(pickling::_replay, m)?)?;
    m.add_class::<robot::Robot>()?;
    m.add_class::<select::Design>()?;
    m.add_class::<page::Page>()?;
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
    m.add_function(wrap_pyfunction!(images::detect, m)?)?;
    m.add_class::<camera_select::CameraDesign>()?;
    m.add_function(wrap_pyfunction!(camera_select::select_camera, m)?)?;
    m.add_class::<contacts::ContactCalibration>()?;
    m.add_function(wrap_pyfunction!(contacts::calibrate_contacts, m)?)?;
    m.add_function(wrap_pyfunction!(bag::extract, m)?)?;
    Ok(())
}
