//! The entry points of the fuzz targets: each reads bytes as one input format through the
//! library's public reader and uses what it returns. Ok or Err are both fine; a panic, an
//! abort, a stack overflow or a runaway allocation is a bug.
//!
//! The discovery target builds folder trees ([`tree`]) in the system's temporary folder.
//!
//! The same functions replay the corpora and the crash reproducers in
//! `crates/iktc/tests/fuzz_replay.rs` (which includes this file), so a fixed crash stays fixed.

#[path = "tree.rs"]
pub mod tree;

use iktc::model::RobotFiles;
use std::collections::HashSet;
use std::path::PathBuf;

use iktc::batch::{discover, BatchRetarget};
use iktc::model::{planar3r, BaseKind, Kinematics, ModelOptions, Robot, StateConfig};
use iktc::motion::{
    detect_format, motion_from_content, read_amc, read_asf, read_bvh, read_c3d, read_deepmimic,
    read_points_csv, Asf, BvhReadOptions, MotionContent, MotionFormat, MotionOptions, RetargetMap,
    DEFAULT_MAX_GAP,
};
use iktc::profile::{ProfileOrigin, RobotProfile};
use iktc::sim::ImitateConfig;

/// The entry point of one fuzz target.
pub type Entry = fn(&[u8]);

/// Every fuzz target by name, for the replay test.
pub const TARGETS: [(&str, Entry); 11] = [
    ("urdf", urdf),
    ("bvh", bvh),
    ("deepmimic", deepmimic),
    ("retarget_map", retarget_map),
    ("config", config),
    ("asf", asf),
    ("amc", amc),
    ("c3d", c3d),
    ("points_csv", points_csv),
    ("discover", discover_tree),
    ("profile", profile),
];

fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// A URDF, with a fixed and a floating base; a model that builds is evaluated at its neutral
/// state.
pub fn urdf(data: &[u8]) {
    let Some(t) = text(data) else { return };
    for base in [BaseKind::Fixed, BaseKind::Floating] {
        let options = ModelOptions {
            base,
            ..ModelOptions::default()
        };
        if let Ok(robot) = Robot::from_urdf_str(t, &options) {
            let state = iktc::model::State::neutral(&robot);
            let _ = Kinematics::new(&robot, &state);
            let _ = robot.total_mass();
        }
    }
}

/// A BVH file in centimetres, then its conversion to a clip and a sample in the middle.
pub fn bvh(data: &[u8]) {
    let Some(t) = text(data) else { return };
    if let Ok(b) = read_bvh(t, "fuzz.bvh", &BvhReadOptions::default()) {
        if let Ok(clip) = b.to_clip() {
            let _ = clip.sample(0.5 * clip.duration());
        }
    }
}

/// A DeepMimic motion file, then a sample in the middle of the clip.
pub fn deepmimic(data: &[u8]) {
    let Some(t) = text(data) else { return };
    if let Ok(clip) = read_deepmimic(t, "fuzz.txt") {
        let _ = clip.sample(0.5 * clip.duration());
        let _ = clip.to_z_up();
    }
}

/// The keypoints of content read from `source`, as `load_motion` finds them after reading
/// (body map, units and up axis decided, plausibility checked).
fn keypoints(source: &str, format: MotionFormat, content: MotionContent) {
    if let Ok(m) = motion_from_content(source.into(), format, content, &MotionOptions::default()) {
        let _ = m.keypoints(DEFAULT_MAX_GAP);
        let _ = m.clip();
    }
}

/// An ASF skeleton, its rest clip, and its keypoints.
pub fn asf(data: &[u8]) {
    let Some(t) = text(data) else { return };
    if let Ok(asf) = read_asf(t, "fuzz.asf") {
        if let Ok(clip) = asf.rest_clip() {
            keypoints("fuzz.asf", MotionFormat::Asf, MotionContent::Skeleton(clip));
        }
    }
}

/// The ASF skeleton the AMC target reads its motions on: the root (all six dofs) and two
/// bones.
const AMC_SKELETON: &str = ":version 1.10
:name fuzz
:units
  length 1.0
  angle deg
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
  end
  begin
    id 2
    name lower
    direction 1 0 0
    length 1
    axis 0 0 0 XYZ
    dof rx ry rz
  end
:hierarchy
  begin
    root upper
    upper lower
  end
";

/// An AMC motion on [`AMC_SKELETON`] at 120 Hz, then a sample in the middle of the clip.
pub fn amc(data: &[u8]) {
    let Some(t) = text(data) else { return };
    static SKELETON: std::sync::OnceLock<Option<Asf>> = std::sync::OnceLock::new();
    let Some(asf) = SKELETON.get_or_init(|| read_asf(AMC_SKELETON, "fuzz.asf").ok()) else {
        return;
    };
    if let Ok(clip) = read_amc(t, "fuzz.amc", asf, 120.0) {
        let _ = clip.sample(0.5 * clip.duration());
    }
}

