//! States outside the limits: `JointLimits::check_state` names the joint, its value and its
//! range; with `OutsideLimits::Recover` a joint outside its range is brought back at the
//! acceleration limit, reported as `BoundSource::Recovery`, without crossing any other limit.

use iktc_core::limits::{
    compute_box, compute_dof, integrate_constant_acceleration, peak_in_step, viable,
    AccelerationBox, BoundMethod, BoundSource, DofLimits, JointLimits, OutsideLimits,
    ViableSettings,
};
use iktc_core::Error;

/// Relative rounding allowed on the acceleration limit [–].
const ROUNDING: f64 = 1e-12;

fn knee() -> DofLimits {
    DofLimits {
        position_min: 0.55,
        position_max: 0.95,
        velocity_max: 4.0,
        acceleration_max: 40.0,
        jerk_max: f64::INFINITY,
    }
}

fn recover(fraction: f64) -> BoundMethod {
    BoundMethod::Viable(ViableSettings {
        braking_fraction: fraction,
        outside: OutsideLimits::Recover,
        approach_rate: 0.0,
    })
}

#[test]
fn check_state_names_the_joint_its_value_and_its_range() {
    let limits = JointLimits::new(vec![DofLimits::unlimited(), knee()])
        .unwrap()
        .with_names(vec!["base".into(), "L_KNEE".into()])
        .unwrap();
    assert!(limits.check_state(&[3.0, 0.55], &[9.0, -4.0]).is_ok());
    assert!(limits.check_state(&[3.0, 0.95], &[9.0, 4.0]).is_ok());
    let err = limits.check_state(&[0.0, 1.2], &[0.0, 0.0]).unwrap_err();
    assert_eq!(
        err,
        Error::StateOutsideLimits {
            joint: "L_KNEE".into(),
            quantity: "position [rad or m]".into(),
            value: 1.2,
            lower: 0.55,
            upper: 0.95,
        }
    );
    match limits.check_state(&[0.0, 0.5], &[0.0, 0.0]) {
        Err(Error::StateOutsideLimits { value, lower, .. }) => {
            assert_eq!((value, lower), (0.5, 0.55))
        }
        other => panic!("{other:?}"),
    }
    let text = err.to_string();
    assert!(
        text.contains("L_KNEE") && text.contains("1.2") && text.contains("0.55"),
        "{text}"
    );
    match limits.check_state(&[0.0, 0.6], &[0.0, -4.5]) {
        Err(Error::StateOutsideLimits {
            value,
            lower,
            upper,
            ..
        }) => assert_eq!((value, lower, upper), (-4.5, -4.0, 4.0)),
        other => panic!("{other:?}"),
    }
    // Unnamed limits are named by index; bad input is an error, not a panic.
    let unnamed = JointLimits::new(vec![knee()]).unwrap();
    match unnamed.check_state(&[0.0], &[0.0]) {
        Err(Error::StateOutsideLimits { joint, .. }) => assert_eq!(joint, "dof[0]"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        unnamed.check_state(&[0.6, 0.7], &[0.0]),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        unnamed.check_state(&[f64::NAN], &[0.0]),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        JointLimits::new(vec![knee()]).unwrap().with_names(vec![]),
        Err(Error::DimensionMismatch { .. })
    ));
    assert_eq!(limits.name(1), Some("L_KNEE"));
    assert_eq!(limits.name(2), None);
}

#[test]
fn paper_bounds_never_recover() {
    assert_eq!(BoundMethod::Paper.outside_limits(), OutsideLimits::Error);
    assert_eq!(
        BoundMethod::default().outside_limits(),
        OutsideLimits::Error
    );
    assert_eq!(recover(0.5).outside_limits(), OutsideLimits::Recover);
}

/// Runs the recovery of one dof from `(q, qd)` and checks it, step by step, against
/// independently computed limits. Returns the number of recovering ticks.
fn recover_and_check(limits: &DofLimits, fraction: f64, q0: f64, qd0: f64, dt: f64) -> usize {
    let method = recover(fraction);
    let (mut q, mut qd) = (q0, qd0);
    let mut recovering = 0;
    let mut back = false;
    let excursion = |q: f64| {
        (q - limits.position_max)
            .max(limits.position_min - q)
            .max(0.0)
    };
    // Recovery leaves excursions up to the threshold to the ordinary (widened) bounds.
    let recovers = |q: f64| excursion(q) > viable::RECOVERY_THRESHOLD;
    for step in 0..20_000 {
        let (_, b) = compute_dof(limits, &method, q, qd, dt).unwrap();
        assert!(!b.is_empty(), "step {step}: {b:?}");
        let outside = recovers(q);
        assert_eq!(
            b.lower_source == BoundSource::Recovery,
            outside,
            "step {step}"
        );
        if outside {
            assert!(!back, "left the range again at step {step}");
            assert_eq!(b.lower, b.upper);
            recovering += 1;
        } else {
            back = true;
        }
        // Push to the upper edge of the box: the worst case once back inside.
        let qdd = b.upper;
        // With a_stop = a_max the braking acceleration sits on the limit and rounding may
        // drop it by a few ulps (documented in `limits::viable`).
        assert!(
            qdd.abs() <= limits.acceleration_max * (1.0 + ROUNDING),
            "step {step}: {qdd}"
        );
        let peak = peak_in_step(q, qd, qdd, dt);
        let (q1, qd1) = integrate_constant_acceleration(q, qd, qdd, dt);
        assert!(
            qd1.abs() <= limits.velocity_max * (1.0 + 1e-12),
            "step {step}: {qd1}"
        );
        if outside {
            // Recovering: the far end is never crossed, the excursion never grows beyond
            // what a state moving out needs to turn round.
            let far = if q > limits.position_max {
                peak.min - limits.position_min
            } else {
                limits.position_max - peak.max
            };
            assert!(far >= 0.0, "step {step}");
            if qd * (q - limits.position_max).signum() <= 0.0 {
                assert!(excursion(q1) <= excursion(q), "step {step}");
            }
        } else {
            assert!(
                limits.excursion(peak) <= viable::RECOVERY_THRESHOLD,
                "step {step}: {peak:?}"
            );
        }
        (q, qd) = (q1, qd1);
        if back && step > recovering + 200 {
            break;
        }
    }
    assert!(
        back,
        "never came back from ({q0}, {qd0}), dt {dt}, fraction {fraction}: ({q}, {qd})"
    );
    recovering
}

