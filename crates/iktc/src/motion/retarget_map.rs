//! Retargeting maps: which captured joint drives which robot joints (a TOML file).
//!
//! ```toml
//! name = "deepmimic_jvrc1"
//! # Rows: the robot's x (forward), y (left) and z (up) axes in the source's coordinates.
//! basis = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
//!
//! [root]
//! source = "root"          # optional, default: the skeleton's root
//! height_scale = 0.8       # pelvis height change per source root height change [–]
//! yaw_scale = 0.0          # scales of the root's yaw, pitch and roll changes [–]
//! pitch_scale = 1.0
//! roll_scale = 1.0
//!
//! [[joint]]
//! source = "right_shoulder"
//! rest_rotation = [0, 0, 0]   # optional, rotation vector in robot axes [rad]
//! targets = [
//!   { joint = "R_SHOULDER_P" },
//!   { joint = "R_SHOULDER_R", sign = 1, scale = 1.0, offset = -0.1 },
//!   { joint = "R_SHOULDER_Y" },
//! ]
//!
//! [[hold]]
//! joint = "R_WRIST_Y"
//! value = 0.0
//! ```

#[cfg(feature = "toml")]
use nalgebra::Matrix3;
use nalgebra::{Rotation3, Vector3};
use serde::Deserialize;

#[cfg(feature = "toml")]
use crate::error::{Error, Result};

/// Names accepted by [`builtin_map`].
#[cfg(feature = "toml")]
pub const BUILTIN_MAP_NAMES: [&str; 3] = ["deepmimic_jvrc1", "bvh_jvrc1", "deepmimic_g1"];

#[cfg(feature = "toml")]
const BUILTIN_MAP_TEXTS: [&str; 3] = [
    include_str!("../../data/maps/deepmimic_jvrc1.toml"),
    include_str!("../../data/maps/bvh_jvrc1.toml"),
    include_str!("../../data/maps/deepmimic_g1.toml"),
];

/// A built-in map by name: `deepmimic_jvrc1` (the DeepMimic character of the built-in clips
/// onto JVRC-1), `bvh_jvrc1` (a BVH skeleton with the common `Hips / Spine / Neck / LeftArm /
/// LeftForeArm …` naming, Y-up, facing +Z, T-pose rest, onto JVRC-1) or `deepmimic_g1` (the
/// DeepMimic character onto the Unitree G1).
#[cfg(feature = "toml")]
pub fn builtin_map(name: &str) -> Result<RetargetMap> {
    match BUILTIN_MAP_NAMES.iter().position(|n| *n == name) {
        Some(i) => RetargetMap::from_toml_str(BUILTIN_MAP_TEXTS[i], name),
        None => Err(Error::UnknownName {
            kind: "built-in retargeting map",
            name: name.into(),
            valid: BUILTIN_MAP_NAMES.iter().map(|s| s.to_string()).collect(),
        }),
    }
}

/// The TOML text of a built-in map (see [`builtin_map`]), to print or edit.
pub fn builtin_map_text(name: &str) -> Result<&'static str> {
    BUILTIN_MAP_NAMES
        .iter()
        .position(|n| *n == name)
        .map(|i| BUILTIN_MAP_TEXTS[i])
        .ok_or_else(|| Error::UnknownName {
            kind: "built-in retargeting map",
            name: name.into(),
            valid: BUILTIN_MAP_NAMES.iter().map(|s| s.to_string()).collect(),
        })
}

/// One robot joint driven by a decomposed source rotation:
/// `q = offset + sign · scale · θ` \[rad\], `θ` the decomposed angle about this joint's axis.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetJoint {
    /// The robot joint's name (an active revolute joint).
    pub joint: String,
    /// +1 or −1 \[–\] (default +1).
    #[serde(default = "one")]
    pub sign: f64,
    /// Scale \[–\] (default 1).
    #[serde(default = "one")]
    pub scale: f64,
    /// Offset \[rad\] (default 0).
    #[serde(default)]
    pub offset: f64,
}

fn one() -> f64 {
    1.0
}

