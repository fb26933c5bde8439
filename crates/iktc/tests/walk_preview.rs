//! COM by preview control: ZMP tracking, ZMP inside the support polygon, continuity of the
//! COM trajectory, consistency with the cart-table model, bad input.
//!
//! Tolerances (stated once, used below):
//! * `ZMP_TOL = 1 cm`: largest distance between the cart-table ZMP and its reference over
//!   the whole walk. Preview control does not track exactly: with `R = 10⁻⁶` it trades a
//!   small error for bounded jerk, the ZMP lags and overshoots a little around each DSP
//!   shift (measured ≈ 3.5 mm), and at the start, seeing the first shift coming within the
//!   1.6 s preview, it moves the ZMP away from the reference to get the COM going (measured
//!   ≈ 6.9 mm).
//! * `ZMP_TOL_SSP = 3 mm`: the same once a single support has lasted 0.2 s (the transient of
//!   the preceding shift has died out; measured ≤ 1.4 mm).
//! * `ZMP_RMS_TOL = 2 mm`: root mean square of that distance over the walk (measured 1.2 mm).
//! * `POLYGON_MARGIN = sole_width/2 − 2 cm = 4 cm`: the reference lies at least half a sole
//!   width inside the support polygon (Minkowski-sum argument, see `walk_timeline.rs`); the
//!   tracking error takes at most `ZMP_TOL` of that; we leave another centimetre of slack.

use iktc::walk::{
    FootstepPlan, PreviewAxis, PreviewController, PreviewSettings, SupportPolygon, WalkSettings,
    WalkingPattern,
};
use iktc::Error;

const ZMP_TOL: f64 = 0.01;
const ZMP_TOL_SSP: f64 = 0.003;
const ZMP_RMS_TOL: f64 = 0.002;
const SSP_SETTLE: f64 = 0.2;

fn check_tracking(plan: &FootstepPlan) {
    let w = WalkSettings::default();
    let ps = PreviewSettings::default();
    let p = WalkingPattern::new(plan, &w, &ps).unwrap();
    let margin = 0.5 * w.sole_width - 0.02;
    let zc_g = ps.com_height / ps.gravity;
    let dt = p.dt();
    let n = (p.duration() / dt).floor() as usize;
    let mut poly = SupportPolygon::default();
    let (mut worst, mut sum_sq) = (0.0f64, 0.0);
    for k in 0..=n {
        let t = k as f64 * dt;
        let s = p.sample(t).unwrap();
        // The cart-table ZMP, computed here from the COM reference: p = x − (z_c/g) ẍ.
        let zx = s.com.position.x - zc_g * s.com.acceleration.x;
        let zy = s.com.position.y - zc_g * s.com.acceleration.y;
        assert!((zx - s.zmp_model.0).abs() < 1e-12 && (zy - s.zmp_model.1).abs() < 1e-12);
        let (rx, ry) = s.zmp_reference;
        let err = (zx - rx).hypot(zy - ry);
        worst = worst.max(err);
        sum_sq += err * err;
        assert!(err <= ZMP_TOL, "t = {t}: ZMP error {err}");
        let ph = p.timeline().interval_at(t);
        if ph.swing_side().is_some() && t >= ph.start + SSP_SETTLE {
            assert!(
                err <= ZMP_TOL_SSP,
                "t = {t} (single support): ZMP error {err}"
            );
        }
        p.support_polygon_into(t, &mut poly).unwrap();
        let m = poly.margin((zx, zy));
        assert!(
            m >= margin,
            "t = {t}: ZMP only {m} m inside the support polygon"
        );
    }
    let rms = (sum_sq / (n + 1) as f64).sqrt();
    assert!(rms <= ZMP_RMS_TOL, "rms {rms}");
    assert!(worst > 0.0);
    // At the end the COM stands over the final ZMP reference, nearly at rest.
    let end = p.sample(p.duration()).unwrap();
    let (rx, ry) = end.zmp_reference;
    assert!((end.com.position.x - rx).hypot(end.com.position.y - ry) < 1e-3);
    assert!(end.com.velocity.norm() < 5e-3);
    assert_eq!(end.com.position.z, ps.com_height);
}

