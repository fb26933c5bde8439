//! Each bound of `viable.rs` against a brute-force evaluation of the condition it stands for
//! (the trajectory of the constant-acceleration step evaluated directly, the braking policy
//! simulated step by step, bisection on the condition), on seeded random states.

use super::*;
use crate::limits::method::OutsideLimits;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Relative agreement required between a closed form and its brute-force evaluation \[–\]:
/// both are a few floating-point operations on numbers of similar size, except the bisections,
/// which run to machine precision.
const AGREE: f64 = 1e-8;

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= AGREE * (scale + a.abs() + b.abs())
}

/// The highest position over the step `[0, Δt]` \[rad\] under constant `qdd`: the ends and,
/// where the velocity vanishes inside, the vertex.
fn peak(q: f64, qd: f64, qdd: f64, dt: f64) -> f64 {
    let at = |t: f64| q + qd * t + 0.5 * qdd * t * t;
    let mut m = at(0.0).max(at(dt));
    if qdd != 0.0 {
        let t = -qd / qdd;
        if t > 0.0 && t < dt {
            m = m.max(at(t));
        }
    }
    m
}

/// The braking policy of the module documentation simulated step by step: the distance
/// travelled \[rad\] from `v` until rest.
fn simulated_stopping_distance(mut v: f64, a: f64, dt: f64) -> f64 {
    let mut x = 0.0;
    while v > 0.0 {
        let qdd = if v >= a * dt { -a } else { -v / dt };
        x += v * dt + 0.5 * qdd * dt * dt;
        v += qdd * dt;
        if v.abs() < 1e-15 * (1.0 + a * dt) {
            v = 0.0;
        }
    }
    x
}

/// A random state inside `[q_min, q_max]` of a random range, with limits over six decades.
struct Draw {
    q: f64,
    qd: f64,
    lo: f64,
    hi: f64,
    a: f64,
    dt: f64,
}

fn draw(rng: &mut ChaCha8Rng) -> Draw {
    let width = 10f64.powf(rng.random_range(-3.0..0.5));
    let lo = rng.random_range(-1.0..1.0);
    let hi = lo + width;
    let q = rng.random_range(lo..=hi);
    let dt = 10f64.powf(rng.random_range(-4.0..-1.0));
    let a = 10f64.powf(rng.random_range(-1.0..5.0));
    let qd = rng.random_range(-1.0..1.0) * (2.0 * a * width).sqrt();
    Draw {
        q,
        qd,
        lo,
        hi,
        a,
        dt,
    }
}

#[test]
fn position_upper_is_exactly_the_in_step_peak_condition() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut turning = 0;
    for _ in 0..20_000 {
        let Draw {
            q, qd, lo, hi, dt, ..
        } = draw(&mut rng);
        if (hi - q <= 0.0 && qd > 0.0) || (q - lo <= 0.0 && qd < 0.0) {
            continue; // at a limit moving out: not a viable state (fallback documented)
        }
        // The lower side on its own limit: the lowest point of the step stays above q_min.
        let bl = position_lower(q, qd, lo, dt);
        let s = 1e-6 * (1.0 + bl.abs() + qd.abs() / dt);
        assert!(-peak(-q, -qd, -(bl + s), dt) >= lo - 1e-12 * (1.0 + lo.abs()));
        assert!(-peak(-q, -qd, -(bl - s), dt) < lo);
        let b = position_upper(q, qd, hi, dt);
        let scale = 1.0 + b.abs() + qd.abs() / dt;
        let inside = b - 1e-6 * scale;
        let outside = b + 1e-6 * scale;
        let room = 1e-12 * (1.0 + hi.abs());
        assert!(
            peak(q, qd, inside, dt) <= hi + room,
            "q {q} qd {qd} hi {hi} dt {dt}"
        );
        assert!(
            peak(q, qd, outside, dt) > hi,
            "q {q} qd {qd} hi {hi} dt {dt}"
        );
        if qd > 0.0 && b < -qd / dt {
            turning += 1;
        }
        // The mirror.
        let l = position_lower(-q, -qd, -hi, dt);
        assert_eq!(l, -b);
    }
    assert!(
        turning > 100,
        "the turning branch must be exercised ({turning})"
    );
    assert_eq!(position_upper(0.0, 1.0, f64::INFINITY, 0.01), f64::INFINITY);
    // At the limit moving out: the end-of-step fallback −2q̇/Δt.
    assert_eq!(position_upper(1.0, 2.0, 1.0, 0.5), -8.0);
}

