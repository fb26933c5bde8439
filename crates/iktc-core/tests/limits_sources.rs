//! Closed-form checks of each source of acceleration bound on hand-computed cases, infinite
//! limits, conflict resolution and input validation.

use approx::assert_relative_eq;
use iktc_core::limits::{
    compute_box, compute_dof, integrate_constant_acceleration, intersect, paper, peak_in_step,
    viable, AccelerationBox, BoundMethod, BoundSource, DofBoundSources, DofLimits, JointLimits,
    SourceBounds, ViableSettings,
};
use iktc_core::Error;

const INF: f64 = f64::INFINITY;

fn joint(range: f64, v_max: f64, a_max: f64) -> DofLimits {
    DofLimits {
        position_min: -range,
        position_max: range,
        velocity_max: v_max,
        acceleration_max: a_max,
        jerk_max: f64::INFINITY,
    }
}

fn viable_half() -> BoundMethod {
    BoundMethod::Viable(ViableSettings {
        braking_fraction: 0.5,
        ..ViableSettings::default()
    })
}

// ---------------------------------------------------------------- paper, eq. (14)

#[test]
fn paper_sources_by_hand_far_from_the_limit() {
    // q ∈ [−1, 1], v_max = 3, a_max = 8, Δt = 0.1, q = 0.5, q̇ = 1.
    let (s, b) = compute_dof(&joint(1.0, 3.0, 8.0), &BoundMethod::Paper, 0.5, 1.0, 0.1).unwrap();
    assert_eq!(s.upper.acceleration, 8.0);
    assert_eq!(s.lower.acceleration, -8.0);
    assert_relative_eq!(s.upper.velocity, 20.0, epsilon = 1e-12); // (3 − 1)/0.1
    assert_relative_eq!(s.lower.velocity, -40.0, epsilon = 1e-12); // (−3 − 1)/0.1
    assert_relative_eq!(
        s.upper.position,
        (8.0_f64.sqrt() - 1.0) / 0.1,
        epsilon = 1e-12
    ); // √(2·8·0.5)
    assert_relative_eq!(
        s.lower.position,
        (-24.0_f64.sqrt() - 1.0) / 0.1,
        epsilon = 1e-12
    ); // √(2·8·1.5)
    assert_eq!(s.upper.viability, INF);
    assert_eq!(s.lower.viability, -INF);
    assert_eq!((b.lower, b.upper), (-8.0, 8.0));
    assert_eq!(b.lower_source, BoundSource::Acceleration);
    assert_eq!(b.upper_source, BoundSource::Acceleration);
    assert!(!b.dropped.any());
}

#[test]
fn paper_position_term_binds_near_the_limit() {
    // q = 0.9, q̇ = 2: (√(2·8·0.1) − 2)/0.1 = (1.2649111 − 2)/0.1 = −7.350889.
    let (_, b) = compute_dof(&joint(1.0, 3.0, 8.0), &BoundMethod::Paper, 0.9, 2.0, 0.1).unwrap();
    assert_relative_eq!(b.upper, (1.6_f64.sqrt() - 2.0) / 0.1, epsilon = 1e-12);
    assert_eq!(b.upper_source, BoundSource::PaperPosition);
    assert_eq!(b.lower, -8.0);
}

#[test]
fn paper_beyond_the_limit_takes_the_square_root_of_a_negative_argument_as_zero() {
    // q = 1.2 > q_max = 1: the term becomes −q̇/Δt.
    assert_relative_eq!(
        paper::position_term_upper(1.2, 0.5, 1.0, 8.0, 0.1),
        -5.0,
        epsilon = 1e-12
    );
    assert_relative_eq!(
        paper::position_term_lower(-1.2, -0.5, -1.0, 8.0, 0.1),
        5.0,
        epsilon = 1e-12
    );
    // At the limit and at rest: zero, not NaN, even with an infinite a_max.
    assert_eq!(paper::position_term_upper(1.0, 0.0, 1.0, INF, 0.1), 0.0);
    assert_eq!(paper::position_term_upper(0.0, 0.0, 1.0, INF, 0.1), INF);
}

// ---------------------------------------------------------------- viable position bound

#[test]
fn viable_position_bound_end_of_step_case() {
    // d = 0.5, q̇ = 1, Δt = 0.1: 2(0.5 − 0.1)/0.01 = 80 ≥ −10.
    assert_relative_eq!(
        viable::position_upper(0.5, 1.0, 1.0, 0.1),
        80.0,
        epsilon = 1e-9
    );
    // Moving away: d = 0.02, q̇ = −1: 2(0.02 + 0.1)/0.01 = 24.
    assert_relative_eq!(
        viable::position_upper(0.98, -1.0, 1.0, 0.1),
        24.0,
        epsilon = 1e-9
    );
}

