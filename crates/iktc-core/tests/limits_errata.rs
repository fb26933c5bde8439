//! Errata §3.1: the paper's eq. (14) is not safe in discrete time; the viable bounds are.
//!
//! One joint, q ∈ [−1, 1] rad, v_max = π rad/s, a_max = 10π rad/s², starting at rest at 0 and
//! always commanding the upper bound b_u. With eq. (14) the box first empties near t ≈ 0.32 s
//! and the joint overshoots q_max. The command is b_u saturated to the acceleration the joint
//! can deliver, `max(b_u, −a_max)` (when the box is empty, b_u < −a_max); the overshoot is then
//! about 3, 16 and 31 mrad at Δt = 1, 5, 10 ms. Without the saturation the joint brakes harder
//! than a_max (so the acceleration limit is broken instead) and still overshoots.
//!
//! The expected values are computed here a second time by a plain simulation with its own
//! copy of eq. (14) and its own in-step peak (dense sampling of the parabola).

use std::f64::consts::PI;

use iktc_core::limits::{
    compute_box, integrate_constant_acceleration, peak_in_step, AccelerationBox, BoundMethod,
    BoundSource, DofLimits, JointLimits, ViableSettings,
};

const Q_MAX: f64 = 1.0;
const V_MAX: f64 = PI;
const A_MAX: f64 = 10.0 * PI;
const DURATION: f64 = 1.0;

fn limits() -> JointLimits {
    JointLimits::new(vec![DofLimits {
        position_min: -Q_MAX,
        position_max: Q_MAX,
        velocity_max: V_MAX,
        acceleration_max: A_MAX,
        jerk_max: f64::INFINITY,
    }])
    .unwrap()
}

#[derive(Debug)]
struct Run {
    first_empty: Option<f64>,
    overshoot: f64,
    most_negative_command: f64,
    any_dropped: bool,
    closest_approach: f64,
}

/// Always command b_u with the library's box; `saturate` clamps it at −a_max.
fn run_library(method: &BoundMethod, dt: f64, saturate: bool) -> Run {
    let limits = limits();
    let mut bounds = AccelerationBox::new(1);
    let (mut q, mut qd) = (0.0, 0.0);
    let mut run = Run {
        first_empty: None,
        overshoot: 0.0,
        most_negative_command: 0.0,
        any_dropped: false,
        closest_approach: Q_MAX,
    };
    let steps = (DURATION / dt).round() as usize;
    for k in 0..steps {
        compute_box(&limits, method, &[q], &[qd], dt, &mut bounds).unwrap();
        if bounds.is_empty() && run.first_empty.is_none() {
            run.first_empty = Some(k as f64 * dt);
        }
        run.any_dropped |= bounds.any_dropped();
        let mut qdd = bounds.upper[0];
        if saturate {
            qdd = qdd.max(-A_MAX);
        }
        run.most_negative_command = run.most_negative_command.min(qdd);
        let peak = peak_in_step(q, qd, qdd, dt).max;
        run.overshoot = run.overshoot.max(peak - Q_MAX);
        (q, qd) = integrate_constant_acceleration(q, qd, qdd, dt);
        run.closest_approach = run.closest_approach.min(Q_MAX - q);
    }
    run
}

/// The same experiment with eq. (14) written out here, without the library.
fn run_plain_paper(dt: f64, saturate: bool) -> (Option<f64>, f64) {
    let (mut q, mut qd) = (0.0_f64, 0.0_f64);
    let mut first_empty = None;
    let mut overshoot = 0.0_f64;
    let steps = (DURATION / dt).round() as usize;
    for k in 0..steps {
        let sqrt_up = (2.0 * A_MAX * (Q_MAX - q).max(0.0)).sqrt();
        let sqrt_down = (2.0 * A_MAX * (q + Q_MAX).max(0.0)).sqrt();
        let b_u = A_MAX.min((V_MAX - qd) / dt).min((sqrt_up - qd) / dt);
        let b_l = (-A_MAX).max((-V_MAX - qd) / dt).max((-sqrt_down - qd) / dt);
        if b_u < b_l && first_empty.is_none() {
            first_empty = Some(k as f64 * dt);
        }
        let qdd = if saturate { b_u.max(-A_MAX) } else { b_u };
        for i in 0..=1000 {
            let t = dt * f64::from(i) / 1000.0;
            overshoot = overshoot.max(q + t * qd + 0.5 * t * t * qdd - Q_MAX);
        }
        q += dt * qd + 0.5 * dt * dt * qdd;
        qd += dt * qdd;
    }
    (first_empty, overshoot)
}

