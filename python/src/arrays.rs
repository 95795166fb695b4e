//! NumPy arrays in and out: every array a Python caller hands in is checked here — its shape
//! against the one the function needs and every entry finite — before a number reaches the
//! library, so a wrong array is a `PosecovError` naming the argument, never a panic.

use nalgebra::{SMatrix, SVector};
use numpy::{
    AllowTypeChange, PyArray1, PyArray2, PyArrayLikeDyn, PyUntypedArrayMethods, ToPyArray,
};
use pyo3::prelude::*;

use crate::PosecovError;

/// A Python error naming the argument `what` and what is wrong with it.
pub fn bad(what: &str, message: impl std::fmt::Display) -> PyErr {
    PosecovError::new_err(format!("{what}: {message}"))
}

/// The shape of an array in Python's words, `(3,)` or `(4, 4)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The entries of an array-like of `shape` (row-major), each finite; anything NumPy can turn
/// into a float array is accepted (lists, integer arrays).
pub fn floats(what: &str, value: &Bound<'_, PyAny>, shape: &[usize]) -> PyResult<Vec<f64>> {
    let array: PyArrayLikeDyn<'_, f64, AllowTypeChange> = value
        .extract()
        .map_err(|_| bad(what, "not an array of numbers"))?;
    let got = array.shape().to_vec();
    if got != shape {
        return Err(bad(
            what,
            format!(
                "expected an array of shape {}, got shape {}",
                shape_text(shape),
                shape_text(&got)
            ),
        ));
    }
    let values: Vec<f64> = array.as_array().iter().copied().collect();
    if let Some((index, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(bad(
            what,
            format!("element {index} is {v}, but every element must be finite"),
        ));
    }
    Ok(values)
}

/// An R×C matrix from an array-like of shape (R, C).
pub fn matrix<const R: usize, const C: usize>(
    what: &str,
    value: &Bound<'_, PyAny>,
) -> PyResult<SMatrix<f64, R, C>> {
    let values = floats(what, value, &[R, C])?;
    Ok(SMatrix::<f64, R, C>::from_row_slice(&values))
}

/// A vector of N numbers from an array-like of shape (N,); a plain number when N = 1.
pub fn vector<const N: usize>(what: &str, value: &Bound<'_, PyAny>) -> PyResult<SVector<f64, N>> {
    if N == 1
        && let Ok(v) = value.extract::<f64>()
    {
        if !v.is_finite() {
            return Err(bad(what, format!("{v} is not finite")));
        }
        return Ok(SVector::<f64, N>::from_element(v));
    }
    let values = floats(what, value, &[N])?;
    Ok(SVector::<f64, N>::from_column_slice(&values))
}

/// A matrix as a 2-D array.
pub fn out_matrix<'py, const R: usize, const C: usize>(
    py: Python<'py>,
    m: &SMatrix<f64, R, C>,
) -> Bound<'py, PyArray2<f64>> {
    m.to_pyarray(py)
}

/// A vector as a 1-D array.
pub fn out_vector<'py, const N: usize>(
    py: Python<'py>,
    v: &SVector<f64, N>,
) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v.as_slice())
}

/// A library error as a Python error (the library's message names the quantity and value).
pub fn lib_err(e: posecov::Error) -> PyErr {
    PosecovError::new_err(e.to_string())
}