#[test]
fn viable_position_bound_in_step_peak_case() {
    // d = 0.02, q̇ = 1, Δt = 0.1: end-of-step bound 2(0.02 − 0.1)/0.01 = −16 < −q̇/Δt = −10,
    // so the joint turns round inside the step; the peak q + q̇²/(2|q̈|) ≤ 1 needs
    // q̈ ≤ −1/(2·0.02) = −25.
    let bound = viable::position_upper(0.98, 1.0, 1.0, 0.1);
    assert_relative_eq!(bound, -25.0, epsilon = 1e-9);
    // The peak at the bound touches the limit; the end-of-step bound −16 would overshoot.
    assert_relative_eq!(
        peak_in_step(0.98, 1.0, bound, 0.1).max,
        1.0,
        epsilon = 1e-12
    );
    assert!(peak_in_step(0.98, 1.0, -16.0, 0.1).max > 1.0 + 1e-3);
    // Mirror on the lower side.
    assert_relative_eq!(
        viable::position_lower(-0.98, -1.0, -1.0, 0.1),
        25.0,
        epsilon = 1e-9
    );
}

#[test]
fn viable_position_bound_beyond_the_limit_does_not_let_the_excursion_grow() {
    // q = 1.1 > q_max, q̇ = 1: range widened to q, end-of-step fallback −2q̇/Δt = −20.
    let bound = viable::position_upper(1.1, 1.0, 1.0, 0.1);
    assert_relative_eq!(bound, -20.0, epsilon = 1e-9);
    let (q_next, qd_next) =
        iktc_core::limits::integrate_constant_acceleration(1.1, 1.0, bound, 0.1);
    assert_relative_eq!(q_next, 1.1, epsilon = 1e-12);
    assert_relative_eq!(qd_next, -1.0, epsilon = 1e-12);
    // Beyond the limit and moving back in: only "not further out".
    assert!(viable::position_upper(1.1, -1.0, 1.0, 0.1) > 0.0);
}

// ---------------------------------------------------------------- viability bound

#[test]
fn viability_bound_by_hand() {
    // d = 1, q̇ = 0, a_stop = 10, Δt = 0.1: a = 0.01, b = 0.1, c = −20, disc = 0.81,
    // x₊ = (−0.1 + 0.9)/0.02 = 40. Check: q̇⁺ = 4, q⁺ = 0.2, √(2·10·0.8) = 4.
    assert_relative_eq!(
        viable::viability_upper(0.0, 0.0, 1.0, 10.0, 0.1),
        40.0,
        epsilon = 1e-9
    );
    assert_relative_eq!(
        viable::viability_lower(0.0, 0.0, -1.0, 10.0, 0.1),
        -40.0,
        epsilon = 1e-9
    );
}

#[test]
fn viability_bound_on_the_braking_curve_is_minus_a_stop() {
    // q̇ = 2, a_stop = 10 → d = q̇²/(2 a_stop) = 0.2; 2q̇ ≥ a_stop Δt, so x₊ = −a_stop.
    for dt in [0.001, 0.005, 0.01] {
        assert_relative_eq!(
            viable::viability_upper(0.8, 2.0, 1.0, 10.0, dt),
            -10.0,
            epsilon = 1e-9
        );
    }
}

#[test]
fn viability_bound_uses_stop_in_one_step_when_the_root_is_below_it() {
    // On the braking curve with 2q̇ < a_stop Δt (q̇ = 0.5, a_stop = 100, Δt = 0.1,
    // d = 0.00125): roots −100 and −2q̇/Δt = −10, both below −q̇/Δt = −5.
    assert_relative_eq!(
        viable::viability_upper(1.0 - 0.00125, 0.5, 1.0, 100.0, 0.1),
        -5.0,
        epsilon = 1e-9
    );
    // Negative discriminant: d = 0.01, q̇ = 3, a_stop = 10, Δt = 0.1 → −q̇/Δt = −30.
    assert_relative_eq!(
        viable::viability_upper(0.99, 3.0, 1.0, 10.0, 0.1),
        -30.0,
        epsilon = 1e-9
    );
}