/// A C3D file, then its keypoints where its markers are recognised.
pub fn c3d(data: &[u8]) {
    if let Ok(m) = read_c3d(data, "fuzz.c3d") {
        keypoints("fuzz.c3d", MotionFormat::C3d, MotionContent::Markers(m));
    }
}

/// A CSV of named points, then its keypoints; the format detection runs on the bytes too.
pub fn points_csv(data: &[u8]) {
    let _ = detect_format(data);
    let Some(t) = text(data) else { return };
    if let Ok(m) = read_points_csv(t, "fuzz.csv") {
        keypoints(
            "fuzz.csv",
            MotionFormat::PointsCsv,
            MotionContent::Markers(m),
        );
    }
}

/// A TOML retargeting map.
pub fn retarget_map(data: &[u8]) {
    let Some(t) = text(data) else { return };
    if let Ok(map) = RetargetMap::from_toml_str(t, "fuzz.toml") {
        let _ = map.robot_joints();
    }
}

/// A state configuration, as TOML and as JSON, applied to the 3R arm and to a floating
/// two-link robot; a state that builds is evaluated.
pub fn config(data: &[u8]) {
    let Some(t) = text(data) else { return };
    static ROBOTS: std::sync::OnceLock<Vec<Robot>> = std::sync::OnceLock::new();
    let robots = ROBOTS.get_or_init(|| {
        [Some(planar3r()), floating_robot()]
            .into_iter()
            .flatten()
            .collect()
    });
    for cfg in [
        StateConfig::from_toml_str(t, "fuzz.toml"),
        StateConfig::from_json_str(t, "fuzz.json"),
    ]
    .into_iter()
    .flatten()
    {
        for robot in robots {
            if let Ok(state) = cfg.state(robot) {
                let _ = Kinematics::new(robot, &state);
            }
        }
    }
}

/// A floating-base robot with one revolute joint `j`, for the config target.
fn floating_robot() -> Option<Robot> {
    const URDF: &str = r#"<robot name="f">
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#;
    Robot::from_urdf_str(
        URDF,
        &ModelOptions {
            base: BaseKind::Floating,
            ..ModelOptions::default()
        },
    )
    .ok()
}

/// A folder tree built from the bytes ([`tree::Tree`]), searched by the batch's discovery:
/// from its top folder (named once, or twice), or through a glob pattern under it, with the
/// first folder made as the batch's output folder or none. Every clip is listed once: no two
/// clips share a real file or an output name, and every clip lies under the top folder.
/// Searching again finds the same.
pub fn discover_tree(data: &[u8]) {
    let Some((&how, steps)) = data.split_first() else {
        return;
    };
    let Some(tree) = tree::Tree::build(steps) else {
        return;
    };
    let root = tree.root.display().to_string();
    let inputs = match how % 4 {
        0 => vec![root.clone()],
        1 => vec![root.clone(), root.clone()],
        2 => vec![format!("{root}/*.bvh"), root.clone()],
        _ => vec![format!("{root}/*/?.*")],
    };
    let out = (how & 4 != 0).then(|| tree.dirs.get(1)).flatten();
    let found = discover(&inputs, out.map(PathBuf::as_path));
    let mut real = HashSet::new();
    let mut names = HashSet::new();
    for c in &found.clips {
        assert!(c.path.starts_with(&tree.root), "{c:?} outside {root}");
        let r = c.path.canonicalize().unwrap_or_else(|_| c.path.clone());
        assert!(real.insert(r), "{c:?} listed twice: {:?}", found.clips);
        assert!(names.insert(c.name.clone()), "name of {c:?} taken twice");
    }
    assert_eq!(discover(&inputs, out.map(PathBuf::as_path)), found);
}

/// A robot profile in TOML (as `--profile` and `iktc retarget` read it), its paths naming
/// the library's embedded files. One that reads is written back to TOML and read again to an
/// equal profile, and becomes a batch as `iktc retarget` makes one, whose settings and
/// dependency digest (the clips' records) are formed.
pub fn profile(data: &[u8]) {
    let Some(t) = text(data) else { return };
    let Ok(p) = RobotProfile::from_toml_str(t, "fuzz.toml", ProfileOrigin::Builtin) else {
        return;
    };
    if let Ok(written) = p.to_toml_string() {
        let back = RobotProfile::from_toml_str(&written, "fuzz.toml", ProfileOrigin::Builtin);
        assert_eq!(back.as_ref().ok(), Some(&p), "{written}");
    }
    if let Ok(batch) = BatchRetarget::from_profile(p, ImitateConfig::default()) {
        let _ = batch.settings_text();
        let _ = batch.dependency_digest();
    }
}
