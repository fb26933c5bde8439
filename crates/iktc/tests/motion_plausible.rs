//! What no human capture holds is refused on loading, with the file, the frame and the
//! channel or body point named: frame times outside the capture rates, huge angles and
//! positions, bodies standing tens of metres tall, body points faster than any human limb.
//! A UTF-8 byte-order mark is accepted.

use iktc::model::RobotFiles;
use std::path::{Path, PathBuf};

use iktc::motion::plausible::{MAX_BODY_POINT_SPEED, STANDING_HEIGHT_RANGE};
use iktc::motion::{load_motion, LengthUnit, MotionOptions, Units};
use iktc::Error;

fn cmu_131_01() -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/motions/cmu/131_01.bvh");
    std::fs::read_to_string(p).unwrap()
}

fn temp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("iktc_plausible_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The clip's text with its first `n` frames only.
fn first_frames(text: &str, n: usize) -> String {
    let mut out = String::new();
    let mut frames_left = None;
    for line in text.lines() {
        if let Some(left) = frames_left.as_mut() {
            if *left == 0 {
                break;
            }
            *left -= 1;
            out.push_str(line);
        } else if line.starts_with("Frames:") {
            out.push_str(&format!("Frames: {n}"));
        } else {
            out.push_str(line);
            if line.starts_with("Frame Time:") {
                frames_left = Some(n);
            }
        }
        out.push('\n');
    }
    out
}

/// `text` with the `value`-th number (0-based) of frame line `frame` replaced by `with`.
fn with_value(text: &str, frame: usize, value: usize, with: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let first = lines
        .iter()
        .position(|l| l.starts_with("Frame Time:"))
        .unwrap()
        + 1;
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    let mut v: Vec<&str> = lines[first + frame].split_whitespace().collect();
    v[value] = with;
    out[first + frame] = v.join(" ");
    out.join("\n") + "\n"
}

fn load_error(name: &str, text: &str) -> String {
    let p = temp(name, text);
    match load_motion(&p, &MotionOptions::default()) {
        Ok(_) => panic!("{name} loaded"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_bvh_with_a_byte_order_mark_loads_as_without() {
    let text = first_frames(&cmu_131_01(), 40);
    let plain = load_motion(&temp("plain.bvh", &text), &MotionOptions::default()).unwrap();
    let bom = load_motion(
        &temp("bom.bvh", &format!("\u{feff}{text}")),
        &MotionOptions::default(),
    )
    .unwrap();
    // The same clip but for its name (the file's).
    let (iktc::motion::MotionContent::Skeleton(a), iktc::motion::MotionContent::Skeleton(b)) =
        (&plain.content, &bom.content)
    else {
        panic!("not skeletons");
    };
    assert_eq!(a.skeleton(), b.skeleton());
    assert_eq!(a.frames(), b.frames());
    assert_eq!(a.times(), b.times());
    assert_eq!(plain.units, bom.units);
}

#[test]
fn frame_times_outside_the_capture_rates_are_refused_naming_the_line() {
    let text = first_frames(&cmu_131_01(), 40);
    for bad in ["1e-9", "1e-300", "2"] {
        let t = text.replace("Frame Time: .0083333", &format!("Frame Time: {bad}"));
        let e = load_error("time.bvh", &t);
        assert!(
            e.contains("time.bvh:187:") && e.contains("Frame Time"),
            "{e}"
        );
        assert!(e.len() < 400, "{e}");
    }
}

#[test]
fn a_huge_value_is_refused_naming_the_frame_and_channel() {
    let text = first_frames(&cmu_131_01(), 40);
    // Frame 5: the root's Yposition (value 1), then its Zrotation (value 3).
    let e = load_error("up.bvh", &with_value(&text, 5, 1, "1e308"));
    assert!(
        e.contains("up.bvh") && e.contains("frame 5") && e.contains("Hips Yposition"),
        "{e}"
    );
    assert!(!e.contains("00000000"), "{e}");
    let e = load_error("turn.bvh", &with_value(&text, 5, 3, "1e308"));
    assert!(e.contains("frame 5") && e.contains("Hips Zrotation"), "{e}");
}

#[test]
fn a_root_far_up_in_every_frame_is_refused() {
    // Every frame's root 9e6 units up: 5e5 m in the clip's unit (0.056 m), beyond the
    // 1e4 m of any capture.
    let text = first_frames(&cmu_131_01(), 40);
    let mut t = text.clone();
    for f in 0..40 {
        t = with_value(&t, f, 1, "9e6");
    }
    let e = load_error("high.bvh", &t);
    assert!(e.contains("high.bvh") && e.contains("frame 0"), "{e}");
}

#[test]
fn a_root_jumping_faster_than_any_human_body_point_is_refused() {
    let text = first_frames(&cmu_131_01(), 40);
    // At 120 Hz, a jump of 1000 file units (the CMU inch-like unit is 0.056 m, so 56 m) in
    // one frame is 6700 m/s.
    let e = load_error("jump.bvh", &with_value(&text, 10, 1, "1000"));
    assert!(
        e.contains("jump.bvh") && e.contains("frame 10") && e.contains("m/s"),
        "{e}"
    );
    assert!(e.contains(&format!("{MAX_BODY_POINT_SPEED}")), "{e}");
}

#[test]
fn the_shared_clips_are_plausible() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for dir in ["data/motions/deepmimic", "tests/data/motions/cmu"] {
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|e| e == "bvh" || e == "txt") {
                load_motion(&p, &MotionOptions::default())
                    .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            }
        }
    }
}

#[test]
fn a_body_of_the_wrong_unit_is_refused_by_its_height() {
    // The CMU clip (about 30 units from ankles to head) read as millimetres stands 30 mm
    // tall; as metres, 30 m.
    let p = temp("units.bvh", &first_frames(&cmu_131_01(), 40));
    for units in [
        Units::Fixed(LengthUnit::Millimetres),
        Units::Fixed(LengthUnit::Metres),
    ] {
        let o = MotionOptions {
            units,
            ..MotionOptions::default()
        };
        match load_motion(&p, &o) {
            Err(Error::Parse { message, .. }) => {
                assert!(
                    message.contains(&format!("{}", STANDING_HEIGHT_RANGE.1)),
                    "{message}"
                )
            }
            other => panic!("{units:?}: {other:?}"),
        }
    }
}

#[test]
fn deepmimic_durations_of_a_nanosecond_are_refused() {
    let p =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/motions/deepmimic/humanoid3d_walk.txt");
    let text = std::fs::read_to_string(p).unwrap();
    // Every frame's duration (its first value) 1e-9 s.
    let fast = text.replace("[        0.0333320000,", "[1e-9,");
    assert_ne!(fast, text);
    let e = load_error("fast.txt", &fast);
    assert!(
        e.contains("fast.txt") && e.contains("frame 1: frame time"),
        "{e}"
    );
}

#[test]
fn a_massless_robot_has_no_centre_of_mass_task() {
    const URDF: &str = r#"<robot name="m">
  <link name="a"/><link name="b"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#;
    let robot =
        iktc::model::Robot::from_urdf_str(URDF, &iktc::model::ModelOptions::default()).unwrap();
    assert_eq!(robot.total_mass(), 0.0);
    let e = iktc::task::ComTask::new(&robot, [true, true, false], iktc::task::Gains::default())
        .unwrap_err();
    match e {
        Error::InvalidSetting { name, .. } => assert!(name.contains("total mass"), "{name}"),
        other => panic!("{other:?}"),
    }
}
