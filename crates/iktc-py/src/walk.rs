//! `iktc.Walking`: walking while imitating (the walking pattern of `iktc::walk` driving the feet
//! and COM tasks of the Section 5.3 stack) stepped tick by tick from Python, for a robot with a
//! profile; the physics loop around it is the caller's, and so is the measured ZMP the damping
//! controller (off by default) reads.

use iktc::sim::imitate::{support_polygon, SupportSettings};
use iktc::sim::{imitation_references, WalkImitateConfig, WalkingController};
use iktc::walk::SupportPolygon;
use nalgebra::{Isometry3, Rotation2, Vector2};
use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::balance::PyPlaneModel;
use crate::controller::PySolveReport;
use crate::convert::{array, pose_matrix};
use crate::imitate::{narrowed, pose_of};
use crate::motion::{resolve_map, PyMotion};
use crate::robot::PyRobot;
use crate::to_py;

/// The pattern's model ZMP (world) \[m\] and the local frame's yaw \[rad\] of a tick.
type PatternZmp = (Vector2<f64>, f64);

/// Walking while imitating: `steps` footsteps of `step_length` [m] (default: the robot
/// profile's `walk` settings, else 0.1 m steps, 0.8 s initial and final double support, 0.6 s
/// single, 0.1 s double, 4 cm swing), the upper body imitating `motion`; `narrow` a list of
/// (joint, lower, upper) [rad] replacing the profile's narrowed ranges. With `damping` the
/// damping controller of Section 4 is in the loop: each `tick(zmp)` it reads the measured ZMP's
/// deviation from the pattern's and moves the COM reference; `cases` are its four models
/// (xz SSP, xz DSP, yz SSP, yz DSP, `PlaneModel`s; their length is replaced by the COM height),
/// None the synthetic ones of `iktc::balance::CaseParams::synthetic`; `offset_feedforward`
/// False gives the COM task the controller's offset without its rates fed forward (as
/// `iktc.mujoco`'s identification sweeps it); `smoothing` [Hz] and `approach_rate` [1/s] as in
/// `Imitation` (default 6 Hz and the imitation's approach, √k_p = 10 /s; None and 0 turn
/// them off); `zmp_passes` passes of the ZMP correction (`WalkingController::correct_zmp`:
/// where the plan's own multibody ZMP comes within 5 mm of the support polygon's edge, the COM
/// reference is moved by preview control so that it does not; at most 10
/// (`iktc::resources::MAX_ZMP_PASSES`), stopping once a pass no longer brings the ZMP closer;
/// 0, the default, is the paper's cart-table pattern).
#[pyclass(name = "Walking", module = "iktc")]
pub struct PyWalking {
    ctl: WalkingController,
    k: usize,
    dt: f64,
    polygon: SupportPolygon,
    /// The soles (for the polygon of given feet).
    support: SupportSettings,
    /// The pattern's model ZMP (world) and the local frame's yaw of the last tick, which the
    /// next tick's measured ZMP is compared with.
    last_zmp: Option<PatternZmp>,
}

