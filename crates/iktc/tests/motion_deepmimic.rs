//! Tests of the DeepMimic reader, the DeepMimic skeleton and clip sampling / forward kinematics.

use iktc::motion::{
    builtin_clip, deepmimic_skeleton, read_deepmimic, read_deepmimic_with, rotation_angle,
    y_up_to_z_up, Clip, DeepMimicSettings, JointKind, UpAxis, BUILTIN_CLIP_NAMES,
};
use iktc::Error;
use nalgebra::Vector3;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/motions/deepmimic/");

fn file_text(name: &str) -> String {
    std::fs::read_to_string(format!("{DATA}{name}.txt")).unwrap()
}

/// Frame counts counted independently of the reader (one `[` per frame plus the outer array).
fn bracket_frames(text: &str) -> usize {
    text.matches('[').count() - 1
}

#[test]
fn all_builtin_clips_load_with_the_stated_durations_and_rates() {
    // (name, duration stated in data/NOTICE.md [s], rate [Hz])
    let stated = [
        ("humanoid3d_dance_a", 1.62, 60.0),
        ("humanoid3d_dance_b", 2.53, 60.0),
        ("humanoid3d_punch", 2.13, 30.0),
        ("humanoid3d_walk", 1.27, 30.0),
    ];
    assert_eq!(BUILTIN_CLIP_NAMES.len(), stated.len());
    for (name, duration, rate) in stated {
        let clip = builtin_clip(name).unwrap();
        let text = file_text(name);
        assert_eq!(clip.frame_count(), bracket_frames(&text), "{name}");
        assert!(
            (clip.duration() - duration).abs() < 0.01,
            "{name}: {}",
            clip.duration()
        );
        let measured = clip.mean_frame_rate().unwrap();
        assert!((measured - rate).abs() < 0.01, "{name}: {measured} Hz");
        assert_eq!(clip.times()[0], 0.0);
        assert_eq!(clip.up_axis(), UpAxis::Y);
        // Same as reading the file from disk.
        assert_eq!(read_deepmimic(&text, name).unwrap(), clip);
    }
    assert_eq!(
        builtin_clip("humanoid3d_dance_a").unwrap().frame_count(),
        98
    );
    assert_eq!(
        builtin_clip("humanoid3d_dance_b").unwrap().frame_count(),
        153
    );
    assert_eq!(builtin_clip("humanoid3d_punch").unwrap().frame_count(), 65);
    assert_eq!(builtin_clip("humanoid3d_walk").unwrap().frame_count(), 39);
}

