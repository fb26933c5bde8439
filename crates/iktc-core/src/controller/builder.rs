//! Building a [`Controller`]: the robot, the state it starts from, and levels of tasks.

use std::sync::Arc;

use nalgebra::DVector;

use super::handle::{ComHandle, ControllerId, FrameHandle, JointsHandle, TaskRef};
use super::settings::ControllerSettings;
use super::Controller;
use crate::error::{check_dim, Error, Result};
use crate::limits::{AccelerationBox, JointLimits};
use crate::model::{Kinematics, Robot, State};
use crate::solver::Solver;
use crate::task::{
    Axes, ComReference, ComTask, FrameReference, FrameTask, Gains, JointTask, Task, TaskStack,
};

/// Builds a [`Controller`] level by level.
///
/// Every task is created *holding where the robot is* in the state given to
/// [`ControllerBuilder::new`]: a frame task's reference is the frame's pose there, a COM task's
/// the COM there, a joint task's the joints' positions there (all with zero rate and
/// acceleration). A controller stepped from that state therefore asks for q̈ = 0 until a
/// reference is moved.
///
/// ```
/// use iktc_core::prelude::*;
///
/// let robot = planar3r();
/// let state = State::neutral(&robot);
/// let mut b = ControllerBuilder::new(robot, &state)?;
/// let tip = b.level("tip").frame("tip", Axes::POSITION)?; // level 0
/// let mut ctl = b.build()?;
/// assert_eq!(tip.level(), 0);
/// assert_eq!(ctl.level_dims().collect::<Vec<_>>(), [3]);
/// # Ok::<(), iktc_core::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct ControllerBuilder {
    id: ControllerId,
    robot: Arc<Robot>,
    state: State,
    kin: Kinematics,
    gains: Gains,
    settings: ControllerSettings,
    limits: Option<JointLimits>,
    stack: TaskStack,
}

impl ControllerBuilder {
    /// A builder for `robot` (a `Robot` or an `Arc<Robot>`), whose tasks will hold the robot
    /// where `state` puts it. Gains default to k_p = 100 s⁻², k_v = 20 s⁻¹
    /// ([`Gains::critical`]); limits to the robot's own ([`JointLimits::from_robot`]).
    ///
    /// Errors: a state of the wrong size or with a non-finite entry.
    pub fn new(robot: impl Into<Arc<Robot>>, state: &State) -> Result<Self> {
        let robot = robot.into();
        state.validate(&robot)?;
        let kin = Kinematics::new(&robot, state)?;
        Ok(Self {
            id: ControllerId::fresh(),
            robot,
            state: state.clone(),
            kin,
            gains: Gains::default(),
            settings: ControllerSettings::default(),
            limits: None,
            stack: TaskStack::default(),
        })
    }

    /// The robot.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// Kinematics at the state the tasks are created from.
    pub fn kinematics(&self) -> &Kinematics {
        &self.kin
    }

    /// CLIK gains of the tasks added from now on (checked when a task is added).
    pub fn gains(&mut self, gains: Gains) -> &mut Self {
        self.gains = gains;
        self
    }

    /// Solver, bounds and their settings (checked by [`ControllerBuilder::build`]).
    pub fn settings(&mut self, settings: ControllerSettings) -> &mut Self {
        self.settings = settings;
        self
    }

    /// Joint limits other than the robot's own, e.g. with narrowed ranges (one entry per
    /// velocity dof; checked by [`ControllerBuilder::build`]).
    pub fn limits(&mut self, limits: JointLimits) -> &mut Self {
        self.limits = Some(limits);
        self
    }

    /// Starts a new level below the existing ones; the tasks added next go into it. Priority
    /// is the order of the levels: the first is the highest.
    pub fn level(&mut self, name: impl Into<String>) -> &mut Self {
        self.stack.push(name, Vec::new());
        self
    }

    /// Adds a frame task on `frame`, selected `axes`, holding the frame's pose in the builder's
    /// state, to the current level.
    ///
    /// Errors: no level started, an unknown frame, no axis, bad gains.
    pub fn frame(&mut self, frame: &str, axes: Axes) -> Result<FrameHandle> {
        self.weighted_frame(frame, axes, 1.0)
    }

