//! Joint position, velocity and acceleration limits turned into one box on the joint
//! accelerations, `b_l ≤ q̈ ≤ b_u` (paper eqs. 13–14), for a control period `Δt`.
//!
//! Three methods, side by side ([`BoundMethod`]):
//!
//! | method | formula | discrete-time safe |
//! |---|---|---|
//! | [`BoundMethod::Paper`] | Proposition 3.1, eq. (14), as printed ([`paper`]) | no: the box can empty and the joint overshoot (errata §3.1) |
//! | [`BoundMethod::Viable`] | position with in-step peak, exact velocity, viability (discrete stopping distance) at the next state, `±a_max`; after Del Prete, IEEE RA-L 2018 ([`viable`]) | yes, from a viable state, for every `Δt` and ratio of the limits (proof in [`viable`]) |
//! | [`BoundMethod::Quiet`] | as `Viable`, with a discrete braking profile that ends at rest at a tick ([`quiet`]) | yes, from a quietly viable state; the box never empties and a joint pushed into a limit rests on it with `q̈ = 0` |
//!
//! Each source of bound (acceleration, velocity, position, viability) is computed separately,
//! as in TSID, then intersected ([`intersect`]). An optional soft approach to the range ends
//! (a critically damped wall, [`approach`]) is applied next at lower precedence, and optional
//! jerk limits last with the lowest ([`limit_jerk`], [`jerk`]). From a viable state the sources of `Viable`
//! never conflict (beyond rounding); from any other state the acceleration limit is dropped
//! first (exceeded by the least amount), then viability; position and velocity are kept, and
//! if they conflict the box is reported empty. A run checks its start state
//! ([`JointLimits::check_state`]) or, with [`OutsideLimits::Recover`], brings joints outside
//! their range back ([`BoundSource::Recovery`]). The [`AccelerationBox`] records every source value,
//! the source that binds each side and what was dropped, so the caller can see why a joint is
//! constrained.
//!
//! Data are plain and independent of the robot model: [`JointLimits`] holds one
//! [`DofLimits`] per velocity dof (`nv` entries; floating-base dofs and continuous joints have
//! infinite limits), and [`compute_box`] takes the state as slices.
//!
//! ```
//! use iktc_core::limits::{compute_box, AccelerationBox, BoundMethod, DofLimits, JointLimits};
//!
//! let joint = DofLimits {
//!     position_min: -1.0,
//!     position_max: 1.0,
//!     velocity_max: std::f64::consts::PI,
//!     acceleration_max: 10.0 * std::f64::consts::PI, jerk_max: f64::INFINITY,
//! };
//! let limits = JointLimits::new(vec![DofLimits::unlimited(), joint])?;
//! let mut bounds = AccelerationBox::new(limits.nv());
//! compute_box(&limits, &BoundMethod::default(), &[0.0, 0.95], &[0.0, 1.2], 0.005, &mut bounds)?;
//! assert!(!bounds.is_empty());
//! assert_eq!(bounds.upper[0], f64::INFINITY); // unlimited dof
//! assert!(bounds.upper[1] < 0.0); // 0.05 rad from the limit at 1.2 rad/s: must brake
//! # Ok::<(), iktc_core::Error>(())
//! ```

mod acceleration_box;
pub mod approach;
mod compute;
mod from_robot;
mod integrator;
mod intersect;
pub mod jerk;
mod joint_limits;
mod method;
mod narrow;
pub mod paper;
pub mod quiet;
mod source;
mod velocity;
pub mod viable;

pub use acceleration_box::AccelerationBox;
pub use compute::{compute_box, compute_dof};
pub use integrator::{integrate_constant_acceleration, peak_in_step, StepExtremes};
pub use intersect::{intersect, DofBounds};
pub use jerk::limit_jerk;
pub use joint_limits::{DofLimits, JointLimits};
pub use method::{BoundMethod, OutsideLimits, ViableSettings, MAX_APPROACH_STEP};
pub use narrow::NarrowedJoint;
pub use paper::paper_sources;
pub use quiet::quiet_sources;
pub use source::{BoundSource, DofBoundSources, DroppedSources, SourceBounds};
pub use velocity::{velocity_lower, velocity_upper};
pub use viable::viable_sources;

#[cfg(test)]
mod tests;
