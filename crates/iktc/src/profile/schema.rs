//! The robot profile as plain data: the keys of the TOML file.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::limits::NarrowedJoint;
use crate::model::BaseKind;

/// Everything iktc needs about a robot beyond its URDF (one TOML file per robot; see the
/// [module documentation](super) for an example).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotProfile {
    /// The robot's name (key `name`).
    pub name: String,
    /// The URDF file, relative to the profile file's directory (key `urdf`).
    pub urdf: String,
    /// Floating or fixed base (key `base`: `"floating"` or `"fixed"`).
    pub base: BaseKind,
    /// Joints held at a value, by glob pattern (key `lock`, an array of tables).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lock: Vec<LockRule>,
    /// The two feet (key `feet`); absent for a robot that does not stand.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feet: Option<Feet>,
    /// Frames added to the robot (key `frame`, an array of tables), for points the URDF has
    /// no link at; the other keys may name them like any link.
    #[serde(default, rename = "frame", skip_serializing_if = "Vec::is_empty")]
    pub added_frames: Vec<AddedFrame>,
    /// Named body frames (key `frames`).
    #[serde(default)]
    pub frames: BodyFrames,
    /// Initial joint angles \[rad\] (key `posture`, joint name → angle); joints not named start
    /// at 0.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub posture: BTreeMap<String, f64>,
    /// Default narrowed joint ranges \[rad\] (key `narrow`, a table joint name →
    /// `[lower, upper]`), inside the joints' own ranges; in the order the TOML reader gives
    /// (sorted by name).
    #[serde(default, skip_serializing_if = "Vec::is_empty", with = "narrow_table")]
    pub narrow: Vec<NarrowedJoint>,
    /// Velocity limits the robot's file does not give (key `velocity`; none by default).
    #[serde(default, skip_serializing_if = "VelocityProfile::is_empty")]
    pub velocity: VelocityProfile,
    /// Acceleration limits (key `acceleration`).
    #[serde(default)]
    pub acceleration: AccelerationProfile,
    /// Jerk limits (key `jerk`; none by default).
    #[serde(default, skip_serializing_if = "JerkProfile::is_empty")]
    pub jerk: JerkProfile,
    /// Imitation settings (key `imitate`).
    #[serde(default)]
    pub imitate: ImitateProfile,
    /// Walking settings (key `walk`); keys left out keep the defaults of
    /// [`RobotProfile::walk_config`](super::RobotProfile::walk_config).
    #[serde(default, skip_serializing_if = "WalkProfile::is_empty")]
    pub walk: WalkProfile,
    /// Where the profile was read from (not a key): relative paths are resolved against it.
    #[serde(skip)]
    pub origin: ProfileOrigin,
}

/// Where a profile was read from; relative paths in it (`urdf`, `imitate.maps.*`) are resolved
/// against it. Two profiles that differ only in their origin are equal.
#[derive(Debug, Clone, Default)]
pub enum ProfileOrigin {
    /// A built-in profile: paths name files embedded in the library (its `data/profiles/`).
    #[default]
    Builtin,
    /// A profile file in this directory (or profile fields given in code, with paths relative
    /// to this directory).
    Directory(std::path::PathBuf),
}

