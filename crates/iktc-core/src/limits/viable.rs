//! Discrete-time-safe acceleration bounds (errata §3.1, after Del Prete, *Joint position and
//! velocity bounds in discrete-time acceleration/torque control of robot manipulators*,
//! IEEE Robotics and Automation Letters 3(1):281–288, 2018). The viability condition is the
//! continuous braking curve of errata §3.1 where that curve is invariant in discrete time
//! (`a_stop Δt ≤ v_max` and `a_stop Δt² ≤ q_max − q_min`, [`braking_curve_is_invariant`]),
//! and the *discrete* stopping distance elsewhere, so that the viable set is invariant for
//! every control period and every acceleration limit.
//!
//! All bounds are derived for the constant-acceleration integrator
//! ([`integrate_constant_acceleration`](super::integrate_constant_acceleration)):
//! `q⁺ = q + Δt q̇ + ½Δt² q̈`, `q̇⁺ = q̇ + Δt q̈`. Each source is computed separately, as in
//! TSID, and [`compute_box`](super::compute_box) intersects them and resolves conflicts.
//! Formulas are written for the upper side with `d = q_max − q` (distance to the limit) and
//! `q̇` (velocity toward it); the lower side is the mirror image
//! `b_l(q, q̇, q_min) = −b_u(−q, −q̇, −q_min)`.
//!
//! # The discrete stopping distance
//!
//! Braking at `a = a_stop` (`a_stop = braking_fraction · a_max ≤ a_max`) *without reversing*:
//! from `v > 0`, apply `q̈ = −a` while `v ≥ aΔt`, then one last step `q̈ = −v/Δt` that ends at
//! rest. Every acceleration of this policy has `|q̈| ≤ a`, `|q̇|` only decreases and the
//! position only increases, ending at rest after the distance
//!
//! ```text
//! D(v) = vΔt (n + ½) − aΔt² n(n+1)/2,   n = ⌊v/(aΔt)⌋,   D(v) = 0 for v ≤ 0,
//! ```
//!
//! (`n` full braking steps cover `(v² − r²)/(2a)`, the last one `rΔt/2`, `r = v − naΔt`).
//! `D` is the piecewise-linear interpolant of the continuous braking distance `v²/(2a)` at the
//! knots `v = kaΔt`, so `v²/(2a) ≤ D(v) ≤ v²/(2a) + aΔt²/8`; it is continuous, increasing and
//! convex. With `a = +inf` (no acceleration limit) `D(v) = vΔt/2`: stop in one step.
//!
//! # The viable set and its invariance
//!
//! Call a state `(q, q̇)` of one dof *viable* when
//!
//! 1. `q_min ≤ q ≤ q_max`, 2. `|q̇| ≤ v_max`,
//! 3. `S(q̇) ≤ q_max − q` (it can stop before `q_max`), 4. `S(−q̇) ≤ q − q_min`,
//!
//! with the stopping distance `S(v) = v²/(2 a_stop)` (`v > 0`) in the *braking-curve regime*
//! `a_stop Δt ≤ v_max`, `a_stop Δt² ≤ q_max − q_min`, and `S = D` otherwise.
//!
//! **Theorem.** For every `Δt > 0`, `0 < a_max ≤ +inf`, `0 < v_max ≤ +inf`, `q_min ≤ q_max`
//! (a zero-width or half-infinite range included) and `a_stop ∈ (0, a_max]`, from a viable state
//! (i) every `q̈` in the box keeps the position in range over the whole step (in-step peak
//! included), keeps `|q̇⁺| ≤ v_max` and `|q̈| ≤ a_max`, and leads to a viable state, and
//! (ii) the box is not empty, without dropping any source.
//!
//! *Proof of (i).* Each source is exactly the set of `q̈` satisfying its condition (up to the
//! open end noted at `−q̇/Δt`, which the position bound closes): the acceleration source is
//! `|q̈| ≤ a_max`; the velocity source `|q̇ + Δt q̈| ≤ v_max` (the velocity is linear in time,
//! so the end of step decides); [`position_upper`] is `max_{t∈[0,Δt]} q(t) ≤ q_max` (proof
//! in its docs); [`viability_upper`] is condition 3 at the next state. The intersection gives
//! conditions 1–4 at the next state and the limits during the step.
//!
//! *Proof of (ii).* Take the braking acceleration `q̈* = −sign(q̇) min(a_stop, |q̇|/Δt)`
//! (`0` at rest). Say `q̇ > 0` (the other sign is the mirror). `|q̈*| ≤ a_stop ≤ a_max`;
//! `0 ≤ q̇⁺ ≤ q̇ ≤ v_max`; the velocity does not change sign, so the peak is `q⁺`, and
//! `q⁺ − q = q̇Δt − ½min(aΔt², q̇Δt) ≤ D(q̇) ≤ d` (the first step of the policy); `q⁺ ≥ q`
//! keeps the lower side; condition 4 holds at the next state because `q̇⁺ ≥ 0`; condition 3
//! holds because `D(q̇⁺) = D(q̇) − (q⁺ − q) ≤ d − (q⁺ − q) = q_max − q⁺` (the policy
//! continued). So `q̈*` lies in every source. At rest `q̈* = 0` lies in every source as well
//! (`D(0) = 0`). This is the proof for `S = D`.
//!
//! *Proof of (ii) in the braking-curve regime* (`S(v) = v²/(2a)`, `a = a_stop`; `q̇ > 0`):
//! (a) `q̇ ≥ aΔt`: `q̈ = −a` is exact braking, `q̇⁺ = q̇ − aΔt ≥ 0` and
//! `q̇⁺² = q̇² − 2a(q⁺ − q) ≤ 2a(q_max − q⁺)`; no reversal, as above. (b) `q̇ < aΔt`,
//! `d ≥ q̇Δt/2`: `q̈ = −q̇/Δt` stops inside. (c) `q̇ < aΔt`, `d < q̇Δt/2`: `q̈ = −q̇²/(2d)`,
//! in `[−a, −q̇/Δt)` because `q̇² ≤ 2ad`, turns round with its peak on `q_max` and ends with
//! `q̇⁺ = −w`, `w = |q̈|Δt − q̇ < aΔt ≤ v_max` (velocity source kept) at
//! `q⁺ = q_max − w²/(2|q̈|)`; condition 4 there, `w² ≤ 2a(q⁺ − q_min)`, follows from
//! `w² (1 + a/|q̈|) < a²Δt² + a|q̈|Δt² ≤ 2a²Δt² ≤ 2a(q_max − q_min)`, and `q⁺ > q_min` likewise.
//! Outside this regime step (c) can fail: with `v_max < a_stop Δt` the turn breaks the velocity
//! limit (the box `[(−v_max − q̇)/Δt, −a_stop]` is empty), with a range below `a_stop Δt²` the
//! reversed velocity cannot stop before the other end. ∎
//!
//! No ratio of the limits matters: a range narrower than `a_max Δt²`, `v_max < a_max Δt`, a
//! zero-width range (its only viable state is at rest on it, and its box is `{0}`: the joint is
//! held, as if locked; [`compute_box`](super::compute_box) then gives `{−q̇/Δt}`, which is the
//! same at rest and keeps a solver's tolerance from building up into an oscillation) and any
//! `Δt` are covered, so no control period needs to be refused.
//! The braking curve is kept where it is invariant because it brakes later than `D`
//! (by up to `a_stop Δt²/8` of distance): the motions of the default runs do not change.
//!
//! **Assumptions.** The state evolves by the integrator above with the `q̈` applied exactly in
//! the box (a solver's tolerance or rounding can leave the viable set by that much; see
//! below); `a_stop ≤ a_max`. With `a_stop = a_max`, `q̈* = −a_max` sits on the acceleration
//! limit and rounding alone can put the viability bound below `−a_max`: positions carry an
//! absolute error of a few ulps of `|q|`, which the bounds divide by `Δt²/2`, so by about
//! `2ε(1 + |q|)/Δt²` (`ε` = 2.2e-16; 1e-7 rad/s² at `Δt` = 0.1 ms). The conflict
//! resolution then exceeds the acceleration limit by that amount and reports it in
//! [`DroppedSources`](super::DroppedSources); with `a_stop < a_max` there is slack.
//!
//! **Beyond the range** (a state that is not viable, e.g. an initial posture outside a
//! narrowed range), the range is widened to the current position on that side
//! (`d = max(q_max − q, 0)`): the bounds then keep the joint from going further out and let
//! it come back, instead of demanding a return within one step. Such a state is refused at
//! the start of a run by default ([`JointLimits::check_state`](super::JointLimits::check_state));
//! with [`OutsideLimits::Recover`](super::OutsideLimits) the joint is driven back by
//! [`recovery_acceleration`].

