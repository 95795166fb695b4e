//! posecov's Python extension, `posecov._posecov` (issue 34): the library core without Rerun,
//! built by maturin into an abi3 wheel (CPython ≥ 3.9). The `posecov` Python package
//! (`python/posecov/`) wraps it; its stubs are `python/posecov/_posecov.pyi`.
//!
//! - `app.rs`: `report`, `check`, `figure` and `list` through the library's app layer, the
//!   CLI's flags as keyword arguments, errors with the CLI's located message;
//! - `groups.rs`: SO(2), SO(3), SE(2), SE(3) on NumPy arrays (`posecov::lie`);
//! - `uncertain.rs`: `UncertainPose` and its propagations and sampling;
//! - `arrays.rs`: every array checked (shape, finite) on its way in.
//!
//! No input makes it panic: shapes, finiteness, group membership and covariances are
//! checked before the library sees them, and the library returns errors for the rest.

use pyo3::prelude::*;

mod app;
mod arrays;
mod groups;
mod uncertain;

pyo3::create_exception!(
    _posecov,
    PosecovError,
    pyo3::exceptions::PyValueError,
    "An input posecov refuses, with the CLI's located message (file:line:column: key: why). \
     `exit_code` is the CLI's exit code and `details` the `error` object of `report --json` \
     (message, text, file, line, column, key or place where known) for errors of an input; \
     array errors name the argument."
);

/// The native module.
#[pymodule]
fn _posecov(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("PosecovError", m.py().get_type::<PosecovError>())?;
    m.add("REPORT_SCHEMA_VERSION", posecov::app::REPORT_SCHEMA_VERSION)?;
    m.add("POSECOV_VERSION", posecov::app::POSECOV_VERSION)?;
    m.add("OVERRIDES", app::OVERRIDES.to_vec())?;
    m.add_function(wrap_pyfunction!(app::report_json, m)?)?;
    m.add_function(wrap_pyfunction!(app::check_raw, m)?)?;
    m.add_function(wrap_pyfunction!(app::figure_file, m)?)?;
    m.add_function(wrap_pyfunction!(app::figure_svg, m)?)?;
    m.add_function(wrap_pyfunction!(app::examples, m)?)?;
    m.add_function(wrap_pyfunction!(app::expand, m)?)?;
    m.add_class::<groups::SO2>()?;
    m.add_class::<groups::SO3>()?;
    m.add_class::<groups::SE2>()?;
    m.add_class::<groups::SE3>()?;
    m.add_class::<uncertain::UncertainPose>()?;
    Ok(())
}
