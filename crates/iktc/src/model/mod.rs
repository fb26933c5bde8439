//! Robot model (immutable), state and kinematics: the core's [`iktc_core::model`], re-exported
//! here, and the robot description formats.
//!
//! * [`Robot`]: links, joints, frames, the layout of q and q̇; from URDF
//!   ([`RobotFiles::from_urdf_str`]), MuJoCo MJCF ([`RobotFiles::from_mjcf_file`], subset in
//!   [`mjcf`]), either by its root element ([`RobotFiles::from_description_file`]), built in
//!   code ([`RobotBuilder`]) or built in ([`planar3r`], [`jvrc1`], [`g1`]).
//! * [`State`]: q and q̇, and their integration over a control period.
//! * [`Kinematics`]: link poses, frame Jacobians and drifts, centre of mass, computed once per
//!   state without allocation.
//! * [`StateConfig`]: a state written in a file (JSON or TOML).

mod builtin;
mod config;
#[cfg(feature = "urdf")]
mod description;
#[cfg(feature = "urdf")]
mod files;
#[cfg(feature = "mjcf")]
pub mod mjcf;
#[cfg(feature = "urdf")]
mod urdf;
#[cfg(feature = "urdf")]
mod urdf_check;

pub use iktc_core::model::*;

#[cfg(feature = "urdf")]
pub(crate) use description::read_description;
#[cfg(feature = "urdf")]
pub use description::{declared_base, description_format, DescriptionFormat};
#[cfg(feature = "urdf")]
pub use files::RobotFiles;
#[cfg(all(feature = "urdf", feature = "toml"))]
pub(crate) use urdf::pose as urdf_pose;
#[cfg(feature = "urdf")]
pub(crate) use urdf::read_urdf;

#[cfg(feature = "mjcf")]
pub use builtin::G1_MJCF;
pub use builtin::{builtin_robot, BUILTIN_ROBOTS};
#[cfg(feature = "urdf")]
pub use builtin::{g1, jvrc1, G1_URDF, JVRC1_FINGERS, JVRC1_URDF};
pub use config::{BasePose, StateConfig, MAX_CONFIG_MAGNITUDE};
