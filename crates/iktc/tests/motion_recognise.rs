//! Skeletons recognised without a map: naming families (Mixamo, LAFAN1, Blender/Rigify, SMPL,
//! CMU), the shape fallback for unknown names, and the error for an unrecognisable skeleton.

mod motion_common;

use std::path::Path;

use iktc::motion::{
    load_motion, read_bvh, recognise_skeleton, BodyMap, BodyPoint, BvhReadOptions, Clip, FoundBy,
    LengthUnit, MotionOptions, PointSource, UpAxis,
};
use iktc::Error;
use motion_common::{bvh_text, humanoid, Role};

fn clip(text: &str) -> Clip {
    read_bvh(
        text,
        "test.bvh",
        &BvhReadOptions {
            length_unit: LengthUnit::Centimetres,
            up_axis: UpAxis::Y,
            ..Default::default()
        },
    )
    .unwrap()
    .to_clip()
    .unwrap()
}

fn joint(map: &BodyMap, p: BodyPoint) -> String {
    match map.get(p) {
        Some(PointSource::Joint(j)) => j.clone(),
        other => panic!("{p}: {other:?}"),
    }
}

/// Builds the test humanoid with a family's names and checks every body point lands on the
/// joint of the right role and side, found by name or structure.
fn check_family(name: &dyn Fn(Role, char) -> String, twist: bool) {
    let c = clip(&bvh_text(&humanoid(name, twist), 3));
    let map = recognise_skeleton(c.skeleton(), "family").unwrap();
    let expect = [
        (BodyPoint::Pelvis, Role::Hips, ' '),
        (BodyPoint::Chest, Role::Spine2, ' '),
        (BodyPoint::Neck, Role::Neck, ' '),
        (BodyPoint::Head, Role::Head, ' '),
        (BodyPoint::LeftShoulder, Role::UpperArm, 'L'),
        (BodyPoint::LeftElbow, Role::ForeArm, 'L'),
        (BodyPoint::LeftWrist, Role::Hand, 'L'),
        (BodyPoint::LeftHip, Role::UpLeg, 'L'),
        (BodyPoint::LeftKnee, Role::Leg, 'L'),
        (BodyPoint::LeftAnkle, Role::Foot, 'L'),
        (BodyPoint::LeftToe, Role::Toe, 'L'),
        (BodyPoint::RightShoulder, Role::UpperArm, 'R'),
        (BodyPoint::RightElbow, Role::ForeArm, 'R'),
        (BodyPoint::RightWrist, Role::Hand, 'R'),
        (BodyPoint::RightHip, Role::UpLeg, 'R'),
        (BodyPoint::RightKnee, Role::Leg, 'R'),
        (BodyPoint::RightAnkle, Role::Foot, 'R'),
        (BodyPoint::RightToe, Role::Toe, 'R'),
    ];
    for (p, role, side) in expect {
        assert_eq!(joint(&map, p), name(role, side), "{p}");
    }
    assert!(map
        .points
        .iter()
        .all(|p| matches!(p.found_by, FoundBy::Name | FoundBy::Structure)));
}

fn side_word(side: char, left: &str, right: &str) -> String {
    match side {
        'L' => left.to_string(),
        'R' => right.to_string(),
        _ => String::new(),
    }
}

#[test]
fn mixamo_names_are_recognised() {
    check_family(
        &|role, side| {
            let s = side_word(side, "Left", "Right");
            let base = match role {
                Role::Hips => "Hips".to_string(),
                Role::Spine => "Spine".to_string(),
                Role::Spine1 => "Spine1".to_string(),
                Role::Spine2 => "Spine2".to_string(),
                Role::Neck => "Neck".to_string(),
                Role::Head => "Head".to_string(),
                Role::Collar => format!("{s}Shoulder"),
                Role::UpperArm => format!("{s}Arm"),
                Role::ForeArm => format!("{s}ForeArm"),
                Role::Hand => format!("{s}Hand"),
                Role::UpLeg => format!("{s}UpLeg"),
                Role::Leg => format!("{s}Leg"),
                Role::Foot => format!("{s}Foot"),
                Role::Toe => format!("{s}ToeBase"),
                other => panic!("{other:?}"),
            };
            format!("mixamorig:{base}")
        },
        false,
    );
}

