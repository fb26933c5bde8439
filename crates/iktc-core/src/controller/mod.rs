//! One controller a user holds: the robot, levels of tasks, the joint limits and their box, and
//! the solver, built once and stepped once per control tick.
//!
//! A [`Controller`] is built by a [`ControllerBuilder`] from a robot, the state it starts from
//! and levels of tasks in priority order; each task added returns a typed handle
//! ([`FrameHandle`], [`ComHandle`], [`JointsHandle`]) through which its reference is set
//! ([`Controller::set_frame_reference`], …). Every task starts holding where the robot is.
//!
//! One tick ([`Controller::step`]) is, for the state (q, q̇) and the control period Δt:
//!
//! 1. kinematics at (q, q̇): frame poses and Jacobians, drifts J̇q̇, the COM (eqs. 2–3);
//! 2. each level linearised to `J_i q̈ = h_i` with
//!    `h_i = ẍ_d + k_v (ẋ_d − ẋ) + k_p (x_d − x) − J̇_i q̇` (eqs. 3, 11);
//! 3. the joint limits turned into the box `b_l ≤ q̈ ≤ b_u` (eq. 14 or the viable bounds), with
//!    the optional jerk limits around the previous tick's q̈ ([`limit_jerk`]);
//! 4. the solve: the prioritized solution (eqs. 5–10), corrected by IKTC (eqs. 19–25), or GF,
//!    or clamping ([`ControllerSettings::method`]);
//! 5. the constant-acceleration integration q⁺ = q + Δt q̇ + ½Δt² q̈, q̇⁺ = q̇ + Δt q̈.
//!
//! Steps 1–3 are [`Controller::prepare`], after which the problem of the tick can be read
//! ([`Controller::equations`], [`Controller::bounds`]) before [`Controller::solve`] (step 4)
//! and [`Controller::integrate`] (step 5) — what `step` does in one call. Nothing allocates
//! after [`ControllerBuilder::build`].
//!
//! The controller shares the robot through an [`Arc`]: the model is immutable and is needed
//! both by the controller (every tick) and by its user (names, states, kinematics), and a
//! shared pointer lets a scenario own its controller without a lifetime parameter.

mod builder;
mod handle;
mod references;
mod settings;

pub use builder::ControllerBuilder;
pub use handle::{ComHandle, ControllerId, FrameHandle, JointsHandle};
pub use settings::ControllerSettings;

use std::sync::Arc;

use nalgebra::DVector;

use crate::error::{Error, Result};
use crate::limits::{compute_box, limit_jerk, AccelerationBox, JointLimits};
use crate::model::{Kinematics, Robot, State};
use crate::solver::{SolveReport, Solver};
use crate::task::{TaskEquation, TaskStack};

/// How far the current tick has gone.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stage {
    /// Nothing prepared since the last integration (or since building).
    Built,
    /// Equations and box computed for a period `dt` \[s\].
    Prepared { dt: f64 },
    /// q̈ solved for the prepared problem, not yet integrated.
    Solved { dt: f64 },
}

/// Kinematics, task stack, equations, joint limits and box, and solver of one robot, sized once
/// (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct Controller {
    id: ControllerId,
    robot: Arc<Robot>,
    settings: ControllerSettings,
    stack: TaskStack,
    eqs: Vec<TaskEquation>,
    limits: JointLimits,
    bounds: AccelerationBox,
    solver: Solver,
    kin: Kinematics,
    pos: Vec<f64>,
    qdd: DVector<f64>,
    stage: Stage,
}

impl Controller {
    /// A builder for `robot` whose tasks hold the robot where `state` puts it (see
    /// [`ControllerBuilder::new`]).
    pub fn builder(robot: impl Into<Arc<Robot>>, state: &State) -> Result<ControllerBuilder> {
        ControllerBuilder::new(robot, state)
    }

    /// One control tick: [`Controller::prepare`], [`Controller::solve`] and
    /// [`Controller::integrate`]; `state` is advanced by `dt` \[s\]. Allocates nothing.
    ///
    /// Errors: a state of another robot or with a non-finite entry, `dt` not finite and
    /// positive. A hard problem (an empty box, an infeasible correction) is not an error: it is
    /// in the report, with the fallback taken.
    pub fn step(&mut self, state: &mut State, dt: f64) -> Result<&SolveReport> {
        self.prepare(state, dt)?;
        self.solve()?;
        self.integrate(state)?;
        Ok(self.solver.report())
    }

    /// Steps 1–3 of a tick for `state` and the period `dt` \[s\]: kinematics, the equation of
    /// every level and the acceleration box, which can then be read
    /// ([`Controller::equations`], [`Controller::bounds`]) before [`Controller::solve`].
    /// Allocates nothing.
    pub fn prepare(&mut self, state: &State, dt: f64) -> Result<()> {
        self.stage = Stage::Built;
        self.kin.update(&self.robot, state)?;
        self.prepare_tasks(state, dt)
    }

