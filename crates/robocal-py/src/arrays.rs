//! numpy arrays in and out, checked: shapes, dtypes and finite values, each failure an
//! `InputError` naming the argument (and the row and column of a bad value).

use crate::errors::input;
use numpy::ndarray::{Array2, Array3};
use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods,
};
use pyo3::prelude::*;

/// A checked 2-D array of float64 values, row-major, and whether it came as one row (1-D).
pub struct Matrix {
    /// The values, row-major.
    pub data: Vec<f64>,
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// The input was 1-D (one row): results drop the row axis too.
    pub single: bool,
}

impl Matrix {
    /// Row `i`.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.cols..(i + 1) * self.cols]
    }
}

/// `obj` (a numpy array, or anything `numpy.asarray` takes) as a float64 matrix of `cols`
/// columns: shape `(n, cols)`, or `(cols,)` for one row. Booleans, strings, objects and
/// complex numbers are refused, as are NaN and infinite values; `name` names the argument in
/// messages, `what` what a row holds (e.g. "joint values q1..q6").
pub fn matrix(obj: &Bound<'_, PyAny>, name: &str, cols: usize, what: &str) -> PyResult<Matrix> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let arr = np
        .call_method1("asarray", (obj,))
        .map_err(|e| input(format!("{name}: not an array of numbers ({e})")))?;
    let dtype = arr.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u") {
        let dt: String = dtype.str()?.extract()?;
        return Err(input(format!(
            "{name}: expected real numbers ({what}), got an array of dtype {dt}"
        )));
    }
    // No copy when it already is float64.
    let arr = np.call_method1("asarray", (arr, "float64"))?;
    let arr: PyReadonlyArrayDyn<'_, f64> = arr.extract()?;
    let shape = arr.shape().to_vec();
    let (rows, single) = match shape.as_slice() {
        [c] if *c == cols => (1, true),
        [_, c] if *c == cols => (shape[0], false),
        _ => {
            return Err(input(format!(
                "{name}: expected shape (n, {cols}) ({what}) or ({cols},) for one row, got {}",
                shape_text(&shape)
            )))
        }
    };
    // ndarray's `as_slice` is C order only (numpy's would take Fortran order too, transposed).
    let view = arr.as_array();
    let data: Vec<f64> = match view.as_slice() {
        Some(s) => s.to_vec(),
        None => view.iter().copied().collect(),
    };
    if let Some(k) = data.iter().position(|v| !v.is_finite()) {
        let (i, j) = (k / cols, k % cols);
        return Err(input(format!(
            "{name}: row {i}, column {j}: {} is not a finite number",
            data[k]
        )));
    }
    Ok(Matrix {
        data,
        rows,
        cols,
        single,
    })
}

/// A shape as numpy prints it.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// `rows x cols` values as a numpy array: `(rows, cols)`, or `(cols,)` when `single`.
pub fn out2<'py>(
    py: Python<'py>,
    data: Vec<f64>,
    rows: usize,
    cols: usize,
    single: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let a: Bound<'py, PyArray2<f64>> = Array2::from_shape_vec((rows, cols), data)
        .expect("rows * cols values")
        .into_pyarray(py);
    if single {
        Ok(a.reshape([cols])?.into_any())
    } else {
        Ok(a.into_any())
    }
}

/// `n x a x b` values as a numpy array: `(n, a, b)`, or `(a, b)` when `single`.
pub fn out3<'py>(
    py: Python<'py>,
    data: Vec<f64>,
    shape: (usize, usize, usize),
    single: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let a: Bound<'py, PyArray3<f64>> = Array3::from_shape_vec(shape, data)
        .expect("n * a * b values")
        .into_pyarray(py);
    if single {
        Ok(a.reshape([shape.1, shape.2])?.into_any())
    } else {
        Ok(a.into_any())
    }
}