#[test]
fn stopping_distance_is_the_simulated_braking_policy() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for _ in 0..5_000 {
        let a = 10f64.powf(rng.random_range(-1.0..4.0));
        let dt = 10f64.powf(rng.random_range(-3.0..-1.0));
        let v = rng.random_range(0.0..50.0) * a * dt;
        let d = stopping_distance(v, a, dt);
        let sim = simulated_stopping_distance(v, a, dt);
        assert!(close(d, sim, 0.0), "v {v} a {a} dt {dt}: {d} vs {sim}");
        // Between the continuous distance and it plus aΔt²/8.
        let cont = v * v / (2.0 * a);
        assert!(d >= cont * (1.0 - AGREE) && d <= cont + a * dt * dt / 8.0 * (1.0 + AGREE));
    }
    // Exactly on a knot v = 3aΔt: three full steps, 4.5 aΔt² = v²/(2a).
    let (a, dt) = (2.0, 0.1);
    assert!(close(
        stopping_distance(3.0 * a * dt, a, dt),
        4.5 * a * dt * dt,
        0.0
    ));
    assert_eq!(stopping_distance(0.0, a, dt), 0.0);
    assert_eq!(stopping_distance(-1.0, a, dt), 0.0);
    assert_eq!(stopping_distance(2.0, f64::INFINITY, 0.1), 0.1);
}

/// The bracket of the bisections \[rad/s²\]: from `−q̇/Δt` (the joint at rest after the step,
/// admissible) to far above every source.
fn bracket(q: f64, qd: f64, hi: f64, a: f64, dt: f64) -> (f64, f64) {
    let lo = -qd / dt;
    (
        lo,
        lo + 4.0 * ((hi - q).max(0.0) / (dt * dt) + a + qd.abs() / dt),
    )
}

/// The boundary of a condition `ok` that holds at `lo` and fails at `up`, to machine
/// precision (200 halvings).
fn bisect(ok: impl Fn(f64) -> bool, mut lo: f64, mut up: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + up);
        if ok(mid) {
            lo = mid;
        } else {
            up = mid;
        }
    }
    lo
}

/// The largest admissible `q̈` for the no-reversal viability condition by bisection:
/// `D(q̇⁺) ≤ q_max − q⁺` with `D` simulated.
fn bisect_no_reversal(q: f64, qd: f64, hi: f64, a: f64, dt: f64) -> f64 {
    let ok = |qdd: f64| {
        let v = qd + dt * qdd;
        let next = q + dt * qd + 0.5 * dt * dt * qdd;
        v < 0.0 || simulated_stopping_distance(v, a, dt) <= (hi - q).max(0.0) - (next - q)
    };
    let (lo, up) = bracket(q, qd, hi, a, dt);
    assert!(ok(lo) && !ok(up));
    bisect(ok, lo, up)
}

#[test]
fn no_reversal_viability_is_the_largest_acceleration_that_can_still_stop() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let mut compared = 0;
    for _ in 0..3_000 {
        let Draw {
            q, qd, hi, a, dt, ..
        } = draw(&mut rng);
        if (hi - q) / (a * dt * dt) > 1e4 {
            continue; // the simulation would take too many steps
        }
        let b = no_reversal_viability_upper(q, qd, hi, a, dt);
        let room = (hi - q) - 0.5 * dt * qd;
        if room < 0.0 {
            assert_eq!(b, -qd / dt);
            continue;
        }
        let want = bisect_no_reversal(q, qd, hi, a, dt);
        assert!(
            close(b, want, qd.abs() / dt + a),
            "q {q} qd {qd} hi {hi} a {a} dt {dt}"
        );
        let lo_mirror = no_reversal_viability_lower(-q, -qd, -hi, a, dt);
        assert_eq!(lo_mirror, -b);
        compared += 1;
    }
    assert!(compared > 1_000, "{compared}");
    assert_eq!(
        no_reversal_viability_upper(0.0, 1.0, f64::INFINITY, 1.0, 0.1),
        f64::INFINITY
    );
    // No acceleration limit: stop in one step, q̇⁺ = R/Δt.
    let (q, qd, hi, dt) = (0.0, 1.0, 1.0, 0.1);
    let b = no_reversal_viability_upper(q, qd, hi, f64::INFINITY, dt);
    assert!(close(b, ((hi - 0.5 * dt * qd) / dt - qd) / dt, 0.0));
}

