//! Pickling (`pickle`, `multiprocessing`, `joblib`) of `Robot`, `Pool`,
//! `Design`, `Calibration`, `CameraCalibration` and `ContactCalibration`
//! by their recipe: the call that made the
//! object and its arguments. Unpickling makes the call again; every one of
//! them is deterministic (seeded), so the copy has the same poses, ids and
//! estimates, at the cost of the call's time, and the files the call read
//! (a URDF, a frames file) must be readable where the object is unpickled.
//! Array arguments are copied when the object is made, so that a caller's
//! later change to them does not change the copy.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};

/// How an object was made: a function of `activecal._activecal` (a dotted
/// path, `Robot.from_urdf`) and its keyword arguments.
pub struct Recipe {
    func: &'static str,
    kwargs: Py<PyDict>,
}

impl Recipe {
    /// The recipe of `func` called with `kwargs`.
    pub fn new(func: &'static str, kwargs: Bound<'_, PyDict>) -> Self {
        Self {
            func,
            kwargs: kwargs.unbind(),
        }
    }

    /// `__reduce__`'s value: `(_replay, (func, kwargs))`.
    pub fn reduce<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let replay = py.import("activecal._activecal")?.getattr("_replay")?;
        let args = (self.func, self.kwargs.bind(py).clone()).into_pyobject(py)?;
        PyTuple::new(py, [replay, args.into_any()])
    }
}

/// An argument kept for a recipe: activecal's own objects and strings as
/// they are (immutable), anything else (arrays, DataFrames, lists) as a
/// deep copy.
pub fn kept<'py>(obj: Option<&Bound<'py, PyAny>>) -> PyResult<Option<Bound<'py, PyAny>>> {
    let Some(o) = obj else { return Ok(None) };
    let own = o.is_instance_of::<PyString>()
        || o.is_instance_of::<crate::pool::Pool>()
        || o.is_instance_of::<crate::robot::Robot>();
    if own {
        return Ok(Some(o.clone()));
    }
    let copy = o.py().import("copy")?.getattr("deepcopy")?;
    copy.call1((o,)).map(Some)
}

/// The keyword arguments of a recipe, `name = value` pairs.
#[macro_export]
macro_rules! recipe {
    ($py:expr, $func:literal; $($key:ident = $val:expr),* $(,)?) => {{
        let kw = pyo3::types::PyDict::new($py);
        $( kw.set_item(stringify!($key), $val)?; )*
        $crate::pickling::Recipe::new($func, kw)
    }};
}

/// Unpickles an object: calls `func` (a dotted path in this module) with
/// `kwargs`. Not part of the API.
#[pyfunction]
pub fn _replay<'py>(
    py: Python<'py>,
    func: &str,
    kwargs: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyAny>> {
    let mut f = py.import("activecal._activecal")?.into_any();
    for part in func.split('.') {
        f = f.getattr(part)?;
    }
    f.call((), Some(kwargs))
}
