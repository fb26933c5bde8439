//! Reaching a controller's tasks through their handles: references, gains, the task itself.

use super::handle::{ComHandle, FrameHandle, JointsHandle, TaskRef};
use super::Controller;
use crate::error::Result;
use crate::task::{ComReference, ComTask, FrameReference, FrameTask, JointTask, Task};

impl Controller {
    fn task(&self, r: TaskRef, kind: &'static str) -> Result<&Task> {
        if r.owner != self.id {
            return Err(r.foreign(kind, self.id));
        }
        self.stack
            .levels
            .get(r.level)
            .and_then(|l| l.tasks.get(r.index))
            .ok_or_else(|| r.foreign(kind, self.id))
    }

    fn task_mut(&mut self, r: TaskRef, kind: &'static str) -> Result<&mut Task> {
        if r.owner != self.id {
            return Err(r.foreign(kind, self.id));
        }
        let id = self.id;
        self.stack
            .levels
            .get_mut(r.level)
            .and_then(|l| l.tasks.get_mut(r.index))
            .ok_or_else(|| r.foreign(kind, id))
    }

    /// The frame task of `h`. Errors: a handle of another controller.
    pub fn frame(&self, h: FrameHandle) -> Result<&FrameTask> {
        match self.task(h.0, "frame")? {
            Task::Frame(t) => Ok(t),
            _ => Err(h.0.foreign("frame", self.id)),
        }
    }

    /// The frame task of `h`, to change its gains or reference. Errors: a handle of another
    /// controller.
    pub fn frame_mut(&mut self, h: FrameHandle) -> Result<&mut FrameTask> {
        let id = self.id;
        match self.task_mut(h.0, "frame")? {
            Task::Frame(t) => Ok(t),
            _ => Err(h.0.foreign("frame", id)),
        }
    }

    /// Sets the reference of the frame task `h` (pose, twist \[m/s, rad/s\] and acceleration
    /// \[m/s², rad/s²\], world axes). Allocates nothing. Errors: a handle of another
    /// controller, a non-finite entry.
    pub fn set_frame_reference(&mut self, h: FrameHandle, r: FrameReference) -> Result<()> {
        self.frame_mut(h)?.set_reference(r)
    }

    /// The COM task of `h`. Errors: a handle of another controller.
    pub fn com(&self, h: ComHandle) -> Result<&ComTask> {
        match self.task(h.0, "COM")? {
            Task::Com(t) => Ok(t),
            _ => Err(h.0.foreign("COM", self.id)),
        }
    }

    /// The COM task of `h`, to change its gains or reference. Errors: a handle of another
    /// controller.
    pub fn com_mut(&mut self, h: ComHandle) -> Result<&mut ComTask> {
        let id = self.id;
        match self.task_mut(h.0, "COM")? {
            Task::Com(t) => Ok(t),
            _ => Err(h.0.foreign("COM", id)),
        }
    }

    /// Sets the reference of the COM task `h` (position \[m\], velocity \[m/s\], acceleration
    /// \[m/s²\], world axes). Allocates nothing. Errors: a handle of another controller, a
    /// non-finite entry.
    pub fn set_com_reference(&mut self, h: ComHandle, r: ComReference) -> Result<()> {
        self.com_mut(h)?.set_reference(r)
    }

    /// The joint task of `h`. Errors: a handle of another controller.
    pub fn joints(&self, h: JointsHandle) -> Result<&JointTask> {
        match self.task(h.0, "joints")? {
            Task::Joint(t) => Ok(t),
            _ => Err(h.0.foreign("joints", self.id)),
        }
    }

    /// The joint task of `h`, to change its gains or reference. Errors: a handle of another
    /// controller.
    pub fn joints_mut(&mut self, h: JointsHandle) -> Result<&mut JointTask> {
        let id = self.id;
        match self.task_mut(h.0, "joints")? {
            Task::Joint(t) => Ok(t),
            _ => Err(h.0.foreign("joints", id)),
        }
    }

    /// Sets the reference of the joint task `h`: positions \[rad\], rates \[rad/s\] and
    /// accelerations \[rad/s²\], one per joint in the order the task was made with. Allocates
    /// nothing. Errors: a handle of another controller, wrong lengths, a non-finite entry.
    pub fn set_joints_reference(
        &mut self,
        h: JointsHandle,
        position: &[f64],
        velocity: &[f64],
        acceleration: &[f64],
    ) -> Result<()> {
        self.joints_mut(h)?
            .set_reference(position, velocity, acceleration)
    }
}
