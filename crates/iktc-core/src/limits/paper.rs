//! Proposition 3.1, eq. (14) of Kim & Oh, exactly as printed.
//!
//! ```text
//! b_u = min( a_max, (v_max − q̇)/Δt, (√(2 a_max (q_max − q)) − q̇)/Δt )
//! b_l = max(−a_max, (−v_max − q̇)/Δt, (−√(2 a_max (q − q_min)) − q̇)/Δt )
//! ```
//!
//! The third term asks that the *next* velocity lie under the braking curve
//! `q̇⁺ ≤ √(2 a_max (q_max − q))` (eq. 15), but evaluates the curve at the *current*
//! position. One step after the term first binds, the joint has moved closer and needs more
//! than `a_max` to get back under the curve: the box empties (`b_u < b_l`) and the joint
//! overshoots its range (errata §3.1). This module keeps the formula as printed so that the
//! failure can be seen; [`viable`](super::viable) is the remedy.
//!
//! **Beyond the range** (`q > q_max`), the printed square root has a negative argument and is
//! undefined. We take the square root of a negative argument as 0, i.e. the term becomes
//! `−q̇/Δt`: "stop moving further out within this step". This equals evaluating the term with
//! the range widened to the current position and does not pull the joint back in.

use super::joint_limits::DofLimits;
use super::source::{DofBoundSources, SourceBounds};
use super::velocity::{velocity_lower, velocity_upper};

/// The third term of eq. (14), upper side \[rad/s²\]:
/// `(√(2 a_max max(q_max − q, 0)) − q̇)/Δt`.
///
/// `+inf` when `q_max = +inf`, or when `a_max = +inf` and `q < q_max`. At or beyond the limit
/// the square root is taken as 0 (see the module documentation).
///
/// `q` \[rad\], `qd` \[rad/s\], `position_max` = `q_max` \[rad\], `acceleration_max` = `a_max`
/// \[rad/s²\], `dt` \[s\].
pub fn position_term_upper(
    q: f64,
    qd: f64,
    position_max: f64,
    acceleration_max: f64,
    dt: f64,
) -> f64 {
    if position_max == f64::INFINITY {
        return f64::INFINITY;
    }
    let distance = position_max - q;
    let braking_speed = if distance > 0.0 {
        (2.0 * acceleration_max * distance).sqrt()
    } else {
        0.0
    };
    if braking_speed == f64::INFINITY {
        f64::INFINITY
    } else {
        (braking_speed - qd) / dt
    }
}

/// The third term of eq. (14), lower side \[rad/s²\]:
/// `(−√(2 a_max max(q − q_min, 0)) − q̇)/Δt`, the mirror of [`position_term_upper`].
pub fn position_term_lower(
    q: f64,
    qd: f64,
    position_min: f64,
    acceleration_max: f64,
    dt: f64,
) -> f64 {
    -position_term_upper(-q, -qd, -position_min, acceleration_max, dt)
}

/// All sources of eq. (14) for one dof \[rad/s²\]: acceleration `±a_max`, velocity
/// `(±v_max − q̇)/Δt` and the position term; no viability source (infinite).
///
/// Inputs are not validated here; [`compute_box`](super::compute_box) does that.
/// `q` \[rad\], `qd` \[rad/s\], `dt` \[s\].
pub fn paper_sources(limits: &DofLimits, q: f64, qd: f64, dt: f64) -> DofBoundSources {
    let a_max = limits.acceleration_max;
    DofBoundSources {
        lower: SourceBounds {
            acceleration: -a_max,
            velocity: velocity_lower(qd, limits.velocity_max, dt),
            position: position_term_lower(q, qd, limits.position_min, a_max, dt),
            viability: f64::NEG_INFINITY,
            jerk: f64::NEG_INFINITY,
            approach: f64::NEG_INFINITY,
        },
        upper: SourceBounds {
            acceleration: a_max,
            velocity: velocity_upper(qd, limits.velocity_max, dt),
            position: position_term_upper(q, qd, limits.position_max, a_max, dt),
            viability: f64::INFINITY,
            jerk: f64::INFINITY,
            approach: f64::INFINITY,
        },
    }
}
