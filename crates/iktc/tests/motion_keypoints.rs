//! Body keypoints from skeletons: forward kinematics against hand-computed points, units and up
//! axis decided automatically, the two CMU clips, the DeepMimic character.

use std::path::{Path, PathBuf};

use iktc::motion::{
    deepmimic_skeleton, load_motion, motion_from_content, read_bvh, recognise_skeleton, write_bvh,
    BodyPoint, BvhReadOptions, BvhWriteOptions, Clip, LengthUnit, Motion, MotionContent,
    MotionFormat, MotionOptions, Units, UpAxis, UpChoice, CMU_METRES_PER_UNIT,
};
use iktc::Error;
use nalgebra::Vector3;

fn cmu(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/motions/cmu")
        .join(name)
}

fn from_text(text: &str, name: &str, options: &MotionOptions) -> iktc::Result<Motion> {
    let clip = read_bvh(
        text,
        name,
        &BvhReadOptions {
            length_unit: LengthUnit::Metres,
            up_axis: UpAxis::Y,
            ..Default::default()
        },
    )?
    .to_clip()?;
    motion_from_content(
        name.to_string(),
        MotionFormat::Bvh,
        MotionContent::Skeleton(clip),
        options,
    )
}

/// A Mixamo-like chain in centimetres: legs, spine, arms; frame 1 moves and turns the root and
/// bends the left elbow.
const SMALL: &str = "HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT Spine1
    {
      OFFSET 0 12 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT Spine2
      {
        OFFSET 0 12 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT Neck
        {
          OFFSET 0 15 0
          CHANNELS 3 Zrotation Xrotation Yrotation
          JOINT Head
          {
            OFFSET 0 10 0
            CHANNELS 3 Zrotation Xrotation Yrotation
            End Site
            {
              OFFSET 0 18 0
            }
          }
        }
        JOINT LeftShoulder
        {
          OFFSET 5 10 0
          CHANNELS 3 Zrotation Xrotation Yrotation
          JOINT LeftArm
          {
            OFFSET 12 0 0
            CHANNELS 3 Zrotation Xrotation Yrotation
            JOINT LeftForeArm
            {
              OFFSET 28 0 0
              CHANNELS 3 Zrotation Xrotation Yrotation
              JOINT LeftHand
              {
                OFFSET 25 0 0
                CHANNELS 3 Zrotation Xrotation Yrotation
                End Site
                {
                  OFFSET 8 0 0
                }
              }
            }
          }
        }
        JOINT RightShoulder
        {
          OFFSET -5 10 0
          CHANNELS 3 Zrotation Xrotation Yrotation
          JOINT RightArm
          {
            OFFSET -12 0 0
            CHANNELS 3 Zrotation Xrotation Yrotation
            JOINT RightForeArm
            {
              OFFSET -28 0 0
              CHANNELS 3 Zrotation Xrotation Yrotation
              JOINT RightHand
              {
                OFFSET -25 0 0
                CHANNELS 3 Zrotation Xrotation Yrotation
                End Site
                {
                  OFFSET -8 0 0
                }
              }
            }
          }
        }
      }
    }
  }
  JOINT LeftUpLeg
  {
    OFFSET 10 -5 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT LeftLeg
    {
      OFFSET 0 -45 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT LeftFoot
      {
        OFFSET 0 -45 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT LeftToeBase
        {
          OFFSET 0 -5 12
          CHANNELS 3 Zrotation Xrotation Yrotation
          End Site
          {
            OFFSET 0 0 5
          }
        }
      }
    }
  }
  JOINT RightUpLeg
  {
    OFFSET -10 -5 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT RightLeg
    {
      OFFSET 0 -45 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT RightFoot
      {
        OFFSET 0 -45 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT RightToeBase
        {
          OFFSET 0 -5 12
          CHANNELS 3 Zrotation Xrotation Yrotation
          End Site
          {
            OFFSET 0 0 5
          }
        }
      }
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
";

/// Frame 0 at rest with the root at 95 cm; frame 1: root at (10, 95, 0) cm turned 90° about y,
/// the left forearm bent 90° about z. Channels: root 6, then 3 per joint in file order
/// (Spine, Spine1, Spine2, Neck, Head, LeftShoulder, LeftArm, LeftForeArm, ...).
fn small_bvh() -> String {
    let joints = 22;
    let mut f0 = vec![0.0, 95.0, 0.0, 0.0, 0.0, 0.0];
    f0.extend(std::iter::repeat_n(0.0, 3 * (joints - 1)));
    let mut f1 = f0.clone();
    f1[0] = 10.0;
    f1[5] = 90.0; // root Yrotation (order Z X Y)
    let forearm = 6 + 3 * 7; // LeftForeArm is the 8th joint: its Zrotation
    f1[forearm] = 90.0;
    let line = |v: &[f64]| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    format!("{SMALL}{}\n{}\n", line(&f0), line(&f1))
}

fn close(a: Vector3<f64>, b: Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol
}

#[test]
fn forward_kinematics_match_hand_computed_points_in_metres_z_up() {
    let m = from_text(&small_bvh(), "small.bvh", &MotionOptions::default()).unwrap();
    let k = m.keypoints(0.1).unwrap();
    // Decided: centimetres (standing height 177 cm) and +Y up.
    assert_eq!(k.units.unit, LengthUnit::Centimetres);
    assert!(k.units.automatic);
    assert!((k.units.standing_height.unwrap() - 177.0).abs() < 1e-9);
    assert_eq!(k.up.up, UpAxis::Y);
    assert!(k.up.automatic);
    assert_eq!(k.frame_count(), 2);
    // Z-up metres: (x, y, z) cm -> (x, -z, y) / 100.
    let zup = |x: f64, y: f64, z: f64| Vector3::new(x, -z, y) / 100.0;
    // Frame 0: rest pose, root at 95 cm.
    assert!(close(
        k.position(0, BodyPoint::Pelvis).unwrap(),
        zup(0.0, 95.0, 0.0),
        1e-12
    ));
    assert!(close(
        k.position(0, BodyPoint::LeftWrist).unwrap(),
        zup(45.0, 139.0, 0.0) + zup(25.0, 0.0, 0.0),
        1e-12
    ));
    assert!(close(
        k.position(0, BodyPoint::LeftToe).unwrap(),
        zup(10.0, -5.0 - 90.0 - 5.0 + 95.0, 12.0),
        1e-12
    ));
    assert!(close(
        k.position(0, BodyPoint::Head).unwrap(),
        zup(0.0, 95.0 + 59.0, 0.0),
        1e-12
    ));
    // Frame 1: Ry(90°) takes (x, y, z) to (z, y, -x); elbow at root + Ry·(45, 44, 0).
    assert!(close(
        k.position(1, BodyPoint::Pelvis).unwrap(),
        zup(10.0, 95.0, 0.0),
        1e-12
    ));
    assert!(close(
        k.position(1, BodyPoint::LeftElbow).unwrap(),
        zup(10.0, 139.0, -45.0),
        1e-12
    ));
    // Wrist: the hand's offset (25, 0, 0) turned by Rz(90°) to (0, 25, 0), then by Ry.
    assert!(close(
        k.position(1, BodyPoint::LeftWrist).unwrap(),
        zup(10.0, 164.0, -45.0),
        1e-12
    ));
    // The forearm's orientation: Ry(90°)·Rz(90°) takes x to (0, 1, 0) in Y-up, +Z in Z-up.
    let q = k.orientation(1, BodyPoint::LeftElbow).unwrap();
    assert!(close(q * Vector3::x(), Vector3::z(), 1e-12));
    assert!(close(
        k.orientation(0, BodyPoint::LeftElbow).unwrap() * Vector3::x(),
        Vector3::x(),
        1e-12
    ));
}

#[test]
fn given_units_and_up_are_used_and_recorded() {
    let options = MotionOptions {
        units: Units::Fixed(LengthUnit::Centimetres),
        up: UpChoice::Fixed(UpAxis::Y),
        ..MotionOptions::default()
    };
    let m = from_text(&small_bvh(), "small.bvh", &options).unwrap();
    let k = m.keypoints(0.1).unwrap();
    assert!(!k.units.automatic && !k.up.automatic);
    assert!(close(
        k.position(0, BodyPoint::Pelvis).unwrap(),
        Vector3::new(0.0, 0.0, 0.95),
        1e-12
    ));
    // The clip in metres has the offsets scaled by the same unit.
    let clip = m.clip().unwrap().unwrap();
    let spine = clip.skeleton().index_of("Spine").unwrap();
    assert!((clip.skeleton().joints()[spine].offset.y - 0.10).abs() < 1e-15);
}

#[test]
fn a_skeleton_of_no_human_height_in_any_unit_is_an_error_naming_the_heights() {
    // 177 cm tall scaled down 8x: 22 units is CMU's range, so use 12x (14.75 units: none).
    let text = small_bvh()
        .lines()
        .map(|l| match l.trim_start().strip_prefix("OFFSET ") {
            Some(rest) => {
                let v: Vec<String> = rest
                    .split_whitespace()
                    .map(|x| (x.parse::<f64>().unwrap() / 12.0).to_string())
                    .collect();
                format!("OFFSET {}", v.join(" "))
            }
            None => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    let e = from_text(&text, "tiny.bvh", &MotionOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, Error::InvalidSetting { .. }), "{msg}");
    assert!(
        msg.contains("tiny.bvh") && msg.contains("14.75") && msg.contains("give the unit"),
        "{msg}"
    );
}

fn load(path: &Path) -> Motion {
    load_motion(path, &MotionOptions::default()).unwrap()
}

#[test]
fn the_cmu_clips_are_recognised_and_get_their_own_units() {
    let a = load(&cmu("131_01.bvh"));
    let b = load(&cmu("scaled_131_02.bvh"));
    assert_eq!(a.format, MotionFormat::Bvh);
    assert!(
        (a.units.unit.metres_per_unit() - CMU_METRES_PER_UNIT).abs() < 1e-15,
        "{}",
        a.units
    );
    assert_eq!(b.units.unit, LengthUnit::Metres, "{}", b.units);
    assert_eq!((a.up.up, b.up.up), (UpAxis::Y, UpAxis::Y));
    for m in [&a, &b] {
        let map = m.body_map.as_ref().unwrap();
        let joint = |p| match map.get(p) {
            Some(iktc::motion::PointSource::Joint(j)) => j.clone(),
            other => panic!("{p}: {other:?}"),
        };
        assert_eq!(joint(BodyPoint::Pelvis), "Hips");
        assert_eq!(joint(BodyPoint::Chest), "Chest2");
        assert_eq!(joint(BodyPoint::Neck), "lowerneck");
        assert_eq!(joint(BodyPoint::Head), "Head");
        assert_eq!(joint(BodyPoint::LeftShoulder), "LeftShoulder");
        assert_eq!(joint(BodyPoint::RightElbow), "RightElbow");
        assert_eq!(joint(BodyPoint::LeftWrist), "LeftWrist");
        assert_eq!(joint(BodyPoint::RightHip), "RightHip");
        assert_eq!(joint(BodyPoint::LeftKnee), "LeftKnee");
        assert_eq!(joint(BodyPoint::RightAnkle), "RightAnkle");
        assert_eq!(joint(BodyPoint::LeftToe), "LeftToe");
    }
}

/// Rest-pose keypoints (relative to the pelvis) of a motion's skeleton \[m\].
fn rest_points(m: &Motion) -> Vec<(BodyPoint, Vector3<f64>)> {
    let clip = m.clip().unwrap().unwrap();
    let rest = Clip::new(
        "rest",
        clip.skeleton().clone(),
        vec![0.0],
        vec![clip.skeleton().rest_pose()],
        clip.up_axis(),
    )
    .unwrap();
    let mut units = m.units;
    units.unit = LengthUnit::Metres;
    let k = iktc::motion::clip_keypoints(&rest, m.body_map.as_ref().unwrap(), units, m.up).unwrap();
    let pelvis = k.position(0, BodyPoint::Pelvis).unwrap();
    k.points
        .iter()
        .map(|p| (*p, k.position(0, *p).unwrap() - pelvis))
        .collect()
}

#[test]
fn the_two_cmu_clips_give_the_same_skeleton_within_a_millimetre_after_auto_units() {
    let a = rest_points(&load(&cmu("131_01.bvh")));
    let b = rest_points(&load(&cmu("scaled_131_02.bvh")));
    assert_eq!(a.len(), b.len());
    for ((pa, va), (pb, vb)) in a.iter().zip(&b) {
        assert_eq!(pa, pb);
        assert!((va - vb).norm() < 1e-3, "{pa}: {va:?} vs {vb:?}");
    }
    // Not trivially equal: the limbs are tens of centimetres from the pelvis.
    assert!(a.iter().any(|(_, v)| v.norm() > 0.5));
}

#[test]
fn the_cmu_clip_rescaled_to_metres_gives_the_same_keypoints_within_a_millimetre() {
    let original = load(&cmu("131_01.bvh"));
    // The same clip written in metres (read with CMU's unit, written with metres).
    let text = std::fs::read_to_string(cmu("131_01.bvh")).unwrap();
    let bvh = read_bvh(
        &text,
        "131_01",
        &BvhReadOptions {
            length_unit: LengthUnit::Custom {
                metres_per_unit: CMU_METRES_PER_UNIT,
            },
            up_axis: UpAxis::Y,
            ..Default::default()
        },
    )
    .unwrap();
    let metres_text = write_bvh(
        &bvh,
        &BvhWriteOptions {
            length_unit: LengthUnit::Metres,
            decimals: Some(6),
        },
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("iktc_motion_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("131_01_metres.bvh");
    std::fs::write(&path, metres_text).unwrap();
    let rescaled = load(&path);
    assert_eq!(rescaled.units.unit, LengthUnit::Metres);
    let (ka, kb) = (
        original.keypoints(0.1).unwrap(),
        rescaled.keypoints(0.1).unwrap(),
    );
    assert_eq!(ka.frame_count(), 994);
    assert_eq!(ka.points, kb.points);
    let worst = ka
        .positions
        .iter()
        .zip(&kb.positions)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(worst < 1e-3, "worst {worst} m");
    // The pelvis moves: the clip is a walk, not a still pose.
    let travel = (ka.position(993, BodyPoint::Pelvis).unwrap()
        - ka.position(0, BodyPoint::Pelvis).unwrap())
    .norm();
    assert!(travel > 0.3, "{travel}");
    std::fs::remove_file(&path).ok();
}

#[test]
fn the_deepmimic_character_is_recognised_and_stands_about_human_height() {
    let map = recognise_skeleton(&deepmimic_skeleton().unwrap(), "deepmimic").unwrap();
    let joint = |p| match map.get(p) {
        Some(iktc::motion::PointSource::Joint(j)) => j.clone(),
        other => panic!("{p}: {other:?}"),
    };
    assert_eq!(joint(BodyPoint::Pelvis), "root");
    assert_eq!(joint(BodyPoint::Chest), "chest");
    assert_eq!(joint(BodyPoint::Neck), "neck");
    assert_eq!(joint(BodyPoint::Head), "head_top");
    assert_eq!(joint(BodyPoint::LeftWrist), "left_wrist");
    assert_eq!(joint(BodyPoint::RightKnee), "right_knee");
    assert!(map.get(BodyPoint::LeftToe).is_none());
    let clip = iktc::motion::builtin_clip("humanoid3d_walk").unwrap();
    let m = motion_from_content(
        "walk".into(),
        MotionFormat::DeepMimic,
        MotionContent::Skeleton(clip),
        &MotionOptions::default(),
    )
    .unwrap();
    assert_eq!(m.units.unit, LengthUnit::Metres);
    assert_eq!(m.up.up, UpAxis::Y);
    let k = m.keypoints(0.1).unwrap();
    // Z up: the head is above the pelvis, the pelvis above the ankles, in every frame.
    for f in 0..k.frame_count() {
        let z = |p| k.position(f, p).unwrap().z;
        assert!(z(BodyPoint::Head) > z(BodyPoint::Pelvis) + 0.4);
        assert!(z(BodyPoint::Pelvis) > z(BodyPoint::LeftAnkle) + 0.6);
    }
}

/// A rig that lies along +X at rest and writes every joint's whole local translation into six
/// channels (as Bandai Namco's motion dataset does): SMALL with every offset turned by
/// Rz(−90°) (+Y to +X), position channels repeating the turned offsets, and the root turned back
/// up by Rz(+90°) in every frame. Its keypoints equal SMALL's with the same motion; the up axis is
/// decided from the first frame (the rest pose does not stand), the units from its height.
#[test]
fn a_rig_lying_at_rest_with_offsets_in_its_channels_reads_as_standing() {
    use iktc::motion::Measured;
    let turn = |x: f64, y: f64, z: f64| (y, -x, z);
    let mut lying = String::new();
    for line in SMALL.lines() {
        let t = line.trim_start();
        let indent = &line[..line.len() - t.len()];
        if let Some(rest) = t.strip_prefix("OFFSET ") {
            let v: Vec<f64> = rest
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            let (x, y, z) = turn(v[0], v[1], v[2]);
            lying += &format!("{indent}OFFSET {x} {y} {z}\n");
        } else if t == "CHANNELS 3 Zrotation Xrotation Yrotation" {
            lying += &format!(
                "{indent}CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
            );
        } else {
            lying += line;
            lying += "\n";
        }
    }
    // The turned offsets of the joints with channels, in file order (End Site offsets follow
    // their joint's CHANNELS line, so keep only those read before a CHANNELS line).
    let mut channel_offsets = Vec::new();
    let mut last = None;
    for line in lying.lines() {
        let t = line.trim_start();
        if let Some(rest) = t.strip_prefix("OFFSET ") {
            let v: Vec<f64> = rest
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            last = Some((v[0], v[1], v[2]));
        } else if t.starts_with("CHANNELS 6 Xposition") {
            channel_offsets.push(last.take().unwrap());
        }
    }
    let joints = 22;
    assert_eq!(channel_offsets.len(), joints, "{lying}");
    // Frames: root at (0|10, 95, 0) cm; frame 1 bends the left forearm 90° about z.
    let forearm = 7; // the 8th joint
    let frame = |x: f64, bend: f64, standing: bool| -> Vec<f64> {
        let mut v = vec![x, 95.0, 0.0, if standing { 0.0 } else { 90.0 }, 0.0, 0.0];
        for (j, o) in channel_offsets.iter().enumerate().skip(1) {
            if !standing {
                v.extend([o.0, o.1, o.2]);
            }
            v.extend([if j == forearm { bend } else { 0.0 }, 0.0, 0.0]);
        }
        v
    };
    let line = |v: Vec<f64>| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let standing = format!(
        "{SMALL}{}\n{}\n",
        line(frame(0.0, 0.0, true)),
        line(frame(10.0, 90.0, true))
    );
    let lying = format!(
        "{lying}{}\n{}\n",
        line(frame(0.0, 0.0, false)),
        line(frame(10.0, 90.0, false))
    );
    let a = from_text(&standing, "standing.bvh", &MotionOptions::default()).unwrap();
    let b = from_text(&lying, "lying.bvh", &MotionOptions::default()).unwrap();
    assert_eq!(a.up.measured_on, Measured::RestPose);
    assert_eq!(b.up.measured_on, Measured::FirstFrame);
    assert!(b.up.to_string().contains("first frame"), "{}", b.up);
    let (ka, kb) = (a.keypoints(0.1).unwrap(), b.keypoints(0.1).unwrap());
    assert_eq!(ka.units.unit, LengthUnit::Centimetres);
    assert_eq!(kb.units.unit, LengthUnit::Centimetres);
    assert!((kb.units.standing_height.unwrap() - 177.0).abs() < 1e-9);
    for f in 0..2 {
        for p in [
            BodyPoint::Pelvis,
            BodyPoint::Head,
            BodyPoint::LeftWrist,
            BodyPoint::LeftElbow,
            BodyPoint::RightAnkle,
            BodyPoint::LeftToe,
        ] {
            let (x, y) = (ka.position(f, p).unwrap(), kb.position(f, p).unwrap());
            assert!(close(x, y, 1e-9), "frame {f} {p}: {x:?} against {y:?}");
        }
    }
}
