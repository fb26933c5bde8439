//! `iktc.ControllerBuilder`, `iktc.Controller`, the task handles and the solve report.

use iktc::controller::{ComHandle, Controller, ControllerBuilder, FrameHandle, JointsHandle};
use iktc::limits::BoundMethod;
use iktc::model::State;
use iktc::solver::{Fallback, Method, SolveReport};
use iktc::task::{Axes, ComReference, FrameReference, Gains};
use nalgebra::{Vector3, Vector6};
use numpy::{PyArray1, PyArray2, PyReadwriteArray1};
use pyo3::prelude::*;

use crate::convert::{array, matrix, pose, vector, vector3, vector_or_zeros};
use crate::robot::PyRobot;
use crate::{to_py, IktcError};

/// One level's equation as numpy arrays: (J, h).
type Equation<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>);

/// A handle to a frame task of one controller.
#[pyclass(name = "FrameHandle", module = "iktc", frozen)]
#[derive(Clone, Copy)]
pub struct PyFrameHandle(FrameHandle);

/// A handle to a COM task of one controller.
#[pyclass(name = "ComHandle", module = "iktc", frozen)]
#[derive(Clone, Copy)]
pub struct PyComHandle(ComHandle);

/// A handle to a joint task of one controller.
#[pyclass(name = "JointsHandle", module = "iktc", frozen)]
#[derive(Clone, Copy)]
pub struct PyJointsHandle(JointsHandle, usize);

#[pymethods]
impl PyFrameHandle {
    /// The level (0 = highest priority).
    #[getter]
    fn level(&self) -> usize {
        self.0.level()
    }
}

#[pymethods]
impl PyComHandle {
    /// The level (0 = highest priority).
    #[getter]
    fn level(&self) -> usize {
        self.0.level()
    }
}

#[pymethods]
impl PyJointsHandle {
    /// The level (0 = highest priority).
    #[getter]
    fn level(&self) -> usize {
        self.0.level()
    }
}

fn parse_axes(axes: &str) -> PyResult<Axes> {
    match axes {
        "all" => Ok(Axes::ALL),
        "position" => Ok(Axes::POSITION),
        "orientation" => Ok(Axes::ORIENTATION),
        _ => {
            // Letters: x y z for position, r p w (roll, pitch, yaw) for orientation.
            let mut a = [false; 6];
            for c in axes.chars() {
                let i = match c {
                    'x' => 0,
                    'y' => 1,
                    'z' => 2,
                    'r' => 3,
                    'p' => 4,
                    'w' => 5,
                    _ => {
                        return Err(IktcError::new_err(format!(
                            "axes `{axes}`: expected \"all\", \"position\", \"orientation\" or letters of \"xyzrpw\" (x, y, z position; r, p, w rotation about x, y, z)"
                        )))
                    }
                };
                a[i] = true;
            }
            if a.iter().all(|x| !x) {
                return Err(IktcError::new_err("axes: no axis selected"));
            }
            Ok(Axes(a))
        }
    }
}

pub(crate) fn parse_method(method: &str) -> PyResult<Method> {
    match method {
        "iktc" => Ok(Method::Iktc),
        "gf" | "cascade" => Ok(Method::Cascade),
        "clamp" => Ok(Method::Clamp),
        "prioritized" => Ok(Method::Prioritized),
        _ => Err(IktcError::new_err(format!(
            "method `{method}`: expected one of iktc, gf, clamp, prioritized"
        ))),
    }
}

pub(crate) fn parse_bounds(bounds: &str) -> PyResult<BoundMethod> {
    match bounds {
        "viable" => Ok(BoundMethod::viable()),
        "paper" => Ok(BoundMethod::Paper),
        "quiet" => Ok(BoundMethod::quiet()),
        _ => Err(IktcError::new_err(format!(
            "bounds `{bounds}`: expected one of viable, paper, quiet"
        ))),
    }
}

/// Builds a controller level by level. Every task starts holding where the robot is at the
/// builder's state.
///
/// ```python
/// b = iktc.ControllerBuilder(robot, q, kp=100.0)
/// b.level("feet"); rf = b.frame("r_ankle"); lf = b.frame("l_ankle")
/// b.level("com"); com = b.com("xy")
/// ctrl = b.build()
/// ```
#[pyclass(name = "ControllerBuilder", module = "iktc")]
pub struct PyControllerBuilder {
    inner: Option<ControllerBuilder>,
}

