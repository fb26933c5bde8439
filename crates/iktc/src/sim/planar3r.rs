//! The 3R planar arm experiment of Section 3.3 (errata 2.1).
//!
//! Three prioritized tasks on the tip of [`crate::model::planar3r`]: P_y, P_x and the
//! tip angle θ3 (default order 1 = P_y, 2 = P_x, 3 = θ3). References: P_y,d = 2, θ3,d = 90°,
//! P_x,d(t) = 1.5 − 0.5 cos(πt) for t ≤ 1 s, then 2. CLIK gains k_p = 100 s⁻², k_v = 20 s⁻¹,
//! Δt = 5 ms, 2 s, no DLS damping. From q = (90°, −90°, 90°), q1 falls to its 60° limit and
//! the three tasks become incompatible: the lowest one is sacrificed.

use std::time::Instant;

use nalgebra::{DVector, Isometry3, Translation3, UnitQuaternion, Vector3, Vector6};
use serde::Serialize;

use super::margins::{dof_margins, median, DofMargins};
use super::smoothness::{joints_smoothness, JointSmoothness};
use crate::controller::{ControllerBuilder, ControllerSettings};
use crate::error::{Error, Result};
use crate::limits::{BoundMethod, JointLimits, OutsideLimits};
use crate::model::{planar3r, State};
use crate::resources::RunLimits;
use crate::solver::{Method, SolverSettings};
use crate::task::{Axes, FrameReference, Gains};

/// One of the three tasks of the experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
pub enum ArmTask {
    /// Tip x \[m\].
    Px,
    /// Tip y \[m\].
    Py,
    /// Tip angle θ3 = q1 + q2 + q3 \[rad\].
    Theta,
}

impl ArmTask {
    /// Short name.
    pub fn name(&self) -> &'static str {
        match self {
            ArmTask::Px => "Px",
            ArmTask::Py => "Py",
            ArmTask::Theta => "theta3",
        }
    }

    fn index(&self) -> usize {
        match self {
            ArmTask::Px => 0,
            ArmTask::Py => 1,
            ArmTask::Theta => 2,
        }
    }
}

/// Settings of the run.
#[derive(Debug, Clone, PartialEq)]
pub struct Planar3rConfig {
    /// Solver.
    pub method: Method,
    /// Joint bounds.
    pub bounds: BoundMethod,
    /// Control period Δt \[s\].
    pub dt: f64,
    /// Duration \[s\].
    pub duration: f64,
    /// Range of Δt and largest tick count ([`RunLimits`]).
    pub run_limits: RunLimits,
    /// Priority order, highest first.
    pub priority: [ArmTask; 3],
    /// CLIK gains of every task.
    pub gains: Gains,
    /// Solver settings.
    pub solver: SolverSettings,
}

impl Default for Planar3rConfig {
    fn default() -> Self {
        Self {
            method: Method::Iktc,
            bounds: BoundMethod::quiet(),
            dt: 0.005,
            duration: 2.0,
            run_limits: RunLimits::default(),
            priority: [ArmTask::Py, ArmTask::Px, ArmTask::Theta],
            gains: Gains {
                kp: 100.0,
                kv: 20.0,
            },
            solver: SolverSettings::default(),
        }
    }
}

/// One recorded step (state at its start, command applied over it).
#[derive(Debug, Clone, Serialize)]
pub struct Planar3rStep {
    /// Time \[s\].
    pub t: f64,
    /// Joint positions \[rad\].
    pub q: [f64; 3],
    /// Joint rates \[rad/s\].
    pub qd: [f64; 3],
    /// Joint accelerations commanded \[rad/s²\].
    pub qdd: [f64; 3],
    /// Acceleration box lower / upper \[rad/s²\].
    pub box_lower: [f64; 3],
    /// Upper side of the box \[rad/s²\].
    pub box_upper: [f64; 3],
    /// References (P_x \[m\], P_y \[m\], θ3 \[rad\]).
    pub reference: [f64; 3],
    /// Values (P_x, P_y, θ3).
    pub value: [f64; 3],
    /// Errors reference − value.
    pub error: [f64; 3],
    /// IKTC corrections Δh of (P_x, P_y, θ3) \[m/s², rad/s²\].
    pub correction: [f64; 3],
    /// Level (0-based, priority order) the correction started from; `None` without correction.
    pub corrected_from: Option<usize>,
    /// QPs solved this step.
    pub qp_solves: usize,
    /// Dofs with an empty box.
    pub empty_dofs: usize,
    /// Time of the tick (kinematics, tasks, bounds, solve) \[µs\].
    pub tick_us: f64,
}

