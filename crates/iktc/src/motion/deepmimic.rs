//! Reader of DeepMimic motion files and the DeepMimic humanoid skeleton.
//!
//! File format (see `crates/iktc/data/NOTICE.md`): JSON with a `"Frames"` array; each frame holds 44
//! numbers: `[duration of the frame \[s\], root position (3) \[m\], root orientation (w, x, y, z),
//! chest (w, x, y, z), neck, right hip, right knee angle \[rad\], right ankle, right shoulder,
//! right elbow angle \[rad\], left hip, left knee angle, left ankle, left shoulder, left elbow
//! angle]`; the world is Y-up. Quaternions are local rotations of a joint's frame relative to its
//! parent's; the angles are rotations about the hinge axes of `deepmimic_humanoid.urdf`.
//!
//! Frame `i` lasts `duration_i`: frame `i` is at `t_i = Σ_{k<i} duration_k` and the duration of
//! the last frame is ignored (it is 0 in some files), so a clip of `n` frames lasts
//! `Σ_{k<n−1} duration_k`.

use nalgebra::{Quaternion, Unit, UnitQuaternion, Vector3};
use serde::Deserialize;

use super::{Clip, JointKind, Pose, Skeleton, SkeletonJoint, UpAxis};
use crate::error::{Error, Result};
use crate::resources::ReadLimits;

/// The DeepMimic character (pybullet's `humanoid/humanoid.urdf`), embedded.
///
/// It is authored at four times human size; see [`DEEPMIMIC_URDF_SCALE`].
pub const DEEPMIMIC_URDF: &str =
    include_str!("../../data/motions/deepmimic/deepmimic_humanoid.urdf");

/// Length of one URDF unit of [`DEEPMIMIC_URDF`] in metres \[m/unit\].
///
/// pybullet loads that file with `globalScaling = 0.25`; the motion files' root heights confirm it:
/// in the first frame of `humanoid3d_walk` the pelvis is 0.848 m above the floor, and the scaled
/// leg (hip → knee 0.422 m, knee → ankle 0.410 m, ankle → sole 0.050 m) is 0.881 m long, knee
/// slightly bent.
pub const DEEPMIMIC_URDF_SCALE: f64 = 0.25;

/// Names accepted by [`builtin_clip`].
pub const BUILTIN_CLIP_NAMES: [&str; 4] = [
    "humanoid3d_dance_a",
    "humanoid3d_dance_b",
    "humanoid3d_punch",
    "humanoid3d_walk",
];

const BUILTIN_CLIP_TEXTS: [&str; 4] = [
    include_str!("../../data/motions/deepmimic/humanoid3d_dance_a.txt"),
    include_str!("../../data/motions/deepmimic/humanoid3d_dance_b.txt"),
    include_str!("../../data/motions/deepmimic/humanoid3d_punch.txt"),
    include_str!("../../data/motions/deepmimic/humanoid3d_walk.txt"),
];

/// Numbers per frame of a DeepMimic motion file.
pub const DEEPMIMIC_FRAME_LEN: usize = 44;

/// Settings of [`read_deepmimic_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeepMimicSettings {
    /// Largest accepted `|‖q‖ − 1|` \[–\] of a quaternion in the file before it is normalised.
    /// Larger values accept sloppier files (whose rotations are then only what the normalised
    /// quaternion says); smaller values reject them. Default 0.1: the shipped `humanoid3d_punch`
    /// has neck quaternions of norm down to 0.917 (frames 55–64); the other clips are unit to
    /// 1e-6.
    pub max_quaternion_norm_error: f64,
    /// Most frames and longest duration accepted.
    pub limits: ReadLimits,
}

impl Default for DeepMimicSettings {
    fn default() -> Self {
        Self {
            max_quaternion_norm_error: 0.1,
            limits: ReadLimits::default(),
        }
    }
}

