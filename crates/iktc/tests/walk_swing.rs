//! Swing-foot trajectories: continuity of position, velocity and acceleration over the whole
//! timeline (including phase boundaries), exact touch-down, zero velocity and acceleration at
//! lift-off and touch-down, stance feet at rest, swing height.

use iktc::walk::{
    FootState, FootstepPlan, Phase, PreviewSettings, RootPlanParams, RootSample, Side,
    WalkSettings, WalkingPattern,
};

/// (x, y, z, ψ) of position, velocity and acceleration.
fn pva(f: &FootState) -> [[f64; 4]; 3] {
    [
        [f.position.x, f.position.y, f.position.z, f.yaw],
        [
            f.linear_velocity.x,
            f.linear_velocity.y,
            f.linear_velocity.z,
            f.angular_velocity.z,
        ],
        [
            f.linear_acceleration.x,
            f.linear_acceleration.y,
            f.linear_acceleration.z,
            f.angular_acceleration.z,
        ],
    ]
}

/// A plan that walks forward, sideways and turns: a curved root path.
fn curved_pattern() -> WalkingPattern {
    let w = WalkSettings::default();
    let samples: Vec<RootSample> = (0..=40)
        .map(|i| {
            let a = 0.8 * i as f64 / 40.0;
            RootSample {
                t: i as f64,
                x: 1.2 * a.sin(),
                y: 1.2 * (1.0 - a.cos()),
                yaw: a,
            }
        })
        .collect();
    let plan =
        FootstepPlan::from_root_trajectory(&samples, &RootPlanParams::default(), &w).unwrap();
    WalkingPattern::new(&plan, &w, &PreviewSettings::default()).unwrap()
}

/// Upper bound on the jerk of each coordinate (x, y, z, ψ) over the plan, by hand: the
/// quintic smoothstep has `|s'''| ≤ 60/T³` (at its ends), the sextic height
/// `|z'''| = 384 h |(1 − 10τ + 10τ²)(1 − 2τ)|/T³ ≤ 384 h/T³`.
fn jerk_bounds(p: &WalkingPattern) -> [f64; 4] {
    let w = p.settings();
    let t3 = w.ssp_duration.powi(3);
    let mut max_d = [0.0f64; 3];
    let (mut l, mut r) = (p.plan().initial_left(), p.plan().initial_right());
    for s in p.plan().steps() {
        let from = if s.side == Side::Left { &mut l } else { &mut r };
        max_d[0] = max_d[0].max((s.pose.x - from.x).abs());
        max_d[1] = max_d[1].max((s.pose.y - from.y).abs());
        max_d[2] = max_d[2].max((s.pose.yaw - from.yaw).abs());
        *from = s.pose;
    }
    [
        60.0 * max_d[0] / t3,
        60.0 * max_d[1] / t3,
        384.0 * w.swing_height / t3,
        60.0 * max_d[2] / t3,
    ]
}

#[test]
fn feet_are_c2_over_the_whole_timeline() {
    let p = curved_pattern();
    let jb = jerk_bounds(&p);
    // |a| ≤ J T: the acceleration is zero at lift-off and the jerk bounded by J.
    let t_ssp = p.settings().ssp_duration;
    let h = 2e-4;
    let n = (p.duration() / h) as usize;
    for side in [Side::Left, Side::Right] {
        let mut prev = pva(&p.foot(side, 0.0).unwrap());
        for k in 1..=n {
            let t = k as f64 * h;
            let cur = pva(&p.foot(side, t).unwrap());
            for c in 0..4 {
                let j = jb[c];
                let (p0, v0, a0) = (prev[0][c], prev[1][c], prev[2][c]);
                let (p1, v1, a1) = (cur[0][c], cur[1][c], cur[2][c]);
                // Trapezoid rule on v (C² ⇒ error ≤ h³ max|v''|/12) and on a (Lipschitz ⇒ ≤ h² J/4).
                let ep = (p1 - p0 - 0.5 * h * (v0 + v1)).abs();
                let ev = (v1 - v0 - 0.5 * h * (a0 + a1)).abs();
                let ea = (a1 - a0).abs();
                let tol = 1e-12;
                assert!(
                    ep <= h * h * h * j / 12.0 + tol,
                    "{side:?} c{c} t={t}: position {ep}"
                );
                assert!(
                    ev <= h * h * j / 4.0 + tol,
                    "{side:?} c{c} t={t}: velocity {ev}"
                );
                assert!(
                    ea <= h * j + tol,
                    "{side:?} c{c} t={t}: acceleration jump {ea}"
                );
                // Velocity and acceleration are bounded by what the jerk bound allows.
                assert!(a1.abs() <= j * t_ssp + tol);
            }
            prev = cur;
        }
    }
}

#[test]
fn no_jumps_at_phase_boundaries() {
    let p = curved_pattern();
    let jb = jerk_bounds(&p);
    let eps = 1e-9;
    let t = p.settings().ssp_duration;
    for ph in p.timeline().phases().iter().skip(1) {
        let tb = ph.start;
        for side in [Side::Left, Side::Right] {
            let before = pva(&p.foot(side, tb - eps).unwrap());
            let at = pva(&p.foot(side, tb).unwrap());
            for c in 0..4 {
                for (d, what) in ["position", "velocity", "acceleration"].iter().enumerate() {
                    let jump = (at[d][c] - before[d][c]).abs();
                    // Over ε the change is at most ε times the bound of the derivative:
                    // |a| ≤ J T, |v| ≤ J T² (integrating the jerk bound over one swing).
                    let scale = [t * t, t, 1.0][d];
                    assert!(
                        jump <= eps * jb[c] * scale + 1e-12,
                        "{side:?} {what} c{c} jumps {jump} at {tb}"
                    );
                }
            }
        }
    }
}

