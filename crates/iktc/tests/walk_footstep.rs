//! Footstep plans: counts, alternation, positions; the root-trajectory plan against the
//! closed-form plans; bad input.

use iktc::walk::{Footstep, FootstepPlan, Pose2, RootPlanParams, RootSample, Side, WalkSettings};
use iktc::Error;

const EPS: f64 = 1e-12;

fn assert_alternates(plan: &FootstepPlan, first: Side) {
    let mut side = first;
    for s in plan.steps() {
        assert_eq!(s.side, side);
        side = side.opposite();
    }
}

#[test]
fn in_place_keeps_every_foot_where_it_was() {
    let w = WalkSettings::default();
    let plan = FootstepPlan::in_place(5, &w).unwrap();
    assert_eq!(plan.len(), 5);
    assert_alternates(&plan, Side::Left);
    let d = w.foot_separation / 2.0;
    assert_eq!(plan.initial_left(), Pose2::new(0.0, d, 0.0));
    assert_eq!(plan.initial_right(), Pose2::new(0.0, -d, 0.0));
    for s in plan.steps() {
        let expected = plan.initial(s.side);
        assert!((s.pose.x - expected.x).abs() < EPS);
        assert!((s.pose.y - expected.y).abs() < EPS);
        assert!((s.pose.yaw - expected.yaw).abs() < EPS);
    }
}

#[test]
fn first_swing_setting_is_honoured() {
    let w = WalkSettings {
        first_swing: Side::Right,
        ..WalkSettings::default()
    };
    let plan = FootstepPlan::in_place(4, &w).unwrap();
    assert_alternates(&plan, Side::Right);
}

#[test]
fn forward_advances_one_step_length_per_step_and_closes() {
    let w = WalkSettings::default();
    let (n, l) = (6, 0.2);
    let plan = FootstepPlan::forward(n, l, &w).unwrap();
    assert_eq!(plan.len(), n);
    assert_alternates(&plan, Side::Left);
    let d = w.foot_separation / 2.0;
    for (i, s) in plan.steps().iter().enumerate() {
        let k = (i + 1).min(n - 1) as f64;
        let y = if s.side == Side::Left { d } else { -d };
        assert!((s.pose.x - k * l).abs() < EPS, "step {i}: x = {}", s.pose.x);
        assert!((s.pose.y - y).abs() < EPS);
        assert_eq!(s.pose.yaw, 0.0);
    }
    // Ends side by side, (n − 1) step lengths ahead.
    let last = plan.steps()[n - 1].pose;
    let before = plan.steps()[n - 2].pose;
    assert!((last.x - before.x).abs() < EPS);
    assert!((last.x - (n - 1) as f64 * l).abs() < EPS);
    // Consecutive footprints are one step length apart along x (except the closing step).
    for i in 1..n - 1 {
        let dx = plan.steps()[i].pose.x - plan.steps()[i - 1].pose.x;
        assert!((dx - l).abs() < EPS);
    }
}

#[test]
fn turn_rotates_the_stance_about_the_origin() {
    let w = WalkSettings::default();
    let (n, dpsi) = (5, 0.25);
    let plan = FootstepPlan::turn(n, dpsi, &w).unwrap();
    assert_eq!(plan.len(), n);
    assert_alternates(&plan, Side::Left);
    let d = w.foot_separation / 2.0;
    for (i, s) in plan.steps().iter().enumerate() {
        let theta = (i + 1).min(n - 1) as f64 * dpsi;
        let sign = if s.side == Side::Left { 1.0 } else { -1.0 };
        // Hand-computed: R(θ)(0, ±d) = (∓d sin θ, ±d cos θ).
        assert!((s.pose.x + sign * d * theta.sin()).abs() < EPS);
        assert!((s.pose.y - sign * d * theta.cos()).abs() < EPS);
        assert!((s.pose.yaw - theta).abs() < EPS);
        assert!((s.pose.x.hypot(s.pose.y) - d).abs() < EPS);
    }
    let last = plan.steps()[n - 1].pose.yaw;
    assert!((last - (n - 1) as f64 * dpsi).abs() < EPS);
}