impl DeepMimicSettings {
    /// Checks that the tolerance is finite and in (0, 1).
    pub fn validate(&self) -> Result<()> {
        let v = self.max_quaternion_norm_error;
        if v.is_finite() && v > 0.0 && v < 1.0 {
            Ok(())
        } else {
            Err(Error::InvalidSetting {
                name: "max_quaternion_norm_error".to_string(),
                value: v.to_string(),
                expected: "a number in (0, 1)".to_string(),
            })
        }
    }
}

/// What a group of numbers of a frame holds.
#[derive(Clone, Copy)]
enum FieldKind {
    Quaternion,
    Angle,
}

/// The joint fields of a frame after the duration, root position and root orientation:
/// (joint name in the URDF, index of the first number, kind).
const JOINT_FIELDS: [(&str, usize, FieldKind); 12] = [
    ("chest", 8, FieldKind::Quaternion),
    ("neck", 12, FieldKind::Quaternion),
    ("right_hip", 16, FieldKind::Quaternion),
    ("right_knee", 20, FieldKind::Angle),
    ("right_ankle", 21, FieldKind::Quaternion),
    ("right_shoulder", 25, FieldKind::Quaternion),
    ("right_elbow", 29, FieldKind::Angle),
    ("left_hip", 30, FieldKind::Quaternion),
    ("left_knee", 34, FieldKind::Angle),
    ("left_ankle", 35, FieldKind::Quaternion),
    ("left_shoulder", 39, FieldKind::Quaternion),
    ("left_elbow", 43, FieldKind::Angle),
];

/// End sites added to the URDF's joints, from its collision geometry (all in metres after
/// scaling): (end site name, link it is attached to).
///
/// * `head_top`: top of the head sphere of link `neck` (sphere centre + radius along +Y);
/// * `right_sole`, `left_sole`: centre of the bottom face of the foot box of link `*_ankle`
///   (box centre − half its Y size along Y).
const END_SITES: [(&str, &str); 3] = [
    ("head_top", "neck"),
    ("right_sole", "right_ankle"),
    ("left_sole", "left_ankle"),
];

/// The DeepMimic humanoid's skeleton, from [`DEEPMIMIC_URDF`] scaled by
/// [`DEEPMIMIC_URDF_SCALE`].
///
/// Joints, in depth-first order from the root: `root`, the URDF's spherical joints (chest, neck,
/// shoulders, hips, ankles), its revolute joints (knees and elbows, hinges about the joint
/// frame's +Z as the URDF says), its fixed wrists, and three end sites computed from the collision
/// geometry: `head_top`, `right_sole`, `left_sole`. In the rest pose the character stands along
/// +Y, faces +X and has its right side at +Z.
pub fn deepmimic_skeleton() -> Result<Skeleton> {
    skeleton_from_urdf(DEEPMIMIC_URDF, DEEPMIMIC_URDF_SCALE)
}

fn urdf_error(message: String) -> Error {
    Error::Urdf { message }
}

