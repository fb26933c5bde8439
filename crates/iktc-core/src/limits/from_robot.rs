//! Limits of a robot model as plain per-dof data.

use super::joint_limits::{DofLimits, JointLimits};
use crate::error::Result;
use crate::model::Robot;

impl JointLimits {
    /// One [`DofLimits`] per velocity coordinate of `robot`: unlimited for the floating base,
    /// then each active joint's position range \[rad or m\], velocity, acceleration and jerk
    /// limits;
    /// the dofs are named as in [`Robot::dof_names`].
    pub fn from_robot(robot: &Robot) -> Result<JointLimits> {
        let limits = JointLimits::new(
            robot
                .dof_limits()
                .iter()
                .map(|l| DofLimits {
                    position_min: l.lower,
                    position_max: l.upper,
                    velocity_max: l.velocity,
                    acceleration_max: l.acceleration,
                    jerk_max: l.jerk,
                })
                .collect(),
        )?;
        limits.with_names(robot.dof_names())
    }
}
