//! `ImitateConfig::smoothing`: the joint route's references low-passed at the clip's rate before
//! they are clamped and differentiated. Checked on the references themselves (no closed loop):
//! the frame-rate zigzag of their accelerations is gone, the angles move by a bounded amount,
//! and the narrowed ranges still hold.

use iktc::model::{jvrc1, ModelOptions};
use iktc::motion::{builtin_clip, builtin_map, RobotReferences, Track};
use iktc::sim::{imitation_references, ImitateConfig};

fn references(smoothing: Option<f64>) -> RobotReferences {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    let cfg = ImitateConfig {
        smoothing,
        ..ImitateConfig::jvrc1()
    };
    imitation_references(&robot, &clip, &map, &cfg).unwrap()
}

/// Share of ticks where the change of a track's acceleration reverses its sign.
fn reversals(t: &Track) -> f64 {
    let d: Vec<f64> = t.acceleration.windows(2).map(|w| w[1] - w[0]).collect();
    let n = d.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
    n as f64 / (d.len() - 1) as f64
}

/// As captured (60 Hz, cubic splines at 200 Hz) the joints' reference accelerations change
/// direction at the frames; low-passed at 6 Hz, at a smooth motion's extrema. Measured: the
/// median joint's share falls from 22 % to 6 %.
#[test]
fn the_low_pass_takes_the_frame_rate_zigzag_out_of_the_joint_references() {
    let (raw, smooth) = (references(None), references(Some(6.0)));
    assert_eq!(raw.joint_names, smooth.joint_names);
    assert_eq!(raw.len(), smooth.len());
    let median = |r: &RobotReferences| {
        let mut s: Vec<f64> = r
            .joints
            .iter()
            .filter(|t| t.acceleration.iter().any(|a| *a != 0.0))
            .map(reversals)
            .collect();
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    };
    let (r, s) = (median(&raw), median(&smooth));
    assert!(r > 0.15, "as captured: {r}");
    assert!(s < 0.08, "low-passed: {s}");
    // The angles move by at most 0.47 rad, where the decomposition swings L_SHOULDER_P at
    // 32 rad/s (1 400 rad/s²) past the shoulder's gimbal lock; elsewhere by far less.
    let moved = raw
        .joints
        .iter()
        .zip(&smooth.joints)
        .flat_map(|(a, b)| {
            a.position
                .iter()
                .zip(&b.position)
                .map(|(x, y)| (x - y).abs())
        })
        .fold(0.0, f64::max);
    assert!(moved < 0.6, "moved {moved} rad");
}

/// The joints' ranges are applied after the low-pass: the references stay inside them (the
/// samples are clamped 0.05 rad inside; splines between them overshoot by far less).
#[test]
fn ranges_hold_after_the_low_pass() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let smooth = references(Some(6.0));
    for (name, track) in smooth.joint_names.iter().zip(&smooth.joints) {
        let j = robot.joints().iter().find(|j| j.name == *name).unwrap();
        for &q in &track.position {
            assert!(
                q >= j.limit.lower && q <= j.limit.upper,
                "{name} at {q} outside [{}, {}]",
                j.limit.lower,
                j.limit.upper
            );
        }
    }
}

#[test]
fn a_bad_cut_off_is_an_error_naming_it() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    for fc in [0.0, -3.0, f64::NAN] {
        let cfg = ImitateConfig {
            smoothing: Some(fc),
            ..ImitateConfig::jvrc1()
        };
        let e = imitation_references(&robot, &clip, &map, &cfg)
            .unwrap_err()
            .to_string();
        assert!(e.contains("smoothing"), "{e}");
    }
}
