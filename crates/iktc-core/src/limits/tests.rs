//! Unit tests of the box pipeline: intersection and conflict resolution against a direct
//! evaluation of their documented rule, the paper's and the velocity terms against hand
//! values, the integrator against its closed form, the validation rules one by one.

use super::*;
use crate::error::Error;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The rule of [`intersect`] evaluated directly: try the kept sets in order (all; without the
/// acceleration limit; without the viability bound as well), take the first non-empty
/// intersection, then, if the acceleration limit was dropped, the part closest to ±a_max.
fn rule(s: &DofBoundSources, viable: bool) -> (f64, f64, bool, bool) {
    let lows = [
        s.lower.position,
        s.lower.viability,
        s.lower.velocity,
        s.lower.acceleration,
    ];
    let ups = [
        s.upper.position,
        s.upper.viability,
        s.upper.velocity,
        s.upper.acceleration,
    ];
    let attempts: &[[bool; 4]] = if viable {
        &[
            [true; 4],
            [true, true, true, false],
            [true, false, true, false],
        ]
    } else {
        &[[true; 4]]
    };
    let mut last = (f64::NAN, f64::NAN, [true; 4]);
    for keep in attempts {
        let l = (0..4)
            .filter(|&k| keep[k])
            .map(|k| lows[k])
            .fold(f64::NEG_INFINITY, f64::max);
        let u = (0..4)
            .filter(|&k| keep[k])
            .map(|k| ups[k])
            .fold(f64::INFINITY, f64::min);
        last = (l, u, *keep);
        if l <= u {
            break;
        }
    }
    let (mut l, mut u, keep) = last;
    let dropped_acc = !keep[3];
    let dropped_via = !keep[1];
    if dropped_acc && l <= u {
        let (al, au) = (s.lower.acceleration, s.upper.acceleration);
        let (l0, u0) = (l, u);
        l = l0.max(al.min(u0));
        u = u0.min(au.max(l0));
        return (l, u, l < al || u > au, dropped_via);
    }
    (l, u, dropped_acc, dropped_via)
}

fn pick(rng: &mut ChaCha8Rng, sign: f64) -> f64 {
    const VALUES: [f64; 7] = [-3.0, -1.0, 0.0, 0.5, 1.0, 2.0, 4.0];
    if rng.random_bool(0.15) {
        sign * f64::INFINITY
    } else {
        VALUES[rng.random_range(0..VALUES.len())]
    }
}

#[test]
fn intersect_follows_its_rule_on_every_combination() {
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let (mut empty, mut exceeded, mut via) = (0, 0, 0);
    for case in 0..20_000 {
        let mut side = |sign: f64| SourceBounds {
            acceleration: sign * rng.random_range(0.5..3.0),
            velocity: pick(&mut rng, sign),
            position: pick(&mut rng, sign),
            viability: pick(&mut rng, sign),
            jerk: f64::INFINITY * sign,
            approach: f64::INFINITY * sign,
        };
        let s = DofBoundSources {
            lower: side(-1.0),
            upper: side(1.0),
        };
        let viable = case % 3 != 0;
        let method = if viable {
            BoundMethod::viable()
        } else {
            BoundMethod::Paper
        };
        let b = intersect(&s, &method);
        let (l, u, acc, vi) = rule(&s, viable);
        assert_eq!((b.lower, b.upper), (l, u), "case {case}: {s:?}");
        assert_eq!(b.dropped.acceleration, acc, "case {case}: {s:?}");
        assert_eq!(b.dropped.viability, vi, "case {case}: {s:?}");
        assert_eq!(b.is_empty(), l > u);
        empty += usize::from(l > u);
        exceeded += usize::from(acc);
        via += usize::from(vi);
        // The binding source attains the bound (or the bound is infinite and named None).
        for (value, source, lower) in [
            (b.lower, b.lower_source, true),
            (b.upper, b.upper_source, false),
        ] {
            let side = if lower { &s.lower } else { &s.upper };
            let named = match source {
                BoundSource::None => f64::INFINITY.copysign(if lower { -1.0 } else { 1.0 }),
                BoundSource::Acceleration => side.acceleration,
                BoundSource::Velocity => side.velocity,
                BoundSource::Position | BoundSource::PaperPosition => side.position,
                BoundSource::Viability => side.viability,
                BoundSource::Recovery | BoundSource::Jerk => f64::NAN,
                BoundSource::Approach => side.approach,
            };
            // After conflict resolution a side may take the other side's value and source.
            let other = if lower { &s.upper } else { &s.lower };
            let other_named = match source {
                BoundSource::Velocity => other.velocity,
                BoundSource::Position => other.position,
                BoundSource::Viability => other.viability,
                _ => f64::NAN,
            };
            assert!(
                named == value || other_named == value,
                "case {case}: {source:?} {value} {s:?}"
            );
        }
        let position_name = if viable {
            BoundSource::Position
        } else {
            BoundSource::PaperPosition
        };
        if b.upper == s.upper.position && !b.dropped.acceleration {
            assert_eq!(
                b.upper_source, position_name,
                "ties name the position first"
            );
        }
    }
    assert!(
        empty > 100 && exceeded > 100 && via > 50,
        "{empty} {exceeded} {via}"
    );
}

#[test]
fn ties_name_position_then_viability_then_velocity_then_acceleration() {
    let side = |v: f64| SourceBounds {
        acceleration: v,
        velocity: v,
        position: v,
        viability: v,
        jerk: v,
        approach: v,
    };
    let s = DofBoundSources {
        lower: side(-1.0),
        upper: side(1.0),
    };
    let b = intersect(&s, &BoundMethod::viable());
    assert_eq!(
        (b.lower_source, b.upper_source),
        (BoundSource::Position, BoundSource::Position)
    );
    let mut t = s;
    t.upper.position = f64::INFINITY;
    t.lower.position = f64::NEG_INFINITY;
    let b = intersect(&t, &BoundMethod::viable());
    assert_eq!(
        (b.lower_source, b.upper_source),
        (BoundSource::Viability, BoundSource::Viability)
    );
    t.upper.viability = f64::INFINITY;
    let b = intersect(&t, &BoundMethod::viable());
    assert_eq!(b.upper_source, BoundSource::Velocity);
    t.upper.velocity = f64::INFINITY;
    let b = intersect(&t, &BoundMethod::viable());
    assert_eq!(b.upper_source, BoundSource::Acceleration);
    let none = DofBoundSources::default();
    let b = intersect(&none, &BoundMethod::Paper);
    assert_eq!((b.lower, b.upper), (f64::NEG_INFINITY, f64::INFINITY));
    assert_eq!(
        (b.lower_source, b.upper_source),
        (BoundSource::None, BoundSource::None)
    );
    assert!(!b.dropped.any());
    assert!(DroppedSources {
        acceleration: false,
        viability: true,
        jerk: false,
        approach: false,
    }
    .any());
    assert!(DroppedSources {
        jerk: true,
        ..DroppedSources::default()
    }
    .any());
}

#[test]
fn paper_terms_equal_the_printed_formula() {
    let (q, qd, dt, a) = (0.2, 0.3, 0.01, 8.0);
    let want = ((2.0 * a * (1.0_f64 - q)).sqrt() - qd) / dt;
    assert_eq!(paper::position_term_upper(q, qd, 1.0, a, dt), want);
    let want = (-(2.0 * a * (q + 1.0_f64)).sqrt() - qd) / dt;
    assert_eq!(paper::position_term_lower(q, qd, -1.0, a, dt), want);
    // Beyond the range: −q̇/Δt; no range or no acceleration limit: unbounded.
    assert_eq!(paper::position_term_upper(1.5, qd, 1.0, a, dt), -qd / dt);
    assert_eq!(paper::position_term_upper(1.0, qd, 1.0, a, dt), -qd / dt);
    assert_eq!(
        paper::position_term_upper(q, qd, f64::INFINITY, a, dt),
        f64::INFINITY
    );
    assert_eq!(
        paper::position_term_upper(q, qd, 1.0, f64::INFINITY, dt),
        f64::INFINITY
    );
    let lim = DofLimits {
        position_min: -1.0,
        position_max: 1.0,
        velocity_max: 2.0,
        acceleration_max: a,
        jerk_max: f64::INFINITY,
    };
    let s = paper_sources(&lim, q, qd, dt);
    assert_eq!((s.lower.acceleration, s.upper.acceleration), (-a, a));
    assert_eq!(s.upper.velocity, (2.0 - qd) / dt);
    assert_eq!(s.lower.velocity, (-2.0 - qd) / dt);
    assert_eq!(
        s.upper.position,
        paper::position_term_upper(q, qd, 1.0, a, dt)
    );
    assert_eq!(
        s.lower.position,
        paper::position_term_lower(q, qd, -1.0, a, dt)
    );
    assert_eq!(
        (s.lower.viability, s.upper.viability),
        (f64::NEG_INFINITY, f64::INFINITY)
    );
}

#[test]
fn velocity_terms_and_the_integrator_match_their_closed_forms() {
    assert_eq!(velocity_upper(0.5, 2.0, 0.1), 15.0);
    assert_eq!(velocity_lower(0.5, 2.0, 0.1), -25.0);
    assert_eq!(velocity_upper(0.5, f64::INFINITY, 0.1), f64::INFINITY);
    assert_eq!(velocity_lower(0.5, f64::INFINITY, 0.1), f64::NEG_INFINITY);
    assert_eq!(
        integrate_constant_acceleration(1.0, 2.0, 4.0, 0.5),
        (2.5, 4.0)
    );
    // The extremes against a dense sampling of the parabola.
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    for _ in 0..2_000 {
        let (q, qd, qdd) = (
            rng.random_range(-1.0..1.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-50.0..50.0),
        );
        let dt = rng.random_range(0.001..0.2);
        let e = peak_in_step(q, qd, qdd, dt);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..=2000 {
            let t = dt * f64::from(k) / 2000.0;
            let x = q + qd * t + 0.5 * qdd * t * t;
            lo = lo.min(x);
            hi = hi.max(x);
        }
        // The sampling misses the true extreme by at most |q̈| (Δt/2000)²/2.
        let grid = 0.5 * qdd.abs() * (dt / 2000.0).powi(2) + 1e-15;
        assert!(
            e.max >= hi - 1e-15 && e.max <= hi + grid,
            "{e:?} vs [{lo}, {hi}]"
        );
        assert!(
            e.min <= lo + 1e-15 && e.min >= lo - grid,
            "{e:?} vs [{lo}, {hi}]"
        );
    }
    let lim = DofLimits {
        position_min: -1.0,
        position_max: 1.0,
        velocity_max: 1.0,
        acceleration_max: 1.0,
        jerk_max: f64::INFINITY,
    };
    assert_eq!(
        lim.excursion(StepExtremes {
            min: -0.5,
            max: 0.5
        }),
        0.0
    );
    assert_eq!(
        lim.excursion(StepExtremes {
            min: -0.5,
            max: 1.25
        }),
        0.25
    );
    assert_eq!(
        lim.excursion(StepExtremes {
            min: -1.5,
            max: 1.25
        }),
        0.5
    );
}

fn dof(lo: f64, hi: f64, v: f64, a: f64) -> DofLimits {
    DofLimits {
        position_min: lo,
        position_max: hi,
        velocity_max: v,
        acceleration_max: a,
        jerk_max: f64::INFINITY,
    }
}

#[test]
fn every_validation_rule_has_its_error() {
    assert!(dof(-1.0, 1.0, 1.0, 1.0).validate("j").is_ok());
    assert!(dof(0.0, 0.0, f64::INFINITY, f64::INFINITY)
        .validate("j")
        .is_ok());
    assert!(DofLimits::unlimited().validate("j").is_ok());
    for bad in [
        dof(f64::NAN, 1.0, 1.0, 1.0),
        dof(-1.0, f64::NAN, 1.0, 1.0),
        dof(-1.0, 1.0, f64::NAN, 1.0),
        dof(-1.0, 1.0, 1.0, f64::NAN),
    ] {
        assert!(
            matches!(bad.validate("j"), Err(Error::NonFinite { .. })),
            "{bad:?}"
        );
    }
    for bad in [
        dof(1.0, -1.0, 1.0, 1.0),
        dof(f64::INFINITY, f64::INFINITY, 1.0, 1.0),
        dof(f64::NEG_INFINITY, f64::NEG_INFINITY, 1.0, 1.0),
    ] {
        assert!(
            matches!(bad.validate("j"), Err(Error::InvalidLimit { .. })),
            "{bad:?}"
        );
    }
    for bad in [
        dof(-1.0, 1.0, 0.0, 1.0),
        dof(-1.0, 1.0, -1.0, 1.0),
        dof(-1.0, 1.0, 1.0, 0.0),
        dof(-1.0, 1.0, 1.0, -2.0),
    ] {
        assert!(
            matches!(bad.validate("j"), Err(Error::InvalidSetting { .. })),
            "{bad:?}"
        );
    }
    for f in [0.0, -0.5, 1.5, f64::NAN, f64::INFINITY] {
        let s = ViableSettings {
            braking_fraction: f,
            outside: OutsideLimits::Error,
            approach_rate: 0.0,
        };
        assert!(s.validate().is_err(), "{f}");
        assert!(BoundMethod::Viable(s).validate().is_err());
        assert!(BoundMethod::Quiet(s).validate().is_err());
    }
    for f in [1e-6, 0.5, 1.0] {
        let s = ViableSettings {
            braking_fraction: f,
            outside: OutsideLimits::Error,
            approach_rate: 0.0,
        };
        assert!(s.validate().is_ok(), "{f}");
    }
    assert!(BoundMethod::Paper.validate().is_ok());
    assert_eq!(BoundMethod::Paper.name(), "paper");
    assert_eq!(BoundMethod::viable().name(), "viable");
    assert_eq!(BoundMethod::quiet().name(), "quiet");
    assert_eq!(BoundMethod::default(), BoundMethod::quiet());
    let recover = ViableSettings {
        braking_fraction: 0.5,
        outside: OutsideLimits::Recover,
        approach_rate: 0.0,
    };
    assert_eq!(
        BoundMethod::Viable(recover).outside_limits(),
        OutsideLimits::Recover
    );
    assert_eq!(
        BoundMethod::Quiet(recover).outside_limits(),
        OutsideLimits::Recover
    );
    assert_eq!(BoundMethod::Paper.outside_limits(), OutsideLimits::Error);
    assert_eq!(BoundMethod::viable().outside_limits(), OutsideLimits::Error);
}

#[test]
fn joint_limits_check_states_and_sets() {
    let mut lim = JointLimits::new(vec![dof(-1.0, 1.0, 2.0, 3.0), dof(0.0, 0.5, 1.0, 1.0)])
        .and_then(|l| l.with_names(vec!["A".into(), "B".into()]))
        .expect("valid limits");
    assert_eq!(lim.nv(), 2);
    assert_eq!(lim.name(1), Some("B"));
    assert_eq!(lim.name(2), None);
    assert!(lim.check_state(&[1.0, 0.0], &[-2.0, 1.0]).is_ok());
    let err = lim.check_state(&[0.0, 0.6], &[0.0, 0.0]);
    assert!(
        matches!(&err, Err(Error::StateOutsideLimits { joint, value, .. }) if joint == "B" && *value == 0.6),
        "{err:?}"
    );
    assert!(matches!(
        lim.check_state(&[-1.1, 0.0], &[0.0, 0.0]),
        Err(Error::StateOutsideLimits { .. })
    ));
    let err = lim.check_state(&[0.0, 0.0], &[2.5, 0.0]);
    assert!(
        matches!(&err, Err(Error::StateOutsideLimits { lower, upper, .. }) if *lower == -2.0 && *upper == 2.0),
        "{err:?}"
    );
    assert!(matches!(
        lim.check_state(&[0.0, 0.0], &[-2.5, 0.0]),
        Err(Error::StateOutsideLimits { .. })
    ));
    assert!(matches!(
        lim.check_state(&[0.0], &[0.0, 0.0]),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        lim.check_state(&[0.0, 0.0], &[0.0]),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        lim.check_state(&[0.0, f64::NAN], &[0.0, 0.0]),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        lim.check_state(&[0.0, 0.0], &[f64::INFINITY, 0.0]),
        Err(Error::NonFinite { .. })
    ));
    assert!(lim.set(1, dof(0.0, 0.25, 1.0, 1.0)).is_ok());
    assert_eq!(lim.get(1).map(|d| d.position_max), Some(0.25));
    assert!(lim.set(1, dof(1.0, 0.0, 1.0, 1.0)).is_err());
    assert!(matches!(
        lim.set(2, dof(0.0, 1.0, 1.0, 1.0)),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(lim.clone().with_names(vec!["A".into()]).is_err());
    assert!(JointLimits::new(vec![dof(1.0, 0.0, 1.0, 1.0)]).is_err());
    let free = JointLimits::unlimited(3);
    assert_eq!(free.nv(), 3);
    assert_eq!(free.name(2), Some("dof[2]"));
    assert_eq!(free.dofs()[0], DofLimits::unlimited());
}

#[test]
fn compute_box_fills_every_dof_and_rejects_bad_input_unchanged() {
    let lim = JointLimits::new(vec![
        dof(-1.0, 1.0, 2.0, 10.0),
        dof(0.25, 0.25, 1.0, 10.0),
        DofLimits::unlimited(),
    ])
    .expect("valid limits");
    let (q, qd, dt) = ([0.9, 0.25, 3.0], [0.5, 0.01, 1.0], 0.01);
    let mut out = AccelerationBox::new(3);
    let method = BoundMethod::viable();
    compute_box(&lim, &method, &q, &qd, dt, &mut out).expect("valid input");
    for i in 0..3 {
        let (s, b) = compute_dof(&lim.dofs()[i], &method, q[i], qd[i], dt).expect("valid");
        assert_eq!(out.sources[i], s);
        assert_eq!((out.lower[i], out.upper[i]), (b.lower, b.upper));
        assert_eq!(
            (out.lower_source[i], out.upper_source[i]),
            (b.lower_source, b.upper_source)
        );
        assert_eq!(out.dropped[i], b.dropped);
    }
    // The zero-width range stops the joint within the step.
    assert_eq!((out.lower[1], out.upper[1]), (-1.0, -1.0));
    // Unlimited: unbounded.
    assert_eq!(
        (out.lower[2], out.upper[2]),
        (f64::NEG_INFINITY, f64::INFINITY)
    );
    // The paper's bound holds no zero-width special case.
    let (_, b) = compute_dof(&lim.dofs()[1], &BoundMethod::Paper, 0.25, 0.0, dt).expect("valid");
    assert_eq!((b.lower, b.upper), (0.0, 0.0));
    assert_eq!(b.upper_source, BoundSource::PaperPosition);
    let before = out.clone();
    let bad_inputs: [(&[f64], &[f64], f64); 7] = [
        (&q, &qd, 0.0),
        (&q, &qd, -0.01),
        (&q, &qd, f64::NAN),
        (&q[..2], &qd, dt),
        (&q, &qd[..2], dt),
        (&[0.0, f64::NAN, 0.0], &qd, dt),
        (&q, &[0.0, 0.0, f64::INFINITY], dt),
    ];
    for (pos, vel, step) in bad_inputs {
        assert!(compute_box(&lim, &method, pos, vel, step, &mut out).is_err());
        assert_eq!(out, before);
    }
    let mut small = AccelerationBox::new(2);
    assert!(compute_box(&lim, &method, &q, &qd, dt, &mut small).is_err());
    let bad_method = BoundMethod::Viable(ViableSettings {
        braking_fraction: 2.0,
        outside: OutsideLimits::Error,
        approach_rate: 0.0,
    });
    assert!(compute_box(&lim, &bad_method, &q, &qd, dt, &mut out).is_err());
    assert!(compute_dof(&dof(1.0, 0.0, 1.0, 1.0), &method, 0.0, 0.0, dt).is_err());
    assert!(compute_dof(&lim.dofs()[0], &method, f64::NAN, 0.0, dt).is_err());
    assert!(compute_dof(&lim.dofs()[0], &method, 0.0, f64::NAN, dt).is_err());
    assert!(compute_dof(&lim.dofs()[0], &method, 0.0, 0.0, -1.0).is_err());
    assert!(compute_dof(&lim.dofs()[0], &bad_method, 0.0, 0.0, dt).is_err());
}

#[test]
fn recovery_replaces_the_box_only_outside_the_range() {
    let recover = BoundMethod::Viable(ViableSettings {
        braking_fraction: 0.5,
        outside: OutsideLimits::Recover,
        approach_rate: 0.0,
    });
    let d = dof(-1.0, 1.0, 2.0, 10.0);
    let dt = 0.01;
    let (_, b) = compute_dof(&d, &recover, 1.5, 0.0, dt).expect("valid");
    let x = viable::recovery_acceleration(&d, &ViableSettings::default(), 1.5, 0.0, dt);
    assert_eq!(Some(b.lower), x);
    assert_eq!(b.lower, b.upper);
    assert!(b.lower < 0.0);
    assert_eq!(
        (b.lower_source, b.upper_source),
        (BoundSource::Recovery, BoundSource::Recovery)
    );
    let (_, inside) = compute_dof(&d, &recover, 0.5, 0.0, dt).expect("valid");
    let (_, plain) = compute_dof(&d, &BoundMethod::viable(), 0.5, 0.0, dt).expect("valid");
    assert_eq!(inside, plain);
    // Without Recover the state outside keeps the ordinary (widened) bounds.
    let (_, kept) = compute_dof(&d, &BoundMethod::viable(), 1.5, 0.0, dt).expect("valid");
    assert_ne!(kept.upper_source, BoundSource::Recovery);
    let mut out = AccelerationBox::new(1);
    let lim = JointLimits::new(vec![d]).expect("valid");
    compute_box(&lim, &recover, &[1.5], &[0.0], dt, &mut out).expect("valid");
    assert_eq!(out.recovering_dofs().collect::<Vec<_>>(), [0]);
    compute_box(&lim, &recover, &[0.5], &[0.0], dt, &mut out).expect("valid");
    assert_eq!(out.recovering_dofs().count(), 0);
    assert!(!out.any_dropped());
    // Faster than v_max (2 rad/s over 1): only a = (v_max − q̇)/Δt = −100 rad/s² brings the
    // velocity back, beyond a_max = 10: the acceleration limit is dropped, and says so.
    let fast = JointLimits::new(vec![dof(-1.0, 1.0, 1.0, 10.0)]).expect("valid");
    compute_box(&fast, &BoundMethod::viable(), &[0.0], &[2.0], dt, &mut out).expect("valid");
    assert!(out.any_dropped());
    assert!(out.dropped[0].acceleration);
    assert_eq!(out.get(0).map(|b| b.upper), Some(out.upper[0]));
    assert_eq!(out.get(1), None);
}
