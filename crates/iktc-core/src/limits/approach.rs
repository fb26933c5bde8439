//! An optional soft approach to the range ends: a spring–damper wall that starts braking a
//! joint early and gently, so that its commanded acceleration changes smoothly when a limit
//! begins to bind.
//!
//! **Why.** The viability and quiet bounds brake as late as possible: the bound, as a function
//! of the state, falls from far above the tasks' request to `−a_stop` within about one tick
//! once the joint meets its braking curve, so the command jumps by up to `a_max + a_stop` in one
//! step (a finite-difference jerk of `(a_max + a_stop)/Δt`).
//!
//! **The source.** With an approach rate `ω` \[1/s\], the distances `d_u = q_max − q` and
//! `d_l = q − q_min` \[rad\]:
//!
//! ```text
//! q̈ ≤ ω² d_u − 2ω q̇,        q̈ ≥ −ω² d_l − 2ω q̇.
//! ```
//!
//! On the upper side, `q̈` equal to the bound makes `d_u` obey `d̈ + 2ω ḋ + ω² d = 0`: a
//! critically damped approach to the limit, at rest on it in the limit `t → ∞`, without
//! overshoot. The bound is Lipschitz in the state with constants `ω²` and `2ω`, so as the
//! joint's state moves smoothly the bound moves smoothly: it takes over from a task's request
//! continuously instead of in a step. At `(q_max, 0)` it is 0, the same fixed point as the
//! quiet bound. The two sides never cross: their difference is `ω² (q_max − q_min) ≥ 0`.
//!
//! **In discrete time.** Under the constant-acceleration integrator over `Δt`, following the
//! upper bound maps `(d, ḋ)` (with `ḋ = −q̇`) linearly: with `p = ωΔt`,
//!
//! ```text
//! d⁺ = (1 − p²/2) d + Δt (1 − p) ḋ,     ḋ⁺ = −ω p d + (1 − 2p) ḋ,
//! ```
//!
//! whose trace is `2 − 2p − p²/2` and determinant `1 − 2p + p²/2`; the discriminant
//! `2p³ + p⁴/4` is never negative, so both eigenvalues are real, and they lie in `[0, 1)` for
//! `p ≤ 2 − √2` ([`MAX_APPROACH_STEP`](super::MAX_APPROACH_STEP)): the joint settles on the limit
//! without alternating, as `e^{−ωt}` does for small `p`. Beyond it one eigenvalue is negative
//! (the command alternates tick by tick), so a larger rate is taken as `(2 − √2)/Δt`.
//!
//! **Precedence.** It is the lowest-precedence source but for the jerk limit, applied to the
//! interval `[L, U]` the other sources leave after their own conflict resolution: their
//! intersection when it is not empty, otherwise the point of `[L, U]` nearest to it, so the
//! approach gives way by the least amount (a joint already faster than the wall allows is braked
//! by the viability bound as before) and every other limit holds exactly as without it.

use super::intersect::{give_way, DofBounds};
use super::joint_limits::DofLimits;
use super::source::BoundSource;

/// The approach interval `[−ω² d_l − 2ω q̇, ω² d_u − 2ω q̇]` \[rad/s²\] of one dof (module
/// docs) for `q` \[rad\], `qd` \[rad/s\] and the rate `rate` = `ω` \[1/s\]; a side whose range
/// end is infinite is unbounded.
pub fn approach_interval(limits: &DofLimits, q: f64, qd: f64, rate: f64) -> (f64, f64) {
    let damping = 2.0 * rate * qd;
    let stiffness = rate * rate;
    let lower = if limits.position_min == f64::NEG_INFINITY {
        f64::NEG_INFINITY
    } else {
        -stiffness * (q - limits.position_min) - damping
    };
    let upper = if limits.position_max == f64::INFINITY {
        f64::INFINITY
    } else {
        stiffness * (limits.position_max - q) - damping
    };
    (lower, upper)
}

/// `resolved` with the approach interval `[lower, upper]` applied at lower precedence: their
/// intersection when not empty, otherwise the point of `resolved` nearest to it (module docs).
/// An empty `resolved` is returned unchanged.
pub fn apply_approach(resolved: DofBounds, lower: f64, upper: f64) -> DofBounds {
    let (mut out, gave_way) = give_way(resolved, lower, upper, BoundSource::Approach);
    out.dropped.approach |= gave_way;
    out
}

