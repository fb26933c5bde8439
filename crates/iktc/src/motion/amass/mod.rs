//! AMASS motion archives (`.npz`, SMPL-H and SMPL-X layouts) read with the user's own body
//! model file (the `.npz` the model's authors distribute; iktc ships none).
//!
//! **Joints.** The body model gives the rest joints of the archive's shape `β` (`betas`):
//! `J(β) = 𝒥 (T̄ + S β)` \[m\] ([`BodyModel::joints`]): the joint regressor `𝒥` applied to
//! the template vertices `T̄` displaced by the shape blend shapes `S`.
//!
//! **Skeleton.** Joint `i` is named by its layout ([`SmplLayout::joint_names`]: `pelvis`,
//! `left_hip`, …, so that the body points are recognised without a map), its parent `p(i)`
//! is the model's (`kintree_table`), its rest offset `J_i − J_p(i)` (the root's `J_0`), and it
//! is spherical. The rest pose has no rest rotations, as [`Skeleton`] expects.
//!
//! **Frames.** Frame `t` is at `t / rate` \[s\]. With `exp(ω)` the rotation of the axis-angle
//! vector `ω` (Rodrigues: `R = I + sin θ [k]ₓ + (1 − cos θ) [k]ₓ²`, `θ = ‖ω‖`, `k = ω / θ`),
//! the root orientation is `exp(ω_{t,0})`, joint `i`'s local rotation `exp(ω_{t,i})`, and the
//! root position `trans_t + J_0`: SMPL rotates the body about its root joint, then translates
//! it by `trans`. The forward kinematics ([`Skeleton::world_transforms`]),
//! `p_i = p_p(i) + R_p(i) (J_i − J_p(i))`, `R_i = R_p(i) exp(ω_{t,i})`, give SMPL's posed joints
//! (the translation of each joint's global transform, plus `trans`); the pose blend shapes
//! move the surface, not the joints, and are not read.
//!
//! **World.** AMASS's world is Z up, in metres; the rest pose (every `ω` zero) stands in the
//! model's template frame, Y up. [`load_motion`](super::load_motion) therefore takes units and
//! up axis from the format ([`MotionFormat::fixed_frame`](super::MotionFormat::fixed_frame))
//! rather than measuring the rest pose.

mod archive;
mod layout;
mod model;

use std::io::Cursor;
use std::path::Path;

use nalgebra::{UnitQuaternion, Vector3};

pub use archive::{AmassArchive, FRAME_RATE_KEYS, MAX_BETAS};
pub use layout::SmplLayout;
pub use model::{BodyModel, MAX_MODEL_JOINTS, MAX_MODEL_VERTICES, MAX_SHAPE_COMPONENTS};

use super::{Clip, JointKind, Pose, Skeleton, SkeletonJoint, UpAxis};
use crate::error::{Error, Result};
use crate::resources::ReadLimits;

/// The clip of `archive` on `model` (see the module documentation); `name` names it.
///
/// Errors: [`Error::InvalidSetting`] naming both joint counts when the model's differs from
/// the archive's, or when it is neither SMPL-H's (52) nor SMPL-X's (55); those of
/// [`BodyModel::joints`].
pub fn amass_clip(archive: &AmassArchive, model: &BodyModel, name: &str) -> Result<Clip> {
    let j = archive.joint_count;
    if model.joint_count() != j {
        let layout = |n: usize| {
            SmplLayout::from_joint_count(n).map_or_else(String::new, |l| format!(", {}", l.name()))
        };
        return Err(Error::InvalidSetting {
            name: format!("body model `{}` for `{name}`", model.source()),
            value: format!(
                "{} joints{}",
                model.joint_count(),
                layout(model.joint_count())
            ),
            expected: format!(
                "the archive's {j} joints{} ({} pose values per frame): a body model of the \
                 archive's layout",
                layout(j),
                3 * j
            ),
        });
    }
    let layout = archive.layout().ok_or_else(|| Error::InvalidSetting {
        name: format!("joints per frame of `{name}`"),
        value: j.to_string(),
        expected: "52 (SMPL-H, 156 pose values) or 55 (SMPL-X, 165 pose values)".to_string(),
    })?;
    let rest = model.joints(&archive.betas)?;
    let names = layout.joint_names();
    let joints: Vec<SkeletonJoint> = names
        .into_iter()
        .zip(model.parents())
        .zip(&rest)
        .map(|((name, parent), at)| SkeletonJoint {
            name,
            parent: *parent,
            offset: parent.map_or(*at, |p| at - rest[p]),
            kind: if parent.is_some() {
                JointKind::Spherical
            } else {
                JointKind::Root
            },
        })
        .collect();
    let skeleton = Skeleton::new(joints)?;
    let frames: Vec<Pose> = (0..archive.frame_count())
        .map(|t| {
            let rotation = |i: usize| {
                UnitQuaternion::from_scaled_axis(
                    archive.axis_angle(t, i).unwrap_or_else(Vector3::zeros),
                )
            };
            let mut rotations: Vec<UnitQuaternion<f64>> = (0..j).map(rotation).collect();
            let root_orientation = rotations[0];
            rotations[0] = UnitQuaternion::identity();
            Pose {
                root_position: archive.trans[t] + rest[0],
                root_orientation,
                rotations,
                translations: vec![Vector3::zeros(); j],
            }
        })
        .collect();
    let times = (0..frames.len())
        .map(|t| t as f64 / archive.frame_rate)
        .collect();
    Clip::new(name, skeleton, times, frames, UpAxis::Z)
}

/// The error for an AMASS archive read without a body model: which model file it needs (by
/// its layout and gender), that iktc does not ship it, where it is distributed, and how to
/// give it.
pub fn missing_body_model(source: &str, archive: &AmassArchive) -> Error {
    let width = 3 * archive.joint_count;
    let gender = archive
        .gender
        .as_ref()
        .map_or_else(String::new, |g| format!(" (its gender: `{g}`)"));
    let needs = match archive.layout() {
        Some(layout) => {
            let (files, site) = layout.model_files();
            format!(
                "its poses have {width} values per frame ({} joints: {}), so it needs {files}{gender}; \
                 the model's licence does not let iktc ship it: download it from {site}",
                archive.joint_count,
                layout.name()
            )
        }
        None => format!(
            "its poses have {width} values per frame ({} joints), neither SMPL-H's 156 nor \
             SMPL-X's 165; it needs a body model .npz with {} joints{gender}, which iktc does not ship",
            archive.joint_count, archive.joint_count
        ),
    };
    Error::InsufficientData {
        what: format!("body model of the AMASS archive `{source}`"),
        message: format!(
            "an AMASS archive holds poses, not joint positions: its joints come from a body \
             model file; {needs}. Give the model file with --body-model PATH (CLI), \
             body_model=PATH (Python) or MotionOptions::body_model (Rust)"
        ),
    }
}

/// Reads the AMASS archive `bytes` (named `source`) with the body model file `body_model`.
///
/// Errors: [`missing_body_model`] without a model; those of [`AmassArchive::from_reader`],
/// [`BodyModel::read`] and [`amass_clip`].
pub fn read_amass(
    bytes: &[u8],
    source: &str,
    body_model: Option<&Path>,
    limits: &ReadLimits,
) -> Result<Clip> {
    let archive = AmassArchive::from_reader(Cursor::new(bytes), source, limits)?;
    let path = body_model.ok_or_else(|| missing_body_model(source, &archive))?;
    let model = BodyModel::read(path)?;
    amass_clip(&archive, &model, source)
}