use super::joint_limits::DofLimits;
use super::method::ViableSettings;
use super::source::{DofBoundSources, SourceBounds};
use super::velocity::{velocity_lower, velocity_upper};

/// Upper position bound including the in-step peak \[rad/s²\]: exactly the set of `q̈` with
/// `q(t) ≤ q_max` for all `t ∈ [0, Δt]`.
///
/// With `d = max(q_max − q, 0)` and the end-of-step bound `p = 2(d − Δt q̇)/Δt²`
/// (`q⁺ ≤ q_max ⇔ q̈ ≤ p`):
///
/// * if `q̇ ≤ 0` or `p ≥ −q̇/Δt`, the bound is `p`: a `q̈ ≥ −q̇/Δt` keeps `q̇(t) ≥ 0` over the
///   step (the maximum is `q⁺`); a `q̈ < −q̇/Δt` turns round inside the step at the peak
///   `q + q̇²/(2|q̈|)`, which is `≤ q_max` because `p ≥ −q̇/Δt ⇔ d ≥ q̇Δt/2 ⇔
///   −q̇²/(2d) ≥ −q̇/Δt > q̈` (and for `q̇ ≤ 0` the maximum is `max(q, q⁺)`);
/// * if `q̇ > 0` and `p < −q̇/Δt` (the joint cannot keep moving out for the whole step:
///   `d < q̇Δt/2`), no `q̈ ≥ −q̇/Δt` is admissible and the peak decides:
///   `q + q̇²/(2|q̈|) ≤ q_max ⇔ q̈ ≤ −q̇²/(2d)`, which is below `−q̇/Δt` there (errata §3.1
///   writes `min(−q̇²/(2d), −q̇/Δt)`; the minimum is always the first term).
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
    if qd > 0.0 && end_of_step < -qd / dt {
        let peak = -qd * qd / (2.0 * d);
        if peak.is_finite() {
            return peak;
        }
    }
    end_of_step
}