#[cfg(test)]
mod tests {
    use super::{apply_approach, approach_interval};
    use crate::limits::{
        compute_dof, integrate_constant_acceleration, BoundMethod, BoundSource, DofBounds,
        DofLimits, DroppedSources, ViableSettings,
    };

    const LIMITS: DofLimits = DofLimits {
        position_min: -0.5,
        position_max: 0.5,
        velocity_max: 3.0,
        acceleration_max: 60.0,
        jerk_max: f64::INFINITY,
    };

    fn quiet(rate: f64) -> BoundMethod {
        BoundMethod::Quiet(ViableSettings {
            approach_rate: rate,
            ..ViableSettings::default()
        })
    }

    /// By hand: ω = 10 /s, q = 0.3 rad, q̇ = 0.4 rad/s: upper 100·0.2 − 8 = 12, lower
    /// −100·0.8 − 8 = −88 rad/s²; an infinite range end leaves its side unbounded; at rest on
    /// a limit the side toward it is 0.
    #[test]
    fn the_interval_is_a_critically_damped_wall() {
        let (l, u) = approach_interval(&LIMITS, 0.3, 0.4, 10.0);
        assert!(
            (u - 12.0).abs() < 1e-12 && (l + 88.0).abs() < 1e-12,
            "{l} {u}"
        );
        let open = DofLimits {
            position_max: f64::INFINITY,
            ..LIMITS
        };
        assert_eq!(approach_interval(&open, 0.3, 0.4, 10.0).1, f64::INFINITY);
        assert_eq!(
            approach_interval(&DofLimits::unlimited(), 0.0, 1.0, 10.0).0,
            f64::NEG_INFINITY
        );
        assert_eq!(approach_interval(&LIMITS, 0.5, 0.0, 10.0).1, 0.0);
        assert_eq!(approach_interval(&LIMITS, -0.5, 0.0, 10.0).0, 0.0);
    }

    fn interval(lower: f64, upper: f64) -> DofBounds {
        DofBounds {
            lower,
            upper,
            lower_source: BoundSource::Position,
            upper_source: BoundSource::Viability,
            dropped: DroppedSources::default(),
        }
    }

    /// Overlap: the intersection, the approach named where it binds; apart: the nearest end of
    /// the other sources' interval, the approach marked as given way; empty: unchanged.
    #[test]
    fn the_approach_intersects_or_gives_way_by_the_least_amount() {
        let b = apply_approach(interval(-1.0, 1.0), -2.0, 0.5);
        assert_eq!((b.lower, b.upper), (-1.0, 0.5));
        assert_eq!(
            (b.lower_source, b.upper_source),
            (BoundSource::Position, BoundSource::Approach)
        );
        assert!(!b.dropped.approach);
        let below = apply_approach(interval(-1.0, 1.0), -5.0, -3.0);
        assert_eq!((below.lower, below.upper), (-1.0, -1.0));
        assert_eq!(below.upper_source, BoundSource::Position);
        assert!(below.dropped.approach && below.dropped.any());
        let above = apply_approach(interval(-1.0, 1.0), 2.0, 3.0);
        assert_eq!((above.lower, above.upper), (1.0, 1.0));
        assert_eq!(above.lower_source, BoundSource::Viability);
        assert!(above.dropped.approach);
        let empty = interval(1.0, -1.0);
        assert_eq!(apply_approach(empty, -0.5, 0.5), empty);
    }

