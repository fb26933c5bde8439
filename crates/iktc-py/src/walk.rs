//! `iktc.Walking`: walking while imitating (the walking pattern of `iktc::walk` driving the feet
//! and COM tasks of the Section 5.3 stack) stepped tick by tick from Python, for a robot with a
//! profile, without the damping controller (the physics loop around it is the caller's).

use iktc::sim::{imitation_references, WalkImitateConfig, WalkingController};
use iktc::walk::SupportPolygon;
use nalgebra::Isometry3;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::controller::PySolveReport;
use crate::convert::{array, pose_matrix};
use crate::imitate::narrowed;
use crate::motion::{resolve_map, PyMotion};
use crate::robot::PyRobot;
use crate::to_py;

/// Walking while imitating: `steps` footsteps of `step_length` [m] (default: the robot
/// profile's `walk` settings, else 0.1 m steps, 0.8 s initial and final double support, 0.6 s
/// single, 0.1 s double, 4 cm swing), the upper body imitating `motion`, the damping
/// controller off; `narrow` a list of (joint, lower, upper) [rad] replacing the
/// profile's narrowed ranges.
#[pyclass(name = "Walking", module = "iktc")]
pub struct PyWalking {
    ctl: WalkingController,
    robot: std::sync::Arc<iktc::model::Robot>,
    k: usize,
    dt: f64,
    polygon: SupportPolygon,
}

#[pymethods]
impl PyWalking {
    #[new]
    #[pyo3(signature = (robot, motion, *, map=None, steps=4, step_length=None, narrow=None))]
    fn new(
        py: Python<'_>,
        robot: &PyRobot,
        motion: &PyMotion,
        map: Option<&str>,
        steps: usize,
        step_length: Option<f64>,
        narrow: Option<Vec<(String, f64, f64)>>,
    ) -> PyResult<Self> {
        let profile = robot.required_profile("walking", "feet, pelvis and posture")?;
        let mut cfg = profile
            .walk_config(&robot.robot, WalkImitateConfig::jvrc1().map_err(to_py)?)
            .map_err(to_py)?;
        if let Some(n) = narrow {
            cfg.imitate.narrow = narrowed(n);
        }
        cfg.steps = steps;
        if let Some(l) = step_length {
            cfg.step_length = l;
        }
        cfg.push = None;
        cfg.damping = false;
        cfg.noise_std = 0.0;
        let map = resolve_map(robot, motion, map)?;
        let clip = motion.clip()?;
        let r = &robot.robot;
        let ctl = py
            .detach(|| -> iktc::Result<WalkingController> {
                let refs = imitation_references(r, clip, &map, &cfg.imitate)?;
                WalkingController::new(r, &refs, &cfg)
            })
            .map_err(to_py)?;
        Ok(Self {
            ctl,
            robot: robot.robot.clone(),
            k: 0,
            dt: cfg.imitate.dt,
            polygon: SupportPolygon::default(),
        })
    }

    /// Ticks of the walk (its duration over Δt, plus one).
    #[getter]
    fn ticks(&self) -> usize {
        self.ctl.ticks()
    }

    /// Index of the next tick.
    #[getter]
    fn k(&self) -> usize {
        self.k
    }

    /// One control tick: pattern sample, COM and feet references, IK solve, integration; k
    /// advances. Returns (report, phase) with phase "double" or "single". The GIL is released.
    fn tick(&mut self, py: Python<'_>) -> PyResult<(PySolveReport, &'static str)> {
        let (ctl, robot, k) = (&mut self.ctl, &self.robot, self.k);
        let out = py
            .detach(|| -> iktc::Result<(PySolveReport, &'static str)> {
                let wt = ctl.tick(robot, k, [0.0, 0.0])?;
                let report = PySolveReport::from(ctl.imitation().report());
                ctl.integrate(robot)?;
                let phase = match wt.phase {
                    iktc::balance::SupportPhase::Double => "double",
                    iktc::balance::SupportPhase::Single => "single",
                };
                Ok((report, phase))
            })
            .map_err(to_py)?;
        self.k += 1;
        Ok(out)
    }

    /// The configuration q (numpy, length nq) at the start of the next tick.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.ctl.imitation().state().q.as_slice())
    }

    /// The velocity v (numpy, length nv) at the start of the next tick.
    #[getter]
    fn v<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.ctl.imitation().state().qd.as_slice())
    }

    /// The ankle references of the last tick (right, then left), 4 × 4 world poses [m].
    fn feet_references<'py>(&self, py: Python<'py>) -> Vec<Bound<'py, PyArray2<f64>>> {
        let [left, right] = self.ctl.feet_references();
        [right, left]
            .iter()
            .map(|r| pose_matrix(py, &r.pose))
            .collect()
    }

    /// Signed distance [m] from the world point (x, y) to the edge of the pattern's support
    /// polygon at the last tick (positive inside).
    fn support_margin(&mut self, point: (f64, f64)) -> PyResult<f64> {
        let t = self.k.saturating_sub(1) as f64 * self.dt;
        let o = self.ctl.origin();
        self.ctl
            .pattern()
            .support_polygon_into(t, &mut self.polygon)
            .map_err(to_py)?;
        Ok(self.polygon.margin((point.0 - o.x, point.1 - o.y)))
    }

    /// The initial ankle poses (right, then left), 4 × 4.
    fn feet0<'py>(&self, py: Python<'py>) -> Vec<Bound<'py, PyArray2<f64>>> {
        self.ctl
            .imitation()
            .feet0()
            .iter()
            .map(|p: &Isometry3<f64>| pose_matrix(py, p))
            .collect()
    }
}
