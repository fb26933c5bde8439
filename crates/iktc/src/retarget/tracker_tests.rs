//! Tests of the keypoint controller: a held foot's pivot and the levels of its stacks.

use super::*;
use crate::profile::RobotProfile;

/// G1 set up on `humanoid3d_dance_b` with `s`: its robot, start state, body, the
/// controller (for its plan) and the posture's joint names.
fn g1(
    s: &KeypointSettings,
) -> (
    Arc<Robot>,
    State,
    RobotBody,
    KeypointController,
    Vec<String>,
) {
    let profile = RobotProfile::builtin("g1").unwrap();
    let kp = super::super::builtin_motion("humanoid3d_dance_b")
        .unwrap()
        .keypoints(crate::motion::DEFAULT_MAX_GAP)
        .unwrap();
    let robot = Arc::new(profile.robot().unwrap());
    let set = super::super::setup(robot, &profile, &kp, None, s).unwrap();
    // The set-up's robot: the profile's with frames at the joint centres.
    let robot = set.robot.clone();
    let names = robot.active_joints().map(|j| j.name.clone()).collect();
    let state = set.controller.state().clone();
    (robot, state, set.body, set.controller, names)
}

/// A foot whose plan pivots about its sole's centre `c` (yaw `ψ(t) = sin t`, the ankle
/// at `c − R_z(ψ) s`): with the latch at full weight (in stance) the reference keeps the
/// sole's centre at `c + d`, turned by the latched yaw, and with any weight (here
/// `w(t) = (1 − cos t)/2`, fading as in a swing) its velocity and acceleration are the
/// central differences of its pose.
#[test]
fn a_held_foot_pivots_about_its_sole_centre() {
    use super::super::plan::{PointRef, PoseRef};
    let s = KeypointSettings::default();
    let (_, _, _, c, _) = g1(&s);
    let mut p = c.plan().clone();
    // Sample spacing of the synthetic plan [s]: central differences err by O(h²).
    let h = 1e-4;
    let n = 3000;
    let sole = Vector3::new(0.035, 0.01, -0.035);
    let centre = Vector3::new(0.3, -0.1, 0.035);
    let pose = |t: f64| {
        let (psi, om, al) = (t.sin(), t.cos(), -t.sin());
        let rot = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), psi);
        let (w, a) = (om * Vector3::z(), al * Vector3::z());
        let r = rot * sole;
        PoseRef {
            position: PointRef {
                position: centre - r,
                velocity: -w.cross(&r),
                acceleration: -(a.cross(&r) + w.cross(&w.cross(&r))),
            },
            rotation: rot,
            angular_velocity: w,
            angular_acceleration: a,
        }
    };
    let times: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
    p.feet[0] = times.iter().map(|t| pose(*t)).collect();
    let latch = (Vector3::new(0.004, -0.003, 0.0), 0.2);
    // Held: the sole's centre stays where the latch put it.
    p.latch_weight[0] = vec![[1.0, 0.0, 0.0]; n];
    for k in (0..n).step_by(100) {
        let r = foot_reference(&p, 0, k, false, latch, &sole);
        let centre_now = r.pose.translation.vector + r.pose.rotation * sole;
        assert!((centre_now - (centre + latch.0)).norm() < 1e-12, "{k}");
        let yaw = (r.pose.rotation * p.feet[0][k].rotation.inverse()).angle();
        assert!((yaw - latch.1).abs() < 1e-12, "{k}: {yaw}");
    }
    // Fading: the rates are the pose's.
    p.latch_weight[0] = times
        .iter()
        .map(|t| [0.5 * (1.0 - t.cos()), 0.5 * t.sin(), 0.5 * t.cos()])
        .collect();
    let refs: Vec<_> = (0..n)
        .map(|k| foot_reference(&p, 0, k, false, latch, &sole))
        .collect();
    // Largest difference from the central differences [m/s, m/s², rad/s, rad/s²]: O(h²)
    // times third derivatives of order 1.
    let tol = 1e-6;
    for k in 1..n - 1 {
        let (a, r, b) = (&refs[k - 1], &refs[k], &refs[k + 1]);
        let v = (b.pose.translation.vector - a.pose.translation.vector) / (2.0 * h);
        let acc = (b.velocity - a.velocity) / (2.0 * h);
        let om = (b.pose.rotation * a.pose.rotation.inverse()).scaled_axis() / (2.0 * h);
        assert!((v - r.velocity.fixed_rows::<3>(0)).norm() < tol, "{k}: v");
        assert!((om - r.velocity.fixed_rows::<3>(3)).norm() < tol, "{k}: ω");
        assert!((acc - r.acceleration).norm() < tol, "{k}: a");
    }
}