/// The largest `q̈ ≥ −q̇/Δt` with `q̇⁺ ≤ √(2 a (q_max − q⁺))`, by bisection.
fn bisect_braking_curve(q: f64, qd: f64, hi: f64, a: f64, dt: f64) -> f64 {
    let ok = |qdd: f64| {
        let v = qd + dt * qdd;
        let next = q + dt * qd + 0.5 * dt * dt * qdd;
        v <= 0.0 || v * v <= 2.0 * a * ((hi - q).max(0.0) - (next - q))
    };
    let (lo, up) = bracket(q, qd, hi, a, dt);
    if !ok(lo) {
        return lo;
    }
    bisect(ok, lo, up)
}

#[test]
fn braking_curve_viability_is_the_largest_acceleration_on_the_curve() {
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    for _ in 0..10_000 {
        let Draw {
            q, qd, hi, a, dt, ..
        } = draw(&mut rng);
        let b = viability_upper(q, qd, hi, a, dt);
        let want = bisect_braking_curve(q, qd, hi, a, dt);
        assert!(
            close(b, want, qd.abs() / dt + a),
            "q {q} qd {qd} hi {hi} a {a} dt {dt}"
        );
        assert_eq!(viability_lower(-q, -qd, -hi, a, dt), -b);
    }
    // On the curve with 2q̇ ≥ aΔt: exactly −a (constant braking is integrated exactly).
    let (a, dt, d) = (3.0_f64, 0.01, 0.5);
    let qd = (2.0 * a * d).sqrt();
    assert!(close(viability_upper(0.0, qd, d, a, dt), -a, 0.0));
    assert_eq!(
        viability_upper(0.0, 1.0, f64::INFINITY, a, dt),
        f64::INFINITY
    );
    assert_eq!(
        viability_upper(0.0, 1.0, 1.0, f64::INFINITY, dt),
        f64::INFINITY
    );
}

#[test]
fn the_braking_curve_regime_has_inclusive_ends() {
    let lim = DofLimits {
        position_min: -0.5,
        position_max: 0.5,
        velocity_max: 2.0,
        acceleration_max: 100.0,
        jerk_max: f64::INFINITY,
    };
    // aΔt = v_max exactly, aΔt² = 0.2 ≤ 1: invariant; a hair above either: not.
    assert!(braking_curve_is_invariant(&lim, 20.0, 0.1));
    assert!(!braking_curve_is_invariant(&lim, 20.000001, 0.1));
    let wide = DofLimits {
        velocity_max: f64::INFINITY,
        ..lim
    };
    // aΔt² = range exactly: invariant; above: not.
    assert!(braking_curve_is_invariant(&wide, 100.0, 0.1));
    assert!(!braking_curve_is_invariant(&wide, 100.0001, 0.1));
}

#[test]
fn viable_sources_pick_the_regime_and_the_braking_fraction() {
    let settings = ViableSettings {
        braking_fraction: 0.25,
        outside: OutsideLimits::Error,
        approach_rate: 0.0,
    };
    let (q, qd, dt) = (0.3, 0.4, 0.01);
    let lim = DofLimits {
        position_min: -0.5,
        position_max: 0.5,
        velocity_max: 2.0,
        acceleration_max: 40.0,
        jerk_max: f64::INFINITY,
    };
    let s = viable_sources(&lim, &settings, q, qd, dt);
    let a_stop = 10.0;
    assert_eq!(s.upper.acceleration, 40.0);
    assert_eq!(s.lower.acceleration, -40.0);
    assert_eq!(s.upper.velocity, (2.0 - qd) / dt);
    assert_eq!(s.lower.velocity, (-2.0 - qd) / dt);
    assert_eq!(s.upper.position, position_upper(q, qd, 0.5, dt));
    assert_eq!(s.lower.position, position_lower(q, qd, -0.5, dt));
    assert_eq!(s.upper.viability, viability_upper(q, qd, 0.5, a_stop, dt));
    assert_eq!(s.lower.viability, viability_lower(q, qd, -0.5, a_stop, dt));
    // v_max below a_stop Δt: the discrete stopping distance.
    let slow = DofLimits {
        velocity_max: 0.05,
        ..lim
    };
    let s = viable_sources(&slow, &settings, q, 0.01, dt);
    assert_eq!(
        s.upper.viability,
        no_reversal_viability_upper(q, 0.01, 0.5, a_stop, dt)
    );
    assert_eq!(
        s.lower.viability,
        no_reversal_viability_lower(q, 0.01, -0.5, a_stop, dt)
    );
}

