//! Robot model (immutable), state and kinematics.
//!
//! * [`Robot`]: links, joints, frames, the layout of q and q̇; from URDF
//!   ([`Robot::from_urdf_str`]), MuJoCo MJCF ([`Robot::from_mjcf_file`], subset in [`mjcf`]),
//!   either by its root element ([`Robot::from_description_file`]), built in code ([`RobotBuilder`]) or built in ([`planar3r`],
//!   [`jvrc1`]).
//! * [`State`]: q and q̇, and their integration over a control period.
//! * [`Kinematics`]: link poses, frame Jacobians and drifts, centre of mass, computed once per
//!   state without allocation.

mod builtin;
mod config;
#[cfg(feature = "urdf")]
mod description;
mod joint;
mod kinematics;
#[cfg(feature = "mjcf")]
pub mod mjcf;
pub mod plausible;
mod robot;
pub mod spatial;
mod state;
#[cfg(feature = "urdf")]
mod urdf;
#[cfg(feature = "urdf")]
mod urdf_check;

#[cfg(feature = "urdf")]
pub(crate) use description::read_description;
#[cfg(feature = "urdf")]
pub use description::{declared_base, description_format, DescriptionFormat};
#[cfg(feature = "urdf")]
pub(crate) use urdf::{pose as urdf_pose, read_urdf};

#[cfg(feature = "mjcf")]
pub use builtin::G1_MJCF;
pub use builtin::{builtin_robot, planar3r, BUILTIN_ROBOTS};
#[cfg(feature = "urdf")]
pub use builtin::{g1, jvrc1, G1_URDF, JVRC1_FINGERS, JVRC1_URDF};
pub use config::{BasePose, StateConfig, MAX_CONFIG_MAGNITUDE};
pub use joint::{Joint, JointKind, JointLimit, JointRole};
pub use kinematics::Kinematics;
pub use robot::{
    BaseKind, Frame, FrameId, JointSpec, Link, MimicPolicy, ModelOptions, Robot, RobotBuilder,
};
pub use state::{State, QUATERNION_NORM_TOLERANCE};