/// The stopping distance of the no-reversal braking policy, by running it: `q̈ = −a` while
/// `v ≥ aΔt`, then one step `q̈ = −v/Δt`, through the integrator.
fn simulated_stopping_distance(v: f64, a: f64, dt: f64) -> f64 {
    let (mut q, mut v) = (0.0, v);
    while v > 0.0 {
        let qdd = if v >= a * dt { -a } else { -v / dt };
        (q, v) = integrate_constant_acceleration(q, v, qdd, dt);
    }
    q
}

#[test]
fn stopping_distance_matches_the_braking_policy_run_step_by_step() {
    let mut checked = 0;
    for (a, dt) in [(10.0_f64, 0.1_f64), (7.0, 0.004), (1e5, 0.005), (0.3, 0.05)] {
        for i in 0..200 {
            let v = f64::from(i) * 0.0173 * (a * dt).max(0.01);
            let closed = viable::stopping_distance(v, a, dt);
            let run = simulated_stopping_distance(v, a, dt);
            assert_relative_eq!(closed, run, epsilon = 1e-12, max_relative = 1e-9);
            // Between the continuous braking distance and a Δt²/8 more.
            assert!(closed >= v * v / (2.0 * a) * (1.0 - 1e-12));
            assert!(closed <= v * v / (2.0 * a) + a * dt * dt / 8.0 + 1e-12);
            checked += 1;
        }
    }
    assert_eq!(checked, 800);
    // No acceleration limit: stop in one step.
    assert_eq!(viable::stopping_distance(2.0, INF, 0.1), 0.1);
    assert_eq!(viable::stopping_distance(-2.0, 3.0, 0.1), 0.0);
}

