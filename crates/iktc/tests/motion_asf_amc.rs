//! ASF/AMC: forward kinematics against hand-computed points, a CMU-like skeleton recognised and
//! measured in CMU's unit, the ASF found beside the AMC, malformed files.

use std::path::PathBuf;

use iktc::motion::{
    load_motion, read_amc, read_asf, BodyPoint, LengthUnit, MotionFormat, MotionOptions,
    PointSource, UpAxis, CMU_METRES_PER_UNIT,
};
use iktc::Error;
use nalgebra::Vector3;

const SMALL_ASF: &str = ":version 1.10
:name small
:units
  mass 1.0
  length 1.0
  angle deg
:documentation
  two bones
:root
  order TX TY TZ RX RY RZ
  axis XYZ
  position 0 0 0
  orientation 0 0 0
:bonedata
  begin
    id 1
    name upper
    direction 0 0 1
    length 2
    axis 0 0 90 XYZ
    dof rx
    limits (-180 180)
  end
  begin
    id 2
    name lower
    direction 1 0 0
    length 1
    axis 0 0 0 XYZ
    dof rx ry rz
    limits (-180 180)
           (-180 180)
           (-180 180)
  end
:hierarchy
  begin
    root upper
    upper lower
  end
";

const SMALL_AMC: &str = "#!OML:ASF small.asf
:FULLY-SPECIFIED
:DEGREES
1
root 1 2 3 0 0 0
upper 90
lower 90 0 90
2
root 0 0 0 0 90 0
upper 0
lower 0 0 0
";

fn close(a: Vector3<f64>, b: Vector3<f64>) -> bool {
    (a - b).norm() < 1e-12
}

/// upper: axis C = Rz(90°), so its rx turns about C·x = y: Q = Ry(90°), taking its rest vector
/// (0, 0, 2) to (2, 0, 0). lower: M = Rz(90°)·Ry(0)·Rx(90°) (fixed axes, listed order), taking
/// (1, 0, 0) to (0, 1, 0); Ry(90°) keeps it. Frame 2: the root turned by Ry(90°).
#[test]
fn amc_forward_kinematics_match_hand_computed_points() {
    let asf = read_asf(SMALL_ASF, "small.asf").unwrap();
    let clip = read_amc(SMALL_AMC, "small.amc", &asf, 120.0).unwrap();
    assert_eq!(clip.frame_count(), 2);
    assert!((clip.times()[1] - 1.0 / 120.0).abs() < 1e-15);
    let s = clip.skeleton();
    let at = |f: usize, name: &str| clip.world_positions(f).unwrap()[s.index_of(name).unwrap()];
    assert!(close(at(0, "root"), Vector3::new(1.0, 2.0, 3.0)));
    assert!(close(at(0, "upper"), Vector3::new(1.0, 2.0, 3.0)));
    assert!(close(at(0, "lower"), Vector3::new(3.0, 2.0, 3.0)));
    assert!(close(at(0, "lower_end"), Vector3::new(3.0, 3.0, 3.0)));
    assert!(close(at(1, "lower"), Vector3::new(2.0, 0.0, 0.0)));
    assert!(close(at(1, "lower_end"), Vector3::new(2.0, 0.0, -1.0)));
}