/// Lower position bound including the in-step peak \[rad/s²\], the mirror of
/// [`position_upper`]: `−position_upper(−q, −q̇, −q_min, Δt)`.
pub fn position_lower(q: f64, qd: f64, position_min: f64, dt: f64) -> f64 {
    -position_upper(-q, -qd, -position_min, dt)
}

/// The discrete stopping distance `D(v)` \[rad\] of the module documentation: the distance
/// covered by braking from `v` \[rad/s\] at `a` = `braking_acceleration` \[rad/s²\] without
/// reversing, the last step ending at rest, over steps of `dt` \[s\]:
/// `D(v) = vΔt(n + ½) − aΔt² n(n+1)/2`, `n = ⌊v/(aΔt)⌋`; `0` for `v ≤ 0`; `vΔt/2` for
/// `a = +inf`.
pub fn stopping_distance(v: f64, braking_acceleration: f64, dt: f64) -> f64 {
    if v <= 0.0 {
        return 0.0;
    }
    let a = braking_acceleration;
    if a == f64::INFINITY {
        return 0.5 * v * dt;
    }
    let n = (v / (a * dt)).floor();
    v * dt * (n + 0.5) - 0.5 * a * dt * dt * n * (n + 1.0)
}

/// Upper viability bound on the continuous braking curve \[rad/s²\]: the next state can
/// still stop before `q_max` braking at `a_stop`, `q̇⁺ ≤ √(2 a_stop (q_max − q⁺))` (errata
/// §3.1); used where the braking curve is invariant ([`braking_curve_is_invariant`]).
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