#[test]
fn viability_bound_is_tight_against_the_braking_policy_run_from_the_next_state() {
    // Independent check on a grid: at the bound (when above −q̇/Δt) the next state can just
    // stop before q_max by the no-reversal braking policy (run step by step), a little above
    // it cannot.
    let mut checked = 0;
    for (q_max, a_stop, dt) in [(1.0, 7.0, 0.004), (1.0, 40.0, 0.05), (0.3, 1e4, 0.01)] {
        for i in 0..40 {
            for j in 0..40 {
                let q = -1.0 + (q_max + 1.0) * f64::from(i) / 40.0;
                let qd = -4.0 + 8.0 * f64::from(j) / 40.0;
                let x = viable::no_reversal_viability_upper(q, qd, q_max, a_stop, dt);
                if x <= -qd / dt {
                    continue;
                }
                let margin = |a: f64| {
                    let (q1, v1) = integrate_constant_acceleration(q, qd, a, dt);
                    q_max - q1 - simulated_stopping_distance(v1, a_stop, dt)
                };
                let scale = 1e-9 * (1.0 + x.abs());
                assert!(margin(x - scale) >= -1e-12, "q={q} qd={qd} x={x}");
                assert!(
                    margin(x + 1e-3 * (1.0 + x.abs())) < 0.0,
                    "q={q} qd={qd} x={x}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 1000, "{checked}");
}

#[test]
fn viability_bound_by_hand_between_two_knots() {
    // d = 0.3, q̇ = 0, a_stop = 10, Δt = 0.1 (aΔt = 1, aΔt² = 0.1): R = 0.3; the knots of
    // h(v) = D(v) + vΔt/2 are h(k) = 0.05 k(k+1): 0.1 at k = 1, 0.3 at k = 2. So v* = 2
    // (at a knot): q̈ = 20. With R = 0.2: between the knots 1 and 2, on the line
    // h(v) = 0.2 v − 0.1 (piece n = 1): v* = 1.5, q̈ = 15. Check: q⁺ = 0.075 away,
    // D(1.5) = 1.5·0.1·1.5 − 0.1 = 0.125 = 0.2 − 0.075.
    assert_relative_eq!(
        viable::no_reversal_viability_upper(0.7, 0.0, 1.0, 10.0, 0.1),
        20.0,
        epsilon = 1e-9
    );
    assert_relative_eq!(
        viable::no_reversal_viability_upper(0.8, 0.0, 1.0, 10.0, 0.1),
        15.0,
        epsilon = 1e-9
    );
    assert_relative_eq!(
        viable::stopping_distance(1.5, 10.0, 0.1),
        0.125,
        epsilon = 1e-12
    );
    // Moving at q̇ = 1 with d = 0.3: R = 0.3 − 0.05 = 0.25, on piece n = 1: v* = 1.75,
    // q̈ = (1.75 − 1)/0.1 = 7.5.
    assert_relative_eq!(
        viable::no_reversal_viability_upper(0.7, 1.0, 1.0, 10.0, 0.1),
        7.5,
        epsilon = 1e-9
    );
    // No acceleration limit: stop within one step, v* = R/Δt: d = 0.3, q̇ = 1 → 2.5, q̈ = 15.
    assert_relative_eq!(
        viable::no_reversal_viability_upper(0.7, 1.0, 1.0, INF, 0.1),
        15.0,
        epsilon = 1e-9
    );
}

// ---------------------------------------------------------------- infinite limits

#[test]
fn unlimited_dof_gives_an_unbounded_box() {
    for method in [BoundMethod::Paper, viable_half()] {
        let (s, b) = compute_dof(&DofLimits::unlimited(), &method, 3.0, -2.0, 0.005).unwrap();
        assert_eq!(s.upper, SourceBounds::UPPER_NONE);
        assert_eq!(s.lower, SourceBounds::LOWER_NONE);
        assert_eq!((b.lower, b.upper), (-INF, INF));
        assert_eq!(b.lower_source, BoundSource::None);
        assert_eq!(b.upper_source, BoundSource::None);
    }
}

#[test]
fn only_the_limits_that_exist_apply() {
    // Velocity only.
    let vel_only = DofLimits {
        velocity_max: 2.0,
        ..DofLimits::unlimited()
    };
    let (_, b) = compute_dof(&vel_only, &viable_half(), 0.0, 1.0, 0.1).unwrap();
    assert_relative_eq!(b.upper, 10.0, epsilon = 1e-12);
    assert_relative_eq!(b.lower, -30.0, epsilon = 1e-12);
    assert_eq!(b.upper_source, BoundSource::Velocity);
    // Acceleration only.
    let acc_only = DofLimits {
        acceleration_max: 5.0,
        ..DofLimits::unlimited()
    };
    let (s, b) = compute_dof(&acc_only, &viable_half(), 0.0, 1.0, 0.1).unwrap();
    assert_eq!((b.lower, b.upper), (-5.0, 5.0));
    assert_eq!(s.upper.viability, INF);
    assert_eq!(s.upper.position, INF);
    // Range on the upper side only, no acceleration limit: position bound, no viability.
    let half_range = DofLimits {
        position_max: 1.0,
        ..DofLimits::unlimited()
    };
    let (s, b) = compute_dof(&half_range, &viable_half(), 0.98, 1.0, 0.1).unwrap();
    assert_relative_eq!(b.upper, -25.0, epsilon = 1e-9);
    assert_eq!(b.upper_source, BoundSource::Position);
    assert_eq!(s.upper.viability, INF);
    // With a velocity limit too, the braking curve (a_stop Δt = inf > v_max) is not invariant
    // and the viability bound is the one-step stop (a_stop = +inf: D(v) = vΔt/2), here with
    // R = 0.02 − 0.05 < 0, so −q̇/Δt = −10.
    let limited = DofLimits {
        velocity_max: 3.0,
        ..half_range
    };
    let (s, _) = compute_dof(&limited, &viable_half(), 0.98, 1.0, 0.1).unwrap();
    assert_eq!(s.upper.viability, -10.0);
    assert_eq!((b.lower, b.lower_source), (-INF, BoundSource::None));
}

// ---------------------------------------------------------------- conflict resolution

fn sources(lower: [f64; 4], upper: [f64; 4]) -> DofBoundSources {
    let side = |v: [f64; 4]| SourceBounds {
        acceleration: v[0],
        velocity: v[1],
        position: v[2],
        viability: v[3],
        jerk: f64::INFINITY.copysign(v[0]),
        approach: f64::INFINITY.copysign(v[0]),
    };
    DofBoundSources {
        lower: side(lower),
        upper: side(upper),
    }
}

#[test]
fn conflict_drops_acceleration_first() {
    let s = sources([-10.0, -50.0, -60.0, 12.0], [10.0, 50.0, 60.0, 70.0]);
    let b = intersect(&s, &viable_half());
    assert!(!b.is_empty());
    assert!(b.dropped.acceleration && !b.dropped.viability);
    // Without the acceleration limit [12, 50]; its point closest to [−10, 10] is 12, so the
    // limit is exceeded by the least amount.
    assert_eq!((b.lower, b.lower_source), (12.0, BoundSource::Viability));
    assert_eq!((b.upper, b.upper_source), (12.0, BoundSource::Viability));
    // Mirror: without the acceleration limit [−50, −12] → the point −12.
    let m = sources([-10.0, -50.0, -60.0, -70.0], [10.0, 50.0, 60.0, -12.0]);
    let b = intersect(&m, &viable_half());
    assert!(b.dropped.acceleration);
    assert_eq!((b.lower, b.lower_source), (-12.0, BoundSource::Viability));
    assert_eq!((b.upper, b.upper_source), (-12.0, BoundSource::Viability));
    // The paper's method reports the conflict as it is.
    let p = intersect(&s, &BoundMethod::Paper);
    assert!(p.is_empty() && !p.dropped.any());
    assert_eq!(p.upper_source, BoundSource::Acceleration);
}

#[test]
fn conflict_drops_viability_second_and_keeps_position() {
    let s = sources([-10.0, -50.0, -60.0, 20.0], [10.0, 50.0, 15.0, 70.0]);
    let b = intersect(&s, &viable_half());
    assert!(!b.is_empty());
    // Viability (20) against position (15) is resolved by dropping viability: [−50, 15],
    // which overlaps [−10, 10], so the acceleration limit is kept after all.
    assert!(!b.dropped.acceleration && b.dropped.viability);
    assert_eq!(
        (b.lower, b.lower_source),
        (-10.0, BoundSource::Acceleration)
    );
    assert_eq!((b.upper, b.upper_source), (10.0, BoundSource::Acceleration));
    // With the position bound at −12 instead, dropping viability leaves [−50, −12], which
    // misses [−10, 10]: the point −12, exceeding the acceleration limit by 2.
    let s = sources([-10.0, -50.0, -60.0, 20.0], [10.0, 50.0, -12.0, 70.0]);
    let b = intersect(&s, &viable_half());
    assert!(b.dropped.acceleration && b.dropped.viability);
    assert_eq!((b.lower, b.lower_source), (-12.0, BoundSource::Position));
    assert_eq!((b.upper, b.upper_source), (-12.0, BoundSource::Position));
}

#[test]
fn position_against_velocity_is_reported_empty() {
    let s = sources([-10.0, 20.0, -60.0, -70.0], [10.0, 50.0, 15.0, 70.0]);
    let b = intersect(&s, &viable_half());
    assert!(b.is_empty());
    assert_eq!((b.lower, b.lower_source), (20.0, BoundSource::Velocity));
    assert_eq!((b.upper, b.upper_source), (15.0, BoundSource::Position));
    assert!(b.dropped.acceleration && b.dropped.viability);
}

#[test]
fn box_reports_empty_dofs_and_violation() {
    // dof 1 is 1 mm from its limit at 3 rad/s with Δt = 10 ms: position (turn round inside the
    // step: −q̇²/(2d) = −4500) conflicts with velocity ((−3.2 − 3)/0.01 = −620).
    let limits = JointLimits::new(vec![joint(1.0, 5.0, 30.0), joint(1.0, 3.2, 30.0)]).unwrap();
    let mut out = AccelerationBox::new(2);
    compute_box(
        &limits,
        &viable_half(),
        &[0.0, 0.999],
        &[0.0, 3.0],
        0.01,
        &mut out,
    )
    .unwrap();
    assert!(out.is_empty());
    assert_eq!(out.empty_dofs().collect::<Vec<_>>(), vec![1]);
    assert!(out.any_dropped());
    let d1 = out.get(1).unwrap();
    assert_eq!(d1.upper_source, BoundSource::Position);
    assert_eq!(d1.lower_source, BoundSource::Velocity);
    assert_relative_eq!(d1.upper, -4500.0, epsilon = 1e-6);
    assert!(out.max_violation(&[0.0, 0.0]).unwrap() > 0.0);
    assert!(!out.contains(&[0.0, -1000.0], 1e-9).unwrap());
    assert!(out.get(2).is_none());
}

#[test]
fn contains_and_max_violation_by_hand() {
    let mut out = AccelerationBox::new(2);
    out.lower[0] = -1.0;
    out.upper[0] = 2.0;
    assert!(!out.is_empty());
    assert_eq!(out.max_violation(&[0.0, 1e9]).unwrap(), 0.0);
    assert_relative_eq!(out.max_violation(&[2.5, 0.0]).unwrap(), 0.5);
    assert_relative_eq!(out.max_violation(&[-3.0, 0.0]).unwrap(), 2.0);
    assert!(out.contains(&[2.5, 0.0], 0.6).unwrap());
    assert!(!out.contains(&[2.5, 0.0], 0.4).unwrap());
}

// ---------------------------------------------------------------- bad input

#[test]
fn bad_limits_are_errors() {
    let bad = [
        (joint(1.0, 1.0, 1.0), None),
        (
            DofLimits {
                position_min: 1.0,
                position_max: 0.0,
                ..joint(1.0, 1.0, 1.0)
            },
            Some("InvalidLimit"),
        ),
        (
            DofLimits {
                position_min: INF,
                position_max: INF,
                ..joint(1.0, 1.0, 1.0)
            },
            Some("InvalidLimit"),
        ),
        (joint(1.0, 0.0, 1.0), Some("InvalidSetting")),
        (joint(1.0, 1.0, -2.0), Some("InvalidSetting")),
        (joint(f64::NAN, 1.0, 1.0), Some("NonFinite")),
        (joint(1.0, f64::NAN, 1.0), Some("NonFinite")),
    ];
    for (dof, expected) in bad {
        let result = JointLimits::new(vec![DofLimits::unlimited(), dof]);
        match (result, expected) {
            (Ok(_), None) => {}
            (Err(Error::InvalidLimit { what, .. }), Some("InvalidLimit")) => {
                assert!(what.contains("dof[1]"))
            }
            (Err(Error::InvalidSetting { name, .. }), Some("InvalidSetting")) => {
                assert!(name.contains("dof[1]"))
            }
            (Err(Error::NonFinite { what, .. }), Some("NonFinite")) => {
                assert!(what.contains("dof[1]"))
            }
            (other, expected) => panic!("{dof:?}: got {other:?}, expected {expected:?}"),
        }
    }
    let mut limits = JointLimits::unlimited(2);
    assert!(matches!(
        limits.set(2, joint(1.0, 1.0, 1.0)),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(limits.set(1, joint(1.0, 0.0, 1.0)).is_err());
    assert!(limits.set(1, joint(0.5, 1.0, 1.0)).is_ok());
    assert_eq!(limits.get(1).map(|d| d.position_max), Some(0.5));
}

#[test]
fn bad_state_time_step_and_settings_are_errors() {
    let limits = JointLimits::new(vec![joint(1.0, 1.0, 1.0); 3]).unwrap();
    let mut out = AccelerationBox::new(3);
    let q = [0.0; 3];
    let m = viable_half();
    let run = |q: &[f64], qd: &[f64], dt: f64, m: &BoundMethod, out: &mut AccelerationBox| {
        compute_box(&limits, m, q, qd, dt, out)
    };
    assert!(run(&q, &q, 0.005, &m, &mut out).is_ok());
    for dt in [0.0, -0.001] {
        assert!(matches!(
            run(&q, &q, dt, &m, &mut out),
            Err(Error::InvalidSetting { .. })
        ));
    }
    for dt in [f64::NAN, INF] {
        assert!(matches!(
            run(&q, &q, dt, &m, &mut out),
            Err(Error::NonFinite { .. })
        ));
    }
    assert!(matches!(
        run(&q[..2], &q, 0.005, &m, &mut out),
        Err(Error::DimensionMismatch {
            expected: 3,
            got: 2,
            ..
        })
    ));
    assert!(matches!(
        run(&q, &[0.0; 4], 0.005, &m, &mut out),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        run(&[0.0, f64::NAN, 0.0], &q, 0.005, &m, &mut out),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        run(&q, &[0.0, 0.0, -INF], 0.005, &m, &mut out),
        Err(Error::NonFinite { .. })
    ));
    let mut small = AccelerationBox::new(2);
    assert!(matches!(
        run(&q, &q, 0.005, &m, &mut small),
        Err(Error::DimensionMismatch { .. })
    ));
    for f in [0.0, -0.5, 1.5, f64::NAN] {
        let bad = BoundMethod::Viable(ViableSettings {
            braking_fraction: f,
            ..ViableSettings::default()
        });
        assert!(matches!(
            run(&q, &q, 0.005, &bad, &mut out),
            Err(Error::InvalidSetting { .. })
        ));
    }
    assert!(ViableSettings::default().validate().is_ok());
    assert_eq!(ViableSettings::default().braking_fraction, 0.5);
    assert!(out.contains(&[0.0; 2], 0.0).is_err());
    assert!(out.contains(&[0.0; 3], -1.0).is_err());
    assert!(out.max_violation(&[0.0, f64::NAN, 0.0]).is_err());
}

#[test]
fn error_leaves_the_box_unchanged() {
    let limits = JointLimits::new(vec![joint(1.0, 1.0, 1.0)]).unwrap();
    let mut out = AccelerationBox::new(1);
    compute_box(&limits, &viable_half(), &[0.0], &[0.0], 0.01, &mut out).unwrap();
    let before = out.clone();
    assert!(compute_box(&limits, &viable_half(), &[f64::NAN], &[0.0], 0.01, &mut out).is_err());
    assert_eq!(out, before);
}

// ---------------------------------------------------------------- in-step peak

#[test]
fn peak_in_step_by_hand() {
    // q̇ = 1, q̈ = −25, Δt = 0.1: turns at t = 0.04, peak 0.02 above the start.
    let e = peak_in_step(0.0, 1.0, -25.0, 0.1);
    assert_relative_eq!(e.max, 0.02, epsilon = 1e-15);
    assert_relative_eq!(e.min, 0.1 - 0.125, epsilon = 1e-15); // end point −0.025
                                                              // No turn inside the step: the end points.
    let e = peak_in_step(0.0, 1.0, -5.0, 0.1);
    assert_eq!(e.min, 0.0);
    assert_relative_eq!(e.max, 0.1 - 0.025, epsilon = 1e-15);
    // A minimum inside the step.
    let e = peak_in_step(0.0, -1.0, 25.0, 0.1);
    assert_relative_eq!(e.min, -0.02, epsilon = 1e-15);
    // Excursion beyond a range.
    let lim = joint(0.01, 1.0, 1.0);
    assert_relative_eq!(
        lim.excursion(peak_in_step(0.0, 1.0, -25.0, 0.1)),
        0.015,
        epsilon = 1e-15
    );
    assert_eq!(
        joint(1.0, 1.0, 1.0).excursion(peak_in_step(0.0, 1.0, -25.0, 0.1)),
        0.0
    );
}

// ---------------------------------------------------------------- which branch binds

#[test]
fn braking_curve_regime_by_hand() {
    // a_max = 40, a_stop = 20, Δt = 0.01: a_stop Δt = 0.2 ≤ v_max = 4 and a_stop Δt² = 0.002 ≤
    // the range 0.4: the continuous curve. Δt = 0.5: a_stop Δt = 10 > 4: the discrete one.
    let k = DofLimits {
        position_min: 0.55,
        position_max: 0.95,
        velocity_max: 4.0,
        acceleration_max: 40.0,
        jerk_max: f64::INFINITY,
    };
    assert!(viable::braking_curve_is_invariant(&k, 20.0, 0.01));
    assert!(viable::braking_curve_is_invariant(&k, 20.0, 0.1)); // 2 ≤ 4, 0.2 ≤ 0.4
    assert!(!viable::braking_curve_is_invariant(&k, 20.0, 0.2)); // 4 ≤ 4 but 0.8 > 0.4
    assert!(!viable::braking_curve_is_invariant(&k, 20.0, 0.5)); // 10 > 4
                                                                 // Either condition alone decides: a range of 0.002 rad admits Δt up to 0.01 s, a v_max
                                                                 // of 0.1 rad/s Δt up to 0.005 s.
    let narrow = DofLimits {
        position_min: 0.0,
        position_max: 0.002,
        ..k
    };
    assert!(viable::braking_curve_is_invariant(&narrow, 20.0, 0.0099));
    assert!(!viable::braking_curve_is_invariant(&narrow, 20.0, 0.0101));
    let slow = DofLimits {
        velocity_max: 0.1,
        ..k
    };
    assert!(viable::braking_curve_is_invariant(&slow, 20.0, 0.0049));
    assert!(!viable::braking_curve_is_invariant(&slow, 20.0, 0.0051));
    // The sources follow the regime: at q = 0.55 + 0.2, q̇ = 0, Δt = 0.5 the viability bound
    // is the discrete one.
    let (s, _) = compute_dof(&k, &viable_half(), 0.75, 0.0, 0.5).unwrap();
    assert_eq!(
        s.upper.viability,
        viable::no_reversal_viability_upper(0.75, 0.0, 0.95, 20.0, 0.5)
    );
    let (s, _) = compute_dof(&k, &viable_half(), 0.75, 0.0, 0.01).unwrap();
    assert_eq!(
        s.upper.viability,
        viable::viability_upper(0.75, 0.0, 0.95, 20.0, 0.01)
    );
}

#[test]
fn position_bound_branches_pinned_by_closed_forms() {
    // q̇ = 1 rad/s, Δt = 0.01 s, so −q̇/Δt = −100 and the switch is at d = q̇Δt/2 = 0.005.
    // d = 0.006: end of step 2(0.006 − 0.01)/1e-4 = −80 ≥ −100: the end-of-step bound, not
    // the peak bound −q̇²/(2d) = −83.33 (nor −q̇Δt = −0.01).
    assert_relative_eq!(
        viable::position_upper(1.0 - 0.006, 1.0, 1.0, 0.01),
        -80.0,
        epsilon = 1e-9
    );
    // d = 0.004: end of step −120 < −100: the peak bound −1/(2·0.004) = −125 (not −120,
    // nor −100).
    assert_relative_eq!(
        viable::position_upper(1.0 - 0.004, 1.0, 1.0, 0.01),
        -125.0,
        epsilon = 1e-9
    );
    // The bound is exact on both sides of it: at −125 the peak touches q_max, at −80 the end.
    assert_relative_eq!(
        peak_in_step(1.0 - 0.004, 1.0, -125.0, 0.01).max,
        1.0,
        epsilon = 1e-12
    );
    assert_relative_eq!(
        peak_in_step(1.0 - 0.006, 1.0, -80.0, 0.01).max,
        1.0,
        epsilon = 1e-12
    );
    // Δt > 1 s tells −q̇/Δt from −q̇·Δt: q̇ = 1, Δt = 2, d = 0.5: end of step
    // 2(0.5 − 2)/4 = −0.75 < −q̇/Δt = −0.5, so the peak bound −1/(2·0.5) = −1.
    assert_relative_eq!(
        viable::position_upper(0.5, 1.0, 1.0, 2.0),
        -1.0,
        epsilon = 1e-12
    );
    // Δt = 2, d = 0.9: end of step −0.55 < −0.5: peak −1/1.8.
    assert_relative_eq!(
        viable::position_upper(0.1, 1.0, 1.0, 2.0),
        -1.0 / 1.8,
        epsilon = 1e-12
    );
    // Δt = 2, d = 1.2: end of step −0.4 ≥ −0.5: end of step.
    assert_relative_eq!(
        viable::position_upper(-0.2, 1.0, 1.0, 2.0),
        -0.4,
        epsilon = 1e-12
    );
    // Moving away (q̇ < 0) with the end-of-step bound below q̇/Δt in magnitude: never the peak
    // branch. q̇ = −1, Δt = 0.01, d = 0: 2(0 + 0.01)/1e-4 = 200.
    assert_relative_eq!(
        viable::position_upper(1.0, -1.0, 1.0, 0.01),
        200.0,
        epsilon = 1e-9
    );
    // At rest on the limit: 0.
    assert_eq!(viable::position_upper(1.0, 0.0, 1.0, 0.01), 0.0);
}

#[test]
fn viability_bound_pieces_pinned_by_closed_forms() {
    // R = d − Δt q̇/2 < 0 gives −q̇/Δt; R = 0 gives v* = 0, i.e. −q̇/Δt as well.
    assert_relative_eq!(
        viable::no_reversal_viability_upper(1.0 - 0.004, 1.0, 1.0, 10.0, 0.01),
        -100.0,
        epsilon = 1e-9
    );
    assert_relative_eq!(
        viable::no_reversal_viability_upper(1.0 - 0.005, 1.0, 1.0, 10.0, 0.01),
        -100.0,
        epsilon = 1e-9
    );
    // Far from the knot at 0: d = 2.5, q̇ = 0, a = 2, Δt = 0.5 (aΔt² = 0.5): knots of h at
    // 0.25 k(k+1): 0, 0.5, 1.5, 3 → piece n = 2, v* = (2.5 + 1.5)/(0.5·3) = 8/3,
    // q̈ = (8/3)/0.5 = 16/3. The neighbouring lines give 3 (n = 1) and 2.75 (n = 3).
    assert_relative_eq!(
        viable::no_reversal_viability_upper(-1.5, 0.0, 1.0, 2.0, 0.5),
        16.0 / 3.0,
        epsilon = 1e-12
    );
    // Lower side, mirrored.
    assert_relative_eq!(
        viable::no_reversal_viability_lower(1.5, 0.0, -1.0, 2.0, 0.5),
        -16.0 / 3.0,
        epsilon = 1e-12
    );
    // Stopping distance: piece n = 2 of D at v = 2.5, a = 2, Δt = 0.5 (aΔt = 1):
    // 2.5·0.5·2.5 − 0.25·2·3 = 3.125 − 1.5 = 1.625.
    assert_relative_eq!(
        viable::stopping_distance(2.5, 2.0, 0.5),
        1.625,
        epsilon = 1e-12
    );
}