    /// [`Controller::prepare`] with the kinematics at `state` already computed in `kin`
    /// ([`Kinematics::update`] of this controller's robot at `state`): they are swapped in
    /// instead of computed again (`kin` receives the controller's previous ones). The same
    /// problem bit for bit, the kinematics being a function of the robot and the state.
    pub fn prepare_with_kinematics(
        &mut self,
        state: &State,
        dt: f64,
        kin: &mut Kinematics,
    ) -> Result<()> {
        self.stage = Stage::Built;
        std::mem::swap(&mut self.kin, kin);
        self.prepare_tasks(state, dt)
    }

    /// The steps of [`Controller::prepare`] after the kinematics.
    fn prepare_tasks(&mut self, state: &State, dt: f64) -> Result<()> {
        self.stack
            .linearize(&self.robot, &self.kin, state, &mut self.eqs)?;
        state.dof_positions(&self.robot, &mut self.pos)?;
        compute_box(
            &self.limits,
            &self.settings.bounds,
            &self.pos,
            state.qd.as_slice(),
            dt,
            &mut self.bounds,
        )?;
        if self.limits.has_jerk_limits() {
            // The previous command: the last solved q̈ (zero before the first solve).
            limit_jerk(&self.limits, self.qdd.as_slice(), dt, &mut self.bounds)?;
        }
        self.stage = Stage::Prepared { dt };
        Ok(())
    }

    /// Step 4: solves the prepared problem with [`ControllerSettings::method`]; q̈ is then in
    /// [`Controller::qdd`]. Allocates nothing.
    ///
    /// Errors: no problem prepared since the last integration.
    pub fn solve(&mut self) -> Result<&SolveReport> {
        let dt = match self.stage {
            Stage::Prepared { dt } | Stage::Solved { dt } => dt,
            Stage::Built => return Err(out_of_order("solve", "Controller::prepare")),
        };
        self.solver
            .solve(self.settings.method, &self.eqs, &self.bounds, &mut self.qdd)?;
        self.stage = Stage::Solved { dt };
        Ok(self.solver.report())
    }

    /// Step 5: advances `state` (the state the problem was prepared for) by the prepared
    /// period under the solved q̈, constant over the period (the integrator the bounds assume,
    /// [`State::integrate`]). The next tick starts with [`Controller::prepare`].
    ///
    /// Errors: nothing solved since the last integration; a state of another robot.
    pub fn integrate(&mut self, state: &mut State) -> Result<()> {
        let Stage::Solved { dt } = self.stage else {
            return Err(out_of_order("integrate", "Controller::solve"));
        };
        state.integrate(&self.robot, &self.qdd, dt)?;
        self.stage = Stage::Built;
        Ok(())
    }

    /// The identity that this controller's handles carry.
    pub fn id(&self) -> ControllerId {
        self.id
    }

    /// The robot.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// The shared robot.
    pub fn robot_arc(&self) -> &Arc<Robot> {
        &self.robot
    }

    /// The settings.
    pub fn settings(&self) -> &ControllerSettings {
        &self.settings
    }

    /// The task stack (read only: tasks are changed through their handles).
    pub fn stack(&self) -> &TaskStack {
        &self.stack
    }

    /// Level sizes m_i, in priority order.
    pub fn level_dims(&self) -> impl ExactSizeIterator<Item = usize> + '_ {
        self.eqs.iter().map(TaskEquation::dim)
    }

    /// The joint limits.
    pub fn limits(&self) -> &JointLimits {
        &self.limits
    }

    /// Kinematics at the state of the last [`Controller::prepare`] (at the builder's state
    /// before the first).
    pub fn kinematics(&self) -> &Kinematics {
        &self.kin
    }

    /// The equation `J_i q̈ = h_i` of each level from the last [`Controller::prepare`]
    /// (its `error` holds `x_d − x`).
    pub fn equations(&self) -> &[TaskEquation] {
        &self.eqs
    }

    /// The acceleration box from the last [`Controller::prepare`] \[rad/s²\].
    pub fn bounds(&self) -> &AccelerationBox {
        &self.bounds
    }

    /// Dof positions of the last [`Controller::prepare`] \[rad\] (base entries 0).
    pub fn dof_positions(&self) -> &[f64] {
        &self.pos
    }

    /// q̈ of the last solve (base: \[m/s²\], \[rad/s²\]; joints \[rad/s²\]).
    pub fn qdd(&self) -> &DVector<f64> {
        &self.qdd
    }

    /// The report of the last solve.
    pub fn report(&self) -> &SolveReport {
        self.solver.report()
    }
}

fn out_of_order(call: &str, first: &str) -> Error {
    Error::InvalidSetting {
        name: format!("Controller::{call}"),
        value: "called out of order".into(),
        expected: format!("{first} first (a tick is prepare → solve → integrate)"),
    }
}
