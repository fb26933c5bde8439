//! The batch's keypoint route on sources without a skeleton and with maps that do not fit:
//! a CSV of named points (what pose estimators write) is retargeted with the start posture as
//! the posture level's reference, exactly as [`retarget_keypoints`] does it without one; a
//! map given for every clip that does not fit the robot is an error naming what is wrong, not
//! a silent fallback to the start posture.

use std::path::PathBuf;

use iktc::batch::{BatchRetarget, ClipQuality, ClipRun};
use iktc::motion::{load_motion, BodyPoint, MotionOptions, DEFAULT_MAX_GAP};
use iktc::profile::RobotProfile;
use iktc::retarget::{builtin_motion, retarget_keypoints};
use iktc::sim::ImitateConfig;

fn temp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("iktc-batch-sources-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The built-in walk's body points written as a points CSV (metres, Z up, full precision).
fn walk_as_points_csv() -> PathBuf {
    let kp = builtin_motion("humanoid3d_walk")
        .unwrap()
        .keypoints(DEFAULT_MAX_GAP)
        .unwrap();
    let mut header = vec!["time".to_string()];
    for p in &kp.points {
        for a in ["x", "y", "z"] {
            header.push(format!("{}_{a}", p.name()));
        }
    }
    let mut text = header.join(",") + "\n";
    for (f, t) in kp.times.iter().enumerate() {
        let mut row = vec![format!("{t:?}")];
        for p in &kp.points {
            let x = kp.position(f, *p).unwrap();
            row.extend([x.x, x.y, x.z].map(|v| format!("{v:?}")));
        }
        text += &(row.join(",") + "\n");
    }
    temp("walk_points.csv", &text)
}

#[test]
fn a_points_csv_is_retargeted_from_the_start_posture() {
    let profile = RobotProfile::builtin("g1").unwrap();
    let b = BatchRetarget::from_profile(profile.clone(), ImitateConfig::default()).unwrap();
    let path = walk_as_points_csv();
    let o = b.retarget(&path).unwrap();
    let ClipRun::Keypoints {
        keypoints,
        run,
        posture,
    } = &o.run
    else {
        panic!("keypoint route")
    };
    assert!(keypoints.points.contains(&BodyPoint::LeftWrist));
    assert!(posture.contains("start posture"), "{posture}");
    // The same file through the library's own entry point, no posture references.
    let kp = load_motion(&path, &MotionOptions::default())
        .unwrap()
        .keypoints(DEFAULT_MAX_GAP)
        .unwrap();
    let direct = retarget_keypoints(&profile, &kp, None, &b.keypoints).unwrap();
    assert_eq!(run.trajectory, direct.trajectory);
    assert_eq!(o.trajectory.len(), direct.trajectory.len());
    let ClipQuality::Keypoints(f) = &o.quality else {
        panic!("keypoint figures")
    };
    // Healthy is the verdict of the neutral figures and the limits: whatever it says, it says
    // why, and no joint limit is among the failures.
    assert_eq!(f.healthy, f.failures.is_empty(), "{f:?}");
    assert!(!f.failures.iter().any(|m| m.contains("limit")), "{f:?}");
    assert_eq!(f.mean_keypoint_error, direct.quality.mean_cm / 100.0);
    let fid = direct.quality.fidelity.as_ref().unwrap();
    assert_eq!(f.neutral_keypoint_error, fid.keypoint_mean_cm / 100.0);
}

#[test]
fn a_map_given_for_every_clip_that_does_not_fit_the_robot_is_an_error() {
    let g1 = RobotProfile::builtin("g1").unwrap();
    let clip = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/motions/deepmimic/humanoid3d_walk.txt");
    let mut b = BatchRetarget::from_profile(g1, ImitateConfig::default()).unwrap();
    // JVRC-1's DeepMimic map names joints G1 does not have.
    let jvrc1 = RobotProfile::builtin("jvrc1").unwrap();
    b.map = Some(
        jvrc1
            .retarget_map("deepmimic", &jvrc1.robot().unwrap())
            .unwrap(),
    );
    let e = b.retarget(&clip).unwrap_err().to_string();
    assert!(e.contains("WAIST") || e.contains("joint"), "{e}");
}

/// JVRC-1's built-in BVH map names a `Spine` joint that CMU's rig lacks: the keypoint route
/// still runs, from the start posture, and says why.
#[test]
fn a_profile_map_that_does_not_fit_the_rig_leaves_the_start_posture() {
    let profile = RobotProfile::builtin("jvrc1").unwrap();
    let b = BatchRetarget::from_profile(profile, ImitateConfig::default()).unwrap();
    let clip = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/motions/cmu/scaled_131_02.bvh");
    let o = b.retarget(&clip).unwrap();
    let ClipRun::Keypoints { posture, .. } = &o.run else {
        panic!("keypoint route")
    };
    assert!(
        posture.contains("start posture") && posture.contains("Spine"),
        "{posture}"
    );
    let ClipQuality::Keypoints(f) = &o.quality else {
        panic!("keypoint figures")
    };
    assert_eq!(o.quality.healthy(), f.failures.is_empty(), "{f:?}");
    assert!(!f.failures.iter().any(|m| m.contains("limit")), "{f:?}");
}