/// From rest outside the range (either side), recovery keeps |q̈| ≤ a_max and |q̇| ≤ v_max,
/// never overshoots into the range's far side, and arrives within the threshold, at rest.
#[test]
fn recovery_returns_at_rest_within_the_limits() {
    let settings = ViableSettings::default();
    let lim = DofLimits {
        position_min: -0.5,
        position_max: 0.5,
        velocity_max: 1.0,
        acceleration_max: 10.0,
        jerk_max: f64::INFINITY,
    };
    let dt = 0.005;
    for start in [0.9, -0.9, 0.5 + 2e-9, -0.5 - 2e-9] {
        let (mut q, mut qd) = (start, 0.0);
        let mut ticks = 0;
        while let Some(qdd) = recovery_acceleration(&lim, &settings, q, qd, dt) {
            assert!(qdd.abs() <= lim.acceleration_max, "start {start}: q̈ {qdd}");
            assert!(qdd * start < 0.0 || qd * start < 0.0, "toward the range");
            q += dt * qd + 0.5 * dt * dt * qdd;
            qd += dt * qdd;
            assert!(qd.abs() <= lim.velocity_max * (1.0 + AGREE));
            assert!(q > lim.position_min - 1.0 && q < lim.position_max + 1.0);
            ticks += 1;
            assert!(ticks < 10_000, "start {start}: no return");
        }
        assert!(q.abs() <= 0.5 + RECOVERY_THRESHOLD, "start {start}: q {q}");
        assert!(q.abs() >= 0.5 - 1e-6, "start {start}: overshoot to {q}");
        // It arrives slowly enough to stop inside: |q̇| within a braking step.
        assert!(
            qd.abs() <= 0.5 * lim.acceleration_max * dt,
            "start {start}: q̇ {qd}"
        );
        if start.abs() > 0.6 {
            // Time-optimal within the limits: accelerate at a_max to v_max (0.1 s, 0.05 rad),
            // cruise, brake at a_stop = 5 rad/s² (0.2 s, 0.1 rad): 0.1 + 0.25 + 0.2 = 0.55 s,
            // 110 ticks; the discrete braking profile adds up to a few ticks.
            assert!((105..=125).contains(&ticks), "start {start}: {ticks} ticks");
        }
    }
    // Inside (and within the threshold outside) there is nothing to recover.
    assert_eq!(recovery_acceleration(&lim, &settings, 0.5, 0.0, dt), None);
    assert_eq!(
        recovery_acceleration(&lim, &settings, 0.5 + 5e-10, 0.0, dt),
        None
    );
    assert_eq!(
        recovery_acceleration(&lim, &settings, -0.5 - 5e-10, 0.0, dt),
        None
    );
    assert_eq!(recovery_acceleration(&lim, &settings, 0.0, 0.3, dt), None);
}

/// At rest a hair below the limit with `a_stop Δt² ≫ d`, the larger root is
/// `(−aΔt + √(a²Δt² + 8ad))/(2Δt) ≈ 2d/Δt²` (relative error `4d/(aΔt²)`, here 1e-20), the
/// difference of two nearly equal numbers if evaluated as printed: the bound must come from the
/// cancellation-free form.
#[test]
fn the_larger_root_is_free_of_cancellation() {
    let (d, a, dt) = (1e-15, 1e9, 1e-2);
    let want = 2.0 * d / (dt * dt);
    let got = viability_upper(0.0, 0.0, d, a, dt);
    assert!((got - want).abs() <= 1e-9 * want, "{got} vs {want}");
    let got = viability_lower(0.0, 0.0, -d, a, dt);
    assert!((got + want).abs() <= 1e-9 * want, "{got} vs {want}");
}