impl PyControllerBuilder {
    fn get(&mut self) -> PyResult<&mut ControllerBuilder> {
        self.inner
            .as_mut()
            .ok_or_else(|| IktcError::new_err("this builder was already built"))
    }
}

#[pymethods]
impl PyControllerBuilder {
    /// `robot`, the state (q, v = 0 by default) the tasks hold at, CLIK gains k_p [s⁻²] and
    /// k_v [s⁻¹] (default critical damping 2√k_p), the solver method (iktc, gf, clamp), the
    /// bound method (quiet, the default; viable; paper) and the rate [1/s] of the soft approach
    /// to the range ends with viable or quiet bounds (`iktc::limits::ViableSettings::approach_rate`;
    /// 0, the default, leaves it out; √k_p is the imitation's choice).
    #[new]
    #[pyo3(signature = (robot, q, v=None, *, kp=100.0, kv=None, method="iktc", bounds="quiet", approach_rate=0.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        robot: &PyRobot,
        q: &Bound<'_, PyAny>,
        v: Option<&Bound<'_, PyAny>>,
        kp: f64,
        kv: Option<f64>,
        method: &str,
        bounds: &str,
        approach_rate: f64,
    ) -> PyResult<Self> {
        let state = robot.state(q, v)?;
        let mut b = ControllerBuilder::new(robot.robot.clone(), &state).map_err(to_py)?;
        let gains = match kv {
            Some(kv) => Gains { kp, kv },
            None => Gains::critical(kp),
        };
        let bounds = parse_bounds(bounds)?
            .with_approach_rate(approach_rate)
            .map_err(to_py)?;
        let settings = iktc::controller::ControllerSettings {
            method: parse_method(method)?,
            bounds,
            ..Default::default()
        };
        b.gains(gains).settings(settings);
        Ok(Self { inner: Some(b) })
    }

    /// Starts a new level (lower priority than every level before it).
    fn level(&mut self, name: &str) -> PyResult<()> {
        self.get()?.level(name);
        Ok(())
    }

    /// Adds a frame task on `axes` ("all", "position", "orientation" or letters of "xyzrpw").
    #[pyo3(signature = (frame, axes="all"))]
    fn frame(&mut self, frame: &str, axes: &str) -> PyResult<PyFrameHandle> {
        let axes = parse_axes(axes)?;
        self.get()?
            .frame(frame, axes)
            .map(PyFrameHandle)
            .map_err(to_py)
    }

    /// Adds a COM task on `axes` (letters of "xyz").
    #[pyo3(signature = (axes="xyz"))]
    fn com(&mut self, axes: &str) -> PyResult<PyComHandle> {
        let mut a = [false; 3];
        for c in axes.chars() {
            match c {
                'x' => a[0] = true,
                'y' => a[1] = true,
                'z' => a[2] = true,
                _ => {
                    return Err(IktcError::new_err(format!(
                        "COM axes `{axes}`: expected letters of \"xyz\""
                    )))
                }
            }
        }
        self.get()?.com(a).map(PyComHandle).map_err(to_py)
    }

    /// Adds a joint task on the named joints.
    fn joints(&mut self, names: Vec<String>) -> PyResult<PyJointsHandle> {
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let n = refs.len();
        self.get()?
            .joints(&refs)
            .map(|h| PyJointsHandle(h, n))
            .map_err(to_py)
    }

    /// Builds the controller (the builder cannot be used afterwards).
    fn build(&mut self) -> PyResult<PyController> {
        let b = self
            .inner
            .take()
            .ok_or_else(|| IktcError::new_err("this builder was already built"))?;
        let inner = b.build().map_err(to_py)?;
        let state = State::neutral(inner.robot());
        Ok(PyController { inner, state })
    }
}

/// A controller: kinematics, tasks, joint limits and their box, and the solver of one robot.
#[pyclass(name = "Controller", module = "iktc")]
pub struct PyController {
    inner: Controller,
    /// The state exchanged with the numpy arrays (no allocation per step).
    state: State,
}

impl PyController {
    fn load(
        &mut self,
        q: &PyReadwriteArray1<'_, f64>,
        v: &PyReadwriteArray1<'_, f64>,
    ) -> PyResult<()> {
        let (nq, nv) = (self.inner.robot().nq(), self.inner.robot().nv());
        let qs = q
            .as_slice()
            .map_err(|_| IktcError::new_err("q: expected a contiguous float64 array"))?;
        let vs = v
            .as_slice()
            .map_err(|_| IktcError::new_err("v: expected a contiguous float64 array"))?;
        if qs.len() != nq {
            return Err(IktcError::new_err(format!(
                "dimension mismatch in q: expected {nq}, got {}",
                qs.len()
            )));
        }
        if vs.len() != nv {
            return Err(IktcError::new_err(format!(
                "dimension mismatch in v: expected {nv}, got {}",
                vs.len()
            )));
        }
        self.state.q.as_mut_slice().copy_from_slice(qs);
        self.state.qd.as_mut_slice().copy_from_slice(vs);
        Ok(())
    }
}