/// Builds a motion skeleton from a URDF whose joints have no rest rotation (all `rpy` zero):
/// the joint of type fixed whose child is the tree's root link becomes the root; spherical,
/// revolute / continuous and fixed joints become spherical, hinge and fixed skeleton joints.
fn skeleton_from_urdf(text: &str, scale: f64) -> Result<Skeleton> {
    let cleaned: String = text.chars().filter(|c| *c != '\0').collect();
    let robot = urdf_rs::read_from_string(&cleaned)
        .map_err(|e| urdf_error(format!("cannot read the DeepMimic URDF: {e}")))?;
    // The root joint: the one whose parent link is no joint's child.
    let is_child = |link: &str| robot.joints.iter().any(|j| j.child.link == link);
    let root = robot
        .joints
        .iter()
        .find(|j| !is_child(&j.parent.link))
        .ok_or_else(|| urdf_error("the URDF has no root joint".to_string()))?;
    let mut joints: Vec<SkeletonJoint> = Vec::new();
    // Depth-first traversal with an explicit stack of (urdf joint, skeleton parent index).
    let mut stack: Vec<(&urdf_rs::Joint, Option<usize>)> = vec![(root, None)];
    while let Some((uj, parent)) = stack.pop() {
        if uj.origin.rpy.iter().any(|v| *v != 0.0) {
            return Err(urdf_error(format!(
                "joint `{}` has a rest rotation (rpy); motion skeletons need rpy = 0",
                uj.name
            )));
        }
        let offset = Vector3::from(*uj.origin.xyz) * scale;
        let kind = match (parent, &uj.joint_type) {
            (None, _) => JointKind::Root,
            (Some(_), urdf_rs::JointType::Spherical) => JointKind::Spherical,
            (Some(_), urdf_rs::JointType::Fixed) => JointKind::Fixed,
            (Some(_), urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous) => {
                let axis = Vector3::from(*uj.axis.xyz);
                let axis = Unit::try_new(axis, 0.0)
                    .ok_or_else(|| urdf_error(format!("joint `{}` has a zero axis", uj.name)))?;
                JointKind::Hinge { axis }
            }
            (Some(_), other) => {
                return Err(urdf_error(format!(
                "joint `{}` has type {other:?}; expected spherical, revolute, continuous or fixed",
                uj.name
            )))
            }
        };
        let index = joints.len();
        joints.push(SkeletonJoint {
            name: uj.name.clone(),
            parent,
            offset,
            kind,
        });
        let child_link = uj.child.link.as_str();
        for (name, link) in END_SITES.iter().rev() {
            if *link == child_link {
                joints.push(SkeletonJoint {
                    name: (*name).to_string(),
                    parent: Some(index),
                    offset: end_site_offset(&robot, link)? * scale,
                    kind: JointKind::Fixed,
                });
            }
        }
        // Push children in reverse so that they are visited in file order.
        for child in robot
            .joints
            .iter()
            .filter(|j| j.parent.link == child_link)
            .rev()
        {
            stack.push((child, Some(index)));
        }
    }
    // End sites were appended right after their joint, before the joint's children: they are
    // leaves, so the order is still depth-first.
    Skeleton::new(joints)
}

/// Offset of an end site in the frame of `link` \[URDF units\].
fn end_site_offset(robot: &urdf_rs::Robot, link: &str) -> Result<Vector3<f64>> {
    let missing = || {
        urdf_error(format!(
            "link `{link}` has no collision geometry for an end site"
        ))
    };
    let collision = robot
        .links
        .iter()
        .find(|l| l.name == link)
        .and_then(|l| l.collision.first())
        .ok_or_else(missing)?;
    let centre = Vector3::from(*collision.origin.xyz);
    match &collision.geometry {
        urdf_rs::Geometry::Sphere { radius } => Ok(centre + Vector3::y() * *radius),
        urdf_rs::Geometry::Box { size } => Ok(centre - Vector3::y() * (size[1] / 2.0)),
        _ => Err(missing()),
    }
}

#[derive(Deserialize)]
struct MotionFile {
    #[serde(rename = "Frames")]
    frames: Vec<Vec<f64>>,
}

/// Reads a DeepMimic motion file with the default [`DeepMimicSettings`].
///
/// `source_name` names the file in error messages. Errors ([`Error::Parse`], with the line where
/// known): malformed JSON or a non-numeric value, no `"Frames"`, zero frames, a frame that does
/// not hold 44 numbers, a non-positive duration (except the last frame's), a quaternion of zero
/// norm or whose norm is farther from 1 than allowed (naming frame and field); more frames or a
/// longer clip than [`DeepMimicSettings::limits`] allow ([`Error::ResourceLimit`]).
pub fn read_deepmimic(text: &str, source_name: &str) -> Result<Clip> {
    read_deepmimic_with(text, source_name, &DeepMimicSettings::default())
}

