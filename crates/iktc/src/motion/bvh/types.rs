//! The data of a BVH file: channels, joints, the clip of channel values, and options.

use std::collections::HashSet;

use nalgebra::Vector3;

use crate::error::{Error, Result};
use crate::motion::UpAxis;
use crate::resources::ReadLimits;

/// One BVH motion channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BvhChannel {
    /// Translation along the parent frame's x axis \[m after reading\].
    Xposition,
    /// Translation along y.
    Yposition,
    /// Translation along z.
    Zposition,
    /// Rotation about x \[rad after reading, degrees in the file\].
    Xrotation,
    /// Rotation about y.
    Yrotation,
    /// Rotation about z.
    Zrotation,
}

impl BvhChannel {
    /// All six channels.
    pub const ALL: [BvhChannel; 6] = [
        BvhChannel::Xposition,
        BvhChannel::Yposition,
        BvhChannel::Zposition,
        BvhChannel::Xrotation,
        BvhChannel::Yrotation,
        BvhChannel::Zrotation,
    ];

    /// The channel's name in a BVH file (`Xposition`, …, `Zrotation`).
    pub fn name(self) -> &'static str {
        match self {
            BvhChannel::Xposition => "Xposition",
            BvhChannel::Yposition => "Yposition",
            BvhChannel::Zposition => "Zposition",
            BvhChannel::Xrotation => "Xrotation",
            BvhChannel::Yrotation => "Yrotation",
            BvhChannel::Zrotation => "Zrotation",
        }
    }

    /// The channel called `name` (ASCII case-insensitive), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(name))
    }

    /// Whether this is a rotation channel.
    pub fn is_rotation(self) -> bool {
        matches!(
            self,
            BvhChannel::Xrotation | BvhChannel::Yrotation | BvhChannel::Zrotation
        )
    }

    /// The unit axis the channel translates along or rotates about.
    pub fn axis(self) -> Vector3<f64> {
        match self {
            BvhChannel::Xposition | BvhChannel::Xrotation => Vector3::x(),
            BvhChannel::Yposition | BvhChannel::Yrotation => Vector3::y(),
            BvhChannel::Zposition | BvhChannel::Zrotation => Vector3::z(),
        }
    }
}

/// The length unit of a BVH file's offsets and position channels.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum LengthUnit {
    /// 1 m per unit.
    Metres,
    /// 0.01 m per unit (the most common BVH unit).
    #[default]
    Centimetres,
    /// 0.001 m per unit.
    Millimetres,
    /// 0.0254 m per unit.
    Inches,
    /// Any scale given by the caller.
    Custom {
        /// Metres per file unit \[m/unit\], finite and > 0.
        metres_per_unit: f64,
    },
}

impl LengthUnit {
    /// Metres per file unit \[m/unit\].
    pub fn metres_per_unit(self) -> f64 {
        match self {
            LengthUnit::Metres => 1.0,
            LengthUnit::Centimetres => 0.01,
            LengthUnit::Millimetres => 0.001,
            LengthUnit::Inches => 0.0254,
            LengthUnit::Custom { metres_per_unit } => metres_per_unit,
        }
    }

    /// Checks that the scale is finite and > 0.
    pub fn validate(self) -> Result<()> {
        let s = self.metres_per_unit();
        if s.is_finite() && s > 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidSetting {
                name: "length_unit.metres_per_unit".to_string(),
                value: s.to_string(),
                expected: "a finite scale > 0 [m/unit]".to_string(),
            })
        }
    }
}

/// One joint (or end site) of a BVH hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub struct BvhJoint {
    /// The joint's name; end sites, which have none in the file, are called `<parent>_end`.
    pub name: String,
    /// Index of the parent joint, `None` for the root.
    pub parent: Option<usize>,
    /// `OFFSET` \[m\]: the joint's origin in its parent's frame.
    pub offset: Vector3<f64>,
    /// `CHANNELS`, in file order (empty for end sites).
    pub channels: Vec<BvhChannel>,
    /// Whether this is an `End Site` (no name, no channels, no children in the file).
    pub end_site: bool,
}