/// Upper viability bound without reversal \[rad/s²\]: the next state can still stop before
/// `q_max` braking at `a_stop` without reversing, `D(q̇⁺) ≤ q_max − q⁺` (condition 3 of the
/// module documentation, for the discrete stopping distance).
///
/// With `v = q̇⁺ = q̇ + Δt q̈ ≥ 0` the next distance is `q_max − q⁺ = R − vΔt/2`, where
/// `R = d − Δt q̇/2`, so the condition reads `h(v) = D(v) + vΔt/2 ≤ R`. `h` is convex and
/// piecewise linear with knots `h(kaΔt) = aΔt² k(k+1)/2`; on its piece `n`,
/// `h(v) = vΔt(n+1) − aΔt² n(n+1)/2`, and `h` is the maximum of these lines. Hence the largest
/// admissible next velocity is
///
/// ```text
/// v* = min_n (R + aΔt² n(n+1)/2) / (Δt (n+1)),
/// ```
///
/// attained on the piece that contains it, `n = k = ⌊(√(1 + 8R/(aΔt²)) − 1)/2⌋` (the lines of
/// `k − 1`, `k`, `k + 1` are evaluated, which absorbs the rounding of the square root), and the
/// bound is `(v* − q̇)/Δt`. If `R < 0` no `v ≥ 0` is admissible and the bound is `−q̇/Δt` (the
/// joint moves back at the next state; the position bound is the tighter one there). A
/// `q̈` with `q̇⁺ < 0` always satisfies the condition. `d = max(q_max − q, 0)` as in
/// [`position_upper`]; `+inf` when `q_max = +inf`; with `a_stop = +inf`, `v* = R/Δt` (stop
/// in one step).
///
/// `q` \[rad\], `qd` \[rad/s\], `position_max` \[rad\], `braking_acceleration` = `a_stop`
/// \[rad/s²\], `dt` \[s\].
pub fn no_reversal_viability_upper(
    q: f64,
    qd: f64,
    position_max: f64,
    braking_acceleration: f64,
    dt: f64,
) -> f64 {
    if position_max == f64::INFINITY {
        return f64::INFINITY;
    }
    let d = (position_max - q).max(0.0);
    let room = d - 0.5 * dt * qd;
    if room < 0.0 {
        return -qd / dt;
    }
    let v_star = largest_next_velocity(room, braking_acceleration, dt);
    (v_star - qd) / dt
}

/// `v* = min_n (R + aΔt² n(n+1)/2)/(Δt(n+1))` of [`no_reversal_viability_upper`] for
/// `R ≥ 0` \[rad/s\].
fn largest_next_velocity(room: f64, a: f64, dt: f64) -> f64 {
    let step = a * dt * dt;
    if step == f64::INFINITY {
        // No acceleration limit (or aΔt² beyond the floating-point range): stop in one step.
        return room / dt;
    }
    let k = ((1.0 + 8.0 * room / step).sqrt() - 1.0) * 0.5;
    let k = k.floor().max(0.0);
    let line = |n: f64| (room + 0.5 * step * n * (n + 1.0)) / (dt * (n + 1.0));
    let mut best = line(k).min(line(k + 1.0));
    if k >= 1.0 {
        best = best.min(line(k - 1.0));
    }
    best
}

/// Lower viability bound without reversal \[rad/s²\], the mirror of
/// [`no_reversal_viability_upper`].
pub fn no_reversal_viability_lower(
    q: f64,
    qd: f64,
    position_min: f64,
    braking_acceleration: f64,
    dt: f64,
) -> f64 {
    -no_reversal_viability_upper(-q, -qd, -position_min, braking_acceleration, dt)
}

/// Whether the continuous braking curve `|q̇| ≤ √(2 a_stop d)` is invariant for these limits:
/// `a_stop Δt ≤ v_max` and `a_stop Δt² ≤ q_max − q_min` (the regime of the module
/// documentation's second theorem). Otherwise the viability bounds use the discrete stopping
/// distance ([`no_reversal_viability_upper`]), invariant for every `Δt`.
///
/// `braking_acceleration` = `a_stop` \[rad/s²\], `dt` \[s\].
pub fn braking_curve_is_invariant(limits: &DofLimits, braking_acceleration: f64, dt: f64) -> bool {
    let a = braking_acceleration;
    a * dt <= limits.velocity_max && a * dt * dt <= limits.position_max - limits.position_min
}

