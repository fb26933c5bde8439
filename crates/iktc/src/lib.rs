//! # iktc — inverse kinematic control of humanoids under joint constraints
//!
//! A Rust implementation of Kim & Oh, *Inverse Kinematic Control of Humanoids Under Joint
//! Constraints* (IJARS 2013), with the corrections of the project's errata:
//!
//! * second-order (acceleration-level) task-priority inverse kinematics with damped least
//!   squares and closed-loop (CLIK) feedback (paper eqs. 2–12);
//! * joint position, velocity and acceleration limits turned into one box on q̈
//!   (Proposition 3.1, eq. 14, and discrete-time-safe "viable" bounds);
//! * IKTC: when the prioritized solution leaves the box, an optimal correction of the
//!   lowest-priority tasks by one small QP (eqs. 19–25, Algorithms 1–2);
//! * baselines: the cascade of QPs (GF, Kanoun et al.) and clamping;
//! * the ZMP damping controller on the inverted pendulum with a compliant joint (Section 4);
//! * captured motion (DeepMimic, BVH) retargeted to robot references, a walking pattern
//!   generator, and the paper's experiments as scenarios.
//!
//! The flow of one control tick is
//! *state → [`model::Kinematics`] → tasks (plain `J q̈ = h` data) → acceleration box → solver*,
//! held together by a [`Controller`] (built once, stepped once per tick).
//!
//! | module | what |
//! |---|---|
//! | [`controller`] | one controller: robot, levels of tasks with handles, box and solver, one `step` per tick |
//! | [`prelude`] | what a user of the controller needs, in one import |
//! | [`model`] | robot model (URDF or code), state, kinematics |
//! | [`task`] | frame, COM and joint tasks, the priority stack |
//! | [`limits`] | joint limits → acceleration box (eq. 14, viable bounds) |
//! | [`solver`] | prioritized solution, IKTC, GF, clamp, the dense QP |
//! | [`balance`] | the damping controller of Section 4 |
//! | [`motion`] | motion capture readers, retargeting |
//! | `profile` | robot profiles: feet, pelvis, posture, locks of a robot (features `urdf`, `toml`) |
//! | [`walk`] | footsteps, ZMP preview control, swing feet |
//! | [`resources`] | stated maxima on what an input may make iktc allocate or run |
//! | [`sim`] | the 3R arm, the imitation, walking while imitating |
//!
//! ## Notation
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | `q` | configuration: floating-base position and unit quaternion (if any), then joint positions | m, –, rad or m |
//! | `q̇` (`qd`) | generalized velocity, length `nv`: base body twist (linear, angular, in base axes) then joint rates | m/s, rad/s |
//! | `q̈` (`qdd`) | generalized acceleration, length `nv` | m/s², rad/s² |
//! | `J_i` | Jacobian of task *i*, `m_i × nv` | – |
//! | `h_i` | right-hand side of task *i*, `ẍ_d + k_v(ẋ_d − ẋ) + k_p(x_d − x) − J̇q̇` (eqs. 3, 11) | task units / s² |
//! | `b_l, b_u` | lower and upper acceleration bounds (eq. 14) | rad/s² |
//! | `Δh_i` | correction of task *i* (eq. 19) | task units / s² |
//! | `G` | correction-to-acceleration map (eqs. 20–21, Algorithm 1) | – |
//! | `Δt` | control period | s |

#![warn(missing_docs)]

pub mod balance;
#[cfg(all(feature = "urdf", feature = "json", feature = "toml", feature = "npz"))]
pub mod batch;
pub use iktc_core::controller;
pub use iktc_core::error;
pub use iktc_core::limits;
pub mod mesh;
pub mod model;
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub mod motion;
#[cfg(feature = "npz")]
pub(crate) mod npz;
pub mod prelude;
#[cfg(all(feature = "urdf", feature = "toml"))]
pub mod profile;
pub use iktc_core::resources;
#[cfg(all(feature = "urdf", feature = "toml"))]
pub mod retarget;
pub mod sim;
pub use iktc_core::solver;
pub use iktc_core::task;
pub mod walk;

pub use controller::{Controller, ControllerBuilder};
pub use error::{Error, Result};

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeDoctests;
