//! Scalar arguments of `simulate` and `plan` parsed as the CLI parses its flags: counts
//! (refusing negative numbers, bools and floats with a `UsageError` naming the argument rather
//! than an `OverflowError`), per-joint lists, frame vectors and ranges. The settings are checked
//! by the library (`SimulationBuilder`, `PlanBuilder`), for both.

use crate::errors::usage;
use crate::options::describe;
use pyo3::prelude::*;
use pyo3::types::PyBool;
use robocal_core::io::result::FrameVec;

/// An optional argument, `None` when absent or None.
pub fn given<'a, 'py>(v: Option<&'a Bound<'py, PyAny>>) -> Option<&'a Bound<'py, PyAny>> {
    v.filter(|v| !v.is_none())
}

/// Argument `name`, an int within `min..=max` (`why` says what the upper limit protects).
pub fn count(v: &Bound<'_, PyAny>, name: &str, min: u64, max: u64, why: &str) -> PyResult<u64> {
    let bad = || usage(format!("{name}: expected an int, got {}", describe(v)));
    if v.is_instance_of::<PyBool>() {
        return Err(bad());
    }
    // Python ints of any size, numpy integers: through `operator.index` (floats are refused).
    let Ok(i) = v.py().import("operator")?.call_method1("index", (v,)) else {
        return Err(bad());
    };
    // Beyond i128: only its sign matters.
    let value: i128 = match i.extract::<i128>() {
        Ok(x) => x,
        Err(_) if i.lt(0)? => i128::MIN,
        Err(_) => i128::MAX,
    };
    if value < min as i128 {
        let shown: String = i.str()?.to_string();
        return Err(usage(format!("{name} {shown}: must be at least {min}")));
    }
    if value > max as i128 {
        let shown: String = i.str()?.to_string();
        return Err(usage(format!("{name} {shown}: at most {max} ({why})")));
    }
    Ok(value as u64)
}

/// A list of numbers: a number (one value for every joint) or a sequence (the library's
/// settings builder spreads one value to every joint and checks the count).
pub fn per_joint(v: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<f64>> {
    if !v.is_instance_of::<PyBool>() {
        if let Ok(x) = v.extract::<f64>() {
            return Ok(vec![x]);
        }
        if let Ok(xs) = v.extract::<Vec<f64>>() {
            return Ok(xs);
        }
    }
    Err(usage(format!(
        "{name}: expected a number or one number per joint, got {}",
        describe(v)
    )))
}

/// Six numbers x, y, z, A, B, C (mm, deg): a frame vector.
pub fn frame(v: &Bound<'_, PyAny>, name: &str) -> PyResult<FrameVec> {
    let xs: Vec<f64> = v.extract().map_err(|_| {
        usage(format!(
            "{name}: expected 6 numbers x, y, z, A, B, C (mm, deg), got {}",
            describe(v)
        ))
    })?;
    let [x, y, z, a, b, c] = xs[..] else {
        return Err(usage(format!(
            "{name}: expected 6 values x, y, z, A, B, C (mm, deg), got {}",
            xs.len()
        )));
    };
    Ok(FrameVec { x, y, z, a, b, c })
}

/// Two numbers (min, max) of a range of distances (mm), as the CLI's `--range-mm` (the library
/// checks the range).
pub fn range_mm(v: &Bound<'_, PyAny>, name: &str) -> PyResult<(f64, f64)> {
    let xs: Vec<f64> = v.extract().map_err(|_| {
        usage(format!(
            "{name}: expected (min, max) in mm, got {}",
            describe(v)
        ))
    })?;
    let [a, b] = xs[..] else {
        return Err(usage(format!(
            "{name}: expected (min, max) in mm, got {} value(s)",
            xs.len()
        )));
    };
    Ok((a, b))
}

/// A frame vector as a dict {x, y, z, a, b, c}.
pub fn frame_dict<'py>(py: Python<'py>, f: &FrameVec) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let d = pyo3::types::PyDict::new(py);
    for (k, v) in [
        ("x", f.x),
        ("y", f.y),
        ("z", f.z),
        ("a", f.a),
        ("b", f.b),
        ("c", f.c),
    ] {
        d.set_item(k, v)?;
    }
    Ok(d)
}
