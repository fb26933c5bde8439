//! # iktc-core — the real-time core of iktc
//!
//! The part of [iktc](https://crates.io/crates/iktc) a control loop needs, and nothing else:
//! no file format, mesh, motion capture or scenario (those are in the `iktc` crate, which
//! re-exports every module here under the same path). Its dependencies are nalgebra, serde
//! (the reports derive `Serialize`) and thiserror.
//!
//! The flow of one control tick is
//! *state → [`model::Kinematics`] → tasks (plain `J q̈ = h` data) → acceleration box → solver*,
//! held together by a [`Controller`] (built once, stepped once per tick).
//!
//! | module | what |
//! |---|---|
//! | [`prelude`] | what a user of the controller needs, in one import |
//! | [`controller`] | one controller: robot, levels of tasks with handles, box and solver, one `step` per tick |
//! | [`model`] | robot model (built in code), state, kinematics |
//! | [`task`] | frame, COM and joint tasks, the priority stack |
//! | [`limits`] | joint limits → acceleration box (eq. 14, viable bounds) |
//! | [`solver`] | prioritized solution, IKTC, GF, clamp, the dense QP |
//! | [`resources`] | stated maxima on what an input may make iktc allocate or run |
//! | [`error`] | the one error type |
//!
//! The notation, units and equations are in the `iktc` crate's documentation and in each
//! module's.

#![warn(missing_docs)]

mod buffer;
pub mod controller;
pub mod error;
pub mod limits;
pub mod model;
pub mod prelude;
pub mod resources;
pub mod solver;
pub mod task;

pub use controller::{Controller, ControllerBuilder};
pub use error::{Error, Result};