#[test]
fn touch_down_lift_off_and_stance() {
    let p = curved_pattern();
    let w = p.settings();
    for ph in p.timeline().phases() {
        let Phase::SingleSupport { stance } = ph.phase else {
            continue;
        };
        let swing = stance.opposite();
        let target = ph.swing_target.unwrap();
        // Touch-down exactly at the planned footstep, at rest.
        let td = p.foot(swing, ph.end).unwrap();
        assert_eq!(
            (td.position.x, td.position.y, td.yaw),
            (target.x, target.y, target.yaw)
        );
        assert_eq!(td.position.z, 0.0);
        // Zero velocity and acceleration at lift-off and touch-down, from the swing side too.
        let lo = p.foot(swing, ph.start).unwrap();
        let from = ph.foot(swing);
        assert_eq!(
            (lo.position.x, lo.position.y, lo.yaw),
            (from.x, from.y, from.yaw)
        );
        for f in [lo, td] {
            assert_eq!(f.twist(), [0.0; 6]);
            assert_eq!(f.acceleration(), [0.0; 6]);
        }
        let td_left = p.foot(swing, ph.end - 1e-9).unwrap();
        let lo_right = p.foot(swing, ph.start + 1e-9).unwrap();
        for f in [td_left, lo_right] {
            for v in f.twist().iter().chain(f.acceleration().iter()) {
                assert!(v.abs() < 1e-6, "{v}");
            }
        }
        // Peak height at mid-swing, height within [0, h].
        let mid = p.foot(swing, 0.5 * (ph.start + ph.end)).unwrap();
        assert!((mid.position.z - w.swing_height).abs() < 1e-12);
        for i in 0..=50 {
            let t = ph.start + (ph.end - ph.start) * i as f64 / 50.0;
            let f = p.foot(swing, t).unwrap();
            assert!(f.position.z >= 0.0 && f.position.z <= w.swing_height + 1e-12);
            // Stance foot at rest where the phase says.
            let s = p.foot(stance, t).unwrap();
            let sp = ph.foot(stance);
            assert_eq!(
                (s.position.x, s.position.y, s.position.z, s.yaw),
                (sp.x, sp.y, 0.0, sp.yaw)
            );
            assert_eq!(s.twist(), [0.0; 6]);
            assert_eq!(s.acceleration(), [0.0; 6]);
        }
    }
}

#[test]
fn swing_velocity_and_acceleration_match_finite_differences_inside_the_swing() {
    let p = curved_pattern();
    let jb = jerk_bounds(&p);
    let h = 1e-5;
    for ph in p.timeline().phases() {
        let Phase::SingleSupport { stance } = ph.phase else {
            continue;
        };
        let swing = stance.opposite();
        for i in 1..10 {
            let t = ph.start + (ph.end - ph.start) * i as f64 / 10.0;
            let (m, c, pl) = (
                pva(&p.foot(swing, t - h).unwrap()),
                pva(&p.foot(swing, t).unwrap()),
                pva(&p.foot(swing, t + h).unwrap()),
            );
            for k in 0..4 {
                let fd_v = (pl[0][k] - m[0][k]) / (2.0 * h);
                let fd_a = (pl[1][k] - m[1][k]) / (2.0 * h);
                // Central differences: error ≤ h² max|f'''|/6 plus round-off.
                assert!((fd_v - c[1][k]).abs() <= h * h * jb[k] / 6.0 + 1e-9);
                assert!((fd_a - c[2][k]).abs() <= 1e-5 * (1.0 + jb[k]));
            }
        }
    }
    // The rotation of the foot frame is about z by the yaw.
    let f = p.foot(Side::Left, 3.0).unwrap();
    let r = f.rotation();
    assert!((r[(0, 0)] - f.yaw.cos()).abs() < 1e-15 && (r[(2, 2)] - 1.0).abs() < 1e-15);
}

#[test]
fn offset_point_follows_rigid_body_kinematics() {
    let p = curved_pattern();
    let ankle = nalgebra::Vector3::new(0.03, -0.01, 0.1);
    let h = 1e-5;
    for ph in p.timeline().phases() {
        let Phase::SingleSupport { stance } = ph.phase else {
            continue;
        };
        let swing = stance.opposite();
        let t = ph.start + 0.37 * (ph.end - ph.start);
        let at = |t: f64| p.foot(swing, t).unwrap().offset(&ankle);
        let (m, c, pl) = (at(t - h), at(t), at(t + h));
        // Position: sole centre plus the rotated offset, computed here by hand.
        let f = p.foot(swing, t).unwrap();
        let (sn, cs) = f.yaw.sin_cos();
        let expect = f.position
            + nalgebra::Vector3::new(
                cs * ankle.x - sn * ankle.y,
                sn * ankle.x + cs * ankle.y,
                ankle.z,
            );
        assert!((c.position - expect).norm() < 1e-14);
        // Velocity and acceleration: central differences of the offset point.
        let fd_v = (pl.position - m.position) / (2.0 * h);
        let fd_a = (pl.linear_velocity - m.linear_velocity) / (2.0 * h);
        assert!(
            (fd_v - c.linear_velocity).norm() < 1e-7,
            "{}",
            (fd_v - c.linear_velocity).norm()
        );
        assert!((fd_a - c.linear_acceleration).norm() < 1e-5);
        assert_eq!(c.yaw, f.yaw);
        assert_eq!(c.angular_velocity, f.angular_velocity);
    }
}