/// The content of a BVH file in SI units: hierarchy, frame time and channel values.
///
/// `values` is frame-major: frame `f`, channel `c` (channels numbered through the joints in index
/// order, each joint's in its `CHANNELS` order) is `values[f · channel_count + c]`. Positions are
/// in metres, rotations in radians, and every rotation channel is *unwrapped*: consecutive values
/// differ by less than π (the raw angle tracks, ready to be differentiated).
///
/// Invariants (checked by [`BvhClip::new`]): joints in depth-first (file) order with joint 0 the
/// root; unique non-empty names; end sites are leaves without channels; no joint lists a channel
/// twice; at least one channel and one frame; a finite frame time > 0; finite values.
#[derive(Debug, Clone, PartialEq)]
pub struct BvhClip {
    name: String,
    joints: Vec<BvhJoint>,
    channel_starts: Vec<usize>,
    frame_time: f64,
    frame_count: usize,
    values: Vec<f64>,
    up_axis: UpAxis,
}

fn hierarchy_error(message: String) -> Error {
    Error::InvalidSetting {
        name: "BVH hierarchy".to_string(),
        value: message,
        expected: "joints in depth-first order rooted at joint 0, unique names, leaf end sites"
            .to_string(),
    }
}

/// Checks the joints' names and every joint ([`check_joint`]); returns each joint's first
/// channel index and the channel count.
fn channel_layout(joints: &[BvhJoint]) -> Result<(Vec<usize>, usize)> {
    let mut names = HashSet::new();
    let mut channel_starts = Vec::with_capacity(joints.len());
    let mut channel_count = 0usize;
    for (i, joint) in joints.iter().enumerate() {
        if joint.name.is_empty() || !names.insert(joint.name.as_str()) {
            return Err(hierarchy_error(format!(
                "joint {i} has an empty or repeated name `{}`",
                joint.name
            )));
        }
        check_joint(joints, i)?;
        channel_starts.push(channel_count);
        channel_count += joint.channels.len();
    }
    Ok((channel_starts, channel_count))
}

/// Checks joint `i`: the root first, a parent among the previous joint and its ancestors that
/// is not an end site, no channels on an end site, no channel twice, a finite offset.
fn check_joint(joints: &[BvhJoint], i: usize) -> Result<()> {
    let joint = &joints[i];
    match (i, joint.parent) {
        (0, None) if !joint.end_site => {}
        (0, _) => return Err(hierarchy_error("joint 0 must be the root".to_string())),
        (_, Some(p)) if p < i && is_on_path(joints, i - 1, p) => {
            if joints.get(p).is_some_and(|j| j.end_site) {
                return Err(hierarchy_error(format!(
                    "joint `{}` has an end site as parent",
                    joint.name
                )));
            }
        }
        _ => {
            return Err(hierarchy_error(format!(
                "joint {i} (`{}`): its parent must be the previous joint or one of its ancestors",
                joint.name
            )))
        }
    }
    if joint.end_site && !joint.channels.is_empty() {
        return Err(hierarchy_error(format!(
            "end site `{}` has channels",
            joint.name
        )));
    }
    let mut seen = HashSet::new();
    if let Some(c) = joint.channels.iter().find(|c| !seen.insert(**c)) {
        return Err(hierarchy_error(format!(
            "joint `{}` lists channel {} twice",
            joint.name,
            c.name()
        )));
    }
    if joint.offset.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: format!("offset of BVH joint `{}`", joint.name),
            value: f64::NAN,
        });
    }
    Ok(())
}

