//! What a user of the controller needs, in one import: `use iktc_core::prelude::*;`.

pub use crate::controller::{
    ComHandle, Controller, ControllerBuilder, ControllerSettings, FrameHandle, JointsHandle,
};
pub use crate::error::{Error, Result};
pub use crate::limits::{BoundMethod, DofLimits, JointLimits};
pub use crate::model::{planar3r, Kinematics, ModelOptions, Robot, State};
pub use crate::solver::{Damping, Method, SolveReport, SolverSettings};
pub use crate::task::{Axes, ComReference, FrameReference, Gains};
pub use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3, Vector6};
