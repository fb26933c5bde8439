//! Conversions between [`BvhClip`] (channel values) and [`Clip`] (poses).

use nalgebra::{Unit, UnitQuaternion, Vector3};

use super::types::{BvhChannel, BvhClip, BvhExportOptions, BvhJoint};
use crate::error::{Error, Result};
use crate::motion::{decompose_rotation_with, Clip, JointKind, Pose, Skeleton, SkeletonJoint};

/// The rotation of a joint from its rotation channels, in the BVH convention: for channels
/// listed `c_1 c_2 c_3` with angles `θ_1 θ_2 θ_3`, `R = Rot(c_1, θ_1) · Rot(c_2, θ_2) ·
/// Rot(c_3, θ_3)` (column vectors; the child-to-parent rotation), i.e. intrinsic rotations in the
/// listed order: first about the parent's `c_1` axis, then about the once-rotated `c_2` axis, then
/// the twice-rotated `c_3` (equivalently, extrinsic rotations in the reverse order). A
/// `Zrotation Xrotation Yrotation` joint has `R = Rz · Rx · Ry`.
pub fn bvh_rotation(channels: &[BvhChannel], values: &[f64]) -> UnitQuaternion<f64> {
    let mut q = UnitQuaternion::identity();
    for (c, v) in channels.iter().zip(values) {
        if c.is_rotation() {
            q *= UnitQuaternion::from_axis_angle(&Unit::new_unchecked(c.axis()), *v);
        }
    }
    q
}

/// The translation of a joint from its position channels \[m\] (their vector sum).
fn bvh_translation(channels: &[BvhChannel], values: &[f64]) -> Vector3<f64> {
    channels
        .iter()
        .zip(values)
        .filter(|(c, _)| !c.is_rotation())
        .map(|(c, v)| c.axis() * *v)
        .sum()
}

/// Whether the non-root position channels of `clip` hold the joints' whole local translations
/// rather than additions to their offsets: over the non-root joints with position channels and
/// an offset longer than 1e-9 file units, the median of `|t − OFFSET| / |OFFSET|` at the first
/// frame is below 1/2 (additions are near 0, so their ratio is near 1; repeated offsets give
/// near 0). `false` without such joints or frames.
pub fn repeats_offsets(clip: &BvhClip) -> bool {
    let Some(values) = clip.frame(0) else {
        return false;
    };
    let mut ratios: Vec<f64> = clip
        .joints()
        .iter()
        .enumerate()
        .skip(1)
        .filter(|(_, j)| j.channels.iter().any(|c| !c.is_rotation()) && j.offset.norm() > 1e-9)
        .filter_map(|(i, j)| {
            let start = clip.channel_start(i)?;
            let v = values.get(start..start + j.channels.len())?;
            Some((bvh_translation(&j.channels, v) - j.offset).norm() / j.offset.norm())
        })
        .collect();
    if ratios.is_empty() {
        return false;
    }
    ratios.sort_by(f64::total_cmp);
    ratios[ratios.len() / 2] < 0.5
}