#[test]
fn unknown_builtin_name_lists_the_valid_ones() {
    match builtin_clip("humanoid3d_run") {
        Err(Error::UnknownName { name, valid, .. }) => {
            assert_eq!(name, "humanoid3d_run");
            assert_eq!(valid.len(), 4);
            assert!(valid.iter().any(|v| v == "humanoid3d_walk"));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn skeleton_follows_the_urdf() {
    let s = deepmimic_skeleton().unwrap();
    let get = |n: &str| &s.joints()[s.index_of(n).unwrap()];
    // Hand-scaled URDF values (× 0.25 m per unit).
    assert!((get("chest").offset - Vector3::new(0.0, 0.944604 * 0.25, 0.0)).norm() < 1e-12);
    assert!((get("right_hip").offset - Vector3::new(0.0, 0.0, 0.339548 * 0.25)).norm() < 1e-12);
    assert!(
        (get("left_shoulder").offset - Vector3::new(-0.0962, 0.974, -0.73244) * 0.25).norm()
            < 1e-12
    );
    assert!((get("right_knee").offset - Vector3::new(0.0, -1.686184 * 0.25, 0.0)).norm() < 1e-12);
    for hinge in ["right_knee", "left_knee", "right_elbow", "left_elbow"] {
        match get(hinge).kind {
            JointKind::Hinge { axis } => assert_eq!(axis.into_inner(), Vector3::z()),
            k => panic!("{hinge}: {k:?}"),
        }
    }
    for ball in ["chest", "neck", "right_hip", "left_ankle", "right_shoulder"] {
        assert_eq!(get(ball).kind, JointKind::Spherical, "{ball}");
    }
    assert_eq!(get("right_wrist").kind, JointKind::Fixed);
    assert_eq!(get("root").kind, JointKind::Root);
    assert_eq!(s.joints()[0].name, "root");
    // Head top: neck sphere centre 0.7 + radius 0.41 above the neck joint.
    assert!((get("head_top").offset - Vector3::new(0.0, 1.11 * 0.25, 0.0)).norm() < 1e-12);
    // Sole: foot box centre (0.18, −0.09, 0), 0.22 high.
    assert!((get("left_sole").offset - Vector3::new(0.18, -0.2, 0.0) * 0.25).norm() < 1e-12);
    assert!(s.index_of("tail").is_err());
}

/// Standing height of the walk's first frame in a Z-up world: from the lower sole to the top of
/// the head about 1.6 m (pelvis 0.85 m, neck joint 1.31 m for an upright human), left hip at +y.
#[test]
fn walk_has_human_proportions_after_z_up() {
    let clip = builtin_clip("humanoid3d_walk").unwrap().to_z_up();
    assert_eq!(clip.up_axis(), UpAxis::Z);
    let s = clip.skeleton();
    let p = clip.world_positions(0).unwrap();
    let at = |n: &str| p[s.index_of(n).unwrap()];
    let floor = at("right_sole").z.min(at("left_sole").z);
    let height = at("head_top").z - floor;
    eprintln!(
        "walk frame 0 (Z-up): head top {:.3} m, soles {:.3} / {:.3} m, pelvis {:.3} m, neck {:.3} m, height {:.3} m",
        at("head_top").z,
        at("right_sole").z,
        at("left_sole").z,
        at("root").z,
        at("neck").z,
        height
    );
    assert!((1.5..1.9).contains(&height), "height {height}");
    assert!(floor.abs() < 0.1, "the feet are near the floor: {floor}");
    assert!(
        at("left_hip").y > at("right_hip").y,
        "left is +y after Y-up → Z-up"
    );
    assert!(at("neck").z > at("chest").z && at("chest").z > at("root").z);
    // Rigid links: the thigh is 0.25 × 1.686184 m long in every frame of every clip.
    for name in BUILTIN_CLIP_NAMES {
        let c = builtin_clip(name).unwrap();
        let s = c.skeleton();
        let (h, k) = (
            s.index_of("left_hip").unwrap(),
            s.index_of("left_knee").unwrap(),
        );
        for f in 0..c.frame_count() {
            let p = c.world_positions(f).unwrap();
            assert!(((p[k] - p[h]).norm() - 0.25 * 1.686184).abs() < 1e-12);
        }
    }
}

/// FK commutes with the change of world frame: Z-up positions are the Y-up ones rotated.
#[test]
fn z_up_is_a_rotation_of_the_world() {
    let y = builtin_clip("humanoid3d_punch").unwrap();
    let z = y.to_z_up();
    let q = y_up_to_z_up();
    assert!((q * Vector3::y() - Vector3::z()).norm() < 1e-15);
    assert!((q * Vector3::z() + Vector3::y()).norm() < 1e-15);
    for f in [0, 17, 64] {
        let py = y.world_positions(f).unwrap();
        let pz = z.world_positions(f).unwrap();
        for (a, b) in py.iter().zip(&pz) {
            assert!((q * a - b).norm() < 1e-12);
        }
    }
    assert_eq!(z.to_z_up(), z);
}

#[test]
fn hinge_rotations_are_about_the_hinge_axis() {
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let text = file_text("humanoid3d_dance_b");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let k = clip.skeleton().index_of("right_knee").unwrap();
    for (f, pose) in clip.frames().iter().enumerate() {
        let q = pose.rotations[k];
        assert!(q.imag().x.abs() < 1e-15 && q.imag().y.abs() < 1e-15);
        // The signed angle about +z is the file's right-knee number (index 20).
        let angle = 2.0 * q.imag().z.atan2(q.w);
        let file = v["Frames"][f][20].as_f64().unwrap();
        assert!((angle - file).abs() < 1e-12);
    }
}

#[test]
fn sampling_interpolates_between_frames() {
    let clip = builtin_clip("humanoid3d_walk").unwrap();
    let t = clip.times();
    // At frame times: the frames.
    assert_eq!(&clip.sample(t[5]).unwrap(), clip.frame(5).unwrap());
    // Outside the span: clamped.
    assert_eq!(&clip.sample(-1.0).unwrap(), clip.frame(0).unwrap());
    assert_eq!(&clip.sample(100.0).unwrap(), clip.frame(38).unwrap());
    // A quarter between frames 10 and 11.
    let (a, b) = (clip.frame(10).unwrap(), clip.frame(11).unwrap());
    let p = clip.sample(t[10] + 0.25 * (t[11] - t[10])).unwrap();
    let expected = a.root_position * 0.75 + b.root_position * 0.25;
    assert!((p.root_position - expected).norm() < 1e-12);
    for j in 0..clip.skeleton().len() {
        let (qa, qb, q) = (a.rotations[j], b.rotations[j], p.rotations[j]);
        let total = rotation_angle(&(qa.inverse() * qb));
        assert!((rotation_angle(&(qa.inverse() * q)) - 0.25 * total).abs() < 1e-9);
        assert!((rotation_angle(&(q.inverse() * qb)) - 0.75 * total).abs() < 1e-9);
    }
    assert!(clip.sample(f64::NAN).is_err());
    assert!(clip.world_positions(39).is_err());
}

const ZERO_FRAME: &str = "0.0333,0,0.85,0, 1,0,0,0, 1,0,0,0, 1,0,0,0, 1,0,0,0, -0.5, 1,0,0,0, 1,0,0,0, 0.3, 1,0,0,0, -0.4, 1,0,0,0, 1,0,0,0, 0.2";

fn small_file(frames: &[String]) -> String {
    let mut s = String::from("{\n\"Loop\": \"wrap\",\n\"Frames\":\n[\n");
    s.push_str(
        &frames
            .iter()
            .map(|f| format!("[{f}]"))
            .collect::<Vec<_>>()
            .join(",\n"),
    );
    s.push_str("\n]\n}\n");
    s
}

fn parse_error(r: Result<Clip, Error>) -> (usize, String) {
    match r {
        Err(Error::Parse { line, message, .. }) => (line, message),
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn a_small_file_reads_and_bad_ones_name_frame_line_and_field() {
    let ok = small_file(&[ZERO_FRAME.to_string(), ZERO_FRAME.to_string()]);
    let clip = read_deepmimic(&ok, "small").unwrap();
    assert_eq!(clip.frame_count(), 2);
    assert!((clip.duration() - 0.0333).abs() < 1e-15);

    // Frame 1 (line 6) with 43 numbers.
    let short = ZERO_FRAME.rsplit_once(',').unwrap().0.to_string();
    let (line, msg) = parse_error(read_deepmimic(
        &small_file(&[ZERO_FRAME.into(), short]),
        "f",
    ));
    assert_eq!(line, 6);
    assert!(msg.contains("frame 1") && msg.contains("43"), "{msg}");

    // Neck quaternion of zero norm in frame 0 (line 5).
    let zero_neck = ZERO_FRAME.replacen(
        " 1,0,0,0, 1,0,0,0, 1,0,0,0,",
        " 1,0,0,0, 1,0,0,0, 0,0,0,0,",
        1,
    );
    let (line, msg) = parse_error(read_deepmimic(&small_file(&[zero_neck]), "f"));
    assert_eq!(line, 5);
    assert!(msg.contains("frame 0") && msg.contains("`neck`"), "{msg}");

    // A non-numeric value on line 6.
    let text = small_file(&[ZERO_FRAME.into(), ZERO_FRAME.replacen("0.85", "\"x\"", 1)]);
    let (line, _) = parse_error(read_deepmimic(&text, "f"));
    assert_eq!(line, 6);

    // Zero frames, a zero duration before the last frame, missing "Frames".
    let (_, msg) = parse_error(read_deepmimic("{\"Frames\": []}", "f"));
    assert!(msg.contains("zero frames"));
    let zero_dt = ZERO_FRAME.replacen("0.0333", "0", 1);
    let (line, msg) = parse_error(read_deepmimic(
        &small_file(&[zero_dt, ZERO_FRAME.into()]),
        "f",
    ));
    assert_eq!(line, 5);
    assert!(msg.contains("duration"));
    assert!(read_deepmimic("{\"Loop\": 1}", "f").is_err());
    assert!(read_deepmimic("", "f").is_err());
}

/// The shipped punch has neck quaternions of norm 0.917–0.986 in frames 55–64 (computed with a
/// separate script): the default tolerance accepts them, 0.05 rejects frame 57 (norm 0.933).
#[test]
fn quaternion_norm_tolerance_is_a_setting() {
    let text = file_text("humanoid3d_punch");
    let strict = DeepMimicSettings {
        max_quaternion_norm_error: 0.05,
        ..Default::default()
    };
    let (line, msg) = parse_error(read_deepmimic_with(&text, "punch", &strict));
    assert!(msg.contains("frame 57") && msg.contains("`neck`"), "{msg}");
    // The first frame is on line 5 of the file, one frame per line.
    assert_eq!(line, 5 + 57);
    let clip = read_deepmimic(&text, "punch").unwrap();
    for pose in clip.frames() {
        for q in &pose.rotations {
            assert!((q.norm() - 1.0).abs() < 1e-12);
        }
    }
    assert!(DeepMimicSettings {
        max_quaternion_norm_error: 1.5,
        ..Default::default()
    }
    .validate()
    .is_err());
}