#[test]
fn paper_bound_empties_and_overshoots_as_the_errata_says() {
    // (Δt [s], overshoot range [rad]) around the errata's 3, 16, 31 mrad.
    let cases = [
        (0.001, 2.5e-3, 3.7e-3),
        (0.005, 14e-3, 18e-3),
        (0.010, 28e-3, 34e-3),
    ];
    for (dt, low, high) in cases {
        let lib = run_library(&BoundMethod::Paper, dt, true);
        let (plain_empty, plain_overshoot) = run_plain_paper(dt, true);
        let empty = lib.first_empty.expect("the paper's box must empty");
        assert!(
            (0.31..=0.34).contains(&empty),
            "Δt={dt}: empties at {empty}"
        );
        assert_eq!(plain_empty, lib.first_empty, "Δt={dt}");
        assert!(
            (low..=high).contains(&lib.overshoot),
            "Δt={dt}: overshoot {} rad",
            lib.overshoot
        );
        // The dense sampling underestimates the peak by at most (q̇ Δt/1000)² / (2·…): tiny.
        assert!(
            (plain_overshoot - lib.overshoot).abs() < 1e-6,
            "Δt={dt}: plain {plain_overshoot} vs library {}",
            lib.overshoot
        );
    }
}

#[test]
fn paper_bound_unsaturated_breaks_the_acceleration_limit_and_still_overshoots() {
    for dt in [0.001, 0.005, 0.010] {
        let lib = run_library(&BoundMethod::Paper, dt, false);
        let (plain_empty, plain_overshoot) = run_plain_paper(dt, false);
        assert_eq!(plain_empty, lib.first_empty);
        assert!(
            lib.most_negative_command < -A_MAX * 1.01,
            "Δt={dt}: {lib:?}"
        );
        assert!(lib.overshoot > 1e-5, "Δt={dt}: {lib:?}");
        assert!((plain_overshoot - lib.overshoot).abs() < 1e-6);
    }
}

#[test]
fn viable_bound_never_overshoots_nor_empties_under_the_same_policy() {
    let method = BoundMethod::Viable(ViableSettings::default());
    for dt in [0.001, 0.005, 0.010] {
        for saturate in [false, true] {
            let run = run_library(&method, dt, saturate);
            assert_eq!(run.first_empty, None, "Δt={dt}: {run:?}");
            assert!(!run.any_dropped, "Δt={dt}: {run:?}");
            assert!(run.overshoot <= 1e-12, "Δt={dt}: {run:?}");
            assert!(run.most_negative_command >= -A_MAX, "Δt={dt}: {run:?}");
            // Not over-conservative: it does get close to the limit.
            assert!(run.closest_approach < 2e-3, "Δt={dt}: {run:?}");
        }
    }
}

#[test]
fn paper_bound_binding_sources_along_the_run() {
    // Before the braking phase the acceleration limit, then the velocity limit bind; the box
    // empties because the position term asks for more than a_max.
    let limits = limits();
    let mut bounds = AccelerationBox::new(1);
    let dt = 0.005;
    let (mut q, mut qd) = (0.0, 0.0);
    let mut seen = Vec::new();
    for _ in 0..100 {
        compute_box(&limits, &BoundMethod::Paper, &[q], &[qd], dt, &mut bounds).unwrap();
        let source = bounds.upper_source[0];
        if seen.last() != Some(&source) {
            seen.push(source);
        }
        if bounds.is_empty() {
            assert_eq!(source, BoundSource::PaperPosition);
            assert_eq!(bounds.lower_source[0], BoundSource::Acceleration);
            break;
        }
        let qdd = bounds.upper[0];
        (q, qd) = integrate_constant_acceleration(q, qd, qdd, dt);
    }
    assert_eq!(
        seen,
        vec![
            BoundSource::Acceleration,
            BoundSource::Velocity,
            BoundSource::PaperPosition
        ]
    );
}