#[test]
fn zmp_tracks_its_reference_walking_forward() {
    let w = WalkSettings::default();
    check_tracking(&FootstepPlan::forward(6, 0.2, &w).unwrap());
}

#[test]
fn zmp_tracks_its_reference_stepping_in_place() {
    let w = WalkSettings::default();
    check_tracking(&FootstepPlan::in_place(6, &w).unwrap());
}

#[test]
fn zmp_tracks_its_reference_turning() {
    let w = WalkSettings::default();
    check_tracking(&FootstepPlan::turn(6, 0.2, &w).unwrap());
}

#[test]
fn com_moves_forward_and_sways_toward_the_stance_foot() {
    let w = WalkSettings::default();
    let p = WalkingPattern::new(
        &FootstepPlan::forward(6, 0.2, &w).unwrap(),
        &w,
        &PreviewSettings::default(),
    )
    .unwrap();
    for ph in p.timeline().phases() {
        if let Some(swing) = ph.swing_side() {
            let s = p.sample(0.5 * (ph.start + ph.end)).unwrap();
            // Lateral sway toward the stance foot (the swing foot's opposite side).
            assert!(s.com.position.y * swing.lateral_sign() < 0.0);
            assert!(s.com.velocity.x > 0.0, "walking forward");
        }
    }
}

#[test]
fn com_is_c2_across_ticks_and_consistent_with_its_derivatives() {
    let w = WalkSettings::default();
    let p = WalkingPattern::new(
        &FootstepPlan::forward(6, 0.2, &w).unwrap(),
        &w,
        &PreviewSettings::default(),
    )
    .unwrap();
    // A physical bound on the COM jerk for this gait [m/s³] (a 1 m/s² change within 10 ms
    // would be 100 m/s³); the test checks continuity, not the bound's tightness.
    let jerk_bound = 100.0;
    let eps = 1e-9;
    let dt = p.dt();
    let n = (p.duration() / dt).floor() as usize;
    for k in 1..=n {
        let t = k as f64 * dt;
        let before = p.com(t - eps).unwrap();
        let at = p.com(t).unwrap();
        assert!((at.position - before.position).norm() <= eps * 1.0 + 1e-12);
        assert!((at.velocity - before.velocity).norm() <= eps * 10.0 + 1e-12);
        assert!(
            (at.acceleration - before.acceleration).norm() <= eps * jerk_bound + 1e-12,
            "acceleration jumps at t = {t}"
        );
    }
    // Velocity and acceleration are the derivatives of the position (central differences at
    // points between ticks; the position is a cubic there, so the error is round-off only).
    let h = 1e-4;
    for k in (3..n - 3).step_by(37) {
        let t = (k as f64 + 0.5) * dt;
        let (m, c, pl) = (
            p.com(t - h).unwrap(),
            p.com(t).unwrap(),
            p.com(t + h).unwrap(),
        );
        let fd_v = (pl.position - m.position) / (2.0 * h);
        let fd_a = (pl.position - 2.0 * c.position + m.position) / (h * h);
        assert!((fd_v - c.velocity).norm() < 1e-7, "t = {t}");
        assert!((fd_a - c.acceleration).norm() < 1e-3, "t = {t}");
    }
}