    /// Rate 0 leaves the box of every state exactly as without the setting; a positive rate,
    /// however slow, records the approach among the sources and binds where it is the tightest.
    #[test]
    fn rate_zero_changes_nothing_and_a_rate_records_the_source() {
        let dt = 0.005;
        let (slow, _) = compute_dof(&LIMITS, &quiet(0.5), 0.3, 0.4, dt).unwrap();
        assert_eq!(
            slow.upper.approach,
            approach_interval(&LIMITS, 0.3, 0.4, 0.5).1
        );
        for i in 0..200 {
            let q = -0.5 + i as f64 * 0.005;
            for qd in [-2.5, -0.7, 0.0, 0.3, 2.9] {
                let (s0, b0) = compute_dof(&LIMITS, &BoundMethod::quiet(), q, qd, dt).unwrap();
                let (s, b) = compute_dof(&LIMITS, &quiet(0.0), q, qd, dt).unwrap();
                assert_eq!((s0, b0), (s, b));
                let (s, b) = compute_dof(&LIMITS, &quiet(10.0), q, qd, dt).unwrap();
                let (l, u) = approach_interval(&LIMITS, q, qd, 10.0);
                assert_eq!((s.lower.approach, s.upper.approach), (l, u));
                assert!(b.upper <= b0.upper && b.lower >= b0.lower || b.dropped.approach);
                if u < b0.upper && u > b0.lower {
                    assert_eq!((b.upper, b.upper_source), (u, BoundSource::Approach));
                }
            }
        }
    }

    /// Braking at the approach bound from rest or moving toward the limit converges on the
    /// limit at rest, with `q̈ → 0`, for `ωΔt` up to `2 − √2` (module docs).
    #[test]
    fn following_the_wall_converges_onto_the_limit() {
        let dt = 0.005;
        for p in [0.02_f64, 0.1, 0.3, 0.5, 0.58] {
            let rate = p / dt;
            for (d0, v0) in [(0.2, 0.0), (0.05, 0.5), (0.3, 2.0)] {
                let (mut q, mut v) = (0.5 - d0, v0);
                let ticks = (40.0 / p).ceil() as usize;
                let mut a = 0.0;
                for _ in 0..ticks {
                    a = approach_interval(&LIMITS, q, v, rate).1;
                    (q, v) = integrate_constant_acceleration(q, v, a, dt);
                }
                assert!(
                    (0.5 - q).abs() < 1e-9 && v.abs() < 1e-6 && a.abs() < 1e-4,
                    "ωΔt {p}, from ({d0}, {v0}): d {} v {v} q̈ {a}",
                    0.5 - q
                );
            }
        }
    }

    /// A bad rate is an error naming it; a rate too fast for the period is taken as
    /// `(2 − √2)/Δt` (117.16 /s at Δt = 5 ms).
    #[test]
    fn bad_rates_are_errors_and_fast_ones_are_capped() {
        for rate in [-1.0, f64::NAN, f64::INFINITY] {
            let e = compute_dof(&LIMITS, &quiet(rate), 0.0, 0.0, 0.005).unwrap_err();
            assert!(e.to_string().contains("approach_rate"), "{e}");
        }
        let cap = crate::limits::MAX_APPROACH_STEP / 0.005;
        let (s, _) = compute_dof(&LIMITS, &quiet(1e4), 0.2, 0.1, 0.005).unwrap();
        assert_eq!(
            s.upper.approach,
            approach_interval(&LIMITS, 0.2, 0.1, cap).1
        );
        let (s, _) = compute_dof(&LIMITS, &quiet(117.0), 0.2, 0.1, 0.005).unwrap();
        assert_eq!(
            s.upper.approach,
            approach_interval(&LIMITS, 0.2, 0.1, 117.0).1
        );
    }

    /// `with_approach_rate` sets the rate on viable and quiet bounds and reads back; the
    /// paper's bound takes only 0; a bad rate is an error naming it.
    #[test]
    fn with_approach_rate_sets_reads_and_refuses() {
        for m in [BoundMethod::viable(), BoundMethod::quiet()] {
            let a = m.with_approach_rate(12.5).unwrap();
            assert_eq!(a.approach_rate(), 12.5);
            assert_eq!(a.name(), m.name());
            assert_eq!(a.with_approach_rate(0.0).unwrap(), m);
            let e = m.with_approach_rate(-1.0).unwrap_err();
            assert!(e.to_string().contains("approach_rate"), "{e}");
        }
        assert_eq!(
            BoundMethod::Paper.with_approach_rate(0.0).unwrap(),
            BoundMethod::Paper
        );
        assert_eq!(BoundMethod::Paper.approach_rate(), 0.0);
        let e = BoundMethod::Paper.with_approach_rate(5.0).unwrap_err();
        assert!(e.to_string().contains("approach_rate"), "{e}");
    }
}