/// One source joint and the robot joints its rotation is decomposed onto, in the robot's
/// joint-axis order (the order of `targets`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointMap {
    /// The source (captured skeleton) joint's name.
    pub source: String,
    /// 1 to 3 robot joints forming a serial chain, parent first.
    pub targets: Vec<TargetJoint>,
    /// A constant rotation (rotation vector in robot axes \[rad\]) that takes the robot limb's
    /// zero-angle direction to the source limb's rest direction (e.g. ±90° about x for arms
    /// hanging down on the robot and horizontal in a T-pose rest); the decomposed rotation is
    /// `R_parent_restᵀ · R · R_rest`. Default zero (same rest posture).
    #[serde(default)]
    pub rest_rotation: [f64; 3],
    /// The `rest_rotation` of the limb this joint hangs from (rotation vector in robot axes
    /// \[rad\]): a forearm's rotation is seen from the turned upper arm. Default zero.
    #[serde(default)]
    pub parent_rest_rotation: [f64; 3],
}

/// How the source root drives the pelvis references.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RootMap {
    /// The source joint whose world pose is the pelvis; default the skeleton's root.
    #[serde(default)]
    pub source: Option<String>,
    /// Pelvis height change per source height change \[–\] (default 1).
    #[serde(default = "one")]
    pub height_scale: f64,
    /// Scale of the root's yaw change \[–\] (default 0: the feet stay planted, so the captured
    /// turning is not imitated).
    #[serde(default)]
    pub yaw_scale: f64,
    /// Scale of the root's pitch change \[–\] (default 1).
    #[serde(default = "one")]
    pub pitch_scale: f64,
    /// Scale of the root's roll change \[–\] (default 1).
    #[serde(default = "one")]
    pub roll_scale: f64,
}

impl Default for RootMap {
    fn default() -> Self {
        Self {
            source: None,
            height_scale: 1.0,
            yaw_scale: 0.0,
            pitch_scale: 1.0,
            roll_scale: 1.0,
        }
    }
}

/// A robot joint held at a constant reference \[rad\].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HoldJoint {
    /// The robot joint's name.
    pub joint: String,
    /// Its reference \[rad\].
    pub value: f64,
}

#[cfg(feature = "toml")]
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MapFile {
    name: Option<String>,
    basis: [[f64; 3]; 3],
    #[serde(default)]
    root: Option<RootMap>,
    #[serde(default)]
    joint: Vec<JointMap>,
    #[serde(default)]
    hold: Vec<HoldJoint>,
}

/// A retargeting map (see the module documentation for the file format).
#[derive(Debug, Clone, PartialEq)]
pub struct RetargetMap {
    /// The map's name.
    pub name: String,
    /// `B`: takes a vector in source coordinates to robot coordinates, `v_robot = B v_source`
    /// (a proper rotation; its rows are the robot's x, y, z axes in source coordinates). Applies
    /// to the source world and to every source joint frame (all parallel at rest).
    pub basis: Rotation3<f64>,
    /// Root → pelvis.
    pub root: RootMap,
    /// Joint maps.
    pub joints: Vec<JointMap>,
    /// Held joints.
    pub holds: Vec<HoldJoint>,
}

/// Largest `‖BᵀB − I‖` accepted for a basis \[–\] (the file's numbers are typed by hand).
#[cfg(feature = "toml")]
const BASIS_TOLERANCE: f64 = 1e-6;

/// An [`Error::InvalidSetting`] for the setting `name` of the map `source_name`.
#[cfg(feature = "toml")]
fn invalid(source_name: &str, name: String, value: String, expected: &str) -> Error {
    Error::InvalidSetting {
        name: format!("{source_name}: {name}"),
        value,
        expected: expected.into(),
    }
}

/// Checks one joint map: 1 to 3 targets, finite rest rotations \[rad\], signs ±1, finite
/// scales and offsets.
#[cfg(feature = "toml")]
fn check_joint_map(jm: &JointMap, source_name: &str) -> Result<()> {
    if jm.targets.is_empty() || jm.targets.len() > super::MAX_DECOMPOSITION_AXES {
        return Err(invalid(
            source_name,
            format!("targets of `{}`", jm.source),
            format!("{} joints", jm.targets.len()),
            "1 to 3 robot joints",
        ));
    }
    if jm
        .rest_rotation
        .iter()
        .chain(&jm.parent_rest_rotation)
        .any(|v| !v.is_finite())
    {
        return Err(invalid(
            source_name,
            format!("rest_rotation of `{}`", jm.source),
            format!("{:?}", jm.rest_rotation),
            "a finite rotation vector [rad]",
        ));
    }
    for t in &jm.targets {
        if t.sign != 1.0 && t.sign != -1.0 {
            return Err(invalid(
                source_name,
                format!("sign of `{}`", t.joint),
                t.sign.to_string(),
                "+1 or -1",
            ));
        }
        if !(t.scale.is_finite() && t.offset.is_finite()) {
            return Err(invalid(
                source_name,
                format!("scale / offset of `{}`", t.joint),
                format!("{} / {}", t.scale, t.offset),
                "finite numbers",
            ));
        }
    }
    Ok(())
}