impl BvhClip {
    /// Checks and assembles a clip (see the invariants in the type's documentation).
    pub fn new(
        name: impl Into<String>,
        joints: Vec<BvhJoint>,
        frame_time: f64,
        frame_count: usize,
        values: Vec<f64>,
        up_axis: UpAxis,
    ) -> Result<Self> {
        if joints.is_empty() {
            return Err(hierarchy_error("no joint".to_string()));
        }
        let (channel_starts, channel_count) = channel_layout(&joints)?;
        if channel_count == 0 || frame_count == 0 {
            return Err(Error::InsufficientData {
                what: "BVH clip".to_string(),
                message: format!(
                    "{channel_count} channels and {frame_count} frames; at least one of each is needed"
                ),
            });
        }
        crate::error::check_finite(|| "BVH frame time".to_string(), frame_time)?;
        if frame_time <= 0.0 {
            return Err(Error::InvalidSetting {
                name: "frame_time".to_string(),
                value: frame_time.to_string(),
                expected: "a frame time > 0 [s]".to_string(),
            });
        }
        let expected = channel_count.saturating_mul(frame_count);
        crate::error::check_dim("BVH channel values", expected, values.len())?;
        crate::error::check_all_finite("BVH channel values", &values)?;
        Ok(Self {
            name: name.into(),
            joints,
            channel_starts,
            frame_time,
            frame_count,
            values,
            up_axis,
        })
    }

    /// The clip's name (the source it was read from).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The joints and end sites in file order.
    pub fn joints(&self) -> &[BvhJoint] {
        &self.joints
    }

    /// `Frame Time` \[s\].
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Number of frames (at least 1).
    pub fn frame_count(&self) -> usize {
        self.frame_count
    }

    /// Duration \[s\]: `(frame_count − 1) · frame_time`.
    pub fn duration(&self) -> f64 {
        (self.frame_count - 1) as f64 * self.frame_time
    }

    /// Which axis is up in the clip's world (given by the caller when reading).
    pub fn up_axis(&self) -> UpAxis {
        self.up_axis
    }

    /// Total number of channels.
    pub fn channel_count(&self) -> usize {
        self.values.len() / self.frame_count
    }

    /// All values, frame-major \[m, rad\].
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The channel values of frame `index` \[m, rad\].
    pub fn frame(&self, index: usize) -> Option<&[f64]> {
        let c = self.channel_count();
        let start = index.checked_mul(c)?;
        self.values.get(start..start.checked_add(c)?)
    }

    /// Index of the first channel of joint `joint` in a frame's values.
    pub fn channel_start(&self, joint: usize) -> Option<usize> {
        self.channel_starts.get(joint).copied()
    }

    /// The track (one value per frame) of `channel` of joint `joint` \[m or rad, unwrapped\], or
    /// `None` if the joint does not have that channel.
    pub fn track(&self, joint: usize, channel: BvhChannel) -> Option<Vec<f64>> {
        let j = self.joints.get(joint)?;
        let k = j.channels.iter().position(|c| *c == channel)?;
        let c = self.channel_starts.get(joint)? + k;
        let n = self.channel_count();
        Some(self.values.iter().skip(c).step_by(n).copied().collect())
    }

    /// Index of the joint called `name`, or [`Error::UnknownName`].
    pub fn joint_index(&self, name: &str) -> Result<usize> {
        self.joints
            .iter()
            .position(|j| j.name == name)
            .ok_or_else(|| Error::UnknownName {
                kind: "BVH joint",
                name: name.to_string(),
                valid: self.joints.iter().map(|j| j.name.clone()).collect(),
            })
    }
}

/// Whether `ancestor` is `joint` or one of its ancestors.
fn is_on_path(joints: &[BvhJoint], joint: usize, ancestor: usize) -> bool {
    let mut j = Some(joint);
    while let Some(i) = j {
        if i == ancestor {
            return true;
        }
        j = joints.get(i).and_then(|x| x.parent).filter(|p| *p < i);
    }
    false
}