#[test]
fn integral_action_removes_the_steady_state_error_and_rest_is_kept() {
    let ctrl = PreviewController::new(&PreviewSettings::default()).unwrap();
    // A COM at rest over a constant reference stays exactly at rest.
    let mut axis = PreviewAxis::at_rest(0.3);
    for _ in 0..100 {
        assert_eq!(axis.step(&ctrl, 0.3, &[0.3; 400]), 0.0);
    }
    assert_eq!(axis.state, nalgebra::Vector3::new(0.3, 0.0, 0.0));
    // A 5 cm step at 1 s: after 5 s the COM stands on the new reference.
    let reference: Vec<f64> = (0..1200)
        .map(|k| if k < 200 { 0.0 } else { 0.05 })
        .collect();
    let out = ctrl.track(&reference).unwrap();
    let last = out.last().unwrap();
    assert!((last.state[0] - 0.05).abs() < 1e-6);
    assert!(last.state[1].abs() < 1e-6 && last.state[2].abs() < 1e-6);
    // The preview makes the ZMP move before the step (anticipation), and not long before.
    let first_move = out.iter().position(|s| s.state[0].abs() > 1e-9).unwrap();
    assert!(first_move < 200 && first_move + ctrl.preview_gains().len() >= 200);
    // The stepper and the batch agree.
    let mut axis = PreviewAxis::at_rest(0.0);
    for (k, s) in out.iter().enumerate() {
        assert_eq!(axis.state, s.state);
        let end = (k + 1 + 320).min(reference.len());
        axis.step(&ctrl, reference[k], &reference[k + 1..end]);
    }
}

#[test]
fn bad_input_is_an_error() {
    let w = WalkSettings::default();
    let plan = FootstepPlan::forward(2, 0.2, &w).unwrap();
    let good = PreviewSettings::default();
    for bad in [
        PreviewSettings { dt: 0.0, ..good },
        PreviewSettings {
            dt: f64::NAN,
            ..good
        },
        PreviewSettings {
            preview_time: 0.001,
            ..good
        },
        PreviewSettings { q_e: 0.0, ..good },
        PreviewSettings { r: -1e-6, ..good },
        PreviewSettings {
            q_x: [0.0, f64::NAN, 0.0],
            ..good
        },
        PreviewSettings {
            com_height: -0.8,
            ..good
        },
        PreviewSettings {
            gravity: f64::INFINITY,
            ..good
        },
        PreviewSettings {
            dt: 1e-9, // a unit slip: 1.6e9 preview samples
            ..good
        },
    ] {
        assert!(bad.validate().is_err());
        let err = WalkingPattern::new(&plan, &w, &bad).unwrap_err();
        assert!(matches!(err, Error::InvalidSetting { .. }), "{err}");
    }
    let bad_walk = WalkSettings {
        ssp_duration: f64::NAN,
        ..w
    };
    assert!(WalkingPattern::new(&plan, &bad_walk, &good).is_err());
    let endless = WalkSettings {
        ssp_duration: 1e30,
        ..w
    };
    let long_plan = FootstepPlan::forward(2, 0.2, &endless).unwrap();
    assert!(WalkingPattern::new(&long_plan, &endless, &good).is_err());
    let p = WalkingPattern::new(&plan, &w, &good).unwrap();
    assert!(matches!(p.sample(f64::NAN), Err(Error::NonFinite { .. })));
    assert!(p.com(f64::INFINITY).is_err());
    assert!(p.support_polygon(f64::NAN).is_err());
    assert!(p.phase_at(f64::NAN).is_err());
    // Outside the time range the robot stands.
    let before = p.sample(-1.0).unwrap();
    assert_eq!(before.time, 0.0);
    assert_eq!(before.com.velocity.norm(), 0.0);
    let ctrl = PreviewController::new(&good).unwrap();
    assert!(ctrl.track(&[]).is_err());
    assert!(ctrl.track(&[0.0, f64::NAN]).is_err());
}

