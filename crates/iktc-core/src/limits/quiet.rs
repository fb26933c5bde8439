//! Bounds with a quiet fixed point: a joint pushed into a limit comes to rest *on* it, at a tick,
//! and stays there with `q̈ = 0`.
//!
//! **Why the viable bound chatters at rest on a limit.** The viability bound of
//! [`viable`](super::viable) keeps the next state under the continuous braking curve
//! `q̇ ≤ √(2 a_stop d)` (`d = q_max − q`). Braking along that curve at `−a_stop` reaches `q̇ = 0`
//! at `d = 0` after `q̇/a_stop` seconds, which is almost never a whole number of ticks: inside the
//! last step the velocity crosses zero and the (constant) deceleration carries on, so the joint
//! ends the step *short* of the limit, moving away from it. The tasks still push; the bounds let
//! them (the state is well inside the curve), the joint comes back, meets the curve again and
//! brakes at `−a_stop` again. The exact fixed point `(q_max, 0)` is never reached, and the
//! commanded `q̈` settles into a cycle between `−a_stop` and a positive value: in the 3R run a
//! ±900 deg/s² square wave on q1, passed on to q2 and q3 by the tasks (`a_stop` = 900 deg/s²).
//!
//! **The discrete braking profile.** This module asks instead that the next state be able to
//! stop with zero velocity *at a tick*, at or before the limit, with steps of deceleration at
//! most `a_stop`. From a velocity `q̇ = s a_stop Δt` toward the limit (`s ≥ 0`, in units of
//! one tick's braking), the shortest such stop brakes at `a_stop` for `k = ⌊s⌋` ticks and at
//! `(s − k) a_stop` for one more (front-loading the deceleration is optimal for the distance), and
//! the constant-acceleration integrator gives its distance exactly:
//!
//! ```text
//! D(s) = a_stop Δt² (k²/2 + (s − k)(k + ½)),   k = ⌊s⌋,
//! ```
//!
//! the piecewise-linear interpolation of the continuous distance `a_stop Δt² s²/2` between whole
//! ticks (it exceeds it by at most `a_stop Δt²/8`). A state is *quietly viable* when
//! `q_min ≤ q ≤ q_max`, `|q̇| ≤ v_max` and `D(q̇/(a_stop Δt)) ≤ q_max − q` toward the upper end
//! (mirrored toward the lower one).
//!
//! **The bound.** `q̈` keeps the next state quietly viable toward `q_max` iff `q̇⁺ ≤ 0` or
//! `D(s⁺) ≤ d⁺`, with `q̇⁺ = q̇ + Δt q̈ = s⁺ a_stop Δt` and
//! `d⁺ = d − Δt q̇ − ½Δt² q̈ = d − ½Δt q̇ − ½ a_stop Δt² s⁺`. Both sides are monotone in `q̈`,
//! so the set is `q̈ ≤ b` with `b` from the largest `s⁺` solving
//!
//! ```text
//! F(s⁺) = u,   F(s) = D(s)/(a_stop Δt²) + s/2 = k(k+1)/2 + (k+1)(s − k),
//! u = (d − ½ Δt q̇)/(a_stop Δt²).
//! ```
//!
//! `F` is piecewise linear with slope `k + 1` on `[k, k+1]` and equals the triangular number
//! `k(k+1)/2` at whole `s = k`, so for `u ≥ 0`
//!
//! ```text
//! k = ⌊(√(1 + 8u) − 1)/2⌋,   s⁺ = k + (u − k(k+1)/2)/(k+1),   b = a_stop s⁺ − q̇/Δt,
//! ```
//!
//! and for `u < 0` (only beyond the braking profile, not a quietly viable state) no `s⁺ ≥ 0`
//! fits and `b = −q̇/Δt` (stop within the step; the position bound then decides the peak).
//!
//! **Fixed point.** At `q = q_max`, `q̇ = 0`: `u = 0`, `k = 0`, `s⁺ = 0`, `b = 0` exactly, and
//! `q̈ = 0` keeps the state. **Exact arrival.** On the profile, `q̇ = s a_stop Δt` and
//! `d = D(s)`, one finds `u = F(s − 1)` (`D(s) − D(s − 1) = a_stop Δt² (s − ½)` for `s ≥ 1`),
//! so `b = −a_stop`: braking at `b` keeps the joint on the profile; for `s < 1`, `u = 0` and
//! `b = −q̇/Δt`, which lands on `(q_max, 0)` at the end of the step. A joint pushed into the
//! limit (`q̈ = b` whenever the tasks ask for more) thus lands on the profile in one step (if
//! `±a_max` and `v_max` allow), follows it for `⌈s⌉` ticks and rests on the limit, at most
//! `⌈v_max/(a_stop Δt)⌉ + 1` ticks after the profile first binds.
//!
//! **Safety and a box that never empties.** From a quietly viable state with `|q̇| ≤ v_max`,
//! `q̈ = −q̇/Δt` satisfies every source: position (`d ≥ ½ Δt q̇` is implied by `u ≥ 0`, and
//! the velocity does not change sign inside the step), velocity, and this bound (`s⁺ ≥ 0`);
//! the same holds for the lower side. Every upper source is ≥ `−q̇/Δt` and every lower one
//! ≤ `−q̇/Δt`, and on this set every upper source is also ≥ `−a_stop ≥ −a_max` (mirrored
//! below), so the box, `±a_max` included, is never empty, whatever the range and `Δt`; every
//! `q̈` in it leads to a quietly viable state (the position, velocity and this bound are exact
//! for the integrator), in-step peak included. The price: the joint starts braking up to
//! `a_stop Δt²/8` earlier than on the continuous curve.