/// Options of [`read_bvh`](super::read_bvh).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BvhReadOptions {
    /// Unit of the file's offsets and position channels (default centimetres).
    pub length_unit: LengthUnit,
    /// Which axis is up in the file's world (default Y).
    pub up_axis: UpAxis,
    /// Most frames and longest duration accepted, checked on the header before the frames are
    /// read.
    pub limits: ReadLimits,
}

/// Options of [`write_bvh`](super::write_bvh).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BvhWriteOptions {
    /// Unit of the written offsets and position channels (default centimetres).
    pub length_unit: LengthUnit,
    /// Digits after the decimal point; `None` (default) writes the shortest text that reads back
    /// to the same `f64`, so only the unit conversion rounds.
    pub decimals: Option<usize>,
}

/// The order of the three rotation channels written for a ball joint: `Zxy` writes
/// `Zrotation Xrotation Yrotation`, i.e. `R = Rz · Rx · Ry`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RotationOrder {
    /// `Xrotation Yrotation Zrotation`.
    Xyz,
    /// `Xrotation Zrotation Yrotation`.
    Xzy,
    /// `Yrotation Xrotation Zrotation`.
    Yxz,
    /// `Yrotation Zrotation Xrotation`.
    Yzx,
    /// `Zrotation Xrotation Yrotation` (the most common BVH order).
    #[default]
    Zxy,
    /// `Zrotation Yrotation Xrotation`.
    Zyx,
}

impl RotationOrder {
    /// The three rotation channels in order.
    pub fn channels(self) -> [BvhChannel; 3] {
        use BvhChannel::{Xrotation as X, Yrotation as Y, Zrotation as Z};
        match self {
            RotationOrder::Xyz => [X, Y, Z],
            RotationOrder::Xzy => [X, Z, Y],
            RotationOrder::Yxz => [Y, X, Z],
            RotationOrder::Yzx => [Y, Z, X],
            RotationOrder::Zxy => [Z, X, Y],
            RotationOrder::Zyx => [Z, Y, X],
        }
    }
}

/// Options of [`BvhClip::from_clip`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BvhExportOptions {
    /// Euler order of ball joints and of the root (default ZXY).
    pub rotation_order: RotationOrder,
    /// Largest deviation \[s\] of a frame interval from the mean interval; BVH has one frame time,
    /// so a clip with less regular times is refused (resample it first). Default 1e-6 s.
    pub frame_time_tolerance: f64,
    /// Frame time written for a single-frame clip \[s\]. Default 1/30 s.
    pub single_frame_time: f64,
    /// A hinge whose axis is within this of a coordinate axis (`|a·e_k| ≥ 1 − tol`) \[–\] gets
    /// one rotation channel about that coordinate axis; otherwise three. Default 1e-9.
    pub axis_alignment_tolerance: f64,
    /// Settings of the Euler decomposition of every rotation.
    pub decompose: crate::motion::DecomposeSettings,
}

impl Default for BvhExportOptions {
    fn default() -> Self {
        Self {
            rotation_order: RotationOrder::Zxy,
            frame_time_tolerance: 1e-6,
            single_frame_time: 1.0 / 30.0,
            axis_alignment_tolerance: 1e-9,
            decompose: crate::motion::DecomposeSettings::default(),
        }
    }
}

impl BvhExportOptions {
    /// Checks that every value is finite and in range.
    pub fn validate(&self) -> Result<()> {
        let checks = [
            (
                "frame_time_tolerance",
                self.frame_time_tolerance,
                0.0,
                false,
            ),
            ("single_frame_time", self.single_frame_time, 0.0, true),
            (
                "axis_alignment_tolerance",
                self.axis_alignment_tolerance,
                0.0,
                false,
            ),
        ];
        for (name, value, low, strict) in checks {
            let ok = value.is_finite() && if strict { value > low } else { value >= low };
            if !ok {
                return Err(Error::InvalidSetting {
                    name: name.to_string(),
                    value: value.to_string(),
                    expected: format!("a finite number {} {low}", if strict { ">" } else { ">=" }),
                });
            }
        }
        self.decompose.validate()
    }
}