#[pymethods]
impl PyController {
    /// One control tick for the state (q, v) and the period dt [s]: kinematics, tasks, the
    /// acceleration box, the solve and the constant-acceleration integration. `q` and `v`
    /// (float64 numpy arrays) are advanced in place; q̈ is then `controller.qdd`. The GIL is
    /// released while Rust runs.
    fn step(
        &mut self,
        py: Python<'_>,
        mut q: PyReadwriteArray1<'_, f64>,
        mut v: PyReadwriteArray1<'_, f64>,
        dt: f64,
    ) -> PyResult<PySolveReport> {
        self.load(&q, &v)?;
        let (inner, state) = (&mut self.inner, &mut self.state);
        let report = py
            .detach(|| inner.step(state, dt).map(PySolveReport::from))
            .map_err(to_py)?;
        q.as_slice_mut()
            .map_err(|_| IktcError::new_err("q: not writable"))?
            .copy_from_slice(self.state.q.as_slice());
        v.as_slice_mut()
            .map_err(|_| IktcError::new_err("v: not writable"))?
            .copy_from_slice(self.state.qd.as_slice());
        Ok(report)
    }

    /// Steps 1–3 of a tick (kinematics, equations, box) for (q, v) and dt [s], so that the
    /// problem can be read with `equations()` and `bounds()` before `solve()`.
    fn prepare(
        &mut self,
        py: Python<'_>,
        q: PyReadwriteArray1<'_, f64>,
        v: PyReadwriteArray1<'_, f64>,
        dt: f64,
    ) -> PyResult<()> {
        self.load(&q, &v)?;
        let (inner, state) = (&mut self.inner, &self.state);
        py.detach(|| inner.prepare(state, dt)).map_err(to_py)
    }

    /// Solves the prepared problem; q̈ is then `controller.qdd` (q and v are not advanced).
    fn solve(&mut self, py: Python<'_>) -> PyResult<PySolveReport> {
        let inner = &mut self.inner;
        py.detach(|| inner.solve().map(PySolveReport::from))
            .map_err(to_py)
    }

    /// The prepared equations J_i q̈ = h_i, one (J, h) pair of numpy arrays per level.
    fn equations<'py>(&self, py: Python<'py>) -> Vec<Equation<'py>> {
        self.inner
            .equations()
            .iter()
            .map(|e| (matrix(py, &e.jacobian), array(py, e.rhs.as_slice())))
            .collect()
    }

    /// The prepared acceleration box (lower, upper) [rad/s²], numpy arrays of length nv.
    fn bounds<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
        let b = self.inner.bounds();
        (array(py, b.lower.as_slice()), array(py, b.upper.as_slice()))
    }

    /// q̈ of the last solve (numpy array of length nv).
    #[getter]
    fn qdd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.inner.qdd().as_slice())
    }

    /// The report of the last solve.
    #[getter]
    fn report(&self) -> PySolveReport {
        PySolveReport::from(self.inner.report())
    }

    /// Level sizes m_i, in priority order.
    #[getter]
    fn level_dims(&self) -> Vec<usize> {
        self.inner.level_dims().collect()
    }

    /// Sets a frame task's reference: position [m], orientation quaternion (x, y, z, w), and
    /// optionally its twist (linear [m/s], angular [rad/s]) and acceleration, world axes.
    #[pyo3(signature = (handle, position, orientation, velocity=None, acceleration=None))]
    fn set_frame_reference(
        &mut self,
        handle: &PyFrameHandle,
        position: &Bound<'_, PyAny>,
        orientation: &Bound<'_, PyAny>,
        velocity: Option<&Bound<'_, PyAny>>,
        acceleration: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let r = FrameReference {
            pose: pose(position, orientation)?,
            velocity: Vector6::from_column_slice(&vector_or_zeros(velocity, 6, "frame velocity")?),
            acceleration: Vector6::from_column_slice(&vector_or_zeros(
                acceleration,
                6,
                "frame acceleration",
            )?),
        };
        self.inner.set_frame_reference(handle.0, r).map_err(to_py)
    }

    /// Sets a COM task's reference: position [m], optionally velocity [m/s] and acceleration
    /// [m/s²], world axes.
    #[pyo3(signature = (handle, position, velocity=None, acceleration=None))]
    fn set_com_reference(
        &mut self,
        handle: &PyComHandle,
        position: &Bound<'_, PyAny>,
        velocity: Option<&Bound<'_, PyAny>>,
        acceleration: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let v = vector_or_zeros(velocity, 3, "COM velocity")?;
        let a = vector_or_zeros(acceleration, 3, "COM acceleration")?;
        let r = ComReference {
            position: vector3(position, "COM position")?,
            velocity: Vector3::new(v[0], v[1], v[2]),
            acceleration: Vector3::new(a[0], a[1], a[2]),
        };
        self.inner.set_com_reference(handle.0, r).map_err(to_py)
    }

    /// Sets a joint task's reference: positions [rad], optionally rates [rad/s] and
    /// accelerations [rad/s²], in the order the task was made with.
    #[pyo3(signature = (handle, position, velocity=None, acceleration=None))]
    fn set_joints_reference(
        &mut self,
        handle: &PyJointsHandle,
        position: &Bound<'_, PyAny>,
        velocity: Option<&Bound<'_, PyAny>>,
        acceleration: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let n = handle.1;
        let p = vector(position, n, "joint reference position")?;
        let v = vector_or_zeros(velocity, n, "joint reference velocity")?;
        let a = vector_or_zeros(acceleration, n, "joint reference acceleration")?;
        self.inner
            .set_joints_reference(handle.0, &p, &v, &a)
            .map_err(to_py)
    }
}

