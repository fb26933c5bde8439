//! The entry points of the fuzz targets: each reads bytes as one input format through the
//! library's public reader and uses what it returns. Ok or Err are both fine; a panic, an
//! abort, a stack overflow or a runaway allocation is a bug.
//!
//! The same functions replay the corpora and the crash reproducers in
//! `crates/iktc/tests/fuzz_replay.rs` (which includes this file), so a fixed crash stays fixed.

use iktc::model::{planar3r, BaseKind, Kinematics, ModelOptions, Robot, StateConfig};
use iktc::motion::{read_bvh, read_deepmimic, BvhReadOptions, RetargetMap};

/// The entry point of one fuzz target.
pub type Entry = fn(&[u8]);

/// Every fuzz target by name, for the replay test.
pub const TARGETS: [(&str, Entry); 5] = [
    ("urdf", urdf),
    ("bvh", bvh),
    ("deepmimic", deepmimic),
    ("retarget_map", retarget_map),
    ("config", config),
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