/// The feet's levels of a stack (what GF takes over when IKTC corrects them under a held
/// foot) are its leading `stance_feet` and `swing_floor` levels, whichever it has.
#[test]
fn the_feet_levels_are_the_leading_stance_and_floor_levels() {
    use FootMode::{Floor, Landing, Stance, Swing};
    let s = KeypointSettings::default();
    let (robot, state, body, c, names) = g1(&s);
    for (modes, want) in [
        ([Stance, Stance], 1),
        ([Stance, Swing], 1),
        ([Stance, Landing], 2),
        ([Swing, Floor], 1),
        ([Swing, Swing], 0),
    ] {
        let stack = build_stack(&robot, &state, &body, c.plan(), &names, &s, modes).unwrap();
        let lead = levels(&stack)
            .iter()
            .take_while(|l| l.0 == KEYPOINT_LEVELS[0] || l.0 == KEYPOINT_LEVELS[1])
            .count();
        assert_eq!(lead, want, "{modes:?}");
        assert_eq!(stack.feet_levels, want, "{modes:?}");
    }
}

/// A foot near the ground that is not held has its floor rows (height, roll, pitch) in the
/// first level, beside the held feet; a landing foot its horizontal position and yaw in
/// the second; a foot in the air, its floor engaged or not, its position in `swing_feet`,
/// before the pelvis and the torso's orientation; the COM only with `balance` (or
/// standing), between the feet's levels and the swing feet, the torso's orientation then
/// with the elbows.
#[test]
fn the_floor_leads_and_the_feet_in_the_air_come_before_the_pelvis() {
    use FootMode::{Floor, Landing, Stance, Swing};
    let s = KeypointSettings::default();
    let (robot, state, body, c, names) = g1(&s);
    let rows = |modes: [FootMode; 2], s: &KeypointSettings| {
        let stack = build_stack(&robot, &state, &body, c.plan(), &names, s, modes).unwrap();
        levels(&stack).into_iter().take(5).collect::<Vec<_>>()
    };
    assert_eq!(
        rows([Stance, Floor], &s),
        named(&[
            ("stance_feet", 6 + 3),
            ("swing_feet", 3),
            ("pelvis_torso", 6 + 3),
            ("hands", 6 + 29),
            ("elbows_head", 6 + 3),
        ])
    );
    assert_eq!(
        rows([Landing, Swing], &s),
        named(&[
            ("stance_feet", 3),
            ("swing_floor", 3),
            ("swing_feet", 3),
            ("pelvis_torso", 6 + 3),
            ("hands", 6 + 29),
        ])
    );
    let balance = KeypointSettings {
        balance: true,
        ..s.clone()
    };
    // With the COM level the torso's orientation joins the elbows in the seventh level.
    let all = |modes: [FootMode; 2], s: &KeypointSettings| {
        let stack = build_stack(&robot, &state, &body, c.plan(), &names, s, modes).unwrap();
        levels(&stack)
    };
    assert_eq!(
        all([Swing, Stance], &balance),
        named(&[
            ("stance_feet", 6),
            ("com_xy", 2),
            ("swing_feet", 3),
            ("pelvis_torso", 6),
            ("hands", 6 + 29),
            ("elbows_head", 6 + 3 + 3),
        ])
    );
    let standing = KeypointSettings {
        standing: true,
        ..s
    };
    assert_eq!(
        rows([Stance, Stance], &standing)[..2],
        named(&[("stance_feet", 12), ("com_xy", 2)])[..]
    );
}

/// The levels of a stack, as (name, rows).
fn levels(stack: &Stack) -> Vec<(String, usize)> {
    let levels = &stack.ctl.stack().levels;
    levels.iter().map(|l| (l.name.clone(), l.dim())).collect()
}

fn named(v: &[(&str, usize)]) -> Vec<(String, usize)> {
    v.iter().map(|(n, m)| (n.to_string(), *m)).collect()
}

