//! Discrete-time-safe acceleration bounds (errata §3.1, after Del Prete, *Joint position and
//! velocity bounds in discrete-time acceleration/torque control of robot manipulators*,
//! IEEE Robotics and Automation Letters 3(1):281–288, 2018).
//!
//! All bounds are derived for the constant-acceleration integrator
//! ([`integrate_constant_acceleration`](super::integrate_constant_acceleration)):
//! `q⁺ = q + Δt q̇ + ½Δt² q̈`, `q̇⁺ = q̇ + Δt q̈`. Each source is computed separately, as in
//! TSID, and [`compute_box`](super::compute_box) intersects them and resolves conflicts.
//! Formulas are written for the upper side with `d = q_max − q` (distance to the limit) and
//! `q̇` (velocity toward it); the lower side is the mirror image
//! `b_l(q, q̇, q_min) = −b_u(−q, −q̇, −q_min)`.
//!
//! **Guarantee.** Call *viable* a state with `q_min ≤ q ≤ q_max`, `|q̇| ≤ v_max` and
//! `−√(2 a_stop (q − q_min)) ≤ q̇ ≤ √(2 a_stop (q_max − q))`. From a viable state every `q̈`
//! in the box keeps the position inside the range during the whole step (in-step peak
//! included), keeps `|q̇⁺| ≤ v_max` and leads to a viable state, because the position,
//! velocity and viability bounds are exact for the integrator. The box is then non-empty
//! without dropping any source provided the time step is fine compared with the limits
//! (property-tested for `q_max − q_min ≥ 5 a_max Δt²`, `v_max ≥ a_max Δt` and
//! `a_stop ≤ 0.95 a_max`; a random exploration found conflicts only for ranges narrower than
//! about `a_max Δt²` or `v_max` below about `a_max Δt`). At `a_stop = a_max` rounding alone
//! can make the acceleration limit conflict on the braking curve, where exactly `a_max` is
//! needed; it is then dropped. Coarser steps can make position and velocity bounds conflict;
//! that is reported, not hidden.
//!
//! **Beyond the range** (a state that is not viable, e.g. an initial posture outside a
//! narrowed range), the range is widened to the current position on that side
//! (`d = max(q_max − q, 0)`): the bounds then keep the joint from going further out and let
//! it come back, instead of demanding a return within one step.

use super::joint_limits::DofLimits;
use super::method::ViableSettings;
use super::source::{DofBoundSources, SourceBounds};
use super::velocity::{velocity_lower, velocity_upper};

/// Upper position bound including the in-step peak \[rad/s²\].
///
/// With `d = max(q_max − q, 0)`:
///
/// * end of step: `q⁺ ≤ q_max ⇔ q̈ ≤ p = 2(d − Δt q̇)/Δt²`;
/// * if `p ≥ −q̇/Δt`, every `q̈ ≤ p` either keeps `q̇(t) ≥ 0` over the step (the maximum is
///   `q⁺`) or turns round inside it at a peak `q − q̇²/(2q̈) ≤ q_max` (since then
///   `q̈ < −q̇/Δt ≤ −q̇²/(2d)`), so the bound is `p`;
/// * if `p < −q̇/Δt` (only when `q̇ > 0` and `d < q̇Δt/2`), every admissible `q̈` turns the
///   joint round inside the step and the peak decides: `q − q̇²/(2q̈) ≤ q_max ⇔
///   q̈ ≤ −q̇²/(2d)`; the bound is `min(−q̇²/(2d), −q̇/Δt)` (errata §3.1).
///
/// If `d = 0` and `q̇ > 0` (at or beyond the limit and moving out, not a viable state), no
/// `q̈` keeps the peak inside; the bound falls back to the end-of-step condition
/// `p = −2q̇/Δt` (`q⁺` back at the start, the peak `q̇Δt/4` beyond it). The same fallback is
/// used if `−q̇²/(2d)` overflows. `+inf` when `q_max = +inf`.
///
/// `q` \[rad\], `qd` \[rad/s\], `position_max` \[rad\], `dt` \[s\].
pub fn position_upper(q: f64, qd: f64, position_max: f64, dt: f64) -> f64 {
    if position_max == f64::INFINITY {
        return f64::INFINITY;
    }
    let d = (position_max - q).max(0.0);
    let end_of_step = 2.0 * (d - dt * qd) / (dt * dt);
    let stop_in_step = -qd / dt;
    if qd > 0.0 && end_of_step < stop_in_step {
        let peak = -qd * qd / (2.0 * d);
        if peak.is_finite() {
            return peak.min(stop_in_step);
        }
    }
    end_of_step
}