impl BvhClip {
    /// The clip as poses on a skeleton.
    ///
    /// Joint kinds: the root is [`JointKind::Root`]; a joint with 2 or 3 rotation channels is
    /// spherical, with 1 a hinge about that channel's axis, with none (and end sites) fixed.
    /// Local rotations follow [`bvh_rotation`]. Position channels add to the offset (Meredith &
    /// Maddock, "Motion capture file formats explained", 2001): the root is at
    /// `OFFSET + (Xposition, Yposition, Zposition)` in the world, and a non-root joint with position
    /// channels at `OFFSET + translation` in its parent's frame. Some exporters write instead
    /// the whole local translation into every joint's position channels (Bandai Namco's motion
    /// dataset: six channels per joint, their first frame repeating each `OFFSET`): when the
    /// first frame's non-root position channels lie within half their offset of it for most
    /// such joints ([`repeats_offsets`]), a non-root joint is at its channels' translation in
    /// its parent's frame, not at `OFFSET` plus it (which doubled every bone). Frame `k` is at
    /// `k · frame_time`.
    pub fn to_clip(&self) -> Result<Clip> {
        let joints: Vec<SkeletonJoint> = self
            .joints()
            .iter()
            .enumerate()
            .map(|(i, j)| {
                let rotations: Vec<BvhChannel> = j
                    .channels
                    .iter()
                    .copied()
                    .filter(|c| c.is_rotation())
                    .collect();
                let kind = match (i, rotations.as_slice()) {
                    (0, _) => JointKind::Root,
                    (_, []) => JointKind::Fixed,
                    (_, [c]) => JointKind::Hinge {
                        axis: Unit::new_unchecked(c.axis()),
                    },
                    _ => JointKind::Spherical,
                };
                SkeletonJoint {
                    name: j.name.clone(),
                    parent: j.parent,
                    offset: j.offset,
                    kind,
                }
            })
            .collect();
        let skeleton = Skeleton::new(joints)?;
        let n = self.joints().len();
        let absolute = repeats_offsets(self);
        let mut times = Vec::with_capacity(self.frame_count());
        let mut poses = Vec::with_capacity(self.frame_count());
        for f in 0..self.frame_count() {
            let values = self.frame(f).ok_or_else(|| Error::InsufficientData {
                what: "BVH clip".to_string(),
                message: format!("frame {f} is missing"),
            })?;
            let mut pose = Pose {
                root_position: Vector3::zeros(),
                root_orientation: UnitQuaternion::identity(),
                rotations: vec![UnitQuaternion::identity(); n],
                translations: vec![Vector3::zeros(); n],
            };
            for (i, j) in self.joints().iter().enumerate() {
                let start = self.channel_start(i).unwrap_or(0);
                let v = values.get(start..start + j.channels.len()).unwrap_or(&[]);
                let rotation = bvh_rotation(&j.channels, v);
                let translation = bvh_translation(&j.channels, v);
                if i == 0 {
                    pose.root_position = j.offset + translation;
                    pose.root_orientation = rotation;
                } else {
                    pose.rotations[i] = rotation;
                    let has_position = j.channels.iter().any(|c| !c.is_rotation());
                    pose.translations[i] = if absolute && has_position {
                        translation - j.offset
                    } else {
                        translation
                    };
                }
            }
            times.push(f as f64 * self.frame_time());
            poses.push(pose);
        }
        Clip::new(self.name(), skeleton, times, poses, self.up_axis())
    }

    /// A clip's poses as BVH channel values.
    ///
    /// Joints are written in depth-first order from the root. Channels: the root gets
    /// `Xposition Yposition Zposition` (the root position minus its rest offset) and three
    /// rotation channels in `options.rotation_order`; a spherical joint the three rotation
    /// channels; a hinge whose axis is a coordinate axis (within
    /// `options.axis_alignment_tolerance`) one rotation channel about it, any other hinge three;
    /// a joint whose translations are not all zero, position channels first; a fixed leaf becomes
    /// an `End Site` (its name is not kept: the reader calls it `<parent>_end`), any other fixed
    /// joint has no channel. Angles come from [`decompose_rotation_with`], each frame continuing
    /// from the previous one, so tracks are continuous (Euler angles near gimbal lock are
    /// split as documented there).
    ///
    /// The frame time is the clip's mean frame interval; errors if an interval deviates from it
    /// by more than `options.frame_time_tolerance`.
    pub fn from_clip(clip: &Clip, options: &BvhExportOptions) -> Result<BvhClip> {
        options.validate()?;
        let skeleton = clip.skeleton();
        let order = depth_first_order(skeleton);
        let frame_time = uniform_frame_time(clip, options)?;
        // Channel layout.
        let mut new_index = vec![0usize; skeleton.len()];
        for (k, &old) in order.iter().enumerate() {
            new_index[old] = k;
        }
        let (joints, plan): (Vec<BvhJoint>, Vec<JointPlan>) = order
            .iter()
            .map(|&old| plan_joint(clip, old, &new_index, options))
            .unzip();
        let channel_count: usize = joints.iter().map(|j| j.channels.len()).sum();
        let values = channel_values(clip, &plan, channel_count, options)?;
        BvhClip::new(
            clip.name(),
            joints,
            frame_time,
            clip.frame_count(),
            values,
            clip.up_axis(),
        )
    }
}

/// What one BVH joint writes per frame.
struct JointPlan {
    /// The joint's index in the clip's skeleton.
    old: usize,
    /// Number of position channels (0 or 3).
    positions: usize,
    /// The axes of its rotation channels, in channel order.
    axes: Vec<Vector3<f64>>,
}