/// With a posture weight the posture rows (one per active joint, 29 on G1) follow the
/// hands' positions (3 rows each) in the sixth level; the elbows (3 rows each) make the
/// seventh, or join the sixth with a body weight; the torso's orientation (3) is in the
/// pelvis' level either way. With a posture weight of 0 the posture has a level of its
/// own, last.
#[test]
fn the_posture_rows_share_the_hands_level() {
    let stance = [FootMode::Stance, FootMode::Stance];
    let s = KeypointSettings::default();
    let (robot, state, body, c, names) = g1(&s);
    assert_eq!(names.len(), 29);
    let stack = build_stack(&robot, &state, &body, c.plan(), &names, &s, stance).unwrap();
    let want = [
        ("stance_feet", 12),
        ("pelvis_torso", 6 + 3),
        ("hands", 6 + 29),
        ("elbows_head", 6),
    ];
    assert_eq!(levels(&stack), named(&want));
    let weighted = KeypointSettings {
        body_weight: 0.2,
        ..s.clone()
    };
    let stack = build_stack(&robot, &state, &body, c.plan(), &names, &weighted, stance).unwrap();
    let want = [
        ("stance_feet", 12),
        ("pelvis_torso", 6 + 3),
        ("hands", 6 + 6 + 29),
    ];
    assert_eq!(levels(&stack), named(&want));
    let s0 = KeypointSettings {
        posture_weight: 0.0,
        ..s
    };
    let stack = build_stack(&robot, &state, &body, c.plan(), &names, &s0, stance).unwrap();
    let want = [
        ("stance_feet", 12),
        ("pelvis_torso", 6 + 3),
        ("hands", 6),
        ("elbows_head", 6),
        ("posture", 29),
    ];
    assert_eq!(levels(&stack), named(&want));
}

/// A body without elbows or head frames has no seventh level while both feet are held
/// (an empty level is an error), and one with the swing foot's orientation otherwise; a
/// body with elbows has it. The torso's orientation is in the pelvis' level when the body
/// has a torso frame.
#[test]
fn the_seventh_level_is_there_only_with_a_task() {
    let s = KeypointSettings::default();
    let (robot, state, body, c, names) = g1(&s);
    let hands_only = RobotBody {
        torso: None,
        points: body
            .points
            .iter()
            .filter(|(p, _)| {
                !matches!(
                    p,
                    BodyPoint::LeftElbow | BodyPoint::RightElbow | BodyPoint::Head
                )
            })
            .copied()
            .collect(),
        ..body.clone()
    };
    let stance = [FootMode::Stance, FootMode::Stance];
    let swing = [FootMode::Swing, FootMode::Stance];
    let stack = build_stack(&robot, &state, &hands_only, c.plan(), &names, &s, stance).unwrap();
    let names_of = |st: &Stack| -> Vec<String> { levels(st).into_iter().map(|l| l.0).collect() };
    assert!(!names_of(&stack).iter().any(|n| n == KEYPOINT_LEVELS[6]));
    assert!(levels(&stack).contains(&(KEYPOINT_LEVELS[4].to_string(), 6)));
    let stack = build_stack(&robot, &state, &hands_only, c.plan(), &names, &s, swing).unwrap();
    assert_eq!(
        levels(&stack).last().unwrap(),
        &(KEYPOINT_LEVELS[6].to_string(), 3)
    );
    let torso_only = RobotBody {
        torso: body.torso,
        ..hands_only.clone()
    };
    let stack = build_stack(&robot, &state, &torso_only, c.plan(), &names, &s, stance).unwrap();
    assert!(!names_of(&stack).iter().any(|n| n == KEYPOINT_LEVELS[6]));
    assert!(levels(&stack).contains(&(KEYPOINT_LEVELS[4].to_string(), 6 + 3)));
    let elbows_only = RobotBody {
        torso: None,
        points: body
            .points
            .iter()
            .filter(|(p, _)| *p != BodyPoint::Head)
            .copied()
            .collect(),
        ..body.clone()
    };
    let stack = build_stack(&robot, &state, &elbows_only, c.plan(), &names, &s, stance).unwrap();
    assert_eq!(
        levels(&stack).last().unwrap(),
        &(KEYPOINT_LEVELS[6].to_string(), 6)
    );
}
