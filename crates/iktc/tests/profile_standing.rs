//! `RobotProfile::standing_state`: the robot in its profile's start posture, standing on the
//! ground, as the keypoint route starts it.

use iktc::model::{Kinematics, State};
use iktc::profile::RobotProfile;
use iktc::sim::imitate::ImitateConfig;

/// Rounding of a few products of decimetre-sized transforms \[m\], \[rad\].
const TOL: f64 = 1e-12;

#[test]
fn the_standing_state_has_the_posture_and_the_lower_sole_on_the_ground() {
    for name in ["g1", "jvrc1"] {
        let profile = RobotProfile::builtin(name).unwrap();
        let robot = profile.robot().unwrap();
        let cfg = profile.imitate_config(ImitateConfig::default()).unwrap();
        let s = profile.standing_state(&robot).unwrap();
        // Every posture joint at its value, the rest at 0, at rest.
        let neutral = State::neutral(&robot);
        for j in robot.active_joints() {
            let want = profile.posture.get(&j.name).copied().unwrap_or(0.0);
            let i = robot.joint_q_index(&j.name).unwrap();
            assert_eq!(s.q[i], want, "{name} {}", j.name);
            assert_eq!(neutral.q[i], 0.0);
        }
        assert!(s.qd.iter().all(|v| *v == 0.0));
        // The base upright, straight above the origin.
        let base = s.base_pose(&robot);
        assert!(base.rotation.angle() < TOL, "{name}");
        assert!(base.translation.vector.xy().norm() < TOL, "{name}");
        // The lower foot frame `ankle_height` above the ground: its sole on z = 0.
        let kin = Kinematics::new(&robot, &s).unwrap();
        let lowest = cfg
            .feet
            .iter()
            .map(|f| {
                kin.frame_pose(&robot, robot.frame_id(f).unwrap())
                    .unwrap()
                    .translation
                    .z
            })
            .fold(f64::INFINITY, f64::min);
        assert!(
            (lowest - cfg.support.ankle_height).abs() < TOL,
            "{name}: lowest foot frame {lowest} m, ankle height {}",
            cfg.support.ankle_height
        );
    }
}

#[test]
fn a_profile_without_feet_or_a_fixed_base_has_no_standing_state() {
    let mut profile = RobotProfile::builtin("g1").unwrap();
    let robot = profile.robot().unwrap();
    profile.feet = None;
    let err = profile.standing_state(&robot).unwrap_err().to_string();
    assert!(err.contains("feet"), "{err}");
    let mut fixed = RobotProfile::builtin("g1").unwrap();
    fixed.base = iktc::model::BaseKind::Fixed;
    let robot = fixed.robot().unwrap();
    let err = fixed.standing_state(&robot).unwrap_err().to_string();
    assert!(err.contains("floating base"), "{err}");
}