impl PartialEq for ProfileOrigin {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Joints whose names match a glob pattern, held at one value (key `lock[i]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LockRule {
    /// Glob pattern over joint names: `*` matches any run of characters, `?` one character
    /// (key `lock[i].joints`, e.g. `"*_FINGER_*"`). It must match at least one movable joint.
    pub joints: String,
    /// The value the matched joints are held at \[rad\] or \[m\] (key `lock[i].value`,
    /// default 0).
    #[serde(default)]
    pub value: f64,
}

/// The feet of a standing robot (key `feet`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Feet {
    /// The left foot (key `feet.left`).
    pub left: Foot,
    /// The right foot (key `feet.right`).
    pub right: Foot,
}

/// One foot: its frame, sole and ankle height (key `feet.left` or `feet.right`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sole {
    /// Length along the foot frame's x axis \[m\], `> 0` (key `…sole.length`).
    pub length: f64,
    /// Width along the foot frame's y axis \[m\], `> 0` (key `…sole.width`).
    pub width: f64,
    /// Forward offset of the sole's centre from the foot frame's origin along its x axis
    /// \[m\] (key `…sole.offset_x`, default 0).
    #[serde(default)]
    pub offset_x: f64,
}

/// One foot (key `feet.left` / `feet.right`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Foot {
    /// The foot frame (a link or frame of the URDF; key `…frame`), its z axis up when the
    /// sole is flat.
    pub frame: String,
    /// Height of the foot frame above the sole \[m\], `≥ 0` (key `…ankle_height`).
    pub ankle_height: f64,
    /// The sole rectangle in the foot frame (key `…sole`).
    pub sole: Sole,
}

/// A frame added to the robot (key `frame`): fixed to a link or frame of the URDF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AddedFrame {
    /// Its name (key `frame[i].name`), one no link or frame has.
    pub name: String,
    /// The link or frame it is fixed to (key `frame[i].parent`).
    pub parent: String,
    /// Its position in the parent \[m\] (key `frame[i].xyz`; default 0).
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Its orientation in the parent, roll, pitch, yaw as in URDF \[rad\] (key
    /// `frame[i].rpy`; default 0).
    #[serde(default)]
    pub rpy: [f64; 3],
}

/// Named body frames (key `frames`); each a link or frame of the URDF, or a frame the profile
/// adds (key `frame`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyFrames {
    /// The pelvis (key `frames.pelvis`): attitude and height tasks of the imitation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pelvis: Option<String>,
    /// The torso (key `frames.torso`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torso: Option<String>,
    /// The head (key `frames.head`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub head: Option<String>,
    /// The left hand (key `frames.left_hand`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_hand: Option<String>,
    /// The right hand (key `frames.right_hand`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub right_hand: Option<String>,
}

/// Velocity limits (key `velocity`) for robots whose file gives none (MJCF never does; a URDF
/// `<limit>` may leave it out): without one, a joint has no velocity limit and, unless
/// `acceleration.limits` names it, no acceleration limit either.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VelocityProfile {
    /// Velocity limit \[rad/s\] or \[m/s\] of every movable joint whose file gives none and
    /// that `limits` does not name, `> 0` (key `velocity.default`). Absent: such joints stay
    /// unlimited.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default: Option<f64>,
    /// Velocity limits by joint name \[rad/s\] or \[m/s\], `> 0`, replacing the file's (key
    /// `velocity.limits`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub limits: BTreeMap<String, f64>,
}

impl VelocityProfile {
    /// Whether the profile states no velocity limit.
    pub fn is_empty(&self) -> bool {
        self.default.is_none() && self.limits.is_empty()
    }
}

/// The default acceleration limit as a multiple of the velocity limit \[1/s\] (the ratio of the
/// paper's 3R arm, 180°/s and 1800°/s²), as in [`crate::model::ModelOptions`].
pub(crate) const DEFAULT_ACCELERATION_PER_VELOCITY: f64 = 10.0;

fn default_per_velocity() -> f64 {
    DEFAULT_ACCELERATION_PER_VELOCITY
}

/// Acceleration limits (URDF has none; key `acceleration`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccelerationProfile {
    /// Acceleration limit of joints not listed in `limits`, as a multiple of their velocity
    /// limit \[1/s\], `> 0` (key `acceleration.per_velocity`, default 10).
    #[serde(default = "default_per_velocity")]
    pub per_velocity: f64,
    /// Acceleration limits by joint name \[rad/s²\] or \[m/s²\] (key `acceleration.limits`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub limits: BTreeMap<String, f64>,
}

impl Default for AccelerationProfile {
    fn default() -> Self {
        Self {
            per_velocity: DEFAULT_ACCELERATION_PER_VELOCITY,
            limits: BTreeMap::new(),
        }
    }
}

/// Jerk limits (key `jerk`): how fast a joint's commanded acceleration may change
/// ([`limit_jerk`](crate::limits::limit_jerk)). None unless stated.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JerkProfile {
    /// Jerk limit of joints not listed in `limits`, as a multiple of their acceleration limit
    /// \[1/s\], `> 0` (key `jerk.per_acceleration`): the acceleration can go from zero to its
    /// limit in 1/this seconds. Absent: no jerk limit on those joints.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per_acceleration: Option<f64>,
    /// Jerk limits by joint name \[rad/s³\] or \[m/s³\] (key `jerk.limits`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub limits: BTreeMap<String, f64>,
}

impl JerkProfile {
    /// Whether the profile states no jerk limit.
    pub fn is_empty(&self) -> bool {
        self.per_acceleration.is_none() && self.limits.is_empty()
    }
}

/// Imitation settings (key `imitate`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImitateProfile {
    /// The retargeting map per motion format (key `imitate.maps`, format → map): `deepmimic`
    /// and `bvh`; a map is a built-in map name or a TOML file relative to the profile.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub maps: BTreeMap<String, String>,
}

/// Walking settings of a robot (key `walk`); every key is optional.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WalkProfile {
    /// Step length along x \[m\] (key `walk.step_length`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_length: Option<f64>,
    /// Peak height of the swing foot \[m\] (key `walk.swing_height`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub swing_height: Option<f64>,
    /// Duration of one single-support phase \[s\] (key `walk.ssp_duration`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ssp_duration: Option<f64>,
    /// Duration of one double-support phase between steps \[s\] (key `walk.dsp_duration`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dsp_duration: Option<f64>,
    /// The push of the walking experiment (key `walk.push`, `{ time = s, impulse = [x, y] }`
    /// in \[s\] and \[N·s\]); left out, the push changes the COM velocity by
    /// [`DEFAULT_PUSH_VELOCITY_CHANGE`](super::DEFAULT_PUSH_VELOCITY_CHANGE) whatever the
    /// robot's mass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub push: Option<PushProfile>,
}

impl WalkProfile {
    /// No key given.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }
}

/// The push of the walking experiment (key `walk.push`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PushProfile {
    /// When \[s\] (key `walk.push.time`).
    pub time: f64,
    /// Horizontal impulse on the COM (world x, y) \[N·s\] (key `walk.push.impulse`).
    pub impulse: [f64; 2],
}

/// The key `narrow` as a TOML table `JOINT = [lower, upper]`, read into [`NarrowedJoint`]s in
/// the order the reader gives them (the TOML reader sorts keys), rejecting a joint given twice.
mod narrow_table {
    use serde::de::{Deserializer, MapAccess, Visitor};
    use serde::ser::{SerializeMap, Serializer};

    use crate::limits::NarrowedJoint;

    pub fn serialize<S: Serializer>(entries: &[NarrowedJoint], s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(entries.len()))?;
        for n in entries {
            m.serialize_entry(&n.joint, &[n.lower, n.upper])?;
        }
        m.end()
    }

    struct Entries;

    impl<'de> Visitor<'de> for Entries {
        type Value = Vec<NarrowedJoint>;

        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a table of joint names, each with [lower, upper] in rad")
        }

        fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<Self::Value, A::Error> {
            let mut out: Vec<NarrowedJoint> = Vec::new();
            while let Some((joint, [lower, upper])) = a.next_entry::<String, [f64; 2]>()? {
                if out.iter().any(|n| n.joint == joint) {
                    return Err(serde::de::Error::custom(format!(
                        "joint `{joint}` given twice"
                    )));
                }
                out.push(NarrowedJoint {
                    joint,
                    lower,
                    upper,
                });
            }
            Ok(out)
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<NarrowedJoint>, D::Error> {
        d.deserialize_map(Entries)
    }
}