/// Seeded random root trajectories (walking with random curvature, speed and turning):
/// the same tracking tolerance and polygon margin hold on every plan.
#[test]
fn random_root_trajectories_keep_the_zmp_inside() {
    use iktc::walk::{RootPlanParams, RootSample};
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
    let w = WalkSettings::default();
    let ps = PreviewSettings::default();
    let ctrl = PreviewController::new(&ps).unwrap();
    let margin = 0.5 * w.sole_width - 0.02;
    for case in 0..8 {
        let params = RootPlanParams {
            stride: rng.random_range(0.05..0.25),
            max_yaw_per_step: rng.random_range(0.1..0.4),
            ..RootPlanParams::default()
        };
        let (mut x, mut y, mut yaw) = (0.0f64, 0.0f64, rng.random_range(-3.0..3.0));
        let curvature = rng.random_range(-1.5..1.5);
        let speed = rng.random_range(0.0..0.4);
        let samples: Vec<RootSample> = (0..30)
            .map(|i| {
                let s = RootSample {
                    t: 0.1 * i as f64,
                    x,
                    y,
                    yaw,
                };
                x += 0.1 * speed * yaw.cos();
                y += 0.1 * speed * yaw.sin();
                yaw += 0.1 * speed * curvature + 0.02;
                s
            })
            .collect();
        let plan = FootstepPlan::from_root_trajectory(&samples, &params, &w).unwrap();
        let p = WalkingPattern::with_controller(&plan, &w, ctrl.clone()).unwrap();
        let mut poly = SupportPolygon::default();
        let n = (p.duration() / p.dt()) as usize;
        for k in 0..=n {
            let t = k as f64 * p.dt();
            let s = p.sample(t).unwrap();
            let err = (s.zmp_model.0 - s.zmp_reference.0).hypot(s.zmp_model.1 - s.zmp_reference.1);
            assert!(err <= ZMP_TOL, "case {case}, t = {t}: ZMP error {err}");
            p.support_polygon_into(t, &mut poly).unwrap();
            let m = poly.margin(s.zmp_model);
            assert!(m >= margin, "case {case}, t = {t}: margin {m}");
        }
    }
}

/// The incremental servo equals Kajita's summed control law
/// `u_k = −G_I Σ_{i≤k} e_i − G_x x_k − Σ_{j=1}^{N} G_p(j) p^ref_{k+j}` (written out here)
/// when the COM starts at rest at 0 and the reference is 0 over the first `N` samples, so that
/// the integration constants of the two forms coincide.
#[test]
fn incremental_servo_equals_kajitas_summed_law() {
    let ps = PreviewSettings::default();
    let ctrl = PreviewController::new(&ps).unwrap();
    let n = ctrl.preview_gains().len();
    // Zero, then a staircase of lateral shifts like a walk.
    let reference: Vec<f64> = (0..2000)
        .map(|k| {
            if k < n + 10 {
                0.0
            } else if ((k - n - 10) / 160) % 2 == 0 {
                0.09
            } else {
                -0.09
            }
        })
        .collect();
    let out = ctrl.track(&reference).unwrap();
    // Kajita's law on the cart-table written out here.
    let (dt, zc_g) = (ps.dt, ps.com_height / ps.gravity);
    let (gi, gx, gp) = (
        ctrl.integral_gain(),
        ctrl.state_gain(),
        ctrl.preview_gains(),
    );
    let mut x = [0.0f64; 3];
    let mut sum_e = 0.0;
    for (k, s) in out.iter().enumerate() {
        for (c, xc) in x.iter().enumerate() {
            assert!(
                (xc - s.state[c]).abs() < 1e-9 * (1.0 + xc.abs()),
                "k = {k}, c = {c}"
            );
        }
        let p = x[0] - zc_g * x[2];
        sum_e += p - reference[k];
        let mut u = -gi * sum_e - (gx[0] * x[0] + gx[1] * x[1] + gx[2] * x[2]);
        for j in 1..=n {
            let r = reference[(k + j).min(reference.len() - 1)];
            u -= gp[j - 1] * r;
        }
        assert!(
            (u - s.jerk).abs() < 1e-6 * (1.0 + u.abs()),
            "k = {k}: {u} vs {}",
            s.jerk
        );
        x = [
            x[0] + dt * x[1] + dt * dt / 2.0 * x[2] + dt * dt * dt / 6.0 * u,
            x[1] + dt * x[2] + dt * dt / 2.0 * u,
            x[2] + dt * u,
        ];
    }
}