use super::joint_limits::DofLimits;
use super::method::ViableSettings;
use super::source::DofBoundSources;
use super::viable::viable_sources;

/// The shortest distance in which a joint moving toward a limit at `q̇ ≥ 0` \[rad/s\] comes to
/// rest at a tick, braking at most `a_stop` \[rad/s²\] per step of `Δt` \[s\]:
/// `D(s) = a_stop Δt² (k²/2 + (s − k)(k + ½))` with `s = q̇/(a_stop Δt)`, `k = ⌊s⌋`
/// (module docs) \[rad\]. 0 for `q̇ ≤ 0`.
pub fn quiet_stopping_distance(qd: f64, braking_acceleration: f64, dt: f64) -> f64 {
    if qd <= 0.0 {
        return 0.0;
    }
    let s = qd / (braking_acceleration * dt);
    let k = s.floor();
    braking_acceleration * dt * dt * (0.5 * k * k + (s - k) * (k + 0.5))
}

/// Upper quiet-viability bound \[rad/s²\]: the largest `q̈` after which the joint can still
/// come to rest at a tick at or before `q_max`, braking at most `a_stop` per step
/// (`b = a_stop s⁺ − q̇/Δt`, module docs). `d = max(q_max − q, 0)` as in
/// [`position_upper`](super::viable::position_upper); `+inf` when `q_max = +inf` or
/// `a_stop = +inf`.
///
/// `q` \[rad\], `qd` \[rad/s\], `position_max` \[rad\], `braking_acceleration` = `a_stop`
/// \[rad/s²\], `dt` \[s\].
pub fn quiet_viability_upper(
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
    let u = (d - 0.5 * dt * qd) / (a_stop * dt * dt);
    // u < 0 (or NaN from an infinite distance and speed): no s⁺ ≥ 0 fits.
    if u.is_nan() || u < 0.0 {
        return stop_in_step;
    }
    if u == f64::INFINITY {
        return f64::INFINITY;
    }
    // k(k+1)/2 ≤ u < (k+1)(k+2)/2; the square root may round k one off either way.
    let mut k = (((1.0 + 8.0 * u).sqrt() - 1.0) * 0.5).floor().max(0.0);
    if 0.5 * k * (k + 1.0) > u {
        k -= 1.0;
    } else if 0.5 * (k + 1.0) * (k + 2.0) <= u {
        k += 1.0;
    }
    let s = k + (u - 0.5 * k * (k + 1.0)) / (k + 1.0);
    (a_stop * s + stop_in_step).max(stop_in_step)
}

/// Lower quiet-viability bound \[rad/s²\], the mirror of [`quiet_viability_upper`]:
/// `−quiet_viability_upper(−q, −q̇, −q_min, a_stop, Δt)`.
pub fn quiet_viability_lower(
    q: f64,
    qd: f64,
    position_min: f64,
    braking_acceleration: f64,
    dt: f64,
) -> f64 {
    -quiet_viability_upper(-q, -qd, -position_min, braking_acceleration, dt)
}

/// All sources of the quiet bounds for one dof \[rad/s²\]: those of
/// [`viable_sources`] (acceleration `±a_max`, velocity `(±v_max − q̇)/Δt`, position with in-step
/// peak) with the quiet viability bound, `a_stop = braking_fraction · a_max`, in the viability
/// slot.
///
/// Inputs are not validated here; [`compute_box`](super::compute_box) does that.
/// `q` \[rad\], `qd` \[rad/s\], `dt` \[s\].
pub fn quiet_sources(
    limits: &DofLimits,
    settings: &ViableSettings,
    q: f64,
    qd: f64,
    dt: f64,
) -> DofBoundSources {
    let a_stop = settings.braking_fraction * limits.acceleration_max;
    let mut sources = viable_sources(limits, settings, q, qd, dt);
    sources.lower.viability = quiet_viability_lower(q, qd, limits.position_min, a_stop, dt);
    sources.upper.viability = quiet_viability_upper(q, qd, limits.position_max, a_stop, dt);
    sources
}