#[test]
fn straight_root_trajectory_gives_the_forward_plan() {
    let w = WalkSettings::default();
    // 1.0 m along x sampled unevenly; stride 0.2 → 5 strides + closing step = 6 steps.
    let xs = [0.0, 0.13, 0.4, 0.41, 0.77, 1.0];
    let samples: Vec<RootSample> = xs
        .iter()
        .enumerate()
        .map(|(i, &x)| RootSample {
            t: i as f64 * 0.3,
            x,
            y: 0.0,
            yaw: 0.0,
        })
        .collect();
    let params = RootPlanParams::default();
    let plan = FootstepPlan::from_root_trajectory(&samples, &params, &w).unwrap();
    let fwd = FootstepPlan::forward(6, 0.2, &w).unwrap();
    assert_eq!(plan.len(), fwd.len());
    for (a, b) in plan.steps().iter().zip(fwd.steps()) {
        assert_eq!(a.side, b.side);
        assert!((a.pose.x - b.pose.x).abs() < 1e-9);
        assert!((a.pose.y - b.pose.y).abs() < 1e-9);
        assert!((a.pose.yaw - b.pose.yaw).abs() < 1e-9);
    }
}

#[test]
fn turning_root_trajectory_gives_the_turn_plan() {
    let w = WalkSettings::default();
    let params = RootPlanParams {
        max_yaw_per_step: 0.25,
        ..RootPlanParams::default()
    };
    // Turn by 1.0 rad in place, heading samples crossing nothing special: 4 parts + closing.
    let samples: Vec<RootSample> = (0..=10)
        .map(|i| RootSample {
            t: i as f64,
            x: 0.0,
            y: 0.0,
            yaw: 0.1 * i as f64,
        })
        .collect();
    let plan = FootstepPlan::from_root_trajectory(&samples, &params, &w).unwrap();
    let turn = FootstepPlan::turn(5, 0.25, &w).unwrap();
    assert_eq!(plan.len(), 5);
    for (a, b) in plan.steps().iter().zip(turn.steps()) {
        assert_eq!(a.side, b.side);
        assert!((a.pose.x - b.pose.x).abs() < 1e-9);
        assert!((a.pose.y - b.pose.y).abs() < 1e-9);
        assert!((a.pose.yaw - b.pose.yaw).abs() < 1e-9);
    }
}