/// The BVH joint for skeleton joint `old` (parent renumbered by `new_index`) with its channels,
/// and what it writes per frame.
fn plan_joint(
    clip: &Clip,
    old: usize,
    new_index: &[usize],
    options: &BvhExportOptions,
) -> (BvhJoint, JointPlan) {
    let skeleton = clip.skeleton();
    let sj = &skeleton.joints()[old];
    let is_root = sj.parent.is_none();
    let translates = !is_root
        && clip.frames().iter().any(|p| {
            p.translations
                .get(old)
                .is_some_and(|t| *t != Vector3::zeros())
        });
    let has_children = skeleton.children(old).next().is_some();
    let mut channels = Vec::new();
    if is_root || translates {
        channels.extend([
            BvhChannel::Xposition,
            BvhChannel::Yposition,
            BvhChannel::Zposition,
        ]);
    }
    let rotation_channels = rotation_channels(sj.kind, options);
    let axes: Vec<Vector3<f64>> = rotation_channels.iter().map(|c| c.axis()).collect();
    channels.extend(rotation_channels);
    let end_site = !is_root && !has_children && channels.is_empty();
    let joint = BvhJoint {
        name: sj.name.clone(),
        parent: sj.parent.and_then(|p| new_index.get(p).copied()),
        offset: sj.offset,
        channels,
        end_site,
    };
    let positions = if is_root || translates { 3 } else { 0 };
    (
        joint,
        JointPlan {
            old,
            positions,
            axes,
        },
    )
}

/// The rotation channels of a joint of kind `kind`: three in `options.rotation_order`, one for
/// a hinge about a coordinate axis, none for a fixed joint.
fn rotation_channels(kind: JointKind, options: &BvhExportOptions) -> Vec<BvhChannel> {
    match kind {
        JointKind::Root | JointKind::Spherical => options.rotation_order.channels().to_vec(),
        JointKind::Hinge { axis } => {
            let aligned = [
                BvhChannel::Xrotation,
                BvhChannel::Yrotation,
                BvhChannel::Zrotation,
            ]
            .into_iter()
            .find(|c| c.axis().dot(&axis).abs() >= 1.0 - options.axis_alignment_tolerance);
            match aligned {
                Some(c) => vec![c],
                None => options.rotation_order.channels().to_vec(),
            }
        }
        JointKind::Fixed => Vec::new(),
    }
}

/// The channel values of every frame (positions in the clip's units, angles \[rad\]), each
/// frame's angles decomposed nearest to the previous frame's.
fn channel_values(
    clip: &Clip,
    plan: &[JointPlan],
    channel_count: usize,
    options: &BvhExportOptions,
) -> Result<Vec<f64>> {
    let skeleton = clip.skeleton();
    let mut values: Vec<f64> = Vec::with_capacity(channel_count * clip.frame_count());
    let mut angles = [0.0; 3];
    for (f, pose) in clip.frames().iter().enumerate() {
        let frame_start = values.len();
        for JointPlan {
            old,
            positions,
            axes,
        } in plan
        {
            let is_root = skeleton.joints()[*old].parent.is_none();
            if *positions > 0 {
                let t = if is_root {
                    pose.root_position - skeleton.joints()[*old].offset
                } else {
                    pose.translations.get(*old).copied().unwrap_or_default()
                };
                values.extend(t.iter());
            }
            if axes.is_empty() {
                continue;
            }
            let q = if is_root {
                pose.root_orientation
            } else {
                pose.rotations.get(*old).copied().unwrap_or_default()
            };
            let k = axes.len();
            let here = values.len() - frame_start;
            let previous: Option<Vec<f64>> = (f > 0).then(|| {
                let start = frame_start - channel_count + here;
                values
                    .get(start..start + k)
                    .map(|s| s.to_vec())
                    .unwrap_or_default()
            });
            let out = angles.get_mut(..k).unwrap_or(&mut []);
            decompose_rotation_with(&q, axes, previous.as_deref(), &options.decompose, out)?;
            values.extend(out.iter());
        }
    }
    Ok(values)
}

/// Joint indices in depth-first order from the root, children in index order.
fn depth_first_order(skeleton: &Skeleton) -> Vec<usize> {
    let mut order = Vec::with_capacity(skeleton.len());
    let mut stack = vec![0usize];
    while let Some(j) = stack.pop() {
        order.push(j);
        let children: Vec<usize> = skeleton.children(j).collect();
        stack.extend(children.into_iter().rev());
    }
    order
}

fn uniform_frame_time(clip: &Clip, options: &BvhExportOptions) -> Result<f64> {
    let times = clip.times();
    if times.len() < 2 {
        return Ok(options.single_frame_time);
    }
    let mean = clip.duration() / (times.len() - 1) as f64;
    for (i, w) in times.windows(2).enumerate() {
        let dt = w[1] - w[0];
        if (dt - mean).abs() > options.frame_time_tolerance {
            return Err(Error::InvalidSetting {
                name: "clip frame times".to_string(),
                value: format!("interval {i} → {} is {dt} s", i + 1),
                expected: format!(
                    "uniform frame times (mean {mean} s, tolerance {} s); resample the clip first",
                    options.frame_time_tolerance
                ),
            });
        }
    }
    Ok(mean)
}