/// The run's summary (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct Planar3rSummary {
    /// Solver name.
    pub solver: String,
    /// Bound method name.
    pub bounds: String,
    /// Δt \[s\].
    pub dt: f64,
    /// Priority order, highest first.
    pub priority: Vec<String>,
    /// Margins per joint (q1, q2, q3).
    pub margins: Vec<DofMargins>,
    /// Largest position excursion over all joints \[rad\] (≤ 0: no limit exceeded).
    pub worst_position_margin: f64,
    /// Largest velocity excursion \[rad/s\].
    pub worst_velocity_margin: f64,
    /// Largest acceleration excursion \[rad/s²\].
    pub worst_acceleration_margin: f64,
    /// Steps with an empty box.
    pub empty_box_steps: usize,
    /// Final error of (P_x \[m\], P_y \[m\], θ3 \[rad\]).
    pub final_error: [f64; 3],
    /// Largest |error| of each task over the run.
    pub max_error: [f64; 3],
    /// Lowest q1 reached \[rad\].
    pub min_q1: f64,
    /// Mean and largest number of QPs per step.
    pub qp_per_step_mean: f64,
    /// Largest number of QPs in a step.
    pub qp_per_step_max: usize,
    /// Steps where a correction was made.
    pub corrected_steps: usize,
    /// Steps where the correction had to climb above the lowest level.
    pub climbed_steps: usize,
    /// Median tick time \[µs\].
    pub tick_median_us: f64,
    /// Smoothness of the commanded q̈ of q1, q2, q3 over the whole run.
    pub smoothness: Vec<JointSmoothness>,
    /// The same from 0.7 s on, once q1 rests on its limit.
    pub smoothness_settled: Vec<JointSmoothness>,
}

/// Start of the window of [`Planar3rSummary::smoothness_settled`] \[s\]: q1 reaches its 60°
/// limit at about 0.5 s (P_x ≈ 1.48 m); from 0.7 s on it should rest there.
pub(crate) const SETTLED_FROM: f64 = 0.7;

/// A whole run.
#[derive(Debug, Clone, Serialize)]
pub struct Planar3rRun {
    /// Every step.
    pub steps: Vec<Planar3rStep>,
    /// Summary.
    pub summary: Planar3rSummary,
}

/// The reference (P_x, P_y, θ3) and its first two derivatives at time t \[s\].
pub fn reference(t: f64) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let pi = std::f64::consts::PI;
    let theta = 0.5 * pi;
    if t <= 1.0 {
        (
            [1.5 - 0.5 * (pi * t).cos(), 2.0, theta],
            [0.5 * pi * (pi * t).sin(), 0.0, 0.0],
            [0.5 * pi * pi * (pi * t).cos(), 0.0, 0.0],
        )
    } else {
        ([2.0, 2.0, theta], [0.0; 3], [0.0; 3])
    }
}

/// Checks that the priority lists each of Px, Py and θ3 exactly once.
fn check_priority(cfg: &Planar3rConfig) -> Result<()> {
    let mut sorted = cfg.priority.map(|t| t.index());
    sorted.sort();
    if sorted != [0, 1, 2] {
        return Err(Error::InvalidSetting {
            name: "priority".into(),
            value: format!("{:?}", cfg.priority),
            expected: "each of Px, Py, theta3 exactly once".into(),
        });
    }
    Ok(())
}

/// The tip's frame reference for the task-space reference `(x, ẋ, ẍ)`: (Px \[m\], Py \[m\],
/// θ3 \[rad\]) and their rates and accelerations.
fn tip_reference(x: &[f64; 3], xd: &[f64; 3], xdd: &[f64; 3]) -> FrameReference {
    let pose = Isometry3::from_parts(
        Translation3::new(x[0], x[1], 0.0),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), x[2]),
    );
    FrameReference {
        pose,
        velocity: Vector6::new(xd[0], xd[1], 0.0, 0.0, 0.0, xd[2]),
        acceleration: Vector6::new(xdd[0], xdd[1], 0.0, 0.0, 0.0, xdd[2]),
    }
}