    /// [`ControllerBuilder::frame`] with the rows weighted by `weight` ([`FrameTask::set_weight`]):
    /// a task that shares a level with others in a weighted least-squares compromise. Errors:
    /// as `frame`, and a weight that is not finite and > 0.
    pub fn weighted_frame(&mut self, frame: &str, axes: Axes, weight: f64) -> Result<FrameHandle> {
        let mut task = FrameTask::new(&self.robot, frame, axes, self.gains)?;
        task.set_weight(weight)?;
        let pose = self.kin.frame_pose(&self.robot, task.frame())?;
        task.set_reference(FrameReference::hold(pose))?;
        self.add(Task::Frame(task)).map(FrameHandle)
    }

    /// Adds a centre-of-mass task on the selected world axes (x, y, z), holding the COM of the
    /// builder's state, to the current level.
    ///
    /// Errors: no level started, no axis, bad gains, a massless robot.
    pub fn com(&mut self, axes: [bool; 3]) -> Result<ComHandle> {
        let mut task = ComTask::new(&self.robot, axes, self.gains)?;
        task.set_reference(ComReference::hold(self.kin.com()))?;
        self.add(Task::Com(task)).map(ComHandle)
    }

    /// Adds a joint task on the named active joints, holding their positions in the builder's
    /// state, to the current level.
    ///
    /// Errors: no level started, no joint, an unknown or inactive joint, bad gains.
    pub fn joints(&mut self, joints: &[&str]) -> Result<JointsHandle> {
        self.weighted_joints(joints, 1.0)
    }

    /// [`ControllerBuilder::joints`] with the rows weighted by `weight` ([`JointTask::set_weight`]):
    /// a posture regulariser sharing a level with other tasks. Errors: as `joints`, and a weight
    /// that is not finite and > 0.
    pub fn weighted_joints(&mut self, joints: &[&str], weight: f64) -> Result<JointsHandle> {
        let mut task = JointTask::new(&self.robot, joints, self.gains)?;
        task.set_weight(weight)?;
        let mut q = DVector::zeros(joints.len());
        for (slot, name) in q.iter_mut().zip(joints) {
            *slot = self.state.joint(&self.robot, name)?;
        }
        let zero = DVector::zeros(joints.len());
        task.set_reference(q.as_slice(), zero.as_slice(), zero.as_slice())?;
        self.add(Task::Joint(task)).map(JointsHandle)
    }

    fn add(&mut self, task: Task) -> Result<TaskRef> {
        let level = self.stack.levels.len();
        let Some(current) = self.stack.levels.last_mut() else {
            return Err(Error::InvalidSetting {
                name: "controller levels".into(),
                value: "no level".into(),
                expected: "a level started with ControllerBuilder::level before adding a task"
                    .into(),
            });
        };
        current.tasks.push(task);
        Ok(TaskRef {
            owner: self.id,
            level: level - 1,
            index: current.tasks.len() - 1,
        })
    }

    /// The controller: equations, box and solver sized for the levels, nothing allocated
    /// after this.
    ///
    /// Errors: no level, a level without a task, bad settings, limits of the wrong size.
    pub fn build(self) -> Result<Controller> {
        self.settings.validate()?;
        if self.stack.levels.is_empty() {
            return Err(Error::InvalidSetting {
                name: "controller levels".into(),
                value: "none".into(),
                expected: "at least one level of tasks".into(),
            });
        }
        if let Some(l) = self.stack.levels.iter().find(|l| l.tasks.is_empty()) {
            return Err(Error::InvalidSetting {
                name: format!("level `{}`", l.name),
                value: "no task".into(),
                expected: "at least one task in every level".into(),
            });
        }
        let nv = self.robot.nv();
        let limits = match self.limits {
            Some(l) => l,
            None => JointLimits::from_robot(&self.robot)?,
        };
        check_dim("joint limits (one per velocity dof)", nv, limits.nv())?;
        let eqs = self.stack.equations(&self.robot);
        let dims: Vec<usize> = eqs.iter().map(|e| e.dim()).collect();
        let solver = Solver::new(nv, &dims, self.settings.solver)?;
        Ok(Controller {
            id: self.id,
            settings: self.settings,
            stack: self.stack,
            eqs,
            limits,
            bounds: AccelerationBox::new(nv),
            solver,
            kin: self.kin,
            pos: vec![0.0; nv],
            qdd: DVector::zeros(nv),
            stage: super::Stage::Built,
            robot: self.robot,
        })
    }
}
