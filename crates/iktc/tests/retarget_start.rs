//! The keypoint route checks its start state against the robot's joint ranges like the joint
//! route: a profile posture outside a URDF range is an error naming the joint, its value and
//! its range.

use iktc::motion::DEFAULT_MAX_GAP;
use iktc::profile::RobotProfile;
use iktc::retarget::{retarget_keypoints, KeypointSettings};

/// G1's `left_hip_pitch_joint` range in its URDF \[rad\] (`<limit lower="-2.5307"
/// upper="2.8798">`).
const G1_HIP_PITCH_RANGE: (f64, f64) = (-2.5307, 2.8798);

#[test]
fn a_start_posture_outside_a_range_is_refused_with_the_joint_named() {
    let mut profile = RobotProfile::builtin("g1").unwrap();
    // 0.1 rad below the lower end.
    let bad = G1_HIP_PITCH_RANGE.0 - 0.1;
    profile.posture.insert("left_hip_pitch_joint".into(), bad);
    let kp = iktc::retarget::builtin_motion("humanoid3d_walk")
        .unwrap()
        .keypoints(DEFAULT_MAX_GAP)
        .unwrap();
    let err = retarget_keypoints(&profile, &kp, None, &KeypointSettings::default()).unwrap_err();
    match &err {
        iktc::Error::StateOutsideLimits {
            joint,
            value,
            lower,
            upper,
            ..
        } => {
            assert_eq!(joint, "left_hip_pitch_joint");
            assert_eq!(*value, bad);
            assert_eq!((*lower, *upper), G1_HIP_PITCH_RANGE);
        }
        other => panic!("{other:?}"),
    }
    let text = err.to_string();
    assert!(text.contains("left_hip_pitch_joint"), "{text}");
}

/// The unchanged profile starts inside every range (the check refuses nothing valid).
#[test]
fn the_shipped_postures_are_inside_their_ranges() {
    for name in ["g1", "jvrc1"] {
        let profile = RobotProfile::builtin(name).unwrap();
        let robot = profile.robot().unwrap();
        for (joint, value) in &profile.posture {
            let j = robot
                .active_joints()
                .find(|j| &j.name == joint)
                .unwrap_or_else(|| panic!("{name}: {joint}"));
            assert!(
                (j.limit.lower..=j.limit.upper).contains(value),
                "{name} {joint} {value}"
            );
        }
    }
}

/// A one-frame clip is refused by the library's keypoint route as by `iktc retarget`: an
/// error naming the clip and the frames needed.
#[test]
fn a_one_frame_clip_is_refused() {
    let profile = RobotProfile::builtin("g1").unwrap();
    let mut kp = iktc::retarget::builtin_motion("humanoid3d_walk")
        .unwrap()
        .keypoints(DEFAULT_MAX_GAP)
        .unwrap();
    let n = kp.points.len();
    kp.times.truncate(1);
    kp.positions.truncate(n);
    if let Some(o) = kp.orientations.as_mut() {
        o.truncate(n);
    }
    match retarget_keypoints(&profile, &kp, None, &KeypointSettings::default()) {
        Err(iktc::Error::InsufficientData { what, message }) => {
            assert!(what.contains(&kp.source), "{what}");
            assert!(message.contains("at least 2"), "{message}");
        }
        other => panic!("{:?}", other.map(|_| ())),
    }
}

/// The keypoint route's control period is bounded by its held feet's gains (ω = 20 rad/s:
/// (2√2 − 2)/20 = 0.0414 s): 0.04 s is accepted, 0.05 s (where JVRC-1's QP overflowed on CMU
/// 131_01) is an error naming `dt`.
#[test]
fn the_keypoint_period_is_bounded_by_the_held_feet_gains() {
    let at = |dt: f64| KeypointSettings {
        dt,
        ..KeypointSettings::default()
    };
    assert!((at(0.005).max_dt() - (8f64.sqrt() - 2.0) / 20.0).abs() < 1e-12);
    assert!(at(0.04).validate().is_ok());
    for dt in [0.05, 0.1] {
        match at(dt).validate() {
            Err(iktc::Error::InvalidSetting { name, .. }) => assert!(name.contains("--dt")),
            other => panic!("{dt}: {other:?}"),
        }
    }
}
