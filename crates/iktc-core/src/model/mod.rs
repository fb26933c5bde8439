//! Robot model (immutable), state and kinematics.
//!
//! * [`Robot`]: links, joints, frames, the layout of q and q̇; built in code
//!   ([`RobotBuilder`]) or built in ([`planar3r`]). The `iktc` crate reads URDF and MuJoCo MJCF
//!   into the same [`RobotBuilder`].
//! * [`State`]: q and q̇, and their integration over a control period.
//! * [`Kinematics`]: link poses, frame Jacobians and drifts, centre of mass, computed once per
//!   state without allocation.

mod build;
mod builtin;
mod joint;
mod kinematics;
pub mod plausible;
mod robot;
pub mod spatial;
mod state;

pub use builtin::planar3r;
pub use joint::{Joint, JointKind, JointLimit, JointRole};
pub use kinematics::Kinematics;
pub use robot::{
    BaseKind, Frame, FrameId, JointSpec, Link, MimicPolicy, ModelOptions, Robot, RobotBuilder,
};
pub use state::{State, QUATERNION_NORM_TOLERANCE};