/// A CMU-like ASF (bone names, directions and lengths of the database's subjects).
fn cmu_asf() -> String {
    let mut bones = String::new();
    let mut id = 0;
    let mut bone = |name: &str, dir: [f64; 3], len: f64, axis: [f64; 3], dof: &str| {
        id += 1;
        let dof = if dof.is_empty() {
            String::new()
        } else {
            format!("    dof {dof}\n")
        };
        bones.push_str(&format!(
            "  begin\n    id {id}\n    name {name}\n    direction {} {} {}\n    length {len}\n    axis {} {} {} XYZ\n{dof}  end\n",
            dir[0], dir[1], dir[2], axis[0], axis[1], axis[2]
        ));
    };
    for (p, s) in [("l", 1.0), ("r", -1.0)] {
        bone(
            &format!("{p}hipjoint"),
            [0.72 * s, -0.69, 0.0],
            2.4,
            [0.0; 3],
            "",
        );
        bone(
            &format!("{p}femur"),
            [0.342 * s, -0.94, 0.0],
            7.2,
            [0.0, 0.0, 20.0 * s],
            "rx ry rz",
        );
        bone(
            &format!("{p}tibia"),
            [0.342 * s, -0.94, 0.0],
            7.4,
            [0.0, 0.0, 20.0 * s],
            "rx",
        );
        bone(
            &format!("{p}foot"),
            [0.0, -0.3, 0.954],
            2.4,
            [0.0; 3],
            "rx rz",
        );
        bone(&format!("{p}toes"), [0.0, 0.0, 1.0], 1.2, [0.0; 3], "rx");
    }
    for name in ["lowerback", "upperback", "thorax"] {
        bone(name, [0.0, 1.0, 0.0], 2.0, [0.0; 3], "rx ry rz");
    }
    for name in ["lowerneck", "upperneck", "head"] {
        bone(name, [0.0, 1.0, 0.0], 1.6, [0.0; 3], "rx ry rz");
    }
    for (p, s) in [("l", 1.0), ("r", -1.0)] {
        bone(
            &format!("{p}clavicle"),
            [0.9 * s, 0.44, 0.0],
            3.4,
            [0.0; 3],
            "ry rz",
        );
        bone(
            &format!("{p}humerus"),
            [s, 0.0, 0.0],
            5.0,
            [0.0, 0.0, 90.0 * s],
            "rx ry rz",
        );
        bone(
            &format!("{p}radius"),
            [s, 0.0, 0.0],
            3.4,
            [0.0, 0.0, 90.0 * s],
            "rx",
        );
        bone(&format!("{p}wrist"), [s, 0.0, 0.0], 1.7, [0.0; 3], "ry");
        bone(&format!("{p}hand"), [s, 0.0, 0.0], 0.7, [0.0; 3], "rx rz");
        bone(&format!("{p}fingers"), [s, 0.0, 0.0], 0.6, [0.0; 3], "rx");
        bone(
            &format!("{p}thumb"),
            [0.7 * s, 0.0, 0.7],
            0.7,
            [0.0; 3],
            "rx rz",
        );
    }
    let mut hierarchy = String::from("  begin\n    root lhipjoint rhipjoint lowerback\n");
    for p in ["l", "r"] {
        hierarchy.push_str(&format!(
            "    {p}hipjoint {p}femur\n    {p}femur {p}tibia\n    {p}tibia {p}foot\n    {p}foot {p}toes\n"
        ));
    }
    hierarchy.push_str("    lowerback upperback\n    upperback thorax\n    thorax lowerneck lclavicle rclavicle\n    lowerneck upperneck\n    upperneck head\n");
    for p in ["l", "r"] {
        hierarchy.push_str(&format!(
            "    {p}clavicle {p}humerus\n    {p}humerus {p}radius\n    {p}radius {p}wrist\n    {p}wrist {p}hand {p}thumb\n    {p}hand {p}fingers\n"
        ));
    }
    hierarchy.push_str("  end\n");
    format!(
        ":version 1.10\n:name VICON\n:units\n  mass 1.0\n  length 0.45\n  angle deg\n:documentation\n   CMU-like\n:root\n   order TX TY TZ RX RY RZ\n   axis XYZ\n   position 0 0 0\n   orientation 0 0 0\n:bonedata\n{bones}:hierarchy\n{hierarchy}"
    )
}