/// [`read_deepmimic`] with explicit settings.
pub fn read_deepmimic_with(
    text: &str,
    source_name: &str,
    settings: &DeepMimicSettings,
) -> Result<Clip> {
    settings.validate()?;
    let text = super::strip_bom(text);
    let skeleton = deepmimic_skeleton()?;
    let file: MotionFile = serde_json::from_str(text)
        .map_err(|e| frame_error(source_name, e.line(), e.to_string()))?;
    if file.frames.is_empty() {
        return Err(frame_error(
            source_name,
            frame_lines(text).first().copied().unwrap_or(0),
            "the motion has zero frames".to_string(),
        ));
    }
    let reader = FrameReader {
        text,
        source_name,
        settings,
        targets: joint_targets(&skeleton)?,
        skeleton: &skeleton,
    };
    crate::resources::check_count(
        &format!("frames in {source_name}"),
        file.frames.len(),
        settings.limits.max_clip_frames,
        "ReadLimits::max_clip_frames",
    )?;
    let mut times = Vec::with_capacity(file.frames.len());
    let mut poses = Vec::with_capacity(file.frames.len());
    let mut t = 0.0;
    let last = file.frames.len() - 1;
    for (i, frame) in file.frames.iter().enumerate() {
        let (duration, pose) = reader.frame(i, frame, i < last)?;
        times.push(t);
        poses.push(pose);
        t += duration;
    }
    let duration = times.last().copied().unwrap_or(0.0);
    settings
        .limits
        .check_clip(source_name, times.len(), duration)?;
    Clip::new(source_name, skeleton, times, poses, UpAxis::Y)
}

/// An [`Error::Parse`] in `source_name` at `line`.
fn frame_error(source_name: &str, line: usize, message: String) -> Error {
    Error::Parse {
        source_name: source_name.to_string(),
        line,
        message,
    }
}

/// Maps the file's joint fields to skeleton joints (index, kind), checking their kinds against
/// the URDF.
fn joint_targets(skeleton: &Skeleton) -> Result<[(usize, FieldKind); JOINT_FIELDS.len()]> {
    let mut targets = [(0usize, FieldKind::Angle); JOINT_FIELDS.len()];
    for (slot, (name, _, kind)) in targets.iter_mut().zip(JOINT_FIELDS.iter()) {
        let index = skeleton.index_of(name)?;
        let ok = matches!(
            (kind, skeleton.joints().get(index).map(|j| j.kind)),
            (FieldKind::Quaternion, Some(JointKind::Spherical))
                | (FieldKind::Angle, Some(JointKind::Hinge { .. }))
        );
        if !ok {
            return Err(urdf_error(format!(
                "joint `{name}` of the DeepMimic URDF does not have the kind the motion format needs"
            )));
        }
        *slot = (index, *kind);
    }
    Ok(targets)
}

/// Turns the frames of a motion file into poses on the DeepMimic skeleton.
struct FrameReader<'a> {
    /// The file's text, to find a frame's line for an error.
    text: &'a str,
    source_name: &'a str,
    settings: &'a DeepMimicSettings,
    /// Skeleton joint and kind per entry of [`JOINT_FIELDS`].
    targets: [(usize, FieldKind); JOINT_FIELDS.len()],
    skeleton: &'a Skeleton,
}