#[cfg(test)]
mod tests {
    use super::{quiet_stopping_distance, quiet_viability_upper};
    use crate::limits::integrate_constant_acceleration;

    const DT: f64 = 0.005;
    const A: f64 = 15.0;

    /// The lower side mirrors the upper one, and the sources are the viable ones with the
    /// quiet bound, at `a_stop = braking_fraction · a_max`, in the viability slot.
    #[test]
    fn the_lower_side_mirrors_and_the_sources_hold_the_quiet_bound() {
        use super::{quiet_sources, quiet_viability_lower};
        use crate::limits::{viable_sources, DofLimits, OutsideLimits, ViableSettings};
        for (q, qd) in [(0.3, 0.4), (-0.45, -0.9), (0.0, 0.0), (0.49, 0.05)] {
            let up = quiet_viability_upper(-q, -qd, 0.5, A, DT);
            assert_eq!(quiet_viability_lower(q, qd, -0.5, A, DT), -up);
        }
        let lim = DofLimits {
            position_min: -0.5,
            position_max: 0.5,
            velocity_max: 2.0,
            acceleration_max: 40.0,
            jerk_max: f64::INFINITY,
        };
        let settings = ViableSettings {
            braking_fraction: 0.25,
            outside: OutsideLimits::Error,
            approach_rate: 0.0,
        };
        let (q, qd) = (0.45, 0.6);
        let s = quiet_sources(&lim, &settings, q, qd, DT);
        let v = viable_sources(&lim, &settings, q, qd, DT);
        assert_eq!(
            s.upper.viability,
            quiet_viability_upper(q, qd, 0.5, 10.0, DT)
        );
        assert_eq!(
            s.lower.viability,
            quiet_viability_lower(q, qd, -0.5, 10.0, DT)
        );
        assert_ne!(s.upper.viability, v.upper.viability);
        assert_eq!(
            (s.upper.position, s.upper.velocity),
            (v.upper.position, v.upper.velocity)
        );
        assert_eq!(
            (s.lower.position, s.lower.velocity),
            (v.lower.position, v.lower.velocity)
        );
        assert_eq!((s.lower.acceleration, s.upper.acceleration), (-40.0, 40.0));
    }

    /// No range end or no acceleration limit: the viability source does not bound (each on
    /// its own).
    #[test]
    fn without_a_range_end_or_an_acceleration_limit_it_is_unbounded() {
        assert_eq!(
            quiet_viability_upper(0.0, 0.5, f64::INFINITY, A, DT),
            f64::INFINITY
        );
        assert_eq!(
            quiet_viability_upper(0.0, 0.5, 1.0, f64::INFINITY, DT),
            f64::INFINITY
        );
    }

    #[test]
    fn rest_on_the_limit_is_a_fixed_point() {
        assert_eq!(quiet_viability_upper(1.0, 0.0, 1.0, A, DT), 0.0);
        // Beyond the limit at rest: d = 0, the same.
        assert_eq!(quiet_viability_upper(1.0 + 1e-12, 0.0, 1.0, A, DT), 0.0);
    }

    #[test]
    fn stopping_distance_interpolates_the_continuous_one_at_whole_ticks() {
        for k in 0..20 {
            let v = k as f64 * A * DT;
            let continuous = v * v / (2.0 * A);
            assert!((quiet_stopping_distance(v, A, DT) - continuous).abs() < 1e-15);
        }
        // Between whole ticks it is above the continuous distance by at most a Δt²/8.
        for i in 0..1000 {
            let v = i as f64 * 0.0137 * A * DT;
            let gap = quiet_stopping_distance(v, A, DT) - v * v / (2.0 * A);
            assert!(
                (-1e-15..=A * DT * DT / 8.0 + 1e-15).contains(&gap),
                "{v}: {gap}"
            );
        }
    }

    /// Braking at the bound from a state on the profile follows the profile: −a_stop for
    /// ⌊s⌋ ticks, then the rest, and lands exactly (to rounding) on the limit at rest.
    #[test]
    fn braking_on_the_profile_lands_on_the_limit() {
        for s0 in [0.3, 1.0, 2.5, 7.9, 12.0] {
            let v0 = s0 * A * DT;
            let (mut q, mut v) = (1.0 - quiet_stopping_distance(v0, A, DT), v0);
            let mut ticks = 0;
            while v > 1e-12 && ticks < 100 {
                let b = quiet_viability_upper(q, v, 1.0, A, DT);
                if v >= A * DT * (1.0 + 1e-9) {
                    assert!((b + A).abs() < 1e-6, "s0 {s0}: {b}");
                }
                (q, v) = integrate_constant_acceleration(q, v, b, DT);
                ticks += 1;
            }
            assert_eq!(ticks, s0.ceil() as usize, "s0 {s0}");
            assert!(
                (q - 1.0).abs() < 1e-12 && v.abs() < 1e-9,
                "s0 {s0}: {q} {v}"
            );
        }
    }
}