#[test]
fn recovery_brings_the_joint_back_and_keeps_every_other_limit() {
    let k = knee();
    let mut total = 0;
    for dt in [1e-3, 0.005, 0.05, 0.5] {
        for fraction in [0.5, 1.0] {
            // Above, at rest, far and near; below; moving out at up to v_max.
            for (q, qd) in [
                (10.0, 0.0),
                (1.2, 0.0),
                (0.95 + 1e-6, 0.0),
                (0.0, 0.0),
                (1.2, 3.0),
                (0.3, -4.0),
            ] {
                let ticks = recover_and_check(&k, fraction, q, qd, dt);
                assert!(ticks >= 1);
                total += ticks;
            }
        }
    }
    assert!(total > 1000, "{total}");
}

#[test]
fn recovery_acceleration_by_hand() {
    // From rest 1 rad above q_max = 0.95, a_max = 40, a_stop = 20, Δt = 0.01, v_max = 4:
    // far from the range the joint accelerates in at the full limit.
    let k = knee();
    let s = ViableSettings {
        braking_fraction: 0.5,
        outside: OutsideLimits::Recover,
        approach_rate: 0.0,
    };
    assert_eq!(
        viable::recovery_acceleration(&k, &s, 1.95, 0.0, 0.01),
        Some(-40.0)
    );
    // At full speed inward, it holds the speed: the velocity bound (−4 + 4)/0.01 = 0.
    assert_eq!(
        viable::recovery_acceleration(&k, &s, 1.95, -4.0, 0.01),
        Some(0.0)
    );
    // Moving in faster than it can brake on q_max (q = 0.96, q̇ = −4, Δt = 0.01): the peak
    // bound of the virtual limit asks 4²/(2·0.01) = 800 rad/s², capped at a_max = 40.
    assert_eq!(
        viable::recovery_acceleration(&k, &s, 0.96, -4.0, 0.01),
        Some(40.0)
    );
    assert_eq!(
        viable::recovery_acceleration(&k, &s, 0.54, 4.0, 0.01),
        Some(-40.0)
    );
    // Inside the range: none.
    assert_eq!(viable::recovery_acceleration(&k, &s, 0.7, 0.0, 0.01), None);
    // Within the threshold: left to the ordinary bounds; beyond it: recovered.
    let t = viable::RECOVERY_THRESHOLD;
    assert_eq!(
        viable::recovery_acceleration(&k, &s, 0.95 + 0.5 * t, 0.0, 0.01),
        None
    );
    assert_eq!(
        viable::recovery_acceleration(&k, &s, 0.55 - 0.5 * t, 0.0, 0.01),
        None
    );
    assert!(viable::recovery_acceleration(&k, &s, 0.95 + 2.0 * t, 0.0, 0.01).unwrap() < 0.0);
    assert!(viable::recovery_acceleration(&k, &s, 0.55 - 2.0 * t, 0.0, 0.01).unwrap() > 0.0);
    // Just above, at rest: the braking condition toward q_max decides. d = 0.001 above,
    // a_stop Δt² = 0.002, the knots of h at 0.001 k(k+1): R = 0.001 lies on piece k = 0,
    // v* = R/Δt = 0.1 rad/s, q̈ = −0.1/0.01 = −10.
    let x = viable::recovery_acceleration(&k, &s, 0.951, 0.0, 0.01).unwrap();
    assert!((x + 10.0).abs() < 1e-9, "{x}");
    // Below the range, the mirror image.
    let y = viable::recovery_acceleration(&k, &s, 0.549, 0.0, 0.01).unwrap();
    assert!((y - 10.0).abs() < 1e-9, "{y}");
}

#[test]
fn recovering_dofs_are_reported_by_the_box() {
    let limits = JointLimits::new(vec![knee(), knee(), DofLimits::unlimited()]).unwrap();
    let mut out = AccelerationBox::new(3);
    compute_box(
        &limits,
        &recover(0.5),
        &[1.2, 0.7, 5.0],
        &[0.0; 3],
        0.005,
        &mut out,
    )
    .unwrap();
    assert_eq!(out.recovering_dofs().collect::<Vec<_>>(), vec![0]);
    assert_eq!(out.upper_source[0], BoundSource::Recovery);
    // Without recovery the same state is bounded (widened range), not driven.
    compute_box(
        &limits,
        &BoundMethod::default(),
        &[1.2, 0.7, 5.0],
        &[0.0; 3],
        0.005,
        &mut out,
    )
    .unwrap();
    assert_eq!(out.recovering_dofs().count(), 0);
    assert!(out.lower[0] < out.upper[0]);
}
