//! The skeleton of a captured motion: named joints, parents, rest offsets, joint kinds, and its
//! forward kinematics.

use std::collections::HashSet;

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::Pose;
use crate::error::{check_dim, Error, Result};

/// What kind of rotation a skeleton joint has.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointKind {
    /// The root: its pose in the world is the frame's root position and orientation. Only joint 0
    /// is a root.
    Root,
    /// A ball joint: any local rotation.
    Spherical,
    /// A revolute joint: its local rotation is a rotation about `axis` (a unit vector in the
    /// joint's frame, which at zero angle coincides with the parent's frame).
    Hinge {
        /// The rotation axis \[–\], unit length.
        axis: Unit<Vector3<f64>>,
    },
    /// A rigid attachment (an end site, a wrist): its local rotation is the identity.
    Fixed,
}

/// One joint of a [`Skeleton`].
#[derive(Debug, Clone, PartialEq)]
pub struct SkeletonJoint {
    /// The joint's name, unique in its skeleton.
    pub name: String,
    /// Index of the parent joint (smaller than this joint's index), `None` for the root.
    pub parent: Option<usize>,
    /// Rest offset \[m\]: position of this joint's origin in its parent's frame when the parent's
    /// rotation is applied (for the root: its rest position in the world, unused by the forward
    /// kinematics, which place the root at the frame's root position).
    pub offset: Vector3<f64>,
    /// Spherical, hinge, fixed or root.
    pub kind: JointKind,
}

/// A tree of joints; joint 0 is the root and every parent comes before its children.
///
/// Frames follow the usual motion-capture convention: every joint has a frame, translated by
/// `offset` from its parent's frame and rotated by the joint's local rotation of the frame
/// (no rest rotation), so that with all local rotations at identity every frame is parallel to the
/// root's.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    joints: Vec<SkeletonJoint>,
}

impl Skeleton {
    /// Checks and wraps a list of joints: at least one joint; joint 0 and only joint 0 is a
    /// [`JointKind::Root`] without parent; every other joint's parent index is smaller than its own;
    /// names are non-empty and unique; offsets and hinge axes are finite.
    pub fn new(joints: Vec<SkeletonJoint>) -> Result<Self> {
        let mut names = HashSet::new();
        if joints.is_empty() {
            return Err(skeleton_error("a skeleton needs at least one (root) joint"));
        }
        for (i, joint) in joints.iter().enumerate() {
            if joint.name.is_empty() {
                return Err(skeleton_error(&format!("joint {i} has an empty name")));
            }
            if !names.insert(joint.name.as_str()) {
                return Err(skeleton_error(&format!(
                    "joint name `{}` is used twice",
                    joint.name
                )));
            }
            let is_root = matches!(joint.kind, JointKind::Root);
            match (i, joint.parent, is_root) {
                (0, None, true) => {}
                (0, _, _) => {
                    return Err(skeleton_error(&format!(
                        "joint 0 (`{}`) must be the root: kind Root and no parent",
                        joint.name
                    )))
                }
                (_, Some(p), false) if p < i => {}
                _ => {
                    return Err(skeleton_error(&format!(
                        "joint {i} (`{}`) must have a parent with a smaller index and must not be a root",
                        joint.name
                    )))
                }
            }
            if joint.offset.iter().any(|v| !v.is_finite()) {
                return Err(skeleton_error(&format!(
                    "joint `{}` has a non-finite offset",
                    joint.name
                )));
            }
            if let JointKind::Hinge { axis } = joint.kind {
                if axis.iter().any(|v| !v.is_finite()) {
                    return Err(skeleton_error(&format!(
                        "hinge joint `{}` has a non-finite axis",
                        joint.name
                    )));
                }
            }
        }
        Ok(Self { joints })
    }

    /// The joints, root first.
    pub fn joints(&self) -> &[SkeletonJoint] {
        &self.joints
    }

    /// Number of joints (including the root and fixed joints).
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// Always `false`: a skeleton has at least its root.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Index of the joint called `name`, or [`Error::UnknownName`] listing the joints.
    pub fn index_of(&self, name: &str) -> Result<usize> {
        self.joints
            .iter()
            .position(|j| j.name == name)
            .ok_or_else(|| Error::UnknownName {
                kind: "skeleton joint",
                name: name.to_string(),
                valid: self.joints.iter().map(|j| j.name.clone()).collect(),
            })
    }

    /// Indices of the children of joint `index`, in index order (empty for a bad index).
    pub fn children(&self, index: usize) -> impl Iterator<Item = usize> + '_ {
        self.joints
            .iter()
            .enumerate()
            .filter(move |(_, j)| j.parent == Some(index))
            .map(|(i, _)| i)
    }

    /// A pose with every rotation at identity, no extra translation and the root at its rest
    /// offset.
    pub fn rest_pose(&self) -> Pose {
        Pose {
            root_position: self.joints.first().map_or(Vector3::zeros(), |j| j.offset),
            root_orientation: UnitQuaternion::identity(),
            rotations: vec![UnitQuaternion::identity(); self.joints.len()],
            translations: vec![Vector3::zeros(); self.joints.len()],
        }
    }

    /// Forward kinematics: the pose of every joint frame in the world.
    ///
    /// `T_0 = (root_position, root_orientation)`; for a joint `j` with parent `p`,
    /// `p_j = p_p + R_p (offset_j + translation_j)` \[m\] and `R_j = R_p · rotation_j`.
    /// `out` must have one entry per joint. Allocates nothing.
    pub fn world_transforms(&self, pose: &Pose, out: &mut [Isometry3<f64>]) -> Result<()> {
        self.check_pose(pose)?;
        check_dim("forward kinematics output", self.joints.len(), out.len())?;
        for j in 0..self.joints.len() {
            let joint = &self.joints[j];
            let transform = match joint.parent {
                None => Isometry3::from_parts(
                    Translation3::from(pose.root_position),
                    pose.root_orientation,
                ),
                Some(p) => {
                    let parent = out[p];
                    let local = joint.offset + pose.translations[j];
                    Isometry3::from_parts(
                        Translation3::from(parent.translation.vector + parent.rotation * local),
                        parent.rotation * pose.rotations[j],
                    )
                }
            };
            out[j] = transform;
        }
        Ok(())
    }

    /// World positions of all joints \[m\] (see [`Skeleton::world_transforms`]).
    pub fn world_positions(&self, pose: &Pose) -> Result<Vec<Vector3<f64>>> {
        let mut transforms = vec![Isometry3::identity(); self.joints.len()];
        self.world_transforms(pose, &mut transforms)?;
        Ok(transforms.iter().map(|t| t.translation.vector).collect())
    }

    /// Checks that `pose` has one rotation and one translation per joint.
    pub fn check_pose(&self, pose: &Pose) -> Result<()> {
        check_dim("pose rotations", self.joints.len(), pose.rotations.len())?;
        check_dim(
            "pose translations",
            self.joints.len(),
            pose.translations.len(),
        )
    }
}

fn skeleton_error(message: &str) -> Error {
    Error::InvalidSetting {
        name: "skeleton".to_string(),
        value: message.to_string(),
        expected: "a tree of uniquely named joints rooted at joint 0, parents before children"
            .to_string(),
    }
}
