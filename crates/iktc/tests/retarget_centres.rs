//! The robot's joint centres (`iktc::retarget::centres`) against the URDF's geometry.

use iktc::model::{Kinematics, Robot, State};
use iktc::motion::BodyPoint;
use iktc::profile::RobotProfile;
use iktc::retarget::centres::JOINT_CENTRES;
use iktc::retarget::{BodyFrameNames, RobotBody, RobotJointCentres};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn jvrc1() -> (Robot, RobotBody) {
    let robot = RobotProfile::builtin("jvrc1").unwrap().robot().unwrap();
    let kin = Kinematics::new(&robot, &State::neutral(&robot)).unwrap();
    let names = BodyFrameNames {
        pelvis: "PELVIS_S".into(),
        torso: None,
        head: None,
        feet: ["l_ankle".into(), "r_ankle".into()],
        hands: ["l_wrist".into(), "r_wrist".into()],
    };
    let body = RobotBody::find(&robot, &kin, &names).unwrap();
    (robot, body)
}

fn ix(p: BodyPoint) -> usize {
    JOINT_CENTRES.iter().position(|q| *q == p).unwrap()
}

/// JVRC-1's URDF puts the three hip joints at one origin, 0.096 m to the side of the pelvis
/// frame, and the knee 0.02 m back and 0.389 m below it: the centres are those points.
#[test]
fn jvrc1_centres_are_its_joint_origins() {
    let (robot, body) = jvrc1();
    let centres = RobotJointCentres::find(&robot, &body).unwrap();
    let kin = Kinematics::new(&robot, &State::neutral(&robot)).unwrap();
    let x = centres.at(&kin).unwrap();
    let pelvis = kin
        .frame_pose(&robot, robot.frame_id("PELVIS_S").unwrap())
        .unwrap()
        .translation
        .vector;
    for (side, y) in [(0usize, 0.096), (1, -0.096)] {
        let (hip, knee) = if side == 0 {
            (BodyPoint::LeftHip, BodyPoint::LeftKnee)
        } else {
            (BodyPoint::RightHip, BodyPoint::RightKnee)
        };
        let h = x[ix(hip)] - pelvis;
        assert!((h - Vector3::new(0.0, y, 0.0)).norm() < 1e-9, "{side}: {h}");
        let k = x[ix(knee)] - pelvis;
        assert!(
            (k - Vector3::new(-0.02, y, -0.389)).norm() < 1e-9,
            "{side}: {k}"
        );
    }
}

/// The hip joints turn about axes through the hip centre: at random angles of the three hip
/// joints (seeded) the centre does not move, while the knee's does.
#[test]
fn turning_the_hip_leaves_its_centre_in_place() {
    let (robot, body) = jvrc1();
    let centres = RobotJointCentres::find(&robot, &body).unwrap();
    let mut state = State::neutral(&robot);
    let still = centres
        .at(&Kinematics::new(&robot, &state).unwrap())
        .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..20 {
        for j in ["L_HIP_P", "L_HIP_R", "L_HIP_Y"] {
            state
                .set_joint(&robot, j, rng.random_range(-0.3..0.3))
                .unwrap();
        }
        let x = centres
            .at(&Kinematics::new(&robot, &state).unwrap())
            .unwrap();
        let hip = ix(BodyPoint::LeftHip);
        assert!((x[hip] - still[hip]).norm() < 1e-12, "{}", x[hip]);
        let knee = ix(BodyPoint::LeftKnee);
        assert!((x[knee] - still[knee]).norm() > 1e-3);
    }
}

/// G1's hip axes do not meet (the pitch joint sits 3 cm above the roll and yaw axes): its
/// hip centre is a least-squares point, within 4 cm of each of the three axes, below the
/// pelvis and to its side; the knee centre is the knee joint's origin at any posture.
#[test]
fn g1_hip_centre_is_near_each_hip_axis() {
    let profile = RobotProfile::builtin("g1").unwrap();
    let robot = profile.robot().unwrap();
    let kin = Kinematics::new(&robot, &State::neutral(&robot)).unwrap();
    let names = BodyFrameNames {
        pelvis: "pelvis".into(),
        torso: Some("torso_link".into()),
        head: None,
        feet: [
            "left_ankle_roll_link".into(),
            "right_ankle_roll_link".into(),
        ],
        hands: ["left_rubber_hand".into(), "right_rubber_hand".into()],
    };
    let body = RobotBody::find(&robot, &kin, &names).unwrap();
    let centres = RobotJointCentres::find(&robot, &body).unwrap();
    let x = centres.at(&kin).unwrap();
    let hip = x[ix(BodyPoint::LeftHip)];
    for name in [
        "left_hip_pitch_joint",
        "left_hip_roll_joint",
        "left_hip_yaw_joint",
    ] {
        let j = robot.joints().iter().find(|j| j.name == name).unwrap();
        let frame = kin.link_pose(j.parent).unwrap() * j.origin;
        let axis = match j.kind {
            iktc::model::JointKind::Revolute { axis } => frame.rotation * axis.into_inner(),
            _ => panic!("{name} is revolute"),
        };
        let d = hip - frame.translation.vector;
        let off = (d - axis * axis.dot(&d)).norm();
        assert!(off < 0.04, "{name}: {off} m off its axis");
    }
    assert!(hip.y > 0.05 && hip.z < -0.05, "{hip}");
    let knee = robot
        .joints()
        .iter()
        .find(|j| j.name == "left_knee_joint")
        .unwrap();
    let mut state = State::neutral(&robot);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..10 {
        for j in ["left_hip_pitch_joint", "left_knee_joint", "waist_yaw_joint"] {
            state
                .set_joint(&robot, j, rng.random_range(0.0..0.5))
                .unwrap();
        }
        let kin = Kinematics::new(&robot, &state).unwrap();
        let origin = (kin.link_pose(knee.parent).unwrap() * knee.origin)
            .translation
            .vector;
        let x = centres.at(&kin).unwrap()[ix(BodyPoint::LeftKnee)];
        assert!((x - origin).norm() < 1e-12, "{x} vs {origin}");
    }
}
