//! Walking-pattern generation: footstep plans, the support-phase timeline, the ZMP reference,
//! the COM by ZMP preview control on the cart-table model, and swing-foot trajectories.
//!
//! The output is plain data, independent of any robot model: poses, velocities and
//! accelerations of both feet (sole-centre frames), of the COM and the ZMP, in world axes,
//! at any time. The parts:
//!
//! * [`settings`]: [`WalkSettings`] (durations, foot separation, swing height, sole size) and
//!   [`Side`];
//! * [`footstep`]: [`Footstep`] and [`FootstepPlan`] (in place, forward, turn, along a root
//!   trajectory);
//! * [`timeline`]: the SSP/DSP [`Timeline`] and the ZMP reference on it;
//! * [`polygon`]: support polygons without allocation;
//! * [`dare`]: the discrete algebraic Riccati equation by the doubling algorithm;
//! * [`preview`]: the cart-table model and the optimal preview servo (Kajita et al. 2003);
//! * [`swing`]: foot trajectories (quintic horizontal, sextic vertical);
//! * [`multibody`]: the ZMP of a sampled multibody motion (the links, not the cart-table);
//! * [`pattern`]: [`WalkingPattern`], all of it precomputed for a plan, queried per tick.
//!
//! Conventions: world frame with `z` up and the ground at `z = 0`; a foot's frame is the centre
//! of its sole, its `x` axis pointing forward, roll and pitch zero (use [`FootState::offset`]
//! for the ankle or another point of the foot); the COM moves at the constant height
//! [`PreviewSettings::com_height`]; time starts at 0 with both feet down and the COM at rest
//! over the midpoint between the feet.
//!
//! ```
//! use iktc::walk::{FootstepPlan, PreviewSettings, WalkSettings, WalkingPattern};
//!
//! let walk = WalkSettings::default();
//! let plan = FootstepPlan::forward(4, 0.2, &walk)?;
//! let pattern = WalkingPattern::new(&plan, &walk, &PreviewSettings::default())?;
//! let s = pattern.sample(0.5 * pattern.duration())?;
//! assert!(s.com.position.x > 0.0);
//! # Ok::<(), iktc::Error>(())
//! ```

pub mod dare;
pub mod footstep;
pub mod multibody;
pub mod pattern;
pub mod polygon;
pub mod preview;
pub mod settings;
pub mod swing;
pub mod timeline;

pub use dare::{dare_residual, solve_dare, DareSettings, DareSolution, DareStatus};
pub use footstep::{Footstep, FootstepPlan, Pose2, RootPlanParams, RootSample};
pub use multibody::{configuration_zmp, link_masses, multibody_zmp, BodyMass};
pub use pattern::{ComState, WalkSample, WalkingPattern, MAX_PATTERN_SAMPLES};
pub use polygon::{sole_corners, PolygonEdge, SupportPolygon, MAX_POLYGON_VERTICES, MAX_SOLES};
pub use preview::{
    CartSample, CartTable, PreviewAxis, PreviewController, PreviewSettings, MAX_PREVIEW_SAMPLES,
};
pub use settings::{Side, WalkSettings};
pub use swing::{foot_state, swing_height_profile, FootState};
pub use timeline::{smoothstep, Phase, PhaseInterval, Timeline};
