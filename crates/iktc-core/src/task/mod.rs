//! Tasks, each linearised to plain data `J q̈ = h` (paper eqs. 2, 3, 11).
//!
//! A [`Task`] is a frame task ([`FrameTask`]: any subset of position and orientation axes), a
//! centre-of-mass task ([`ComTask`]) or a joint task ([`JointTask`]). A [`TaskStack`] is the
//! priority order: a list of levels, each a list of tasks whose rows are stacked into one
//! [`TaskEquation`]. Priority 1 is the first level.

mod com;
mod equation;
mod frame;
mod joint;

pub use com::{ComReference, ComTask};
pub use equation::{Gains, TaskEquation};
pub use frame::{Axes, FrameReference, FrameTask};
pub use joint::JointTask;

use crate::error::{check_dim, Result};
use crate::model::{Kinematics, Robot, State};

/// One task of any kind.
#[derive(Debug, Clone)]
pub enum Task {
    /// A frame task.
    Frame(FrameTask),
    /// A centre-of-mass task.
    Com(ComTask),
    /// A joint task.
    Joint(JointTask),
}

impl Task {
    /// Number of rows.
    pub fn dim(&self) -> usize {
        match self {
            Task::Frame(t) => t.dim(),
            Task::Com(t) => t.dim(),
            Task::Joint(t) => t.dim(),
        }
    }

    /// Writes rows `offset..offset + dim()` of `out`. Allocates nothing.
    pub fn linearize(
        &mut self,
        robot: &Robot,
        kin: &Kinematics,
        state: &State,
        out: &mut TaskEquation,
        offset: usize,
    ) -> Result<()> {
        match self {
            Task::Frame(t) => t.linearize(robot, kin, state, out, offset),
            Task::Com(t) => t.linearize(robot, kin, state, out, offset),
            Task::Joint(t) => t.linearize(robot, kin, state, out, offset),
        }
    }
}

/// One priority level: a name and the tasks whose rows it stacks.
#[derive(Debug, Clone)]
pub struct Level {
    /// Name for reports.
    pub name: String,
    /// Tasks, rows stacked in this order.
    pub tasks: Vec<Task>,
}

impl Level {
    /// Number of rows m_i.
    pub fn dim(&self) -> usize {
        self.tasks.iter().map(Task::dim).sum()
    }
}

/// The hierarchy: levels in priority order (first = highest).
#[derive(Debug, Clone, Default)]
pub struct TaskStack {
    /// The levels.
    pub levels: Vec<Level>,
}

impl TaskStack {
    /// Adds a level of one or more tasks, below the existing ones.
    pub fn push(&mut self, name: impl Into<String>, tasks: Vec<Task>) -> &mut Self {
        self.levels.push(Level {
            name: name.into(),
            tasks,
        });
        self
    }

    /// Zeroed equations sized for this stack (one per level). Call once, then
    /// [`TaskStack::linearize`] every tick.
    pub fn equations(&self, robot: &Robot) -> Vec<TaskEquation> {
        self.levels
            .iter()
            .map(|l| TaskEquation::zeros(l.name.clone(), l.dim(), robot.nv()))
            .collect()
    }

    /// Linearises every level into `out` (from [`TaskStack::equations`]). Allocates nothing.
    pub fn linearize(
        &mut self,
        robot: &Robot,
        kin: &Kinematics,
        state: &State,
        out: &mut [TaskEquation],
    ) -> Result<()> {
        check_dim("number of task levels", self.levels.len(), out.len())?;
        for (level, eq) in self.levels.iter_mut().zip(out.iter_mut()) {
            if level.dim() != eq.dim() {
                return Err(crate::Error::DimensionMismatch {
                    what: format!("rows of level `{}`", level.name),
                    expected: level.dim(),
                    got: eq.dim(),
                });
            }
            let mut offset = 0;
            for t in level.tasks.iter_mut() {
                t.linearize(robot, kin, state, eq, offset)?;
                offset += t.dim();
            }
        }
        Ok(())
    }
}
