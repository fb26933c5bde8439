//! numpy ↔ nalgebra conversions with the checks the Python side needs (sizes, finiteness).

use nalgebra::{DMatrix, Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use numpy::ndarray::IntoDimension;
use numpy::npyffi::NPY_ORDER;
use numpy::{PyArray, PyArray1, PyArray2, PyArrayMethods, ToPyArray};
use pyo3::prelude::*;

use crate::IktcError;

/// A length-`n` float vector from a Python sequence or array; `what` names it in errors.
pub(crate) fn vector(x: &Bound<'_, PyAny>, n: usize, what: &str) -> PyResult<Vec<f64>> {
    let v: Vec<f64> = x
        .extract()
        .map_err(|_| IktcError::new_err(format!("{what}: expected a sequence of {n} numbers")))?;
    if v.len() != n {
        return Err(IktcError::new_err(format!(
            "dimension mismatch in {what}: expected {n}, got {}",
            v.len()
        )));
    }
    if let Some((i, x)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(IktcError::new_err(format!(
            "{what}[{i}] is not finite (got {x})"
        )));
    }
    Ok(v)
}

/// An optional vector; zeros when `None`.
pub(crate) fn vector_or_zeros(
    x: Option<&Bound<'_, PyAny>>,
    n: usize,
    what: &str,
) -> PyResult<Vec<f64>> {
    match x {
        Some(x) if !x.is_none() => vector(x, n, what),
        _ => Ok(vec![0.0; n]),
    }
}

/// A 3-vector.
pub(crate) fn vector3(x: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector3<f64>> {
    let v = vector(x, 3, what)?;
    Ok(Vector3::new(v[0], v[1], v[2]))
}

/// A pose from a position \[m\] and a unit quaternion (x, y, z, w), the project's order.
pub(crate) fn pose(
    position: &Bound<'_, PyAny>,
    quaternion: &Bound<'_, PyAny>,
) -> PyResult<Isometry3<f64>> {
    let p = vector3(position, "position")?;
    let q = vector(quaternion, 4, "orientation quaternion (x, y, z, w)")?;
    let norm = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if norm.is_nan() || norm <= 0.0 {
        return Err(IktcError::new_err(
            "orientation quaternion (x, y, z, w) is zero: expected a unit quaternion",
        ));
    }
    let r = UnitQuaternion::from_quaternion(Quaternion::new(q[3], q[0], q[1], q[2]));
    Ok(Isometry3::from_parts(Translation3::from(p), r))
}

/// A 4 × 4 homogeneous matrix of a pose.
pub(crate) fn pose_matrix<'py>(py: Python<'py>, p: &Isometry3<f64>) -> Bound<'py, PyArray2<f64>> {
    let m = p.to_homogeneous();
    let rows: Vec<Vec<f64>> = (0..4)
        .map(|i| (0..4).map(|j| m[(i, j)]).collect())
        .collect();
    // Always 4 rows of 4: from_vec2 cannot fail here.
    PyArray2::from_vec2(py, &rows).unwrap_or_else(|_| PyArray2::zeros(py, [4, 4], false))
}

/// A dense matrix as a numpy array (copied, row-major).
pub(crate) fn matrix<'py>(py: Python<'py>, m: &DMatrix<f64>) -> Bound<'py, PyArray2<f64>> {
    let (r, c) = m.shape();
    let out = PyArray2::<f64>::zeros(py, [r, c], false);
    {
        // A fresh C-contiguous array owned here: the write borrow cannot fail.
        if let Ok(mut w) = out.try_readwrite() {
            if let Ok(s) = w.as_slice_mut() {
                for i in 0..r {
                    for j in 0..c {
                        s[i * c + j] = m[(i, j)];
                    }
                }
            }
        }
    }
    out
}

/// A slice as a numpy vector (copied).
pub(crate) fn array<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
    v.to_pyarray(py)
}

/// A row-major numpy array of shape `shape` (e.g. `[rows, cols]`) from its flat data (moved,
/// not copied again).
pub(crate) fn table<'py, D: IntoDimension>(
    py: Python<'py>,
    shape: D,
    flat: Vec<f64>,
) -> PyResult<Bound<'py, PyArray<f64, D::Dim>>> {
    PyArray1::from_vec(py, flat).reshape_with_order(shape, NPY_ORDER::NPY_CORDER)
}