/// Lower position bound including the in-step peak \[rad/s²\], the mirror of
/// [`position_upper`]: `−position_upper(−q, −q̇, −q_min, Δt)`.
pub fn position_lower(q: f64, qd: f64, position_min: f64, dt: f64) -> f64 {
    -position_upper(-q, -qd, -position_min, dt)
}

/// Upper viability bound \[rad/s²\]: the next state can still stop before `q_max` braking at
/// `a_stop`.
///
/// The condition `q̇⁺ ≤ √(2 a_stop (q_max − q⁺))` matters only when `q̇⁺ ≥ 0`, where squaring
/// it and substituting the integrator gives `a q̈² + b q̈ + c ≤ 0` with
///
/// ```text
/// a = Δt²,  b = Δt (2q̇ + a_stop Δt),  c = q̇² − 2 a_stop (d − Δt q̇),
/// b² − 4ac = a_stop Δt² (a_stop Δt² + 8d − 4Δt q̇).
/// ```
///
/// The admissible set is `q̈ ≤ −q̇/Δt` (the joint is moving back at the next state) united with
/// the interval between the roots, so the bound is `max(x₊, −q̇/Δt)` with the larger root
/// `x₊ = (−b + √(b² − 4ac))/(2a)`, and `−q̇/Δt` when the discriminant is negative
/// (errata §3.1). `x₊` is evaluated without cancellation (`2c/(−b − √(b² − 4ac))` when
/// `b > 0`). On the braking curve `q̇ = √(2 a_stop d)` with `2q̇ ≥ a_stop Δt`, `x₊ = −a_stop`
/// exactly: the integrator is exact for constant braking. `d = max(q_max − q, 0)` as in
/// [`position_upper`]; `+inf` when `q_max = +inf` or `a_stop = +inf`.
///
/// `q` \[rad\], `qd` \[rad/s\], `position_max` \[rad\], `braking_acceleration` = `a_stop`
/// \[rad/s²\], `dt` \[s\].
pub fn viability_upper(
    q: f64,
    qd: f64,
    position_max: f64,
    braking_acceleration: f64,
    dt: f64,
) -> f64 {
    let a_stop = braking_acceleration;
    if position_max == f64::INFINITY || a_stop == f64::INFINITY {
        return f64::INFINITY;
    }
    let d = (position_max - q).max(0.0);
    let stop_in_step = -qd / dt;
    // Divided by Δt: b' = b/Δt, disc' = (b² − 4ac)/Δt², so x₊ = (−b' + √disc')/(2Δt).
    let b = 2.0 * qd + a_stop * dt;
    let disc = a_stop * (a_stop * dt * dt + 8.0 * d - 4.0 * dt * qd);
    if disc < 0.0 {
        return stop_in_step;
    }
    let root = disc.sqrt();
    let larger = if b > 0.0 {
        let c = qd * qd - 2.0 * a_stop * (d - dt * qd);
        -2.0 * c / (dt * (b + root))
    } else {
        (root - b) / (2.0 * dt)
    };
    larger.max(stop_in_step)
}

/// Lower viability bound \[rad/s²\], the mirror of [`viability_upper`]:
/// `−viability_upper(−q, −q̇, −q_min, a_stop, Δt)`.
pub fn viability_lower(
    q: f64,
    qd: f64,
    position_min: f64,
    braking_acceleration: f64,
    dt: f64,
) -> f64 {
    -viability_upper(-q, -qd, -position_min, braking_acceleration, dt)
}

/// All sources of the viable bounds for one dof \[rad/s²\]: acceleration `±a_max`, velocity
/// `(±v_max − q̇)/Δt`, position with in-step peak, viability with
/// `a_stop = braking_fraction · a_max`.
///
/// Inputs are not validated here; [`compute_box`](super::compute_box) does that.
/// `q` \[rad\], `qd` \[rad/s\], `dt` \[s\].
pub fn viable_sources(
    limits: &DofLimits,
    settings: &ViableSettings,
    q: f64,
    qd: f64,
    dt: f64,
) -> DofBoundSources {
    let a_max = limits.acceleration_max;
    let a_stop = settings.braking_fraction * a_max;
    DofBoundSources {
        lower: SourceBounds {
            acceleration: -a_max,
            velocity: velocity_lower(qd, limits.velocity_max, dt),
            position: position_lower(q, qd, limits.position_min, dt),
            viability: viability_lower(q, qd, limits.position_min, a_stop, dt),
        },
        upper: SourceBounds {
            acceleration: a_max,
            velocity: velocity_upper(qd, limits.velocity_max, dt),
            position: position_upper(q, qd, limits.position_max, dt),
            viability: viability_upper(q, qd, limits.position_max, a_stop, dt),
        },
    }
}
