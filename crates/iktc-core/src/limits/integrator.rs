//! The integrator that the acceleration bounds assume, and the extremes of a step.
//!
//! The bounds of this module are exact only for *this* integrator (errata §2.1): the
//! acceleration `q̈` is held constant over the control period `Δt`, so that inside the step
//!
//! ```text
//! q(t) = q + t q̇ + ½ t² q̈,   q̇(t) = q̇ + t q̈,   0 ≤ t ≤ Δt.
//! ```

/// One step of the constant-acceleration integrator, returns `(q⁺, q̇⁺)`:
///
/// ```text
/// q⁺ = q + Δt q̇ + ½ Δt² q̈,   q̇⁺ = q̇ + Δt q̈
/// ```
///
/// `q` \[rad\] or \[m\], `qd` \[rad/s\], `qdd` \[rad/s²\], `dt` = `Δt` \[s\]. This is the integrator
/// every bound of [`compute_box`](super::compute_box) is derived for (errata §2.1 and §3.1);
/// the exact solution of `q̈ = const` over the step.
pub fn integrate_constant_acceleration(q: f64, qd: f64, qdd: f64, dt: f64) -> (f64, f64) {
    (q + dt * qd + 0.5 * dt * dt * qdd, qd + dt * qdd)
}

/// The smallest and largest position reached during one step \[rad\] or \[m\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepExtremes {
    /// The smallest position over `t ∈ [0, Δt]`.
    pub min: f64,
    /// The largest position over `t ∈ [0, Δt]`.
    pub max: f64,
}

/// The extreme positions reached inside one step of the constant-acceleration integrator
/// (the *in-step peak*).
///
/// `q(t) = q + t q̇ + ½ t² q̈` is a parabola: its extremes over `[0, Δt]` are among the two
/// end points and, when the velocity changes sign inside the step (`0 < t* = −q̇/q̈ < Δt`),
/// the turning point `q(t*) = q − q̇²/(2 q̈)`. A bound that only checks `q⁺` misses that
/// turning point; see [`viable`](super::viable) for the bound that does not.
///
/// `q` \[rad\] or \[m\], `qd` \[rad/s\], `qdd` \[rad/s²\], `dt` \[s\]. With a non-positive or
/// non-finite `dt` the result is not meaningful (no panic).
pub fn peak_in_step(q: f64, qd: f64, qdd: f64, dt: f64) -> StepExtremes {
    let (end, _) = integrate_constant_acceleration(q, qd, qdd, dt);
    let mut min = q.min(end);
    let mut max = q.max(end);
    // The velocity qd + t qdd vanishes inside the step only if qd and qdd have opposite
    // signs and |qd| < dt |qdd|; written without a division so that qdd = 0 needs no case.
    if qd * qdd < 0.0 && qd.abs() < dt * qdd.abs() {
        let turn = q - qd * qd / (2.0 * qdd);
        min = min.min(turn);
        max = max.max(turn);
    }
    StepExtremes { min, max }
}
