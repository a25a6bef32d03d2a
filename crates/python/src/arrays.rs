//! NumPy arrays as faer matrices, in place, and results back as new arrays.

use std::borrow::Cow;

use faer::{Mat, MatRef};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

/// The array as a matrix over the same memory (any strides, negative ones included).
pub fn matrix<'a>(array: &'a PyReadonlyArray2<'_, f64>) -> MatRef<'a, f64> {
    let view = array.as_array();
    let (rows, columns) = view.dim();
    let strides = view.strides();
    // SAFETY: the view describes `rows × columns` elements at these element strides, alive and
    // not written while the read-only borrow `array` (which outlives 'a) is held.
    unsafe { MatRef::from_raw_parts(view.as_ptr(), rows, columns, strides[0], strides[1]) }
}

/// The values of a one-dimensional array, in place when it is contiguous, copied otherwise.
pub fn values<'a>(array: &'a PyReadonlyArray1<'_, f64>) -> Cow<'a, [f64]> {
    match array.as_slice() {
        Ok(slice) => Cow::Borrowed(slice),
        Err(_) => Cow::Owned(array.as_array().to_vec()),
    }
}

/// A new C-ordered array holding `matrix`.
pub fn to_numpy<'py>(py: Python<'py>, matrix: MatRef<'_, f64>) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((matrix.nrows(), matrix.ncols()), |(i, j)| matrix[(i, j)])
        .into_pyarray(py)
}

/// A new array of `rows × columns` from row-major `values`.
pub fn row_major_to_numpy<'py>(
    py: Python<'py>,
    values: Vec<f64>,
    columns: usize,
) -> Bound<'py, PyArray2<f64>> {
    let rows = values.len().checked_div(columns).unwrap_or(0);
    Array2::from_shape_vec((rows, columns), values)
        .expect("row-major values fill their rows")
        .into_pyarray(py)
}

/// An owned copy (for the libraries' types that own their data).
pub fn owned(array: &PyReadonlyArray2<'_, f64>) -> Mat<f64> {
    matrix(array).to_owned()
}
