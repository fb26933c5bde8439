//! Jerk limits (`iktc_core::limits::jerk`): on 10⁴ random joints driven back and forth into their
//! limits by a reference that jumps, the position (in-step peak included) and velocity limits
//! are kept exactly as without a jerk limit, the box never empties, and every tick whose box
//! did not relax the jerk source keeps `|q̈ − q̈₋| ≤ j_max Δt`; a jerk limit at least
//! `2 a_max/Δt` (a change across the whole acceleration range in one tick) never binds.

use iktc_core::limits::{
    compute_box, integrate_constant_acceleration, limit_jerk, peak_in_step, AccelerationBox,
    BoundMethod, DofLimits, JointLimits,
};
use rand::{Rng, SeedableRng};

/// Rounding allowed on positions \[rad\] and velocities \[rad/s\] at the limits.
const SLACK: f64 = 1e-9;
/// Rounding allowed on the jerk interval, relative to `j_max Δt` \[–\].
const JERK_ROUNDING: f64 = 1e-9;

/// One joint, PD-driven toward a target that jumps every 100 ticks between points beyond and
/// inside its range; the command is the PD's wish clamped into the box.
fn drive(limits: DofLimits, method: BoundMethod, dt: f64, rng: &mut impl Rng) -> (usize, usize) {
    let joint = JointLimits::new(vec![limits]).unwrap();
    let mut bx = AccelerationBox::new(1);
    let (mut q, mut v, mut prev) = (0.5 * (limits.position_min + limits.position_max), 0.0, 0.0);
    let (mut relaxed, mut bound) = (0, 0);
    let mut target = 0.0;
    for k in 0..600 {
        if k % 100 == 0 {
            let span = limits.position_max - limits.position_min;
            target = limits.position_min + span * rng.random_range(-0.3..1.3);
        }
        compute_box(&joint, &method, &[q], &[v], dt, &mut bx).unwrap();
        limit_jerk(&joint, &[prev], dt, &mut bx).unwrap();
        let (lo, hi) = (bx.lower[0], bx.upper[0]);
        assert!(
            lo <= hi,
            "tick {k}: empty box [{lo}, {hi}] at q {q} v {v} prev {prev}"
        );
        let wish = 400.0 * (target - q) - 40.0 * v;
        let a = wish.clamp(lo, hi);
        let dropped = bx.dropped[0];
        if dropped.jerk {
            relaxed += 1;
        } else {
            let allowed = limits.jerk_max * dt;
            assert!(
                (a - prev).abs() <= allowed * (1.0 + JERK_ROUNDING),
                "tick {k}: |Δq̈| {} > {allowed}",
                (a - prev).abs()
            );
        }
        bound += usize::from(a == lo || a == hi);
        let peak = peak_in_step(q, v, a, dt);
        assert!(
            peak.max <= limits.position_max + SLACK,
            "tick {k}: {peak:?}"
        );
        assert!(
            peak.min >= limits.position_min - SLACK,
            "tick {k}: {peak:?}"
        );
        (q, v) = integrate_constant_acceleration(q, v, a, dt);
        assert!(
            v.abs() <= limits.velocity_max * (1.0 + SLACK),
            "tick {k}: v {v}"
        );
        prev = a;
    }
    (relaxed, bound)
}

#[test]
fn jerk_limits_keep_every_other_limit_and_hold_unless_relaxed() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x7e4c);
    let (mut relaxed, mut ticks) = (0, 0);
    for case in 0..10_000 {
        let dt = [0.001, 0.005, 0.01][case % 3];
        let a_max = rng.random_range(5.0..200.0);
        let limits = DofLimits {
            position_min: -rng.random_range(0.1..1.0),
            position_max: rng.random_range(0.1..1.0),
            velocity_max: rng.random_range(0.5..5.0),
            acceleration_max: a_max,
            jerk_max: a_max * rng.random_range(5.0..100.0),
        };
        let method = if case % 2 == 0 {
            BoundMethod::viable()
        } else {
            BoundMethod::quiet()
        };
        let (r, _) = drive(limits, method, dt, &mut rng);
        relaxed += r;
        ticks += 600;
    }
    println!(
        "jerk source relaxed on {relaxed} of {ticks} ticks ({:.2} %)",
        100.0 * relaxed as f64 / ticks as f64
    );
    // The jerk limit binds most of the time it matters and gives way rarely.
    assert!(relaxed * 20 < ticks, "relaxed on {relaxed} of {ticks}");
}

#[test]
fn a_jerk_limit_spanning_the_acceleration_range_in_one_tick_never_binds() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x7e4d);
    for case in 0..1_000 {
        let dt = [0.001, 0.005, 0.01][case % 3];
        let a_max = rng.random_range(5.0..200.0);
        let limits = DofLimits {
            position_min: -0.5,
            position_max: 0.5,
            velocity_max: rng.random_range(0.5..5.0),
            acceleration_max: a_max,
            jerk_max: 2.0 * a_max / dt,
        };
        let (relaxed, _) = drive(limits, BoundMethod::quiet(), dt, &mut rng);
        assert_eq!(relaxed, 0, "case {case}");
    }
}

#[test]
fn bad_jerk_limits_and_previous_commands_are_errors() {
    let bad = DofLimits {
        jerk_max: 0.0,
        ..DofLimits::unlimited()
    };
    let e = JointLimits::new(vec![bad]).unwrap_err().to_string();
    assert!(e.contains("jerk_max"), "{e}");
    let joint = JointLimits::new(vec![DofLimits {
        jerk_max: 10.0,
        ..DofLimits::unlimited()
    }])
    .unwrap();
    let mut bx = AccelerationBox::new(1);
    assert!(limit_jerk(&joint, &[f64::NAN], 0.01, &mut bx).is_err());
    assert!(limit_jerk(&joint, &[0.0, 0.0], 0.01, &mut bx).is_err());
}