fn lafan(role: Role, side: char) -> String {
    let s = side_word(side, "Left", "Right");
    match role {
        Role::Hips => "Hips".to_string(),
        Role::Spine => "Spine".to_string(),
        Role::Spine1 => "Spine1".to_string(),
        Role::Spine2 => "Spine2".to_string(),
        Role::Neck => "Neck".to_string(),
        Role::Head => "Head".to_string(),
        Role::Collar => format!("{s}Shoulder"),
        Role::UpperArm => format!("{s}Arm"),
        Role::ForeArm => format!("{s}ForeArm"),
        Role::Hand => format!("{s}Hand"),
        Role::UpLeg => format!("{s}UpLeg"),
        Role::Leg => format!("{s}Leg"),
        Role::Foot => format!("{s}Foot"),
        Role::Toe => format!("{s}Toe"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn lafan1_names_are_recognised() {
    check_family(&lafan, false);
}

fn rigify(role: Role, side: char) -> String {
    let s = side_word(side, ".L", ".R");
    let name = match role {
        Role::Hips => "spine".to_string(),
        Role::Spine => "spine.001".to_string(),
        Role::Spine1 => "spine.002".to_string(),
        Role::Spine2 => "spine.003".to_string(),
        Role::Neck => "spine.004".to_string(),
        Role::Head => "spine.006".to_string(),
        Role::Collar => format!("shoulder{s}"),
        Role::UpperArm => format!("upper_arm{s}"),
        Role::UpperArmTwist => format!("upper_arm{s}.001"),
        Role::ForeArm => format!("forearm{s}"),
        Role::ForeArmTwist => format!("forearm{s}.001"),
        Role::Hand => format!("hand{s}"),
        Role::UpLeg => format!("thigh{s}"),
        Role::UpLegTwist => format!("thigh{s}.001"),
        Role::Leg => format!("shin{s}"),
        Role::LegTwist => format!("shin{s}.001"),
        Role::Foot => format!("foot{s}"),
        Role::Toe => format!("toe{s}"),
    };
    format!("DEF-{name}")
}

#[test]
fn blender_rigify_names_with_twist_bones_are_recognised() {
    check_family(&rigify, true);
}

#[test]
fn smpl_names_in_both_spellings_are_recognised() {
    for (l, r, capital) in [("L_", "R_", true), ("left_", "right_", false)] {
        check_family(
            &|role, side| {
                let s = side_word(side, l, r);
                let word = match role {
                    Role::Hips => "pelvis",
                    Role::Spine => "spine1",
                    Role::Spine1 => "spine2",
                    Role::Spine2 => "spine3",
                    Role::Neck => "neck",
                    Role::Head => "head",
                    Role::Collar => "collar",
                    Role::UpperArm => "shoulder",
                    Role::ForeArm => "elbow",
                    Role::Hand => "wrist",
                    Role::UpLeg => "hip",
                    Role::Leg => "knee",
                    Role::Foot => "ankle",
                    Role::Toe => "foot",
                    other => panic!("{other:?}"),
                };
                let word = if capital {
                    let mut c = word.chars();
                    c.next()
                        .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
                        .unwrap_or_default()
                } else {
                    word.to_string()
                };
                format!("{s}{word}")
            },
            false,
        );
    }
}

/// The BVH text with every joint renamed `J0`, `J1`, … in file order.
fn renamed(text: &str) -> String {
    let mut count = 0;
    let out: Vec<String> = text
        .lines()
        .map(|l| {
            let t = l.trim_start();
            for kw in ["ROOT ", "JOINT "] {
                if t.starts_with(kw) {
                    count += 1;
                    return format!("{kw}J{}", count - 1);
                }
            }
            l.to_string()
        })
        .collect();
    out.join("\n")
}

/// The renamed skeleton is recognised by its shape; every required point lands on the joint
/// that the names put it on, or on a joint at the same place (the CMU wrist's zero-length
/// bone): their positions in the clip's last frame agree, so no limb changed side.
fn check_shape_fallback(text: &str, tolerance: f64) {
    let original = clip(text);
    let by_name = recognise_skeleton(original.skeleton(), "named").unwrap();
    assert!(by_name.points.iter().all(|p| p.found_by != FoundBy::Shape));
    let renamed_clip = clip(&renamed(text));
    let by_shape = recognise_skeleton(renamed_clip.skeleton(), "renamed").unwrap();
    assert!(by_shape.points.iter().all(|p| p.found_by == FoundBy::Shape));
    let rest = |c: &Clip, map: &BodyMap, p: BodyPoint| {
        let name = joint(map, p);
        let j = c.skeleton().index_of(&name).unwrap();
        c.world_positions(c.frame_count() - 1).unwrap()[j]
    };
    for p in BodyPoint::REQUIRED {
        let a = rest(&original, &by_name, p);
        let b = rest(&renamed_clip, &by_shape, p);
        assert!((a - b).norm() <= tolerance, "{p}: {a:?} vs {b:?}");
    }
}

#[test]
fn renamed_generated_skeletons_fall_back_to_their_shape() {
    check_shape_fallback(&bvh_text(&humanoid(&lafan, false), 3), 1e-12);
    check_shape_fallback(&bvh_text(&humanoid(&rigify, true), 3), 1e-12);
}

#[test]
fn the_cmu_clip_renamed_falls_back_to_its_shape_with_limbs_on_the_right_sides() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/motions/cmu/131_01.bvh"),
    )
    .unwrap();
    check_shape_fallback(&text, 1e-12);
}

#[test]
fn a_skeleton_neither_named_nor_shaped_like_a_human_is_an_error_listing_what_is_missing() {
    // A chain of four joints: no legs, no arms.
    let text = "HIERARCHY
ROOT A
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT LeftKnee
  {
    OFFSET 0 -40 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT C
    {
      OFFSET 0 -40 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 -5 10
      }
    }
  }
}
MOTION
Frames: 1
Frame Time: 0.1
0 0 0 0 0 0 0 0 0 0 0 0
";
    let e = recognise_skeleton(clip(text).skeleton(), "snake.bvh").unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, Error::InsufficientData { .. }));
    for part in [
        "snake.bvh",
        "found by name: left_knee=LeftKnee",
        "missing: pelvis, head",
        "right_ankle",
        "joints: A, LeftKnee, C",
        "--map",
        "iktc map init",
    ] {
        assert!(msg.contains(part), "`{part}` not in: {msg}");
    }
    // load_motion with automatic up axis reports the same recognition error.
    let dir = std::env::temp_dir().join(format!("iktc_recognise_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("snake.bvh");
    std::fs::write(&path, text).unwrap();
    let e = load_motion(&path, &MotionOptions::default()).unwrap_err();
    assert!(e.to_string().contains("missing: pelvis"), "{e}");
    std::fs::remove_file(&path).ok();
}

#[test]
fn a_saved_map_reads_back_and_replaces_recognition() {
    let c = clip(&bvh_text(&humanoid(&lafan, false), 2));
    let map = recognise_skeleton(c.skeleton(), "x").unwrap();
    let text = map.to_toml_string();
    let back = BodyMap::from_toml_str(&text, "x.toml").unwrap();
    assert_eq!(back.points.len(), map.points.len());
    for (a, b) in map.points.iter().zip(&back.points) {
        assert_eq!((a.point, &a.source), (b.point, &b.source));
        assert_eq!(b.found_by, FoundBy::Given);
    }
    // A map missing a required point is refused, naming it.
    let cut: String = text
        .lines()
        .filter(|l| !l.starts_with("left_wrist"))
        .collect::<Vec<_>>()
        .join("\n");
    let e = BodyMap::from_toml_str(&cut, "cut.toml").unwrap_err();
    assert!(e.to_string().contains("left_wrist"), "{e}");
    // An unknown body point is refused, listing the valid ones.
    let e = BodyMap::from_toml_str("[points]\nleft_tail = \"X\"\n", "bad.toml").unwrap_err();
    assert!(e.to_string().contains("left_tail") && e.to_string().contains("left_wrist"));
}