/// Checks that no robot joint is named twice among the targets and holds, and that every held
/// value \[rad\] is finite.
#[cfg(feature = "toml")]
fn check_holds(joints: &[JointMap], holds: &[HoldJoint], source_name: &str) -> Result<()> {
    let mut seen: Vec<&str> = Vec::new();
    for name in joints
        .iter()
        .flat_map(|j| j.targets.iter().map(|t| t.joint.as_str()))
        .chain(holds.iter().map(|h| h.joint.as_str()))
    {
        if seen.contains(&name) {
            return Err(invalid(
                source_name,
                "robot joints".into(),
                name.into(),
                "each robot joint driven by one map entry or hold only",
            ));
        }
        seen.push(name);
    }
    for h in holds {
        if !h.value.is_finite() {
            return Err(invalid(
                source_name,
                format!("hold value of `{}`", h.joint),
                h.value.to_string(),
                "a finite angle [rad]",
            ));
        }
    }
    Ok(())
}

impl RetargetMap {
    /// Parses and checks a map. `source_name` names the text in errors.
    ///
    /// Errors: malformed TOML or unknown keys ([`Error::Parse`] with the line), a basis that is
    /// not a proper rotation, a joint map with 0 or more than 3 targets, a sign other than ±1,
    /// a non-finite number, a robot joint named twice.
    #[cfg(feature = "toml")]
    pub fn from_toml_str(text: &str, source_name: &str) -> Result<Self> {
        let file: MapFile =
            toml::from_str(text).map_err(|e| super::body_map::toml_error(text, source_name, &e))?;
        let b = Matrix3::from_fn(|r, c| file.basis[r][c]);
        if b.iter().any(|v| !v.is_finite())
            || (b.transpose() * b - Matrix3::identity()).norm() > BASIS_TOLERANCE
            || b.determinant() < 0.0
        {
            return Err(invalid(
                source_name,
                "basis".into(),
                format!("{:?}", file.basis),
                "a proper rotation matrix (orthonormal rows, determinant +1)",
            ));
        }
        let root = file.root.unwrap_or_default();
        for (n, v) in [
            ("root.height_scale", root.height_scale),
            ("root.yaw_scale", root.yaw_scale),
            ("root.pitch_scale", root.pitch_scale),
            ("root.roll_scale", root.roll_scale),
        ] {
            if !v.is_finite() {
                return Err(invalid(
                    source_name,
                    n.into(),
                    v.to_string(),
                    "a finite number",
                ));
            }
        }
        for jm in &file.joint {
            check_joint_map(jm, source_name)?;
        }
        check_holds(&file.joint, &file.hold, source_name)?;
        Ok(Self {
            name: file.name.unwrap_or_else(|| source_name.to_string()),
            basis: Rotation3::from_matrix_unchecked(b),
            root,
            joints: file.joint,
            holds: file.hold,
        })
    }

    /// The robot joints this map gives a reference to (driven, then held), in map order.
    pub fn robot_joints(&self) -> Vec<String> {
        self.joints
            .iter()
            .flat_map(|j| j.targets.iter().map(|t| t.joint.clone()))
            .chain(self.holds.iter().map(|h| h.joint.clone()))
            .collect()
    }

    /// The rest rotations `(R_parent_rest, R_rest)` of a joint map.
    pub(crate) fn rest(j: &JointMap) -> (Rotation3<f64>, Rotation3<f64>) {
        (
            Rotation3::from_scaled_axis(Vector3::from(j.parent_rest_rotation)),
            Rotation3::from_scaled_axis(Vector3::from(j.rest_rotation)),
        )
    }
}
