//! What a user of the controller needs, in one import: `use iktc::prelude::*;` (the core's
//! [`iktc_core::prelude`], and the robot file readers).

pub use iktc_core::prelude::*;

#[cfg(feature = "urdf")]
pub use crate::model::{jvrc1, RobotFiles};