#[pymethods]
impl PyWalking {
    #[new]
    #[pyo3(signature = (robot, motion, *, map=None, steps=4, step_length=None, narrow=None,
                        damping=false, cases=None, offset_feedforward=true,
                        smoothing=Some(iktc::sim::IMITATE_SMOOTHING), approach_rate=None,
                        zmp_passes=0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        robot: &PyRobot,
        motion: &PyMotion,
        map: Option<&str>,
        steps: usize,
        step_length: Option<f64>,
        narrow: Option<Vec<(String, f64, f64)>>,
        damping: bool,
        cases: Option<Vec<Bound<'_, PyPlaneModel>>>,
        offset_feedforward: bool,
        smoothing: Option<f64>,
        approach_rate: Option<f64>,
        zmp_passes: usize,
    ) -> PyResult<Self> {
        let profile = robot.required_profile("walking", "feet, pelvis and posture")?;
        let mut cfg = profile
            .walk_config(&robot.robot, WalkImitateConfig::jvrc1().map_err(to_py)?)
            .map_err(to_py)?;
        if let Some(n) = narrow {
            cfg.imitate.narrow = narrowed(n);
        }
        cfg.imitate.smoothing = smoothing;
        if let Some(rate) = approach_rate {
            cfg.imitate.bounds = cfg.imitate.bounds.with_approach_rate(rate).map_err(to_py)?;
        }
        cfg.steps = steps;
        if let Some(l) = step_length {
            cfg.step_length = l;
        }
        cfg.push = None;
        cfg.damping = damping;
        if let Some(c) = cases {
            let [xz_ssp, xz_dsp, yz_ssp, yz_dsp] = c.as_slice() else {
                return Err(crate::IktcError::new_err(format!(
                    "cases: expected four PlaneModels (xz SSP, xz DSP, yz SSP, yz DSP), got {}",
                    c.len()
                )));
            };
            cfg.cases = iktc::balance::CaseParams {
                xz_ssp: xz_ssp.get().params(),
                xz_dsp: xz_dsp.get().params(),
                yz_ssp: yz_ssp.get().params(),
                yz_dsp: yz_dsp.get().params(),
            };
            cfg.cases.validate().map_err(to_py)?;
        }
        cfg.noise_std = 0.0;
        cfg.zmp_passes = zmp_passes;
        let map = resolve_map(robot, motion, map)?;
        let clip = motion.clip()?;
        let r = &robot.robot;
        let mut ctl = py
            .detach(|| -> iktc::Result<WalkingController> {
                let refs = imitation_references(r, clip, &map, &cfg.imitate)?;
                WalkingController::new(r, &refs, &cfg)
            })
            .map_err(to_py)?;
        ctl.set_offset_feedforward(offset_feedforward);
        Ok(Self {
            ctl,
            k: 0,
            dt: cfg.imitate.dt,
            polygon: SupportPolygon::default(),
            support: cfg.imitate.support,
            last_zmp: None,
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

    /// One control tick: pattern sample, damping controller, COM and feet references, IK
    /// solve, integration; k advances. `zmp`: the measured ZMP (world x, y) [m] after the last
    /// tick, or None (no measurement: a deviation of 0); the damping controller (if on) reads
    /// its deviation from the last tick's pattern ZMP (cart-table model), in the local frame of
    /// Figure 11. Returns (report, phase) with phase "double" or "single". The GIL is released.
    #[pyo3(signature = (zmp=None))]
    fn tick(
        &mut self,
        py: Python<'_>,
        zmp: Option<(f64, f64)>,
    ) -> PyResult<(PySolveReport, &'static str)> {
        let dev = match (zmp, self.last_zmp) {
            (Some((x, y)), Some((model, yaw))) => {
                let d = Rotation2::new(-yaw) * (Vector2::new(x, y) - model);
                [d.x, d.y]
            }
            _ => [0.0, 0.0],
        };
        let (ctl, k) = (&mut self.ctl, self.k);
        let out = py
            .detach(
                || -> iktc::Result<(PySolveReport, &'static str, PatternZmp)> {
                    let wt = ctl.tick(k, dev)?;
                    let report = PySolveReport::from(ctl.imitation().report());
                    ctl.integrate()?;
                    let phase = match wt.phase {
                        iktc::balance::SupportPhase::Double => "double",
                        iktc::balance::SupportPhase::Single => "single",
                    };
                    let o = ctl.origin();
                    let m = wt.sample.zmp_model;
                    Ok((
                        report,
                        phase,
                        (Vector2::new(m.0 + o.x, m.1 + o.y), wt.local_yaw),
                    ))
                },
            )
            .map_err(to_py)?;
        self.last_zmp = Some(out.2);
        self.k += 1;
        Ok((out.0, out.1))
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

    /// Signed distance [m] from the world point (x, y) to the edge of a support polygon
    /// (positive inside): with `feet` (ankle poses, 4 × 4 world, at least one) the convex hull
    /// of their soles, else the pattern's polygon at the last tick (the stance sole in single
    /// support, both soles in double support).
    #[pyo3(signature = (point, feet=None))]
    fn support_margin(
        &mut self,
        point: (f64, f64),
        feet: Option<Vec<PyReadonlyArray2<'_, f64>>>,
    ) -> PyResult<f64> {
        if let Some(f) = feet {
            let poses = f.iter().map(pose_of).collect::<PyResult<Vec<_>>>()?;
            let p = support_polygon(&poses, &self.support).map_err(to_py)?;
            return Ok(p.margin(point));
        }
        let t = self.k.saturating_sub(1) as f64 * self.dt;
        let o = self.ctl.origin();
        self.ctl
            .pattern()
            .support_polygon_into(t, &mut self.polygon)
            .map_err(to_py)?;
        Ok(self.polygon.margin((point.0 - o.x, point.1 - o.y)))
    }

    /// Per ZMP correction pass, the largest move [m] it asked of the plan's ZMP (empty
    /// without `zmp_passes`).
    fn zmp_corrections(&self) -> Vec<f64> {
        self.ctl.zmp_corrections().to_vec()
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
