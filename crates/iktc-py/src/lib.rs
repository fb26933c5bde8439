//! Python bindings of iktc (module `iktc._iktc`, re-exported by the `iktc` package).
//!
//! The Python API follows the Rust one: a [`PyRobot`] (built-in name, profile or URDF), a controller
//! built level by level through a builder whose `frame`/`com`/`joints` return typed handles,
//! and `Controller.step(q, v, dt)`, which advances the numpy arrays `q` and `v` in place and
//! releases the GIL while Rust runs. Every `iktc::Error` becomes an `iktc.IktcError` (a
//! `ValueError`) with the same message. Motions load with `load_motion` and retarget with
//! `retarget` (numpy arrays out); `Imitation` steps the Section 5.3 imitation tick by tick.

use pyo3::prelude::*;

mod balance;
mod controller;
mod convert;
mod data;
mod imitate;
mod keypoints;
mod motion;
mod robot;
mod walk;

pyo3::create_exception!(
    _iktc,
    IktcError,
    pyo3::exceptions::PyValueError,
    "Bad input to iktc: the message names what is wrong and what was expected."
);

/// Converts an iktc error into the Python exception `iktc.IktcError`, same message.
pub(crate) fn to_py(e: iktc::Error) -> PyErr {
    IktcError::new_err(e.to_string())
}

#[pymodule]
fn _iktc(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("IktcError", m.py().get_type::<IktcError>())?;
    m.add_class::<robot::PyRobot>()?;
    m.add_class::<controller::PyControllerBuilder>()?;
    m.add_class::<controller::PyController>()?;
    m.add_class::<controller::PyFrameHandle>()?;
    m.add_class::<controller::PyComHandle>()?;
    m.add_class::<controller::PyJointsHandle>()?;
    m.add_class::<controller::PySolveReport>()?;
    m.add_class::<imitate::PyImitation>()?;
    m.add_class::<walk::PyWalking>()?;
    m.add_function(wrap_pyfunction!(robot::profile_init, m)?)?;
    m.add_function(wrap_pyfunction!(data::builtin_text, m)?)?;
    motion::register(m)?;
    keypoints::register(m)?;
    balance::register(m)?;
    Ok(())
}