/// `frames` frames of the CMU-like skeleton: the root walks along z, the left knee bends.
fn cmu_amc(frames: usize) -> String {
    let asf = read_asf(&cmu_asf(), "cmu.asf").unwrap();
    let mut out = String::from("#!OML:ASF cmu.asf\n:FULLY-SPECIFIED\n:DEGREES\n");
    for f in 0..frames {
        out.push_str(&format!("{}\nroot 0 16 {} 0 0 0\n", f + 1, f as f64 * 0.1));
        for b in &asf.bones {
            if b.dofs.is_empty() {
                continue;
            }
            let v: Vec<String> = (0..b.dofs.len())
                .map(|_| {
                    if b.name == "ltibia" {
                        (5 * f).to_string()
                    } else {
                        "0".to_string()
                    }
                })
                .collect();
            out.push_str(&format!("{} {}\n", b.name, v.join(" ")));
        }
    }
    out
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("iktc_amc_{tag}_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn an_amc_alone_finds_its_asf_and_is_recognised_in_cmu_units() {
    let dir = temp_dir("beside");
    std::fs::write(dir.join("07.asf"), cmu_asf()).unwrap();
    std::fs::write(dir.join("07_01.amc"), cmu_amc(4)).unwrap();
    // Not the same stem, but the only .asf in the folder.
    let m = load_motion(&dir.join("07_01.amc"), &MotionOptions::default()).unwrap();
    assert_eq!(m.format, MotionFormat::Amc);
    assert!(
        (m.units.unit.metres_per_unit() - CMU_METRES_PER_UNIT).abs() < 1e-15,
        "{}",
        m.units
    );
    assert_eq!(m.up.up, UpAxis::Y);
    let map = m.body_map.as_ref().unwrap();
    let joint = |p| match map.get(p) {
        Some(PointSource::Joint(j)) => j.clone(),
        other => panic!("{p}: {other:?}"),
    };
    for (p, j) in [
        (BodyPoint::Pelvis, "root"),
        (BodyPoint::Chest, "thorax"),
        (BodyPoint::Neck, "lowerneck"),
        (BodyPoint::Head, "head"),
        (BodyPoint::LeftHip, "lfemur"),
        (BodyPoint::LeftKnee, "ltibia"),
        (BodyPoint::LeftAnkle, "lfoot"),
        (BodyPoint::LeftToe, "ltoes"),
        (BodyPoint::RightShoulder, "rhumerus"),
        (BodyPoint::RightElbow, "rradius"),
        (BodyPoint::RightWrist, "rwrist"),
    ] {
        assert_eq!(joint(p), j, "{p}");
    }
    // Frame 0 at rest, root at (0, 16, 0): the left wrist is at the root + back (0, 6, 0)
    // + clavicle 3.4·(0.9, 0.44, 0) + humerus (5, 0, 0) + radius (3.4, 0, 0), Y up, CMU units.
    let k = m.keypoints(0.1).unwrap();
    let y =
        Vector3::new(0.0, 16.0 + 6.0 + 3.4 * 0.44, 0.0) + Vector3::new(3.4 * 0.9 + 8.4, 0.0, 0.0);
    let z_up = Vector3::new(y.x, -y.z, y.y) * CMU_METRES_PER_UNIT;
    assert!((k.position(0, BodyPoint::LeftWrist).unwrap() - z_up).norm() < 1e-12);
    // Two .asf files: the one with the AMC's stem is taken; with neither, an error.
    std::fs::write(dir.join("07_01.asf"), cmu_asf()).unwrap();
    assert!(load_motion(&dir.join("07_01.amc"), &MotionOptions::default()).is_ok());
    std::fs::rename(dir.join("07_01.asf"), dir.join("08.asf")).unwrap();
    let e = load_motion(&dir.join("07_01.amc"), &MotionOptions::default()).unwrap_err();
    assert!(e.to_string().contains("--skeleton"), "{e}");
    // An explicit skeleton is used.
    let options = MotionOptions {
        skeleton: Some(dir.join("08.asf")),
        ..MotionOptions::default()
    };
    assert!(load_motion(&dir.join("07_01.amc"), &options).is_ok());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_asf_alone_is_its_rest_pose() {
    let dir = temp_dir("alone");
    std::fs::write(dir.join("s.asf"), cmu_asf()).unwrap();
    let m = load_motion(&dir.join("s.asf"), &MotionOptions::default()).unwrap();
    assert_eq!(m.format, MotionFormat::Asf);
    assert_eq!(m.keypoints(0.1).unwrap().frame_count(), 1);
    assert_eq!(
        m.units.unit,
        LengthUnit::Custom {
            metres_per_unit: CMU_METRES_PER_UNIT
        }
    );
    std::fs::remove_dir_all(&dir).ok();
}

fn parse_error(e: Error) -> (String, usize, String) {
    match e {
        Error::Parse {
            source_name,
            line,
            message,
        } => (source_name, line, message),
        other => panic!("not a parse error: {other}"),
    }
}

#[test]
fn a_truncated_amc_frame_is_an_error_naming_file_line_and_bone() {
    let asf = read_asf(SMALL_ASF, "small.asf").unwrap();
    // Frame 2 lost its last line.
    let cut = SMALL_AMC.trim_end().rsplit_once('\n').unwrap().0;
    let (file, line, msg) = parse_error(read_amc(cut, "cut.amc", &asf, 120.0).unwrap_err());
    assert_eq!(file, "cut.amc");
    assert_eq!(line, 10);
    assert!(msg.contains("frame 2") && msg.contains("`lower`"), "{msg}");
    // A value line cut short.
    let short = SMALL_AMC.replace("lower 90 0 90", "lower 90 0");
    let (_, line, msg) = parse_error(read_amc(&short, "short.amc", &asf, 120.0).unwrap_err());
    assert_eq!(line, 7);
    assert!(msg.contains("2 values") && msg.contains("need 3"), "{msg}");
    // An unknown bone, a non-number.
    let (_, line, msg) = parse_error(
        read_amc(
            &SMALL_AMC.replace("upper 90", "uper 90"),
            "u.amc",
            &asf,
            120.0,
        )
        .unwrap_err(),
    );
    assert_eq!(line, 6);
    assert!(
        msg.contains("`uper`") && msg.contains("upper, lower"),
        "{msg}"
    );
    let (_, line, _) = parse_error(
        read_amc(
            &SMALL_AMC.replace("upper 0", "upper nan"),
            "n.amc",
            &asf,
            120.0,
        )
        .unwrap_err(),
    );
    assert_eq!(line, 10);
    assert!(read_amc("", "empty.amc", &asf, 120.0).is_err());
}

#[test]
fn an_asf_without_hierarchy_is_an_error_naming_the_file() {
    let cut = SMALL_ASF.split(":hierarchy").next().unwrap();
    let (file, line, msg) = parse_error(read_asf(cut, "nohier.asf").unwrap_err());
    assert_eq!(file, "nohier.asf");
    assert!(line > 0);
    assert!(msg.contains(":hierarchy"), "{msg}");
    // A hierarchy naming a bone that does not exist.
    let bad = SMALL_ASF.replace("upper lower", "upper lowre");
    let (_, line, msg) = parse_error(read_asf(&bad, "bad.asf").unwrap_err());
    assert_eq!(line, 38);
    assert!(msg.contains("`lowre`"), "{msg}");
    // A bone block cut before its end.
    let cut = SMALL_ASF.split("    dof rx ry rz").next().unwrap();
    let (_, line, msg) = parse_error(read_asf(cut, "trunc.asf").unwrap_err());
    assert_eq!(line, 24);
    assert!(msg.contains("without `end`"), "{msg}");
}

/// A hierarchy line naming an unknown parent is an error naming it and its line, as one
/// naming an unknown child is.
#[test]
fn an_asf_hierarchy_naming_an_unknown_parent_is_an_error() {
    let good = cmu_asf();
    // An extra line whose parent is no bone (its child is one, already placed).
    let bad = good.replace(
        "    upperneck head\n",
        "    upperneck head\n    nosuchbone head\n",
    );
    assert_ne!(bad, good);
    let line = 1 + bad[..bad.find("nosuchbone").unwrap()].matches('\n').count();
    let (source, at, message) = parse_error(read_asf(&bad, "cmu.asf").unwrap_err());
    assert_eq!((source.as_str(), at), ("cmu.asf", line));
    assert!(message.contains("`nosuchbone`"), "{message}");
    // And an unknown child, for comparison.
    let bad = good.replace("    upperneck head\n", "    upperneck head nosuchbone\n");
    let (_, _, message) = parse_error(read_asf(&bad, "cmu.asf").unwrap_err());
    assert!(message.contains("`nosuchbone`"), "{message}");
}