#[test]
fn root_trajectory_unwraps_heading_and_follows_an_arc() {
    let w = WalkSettings::default();
    let params = RootPlanParams {
        stride: 0.15,
        max_yaw_per_step: 0.4,
        ..RootPlanParams::default()
    };
    // Quarter circle of radius 1 m around (0, 1), heading tangent, wrapped into (−π, π]
    // and starting near π so that the wrapped value jumps.
    let n = 50;
    let samples: Vec<RootSample> = (0..=n)
        .map(|i| {
            let a = std::f64::consts::FRAC_PI_2 * i as f64 / n as f64;
            let yaw = std::f64::consts::PI - 0.1 + a;
            let wrapped = (yaw + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                - std::f64::consts::PI;
            RootSample {
                t: i as f64 * 0.1,
                x: a.sin(),
                y: 1.0 - a.cos(),
                yaw: wrapped,
            }
        })
        .collect();
    let plan = FootstepPlan::from_root_trajectory(&samples, &params, &w).unwrap();
    // Progress: chord-polyline length / stride + (π/2)/max_yaw; just above that many parts.
    let chord = 2.0 * (std::f64::consts::FRAC_PI_4 / n as f64).sin() * n as f64;
    let sigma = chord / params.stride + std::f64::consts::FRAC_PI_2 / params.max_yaw_per_step;
    assert_eq!(plan.len(), sigma.ceil() as usize + 1);
    assert_alternates(&plan, Side::Left);
    let d = w.foot_separation / 2.0;
    let last = plan.steps()[plan.len() - 1];
    let other = plan.steps()[plan.len() - 2];
    // Final stance around the last sample, heading unwrapped (π − 0.1 + π/2).
    let psi = std::f64::consts::PI - 0.1 + std::f64::consts::FRAC_PI_2;
    for s in [last, other] {
        assert!((s.pose.yaw - psi).abs() < 1e-9, "yaw {}", s.pose.yaw);
        let sign = if s.side == Side::Left { 1.0 } else { -1.0 };
        assert!((s.pose.x - (1.0 - sign * d * psi.sin())).abs() < 1e-9);
        assert!((s.pose.y - (1.0 + sign * d * psi.cos())).abs() < 1e-9);
    }
    // Every body pose lies on the circle: the midpoint of a foot and its nominal partner.
    for s in plan.steps() {
        let sign = if s.side == Side::Left { 1.0 } else { -1.0 };
        let bx = s.pose.x + sign * d * s.pose.yaw.sin();
        let by = s.pose.y - sign * d * s.pose.yaw.cos();
        let r = bx.hypot(by - 1.0);
        assert!((r - 1.0).abs() < 0.01, "body off the arc by {}", r - 1.0);
    }
}

#[test]
fn bad_plans_and_settings_are_errors() {
    let w = WalkSettings::default();
    assert!(FootstepPlan::in_place(0, &w).is_err());
    assert!(FootstepPlan::forward(3, f64::NAN, &w).is_err());
    assert!(FootstepPlan::turn(3, 2.0, &w).is_err());
    assert!(FootstepPlan::turn(3, f64::INFINITY, &w).is_err());
    for bad in [
        WalkSettings {
            ssp_duration: -0.1,
            ..w
        },
        WalkSettings {
            dsp_duration: f64::NAN,
            ..w
        },
        WalkSettings {
            dsp_duration: 0.0,
            ..w
        },
        WalkSettings {
            initial_dsp_duration: 0.05,
            ..w
        },
        WalkSettings {
            final_dsp_duration: -1.0,
            ..w
        },
        WalkSettings {
            foot_separation: 0.1,
            ..w
        },
        WalkSettings {
            swing_height: -0.01,
            ..w
        },
        WalkSettings {
            sole_length: f64::NAN,
            ..w
        },
        WalkSettings {
            sole_width: 0.0,
            ..w
        },
    ] {
        let err = FootstepPlan::in_place(2, &bad).unwrap_err();
        assert!(matches!(err, Error::InvalidSetting { .. }), "{err}");
        assert!(bad.validate().is_err());
    }
    // Hand-made plans.
    let l = Pose2::new(0.0, 0.1, 0.0);
    let r = Pose2::new(0.0, -0.1, 0.0);
    assert!(FootstepPlan::new(l, r, vec![]).is_err());
    let nan = Footstep {
        side: Side::Left,
        pose: Pose2::new(f64::NAN, 0.1, 0.0),
    };
    assert!(matches!(
        FootstepPlan::new(l, r, vec![nan]).unwrap_err(),
        Error::NonFinite { .. }
    ));
    let spin = Footstep {
        side: Side::Right,
        pose: Pose2::new(0.0, -0.1, 3.2),
    };
    assert!(FootstepPlan::new(l, r, vec![spin]).is_err());
    // Root trajectories.
    let p = RootPlanParams::default();
    let s = |t: f64, x: f64| RootSample {
        t,
        x,
        y: 0.0,
        yaw: 0.0,
    };
    assert!(FootstepPlan::from_root_trajectory(&[s(0.0, 0.0)], &p, &w).is_err());
    assert!(FootstepPlan::from_root_trajectory(&[s(0.0, 0.0), s(0.0, 1.0)], &p, &w).is_err());
    assert!(FootstepPlan::from_root_trajectory(&[s(0.0, 0.0), s(1.0, f64::NAN)], &p, &w).is_err());
    for bad in [
        RootPlanParams { stride: 0.0, ..p },
        RootPlanParams {
            max_yaw_per_step: 1.6,
            ..p
        },
        RootPlanParams {
            count_rounding: 0.5,
            ..p
        },
    ] {
        assert!(FootstepPlan::from_root_trajectory(&[s(0.0, 0.0), s(1.0, 1.0)], &bad, &w).is_err());
    }
}
