//! Construction checks of Skeleton, Clip and BvhClip: bad input is an error, never a panic.

use iktc::motion::{
    BvhChannel, BvhClip, BvhJoint, Clip, JointKind, Pose, Skeleton, SkeletonJoint, UpAxis,
};
use nalgebra::{Unit, UnitQuaternion, Vector3};

fn joint(name: &str, parent: Option<usize>, kind: JointKind) -> SkeletonJoint {
    SkeletonJoint {
        name: name.to_string(),
        parent,
        offset: Vector3::new(0.0, 0.0, 0.5),
        kind,
    }
}

fn arm() -> Skeleton {
    Skeleton::new(vec![
        joint("base", None, JointKind::Root),
        joint("shoulder", Some(0), JointKind::Spherical),
        joint(
            "elbow",
            Some(1),
            JointKind::Hinge {
                axis: Vector3::y_axis(),
            },
        ),
        joint("hand", Some(2), JointKind::Fixed),
    ])
    .unwrap()
}

#[test]
fn bad_skeletons_are_refused() {
    let root = joint("r", None, JointKind::Root);
    assert!(Skeleton::new(vec![]).is_err());
    assert!(Skeleton::new(vec![joint("r", None, JointKind::Spherical)]).is_err());
    assert!(Skeleton::new(vec![root.clone(), joint("r", Some(0), JointKind::Fixed)]).is_err());
    assert!(Skeleton::new(vec![root.clone(), joint("a", Some(1), JointKind::Fixed)]).is_err());
    assert!(Skeleton::new(vec![root.clone(), joint("a", Some(0), JointKind::Root)]).is_err());
    assert!(Skeleton::new(vec![root.clone(), joint("", Some(0), JointKind::Fixed)]).is_err());
    let mut nan = joint("a", Some(0), JointKind::Fixed);
    nan.offset.x = f64::NAN;
    assert!(Skeleton::new(vec![root, nan]).is_err());
}

/// Forward kinematics by hand: shoulder turned 90° about x, elbow 90° about y.
#[test]
fn forward_kinematics_by_hand() {
    let s = arm();
    let mut pose = s.rest_pose();
    pose.root_position = Vector3::new(1.0, 0.0, 0.0);
    pose.rotations[1] =
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
    pose.rotations[2] =
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2);
    let p = s.world_positions(&pose).unwrap();
    // shoulder at root + (0, 0, 0.5); elbow at shoulder + Rx(90°)(0, 0, 0.5) = + (0, −0.5, 0);
    // hand at elbow + Rx(90°)Ry(90°)(0, 0, 0.5) = + Rx(90°)(0.5, 0, 0) = + (0.5, 0, 0).
    let expected = [
        Vector3::new(1.0, 0.0, 0.0),
        Vector3::new(1.0, 0.0, 0.5),
        Vector3::new(1.0, -0.5, 0.5),
        Vector3::new(1.5, -0.5, 0.5),
    ];
    for (a, b) in p.iter().zip(&expected) {
        assert!((a - b).norm() < 1e-12, "{a} vs {b}");
    }
    let mut short = pose.clone();
    short.rotations.pop();
    assert!(s.world_positions(&short).is_err());
}

#[test]
fn bad_clips_are_refused() {
    let s = arm();
    let rest = s.rest_pose();
    assert!(Clip::new("c", s.clone(), vec![], vec![], UpAxis::Z).is_err());
    assert!(Clip::new(
        "c",
        s.clone(),
        vec![0.0],
        vec![rest.clone(), rest.clone()],
        UpAxis::Z
    )
    .is_err());
    assert!(Clip::new(
        "c",
        s.clone(),
        vec![0.0, 0.0],
        vec![rest.clone(), rest.clone()],
        UpAxis::Z
    )
    .is_err());
    assert!(Clip::new(
        "c",
        s.clone(),
        vec![0.0, f64::NAN],
        vec![rest.clone(), rest.clone()],
        UpAxis::Z
    )
    .is_err());
    let mut bad: Pose = rest.clone();
    bad.translations.pop();
    assert!(Clip::new("c", s.clone(), vec![0.0], vec![bad], UpAxis::Z).is_err());
    let mut bad = rest.clone();
    bad.root_position.z = f64::INFINITY;
    assert!(Clip::new("c", s.clone(), vec![0.0], vec![bad], UpAxis::Z).is_err());
    let single = Clip::new("c", s, vec![0.25], vec![rest.clone()], UpAxis::Z).unwrap();
    assert_eq!(single.duration(), 0.0);
    assert!(single.mean_frame_rate().is_none());
    assert_eq!(single.sample(3.0).unwrap(), rest);
    // Z-up clips are left alone.
    assert_eq!(single.to_z_up(), single);
}