/// Runs the experiment.
pub fn run_planar3r(cfg: &Planar3rConfig) -> Result<Planar3rRun> {
    let n_steps = cfg.run_limits.ticks("the 3R run", cfg.duration, cfg.dt)?;
    check_priority(cfg)?;
    let robot = planar3r();
    let deg = std::f64::consts::PI / 180.0;
    let mut state = State::neutral(&robot);
    state.q = DVector::from_vec(vec![90.0 * deg, -90.0 * deg, 90.0 * deg]);
    let mut b = ControllerBuilder::new(robot.clone(), &state)?;
    b.gains(cfg.gains).settings(ControllerSettings {
        method: cfg.method,
        bounds: cfg.bounds,
        solver: cfg.solver,
    });
    let mut tasks = Vec::with_capacity(3);
    for t in cfg.priority {
        let mut axes = [false; 6];
        axes[match t {
            ArmTask::Px => 0,
            ArmTask::Py => 1,
            ArmTask::Theta => 5,
        }] = true;
        tasks.push(b.level(t.name()).frame("tip", Axes(axes))?);
    }
    if cfg.bounds.outside_limits() == OutsideLimits::Error {
        let limits = JointLimits::from_robot(&robot)?;
        let mut start = vec![0.0; robot.nv()];
        state.dof_positions(&robot, &mut start)?;
        limits.check_state(&start, state.qd.as_slice())?;
    }
    let mut ctl = b.build()?;
    let mut steps = Vec::with_capacity(n_steps);
    let tip = robot.frame_id("tip")?;
    for k in 0..n_steps {
        let t = k as f64 * cfg.dt;
        let (x, xd, xdd) = reference(t);
        let start = Instant::now();
        let r = tip_reference(&x, &xd, &xdd);
        for h in &tasks {
            ctl.set_frame_reference(*h, r)?;
        }
        ctl.prepare(&state, cfg.dt)?;
        let rep = ctl.solve()?;
        let tick_us = start.elapsed().as_secs_f64() * 1e6;
        let (corrected_from, qp_solves, empty_dofs) =
            (rep.corrected_from, rep.qp_solves, rep.empty_box_dofs);
        let mut correction = [0.0; 3];
        for (lvl, t) in cfg.priority.iter().enumerate() {
            correction[t.index()] = rep.corrections[lvl][0];
        }
        let tp = ctl.kinematics().frame_pose(&robot, tip)?;
        let value = [
            tp.translation.x,
            tp.translation.y,
            state.q[0] + state.q[1] + state.q[2],
        ];
        let (qdd, bx) = (ctl.qdd(), ctl.bounds());
        steps.push(Planar3rStep {
            t,
            q: [state.q[0], state.q[1], state.q[2]],
            qd: [state.qd[0], state.qd[1], state.qd[2]],
            qdd: [qdd[0], qdd[1], qdd[2]],
            box_lower: [bx.lower[0], bx.lower[1], bx.lower[2]],
            box_upper: [bx.upper[0], bx.upper[1], bx.upper[2]],
            reference: x,
            value,
            error: [x[0] - value[0], x[1] - value[1], x[2] - value[2]],
            correction,
            corrected_from,
            qp_solves,
            empty_dofs,
            tick_us,
        });
        ctl.integrate(&mut state)?;
    }
    let summary = summarize(cfg, &robot, &steps);
    Ok(Planar3rRun { steps, summary })
}

fn summarize(
    cfg: &Planar3rConfig,
    robot: &crate::model::Robot,
    steps: &[Planar3rStep],
) -> Planar3rSummary {
    let lims = robot.dof_limits();
    let margins: Vec<DofMargins> = (0..3)
        .map(|j| {
            let q: Vec<f64> = steps.iter().map(|s| s.q[j]).collect();
            let qd: Vec<f64> = steps.iter().map(|s| s.qd[j]).collect();
            let qdd: Vec<f64> = steps.iter().map(|s| s.qdd[j]).collect();
            dof_margins(j, &q, &qd, &qdd, cfg.dt, &lims[j])
        })
        .collect();
    let mut max_error = [0.0f64; 3];
    for s in steps {
        for (m, e) in max_error.iter_mut().zip(s.error) {
            *m = m.max(e.abs());
        }
    }
    let ticks: Vec<f64> = steps.iter().map(|s| s.tick_us).collect();
    let nt = cfg.priority.len();
    let settled = steps.partition_point(|s| s.t < SETTLED_FROM - 0.5 * cfg.dt);
    let smoothness_over = |window: std::ops::Range<usize>| {
        joints_smoothness(
            0..3,
            window,
            cfg.dt,
            |k, d| steps[k].qdd[d],
            |d| format!("q{}", d + 1),
        )
    };
    Planar3rSummary {
        solver: cfg.method.name().into(),
        bounds: cfg.bounds.name().into(),
        dt: cfg.dt,
        priority: cfg.priority.iter().map(|t| t.name().to_string()).collect(),
        worst_position_margin: margins
            .iter()
            .map(|m| m.position)
            .fold(f64::NEG_INFINITY, f64::max),
        worst_velocity_margin: margins
            .iter()
            .map(|m| m.velocity)
            .fold(f64::NEG_INFINITY, f64::max),
        worst_acceleration_margin: margins
            .iter()
            .map(|m| m.acceleration)
            .fold(f64::NEG_INFINITY, f64::max),
        margins,
        empty_box_steps: steps.iter().filter(|s| s.empty_dofs > 0).count(),
        final_error: steps.last().map_or([0.0; 3], |s| s.error),
        max_error,
        min_q1: steps.iter().map(|s| s.q[0]).fold(f64::INFINITY, f64::min),
        qp_per_step_mean: steps.iter().map(|s| s.qp_solves as f64).sum::<f64>()
            / steps.len().max(1) as f64,
        qp_per_step_max: steps.iter().map(|s| s.qp_solves).max().unwrap_or(0),
        corrected_steps: steps.iter().filter(|s| s.corrected_from.is_some()).count(),
        climbed_steps: steps
            .iter()
            .filter(|s| matches!(s.corrected_from, Some(l) if l + 1 < nt))
            .count(),
        tick_median_us: median(&ticks),
        smoothness: smoothness_over(0..steps.len()),
        smoothness_settled: smoothness_over(settled..steps.len()),
    }
}
