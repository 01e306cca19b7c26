//! With the `live` feature, adds the rpath of the libpython that pyo3 links
//! (the one of `PYO3_PYTHON`, e.g. the venv's base interpreter) so the test
//! and bin executables load it without `LD_LIBRARY_PATH`.

fn main() {
    #[cfg(feature = "live")]
    pyo3_build_config::add_libpython_rpath_link_args();
}