/// All sources of the viable bounds for one dof \[rad/s²\]: acceleration `±a_max`, velocity
/// `(±v_max − q̇)/Δt`, position with in-step peak, viability with
/// `a_stop = braking_fraction · a_max` (on the continuous braking curve where it is invariant,
/// [`braking_curve_is_invariant`], else with the discrete stopping distance).
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
    let (lower, upper) = if braking_curve_is_invariant(limits, a_stop, dt) {
        (
            viability_lower(q, qd, limits.position_min, a_stop, dt),
            viability_upper(q, qd, limits.position_max, a_stop, dt),
        )
    } else {
        (
            no_reversal_viability_lower(q, qd, limits.position_min, a_stop, dt),
            no_reversal_viability_upper(q, qd, limits.position_max, a_stop, dt),
        )
    };
    DofBoundSources {
        lower: SourceBounds {
            acceleration: -a_max,
            velocity: velocity_lower(qd, limits.velocity_max, dt),
            position: position_lower(q, qd, limits.position_min, dt),
            viability: lower,
            jerk: f64::NEG_INFINITY,
            approach: f64::NEG_INFINITY,
        },
        upper: SourceBounds {
            acceleration: a_max,
            velocity: velocity_upper(qd, limits.velocity_max, dt),
            position: position_upper(q, qd, limits.position_max, dt),
            viability: upper,
            jerk: f64::INFINITY,
            approach: f64::INFINITY,
        },
    }
}

/// Excursions beyond a position limit up to this size \[rad\] or \[m\] are not recovered
/// ([`recovery_acceleration`] returns `None`): they are the rounding of the integration and
/// the solvers' box tolerance (a `q̈` outside the box by `1e-9` rad/s² moves `q` by
/// `5e-10 Δt²`), and the ordinary bounds, with the range widened to the current position,
/// keep them from growing. A larger value leaves larger start excursions in place; a smaller
/// one makes joints resting on a limit flicker in and out of recovery.
pub const RECOVERY_THRESHOLD: f64 = 1e-9;

/// The acceleration that brings a dof outside its position range back in \[rad/s²\], or
/// `None` when `q` is inside `[q_min − RECOVERY_THRESHOLD, q_max + RECOVERY_THRESHOLD]`
/// ([`RECOVERY_THRESHOLD`]).
///
/// Above the range (`q > q_max`) the joint is driven down as fast as its other limits allow,
/// and brought to rest on `q_max` by the position and viability bounds of a virtual *lower*
/// limit at `q_max`:
///
/// ```text
/// q̈_r = min(a_max, max(−a_max, (−v_max − q̇)/Δt, position_lower(q, q̇, q_max, Δt),
///                        no_reversal_viability_lower(q, q̇, q_max, a_stop, Δt)))
/// ```
///
/// i.e. it accelerates toward the range at `a_max` up to `v_max`, then brakes at `a_stop` along
/// the discrete stopping distance so as to arrive at rest on `q_max`. From a state at rest
/// outside the range, or moving further out (a state moving out is first braked, at most at
/// `a_max`), the velocity and acceleration limits are kept and the far limit `q_min ≤ q_max`
/// is never approached; the state it arrives in on the boundary is viable, and from there the
/// ordinary box applies. Below the range, the mirror image. A state moving *into* the range
/// faster than it can brake on `q_max` is not viable for the virtual limit either; it is
/// braked as hard as `a_max` allows and may cross `q_max` moving.
///
/// `q` \[rad\], `qd` \[rad/s\], `dt` \[s\].
pub fn recovery_acceleration(
    limits: &DofLimits,
    settings: &ViableSettings,
    q: f64,
    qd: f64,
    dt: f64,
) -> Option<f64> {
    let a_max = limits.acceleration_max;
    let a_stop = settings.braking_fraction * a_max;
    if q > limits.position_max + RECOVERY_THRESHOLD {
        let down = (-a_max)
            .max(velocity_lower(qd, limits.velocity_max, dt))
            .max(position_lower(q, qd, limits.position_max, dt))
            .max(no_reversal_viability_lower(
                q,
                qd,
                limits.position_max,
                a_stop,
                dt,
            ));
        Some(down.min(a_max))
    } else if q < limits.position_min - RECOVERY_THRESHOLD {
        let up = a_max
            .min(velocity_upper(qd, limits.velocity_max, dt))
            .min(position_upper(q, qd, limits.position_min, dt))
            .min(no_reversal_viability_upper(
                q,
                qd,
                limits.position_min,
                a_stop,
                dt,
            ));
        Some(up.max(-a_max))
    } else {
        None
    }
}

#[cfg(test)]
#[path = "viable_tests.rs"]
mod tests;