impl FrameReader<'_> {
    /// An [`Error::Parse`] at the line of frame `i`.
    fn error(&self, i: usize, message: String) -> Error {
        let line = frame_lines(self.text).get(i).copied().unwrap_or(0);
        frame_error(self.source_name, line, message)
    }

    /// Frame `i`: its duration \[s\] (checked > 0 when `needs_duration`) and its pose.
    fn frame(&self, i: usize, frame: &[f64], needs_duration: bool) -> Result<(f64, Pose)> {
        let Some(values) = <&[f64; DEEPMIMIC_FRAME_LEN]>::try_from(frame).ok() else {
            return Err(self.error(
                i,
                format!(
                    "frame {i} has {} numbers; expected {DEEPMIMIC_FRAME_LEN}",
                    frame.len()
                ),
            ));
        };
        let duration = values[0];
        if needs_duration && !(duration.is_finite() && duration > 0.0) {
            return Err(self.error(
                i,
                format!("frame {i}, field `duration`: {duration} s; expected a duration > 0"),
            ));
        }
        let n = self.skeleton.len();
        let mut pose = Pose {
            root_position: Vector3::new(values[1], values[2], values[3]),
            root_orientation: self.quaternion(i, values, 4, "root orientation")?,
            rotations: vec![UnitQuaternion::identity(); n],
            translations: vec![Vector3::zeros(); n],
        };
        for ((index, kind), (name, start, _)) in self.targets.iter().zip(JOINT_FIELDS.iter()) {
            let rotation = match kind {
                FieldKind::Quaternion => self.quaternion(i, values, *start, name)?,
                FieldKind::Angle => match self.skeleton.joints().get(*index).map(|j| j.kind) {
                    Some(JointKind::Hinge { axis }) => {
                        UnitQuaternion::from_axis_angle(&axis, values[*start])
                    }
                    _ => UnitQuaternion::identity(),
                },
            };
            if let Some(slot) = pose.rotations.get_mut(*index) {
                *slot = rotation;
            }
        }
        Ok((duration, pose))
    }

    /// The unit quaternion `w x y z` at `values[start..]` of frame `i` (field `field`); a norm
    /// of zero or farther from 1 than the settings allow is an error.
    fn quaternion(
        &self,
        i: usize,
        values: &[f64; DEEPMIMIC_FRAME_LEN],
        start: usize,
        field: &str,
    ) -> Result<UnitQuaternion<f64>> {
        let q = Quaternion::new(
            values[start],
            values[start + 1],
            values[start + 2],
            values[start + 3],
        );
        let norm = q.norm();
        let tolerance = self.settings.max_quaternion_norm_error;
        if norm == 0.0 || (norm - 1.0).abs() > tolerance {
            return Err(self.error(
                i,
                format!(
                    "frame {i}, field `{field}`: quaternion norm {norm}; expected 1 within {tolerance}"
                ),
            ));
        }
        Ok(UnitQuaternion::from_quaternion(q))
    }
}

/// The 1-based line on which each frame (each array inside `"Frames"`) starts.
fn frame_lines(text: &str) -> Vec<usize> {
    let mut lines = Vec::new();
    let Some(start) = text.find("\"Frames\"") else {
        return lines;
    };
    let mut line = 1 + text[..start].matches('\n').count();
    let mut depth = 0usize;
    for c in text[start..].chars() {
        match c {
            '\n' => line += 1,
            '[' => {
                depth += 1;
                if depth == 2 {
                    lines.push(line);
                }
            }
            ']' => {
                if depth <= 1 {
                    break;
                }
                depth -= 1;
            }
            _ => {}
        }
    }
    lines
}

/// The JSON text of one of the four DeepMimic clips shipped with the library, by name (see
/// [`builtin_clip`]): to write a changed copy. Unknown names give [`Error::UnknownName`].
pub fn builtin_clip_text(name: &str) -> Result<&'static str> {
    BUILTIN_CLIP_NAMES
        .iter()
        .zip(BUILTIN_CLIP_TEXTS.iter())
        .find(|(n, _)| **n == name)
        .map(|(_, t)| *t)
        .ok_or_else(|| Error::UnknownName {
            kind: "built-in motion clip",
            name: name.to_string(),
            valid: BUILTIN_CLIP_NAMES.iter().map(|s| s.to_string()).collect(),
        })
}

/// One of the four DeepMimic clips shipped with the library (see `crates/iktc/data/NOTICE.md`), by name:
/// see [`BUILTIN_CLIP_NAMES`]. Unknown names give [`Error::UnknownName`] listing the valid ones.
pub fn builtin_clip(name: &str) -> Result<Clip> {
    read_deepmimic(builtin_clip_text(name)?, name)
}