#[test]
fn bad_bvh_clips_are_refused() {
    let j =
        |name: &str, parent: Option<usize>, channels: Vec<BvhChannel>, end_site: bool| BvhJoint {
            name: name.to_string(),
            parent,
            offset: Vector3::zeros(),
            channels,
            end_site,
        };
    let rz = vec![BvhChannel::Zrotation];
    let ok = vec![
        j("a", None, rz.clone(), false),
        j("b", Some(0), rz.clone(), false),
        j("c", Some(1), vec![], true),
    ];
    assert!(BvhClip::new("x", ok.clone(), 0.1, 2, vec![0.0; 4], UpAxis::Y).is_ok());
    assert!(BvhClip::new("x", ok.clone(), 0.1, 2, vec![0.0; 3], UpAxis::Y).is_err());
    assert!(BvhClip::new("x", ok.clone(), 0.0, 2, vec![0.0; 4], UpAxis::Y).is_err());
    assert!(BvhClip::new("x", ok.clone(), 0.1, 0, vec![], UpAxis::Y).is_err());
    assert!(BvhClip::new("x", ok.clone(), 0.1, 1, vec![0.0, f64::NAN], UpAxis::Y).is_err());
    // Not depth-first: c's parent a is an ancestor of b, fine; but d under b after c (a leaf of a) is not.
    let not_dfs = vec![
        j("a", None, rz.clone(), false),
        j("b", Some(0), rz.clone(), false),
        j("c", Some(0), rz.clone(), false),
        j("d", Some(1), rz.clone(), false),
    ];
    assert!(BvhClip::new("x", not_dfs, 0.1, 1, vec![0.0; 4], UpAxis::Y).is_err());
    let under_end = vec![
        j("a", None, rz.clone(), false),
        j("e", Some(0), vec![], true),
        j("f", Some(1), rz.clone(), false),
    ];
    assert!(BvhClip::new("x", under_end, 0.1, 1, vec![0.0; 2], UpAxis::Y).is_err());
    let twice = vec![j(
        "a",
        None,
        vec![BvhChannel::Zrotation, BvhChannel::Zrotation],
        false,
    )];
    assert!(BvhClip::new("x", twice, 0.1, 1, vec![0.0; 2], UpAxis::Y).is_err());
    // A hinge axis that is not a coordinate axis is exported as three channels.
    let skew = Unit::new_normalize(Vector3::new(1.0, 1.0, 0.0));
    let s = Skeleton::new(vec![
        SkeletonJoint {
            name: "r".into(),
            parent: None,
            offset: Vector3::zeros(),
            kind: JointKind::Root,
        },
        SkeletonJoint {
            name: "h".into(),
            parent: Some(0),
            offset: Vector3::x(),
            kind: JointKind::Hinge { axis: skew },
        },
    ])
    .unwrap();
    let mut pose = s.rest_pose();
    pose.rotations[1] = UnitQuaternion::from_axis_angle(&skew, 0.7);
    let clip = Clip::new("skew", s, vec![0.0], vec![pose.clone()], UpAxis::Z).unwrap();
    let bvh = BvhClip::from_clip(&clip, &Default::default()).unwrap();
    assert_eq!(bvh.joints()[1].channels.len(), 3);
    let back = bvh.to_clip().unwrap();
    assert!(back.frame(0).unwrap().rotations[1].angle_to(&pose.rotations[1]) < 1e-12);
}