/// How q̈ was obtained and which task paid for the limits (plain Python data).
#[pyclass(name = "SolveReport", module = "iktc", frozen, get_all)]
#[derive(Clone)]
pub struct PySolveReport {
    /// "iktc", "gf", "clamp" or "prioritized".
    pub method: String,
    /// The level the correction started from (0 = highest priority), None if no correction.
    pub corrected_from: Option<usize>,
    /// Per level: the correction Δh_i (task units / s²).
    pub corrections: Vec<Vec<f64>>,
    /// Per level: the error J_i q̈ − h_i after the solve.
    pub task_errors: Vec<Vec<f64>>,
    /// Per level: the rank of the projected Jacobian.
    pub ranks: Vec<usize>,
    /// QPs solved.
    pub qp_solves: usize,
    /// Infeasible QPs among them.
    pub qp_infeasible: usize,
    /// Levels declared infeasible by the screen, without a QP.
    pub screened_infeasible: usize,
    /// Dofs whose box was empty (lower > upper).
    pub empty_box_dofs: usize,
    /// Largest violation of the box by q̈ [rad/s²] (0 when inside).
    pub violation: f64,
    /// Largest violation of the box by the prioritized solution before correction [rad/s²].
    pub violation_before: f64,
    /// The fallback taken, if any ("clamped_to_box", "cascade_stopped_at_level_N").
    pub fallback: Option<String>,
}

impl From<&SolveReport> for PySolveReport {
    fn from(r: &SolveReport) -> Self {
        Self {
            method: r.method.name().to_string(),
            corrected_from: r.corrected_from,
            corrections: r
                .corrections
                .iter()
                .map(|c| c.as_slice().to_vec())
                .collect(),
            task_errors: r
                .task_errors
                .iter()
                .map(|c| c.as_slice().to_vec())
                .collect(),
            ranks: r.ranks.clone(),
            qp_solves: r.qp_solves,
            qp_infeasible: r.qp_infeasible,
            screened_infeasible: r.screened_infeasible,
            empty_box_dofs: r.empty_box_dofs,
            violation: r.violation,
            violation_before: r.violation_before,
            fallback: r.fallback.map(|f| match f {
                Fallback::ClampedToBox => "clamped_to_box".to_string(),
                Fallback::CascadeStoppedAtLevel(l) => format!("cascade_stopped_at_level_{l}"),
                #[allow(unreachable_patterns)]
                other => format!("{other:?}"),
            }),
        }
    }
}

#[pymethods]
impl PySolveReport {
    fn __repr__(&self) -> String {
        format!(
            "SolveReport(method={:?}, corrected_from={:?}, qp_solves={}, violation={:.3e}, fallback={:?})",
            self.method, self.corrected_from, self.qp_solves, self.violation, self.fallback
        )
    }
}
