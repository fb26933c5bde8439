//! The immutable robot model: links, joints, frames and the layout of q and q̇.

use nalgebra::{Isometry3, Matrix3, Vector3};

use super::joint::{Joint, JointKind, JointLimit};
use crate::error::{Error, Result};

/// A rigid link.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// The link's name.
    pub name: String,
    /// Mass \[kg\].
    pub mass: f64,
    /// Centre of mass in the link frame \[m\].
    pub com: Vector3<f64>,
    /// Inertia about the centre of mass, in link axes \[kg·m²\].
    pub inertia: Matrix3<f64>,
}

impl Link {
    /// A massless link.
    pub fn massless(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
        }
    }
}

/// How the root link is attached to the world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BaseKind {
    /// The root link is fixed at the world origin.
    Fixed,
    /// The root link is free: q starts with its position \[m\] and unit quaternion (x, y, z, w);
    /// q̇ starts with its body twist: linear velocity \[m/s\] then angular velocity \[rad/s\], both
    /// in the root link's own axes (Pinocchio's free-flyer convention).
    Floating,
}

/// A named frame rigidly attached to a link. Every link is also a frame of the same name.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// The frame's name.
    pub name: String,
    /// The link it is attached to.
    pub link: usize,
    /// Its pose in the link frame.
    pub offset: Isometry3<f64>,
}

/// What to do with URDF `<mimic>` joints whose master is not locked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MimicPolicy {
    /// The mimic joint follows its master (q = multiplier · q_master + offset): it has no
    /// coordinate of its own and its motion adds to its master's Jacobian column.
    #[default]
    Follow,
    /// A mimic joint with an unlocked master is an error.
    Reject,
}

/// Options that shape a model at construction.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelOptions {
    /// Fixed or floating root.
    pub base: BaseKind,
    /// Joints held at a value \[rad\] or \[m\]: they drop out of q. Locking a mimic master also
    /// locks its mimics.
    pub locked: Vec<(String, f64)>,
    /// Velocity limits \[rad/s\] or \[m/s\] by joint name, replacing the description's.
    pub velocity_limits: Vec<(String, f64)>,
    /// Velocity limit \[rad/s\] or \[m/s\] of the joints whose description gives none and
    /// `velocity_limits` does not name (MJCF gives none). Default +∞ (no limit).
    pub fallback_velocity: f64,
    /// Acceleration limits \[rad/s²\] or \[m/s²\] by joint name (URDF has none).
    pub acceleration_limits: Vec<(String, f64)>,
    /// Default acceleration limit as a multiple of the joint's velocity limit \[1/s\]: the joint
    /// reaches full speed from rest in 1/this seconds. Default 10 s⁻¹, the ratio of the paper's
    /// 3R arm (180°/s, 1800°/s²). Used for joints with no explicit acceleration limit.
    pub acceleration_per_velocity: f64,
    /// Acceleration limit \[rad/s²\] for joints that have neither an acceleration nor a velocity
    /// limit. Default +∞ (no limit).
    pub fallback_acceleration: f64,
    /// Jerk limits \[rad/s³\] or \[m/s³\] by joint name (URDF has none); see
    /// [`limit_jerk`](crate::limits::limit_jerk).
    pub jerk_limits: Vec<(String, f64)>,
    /// Default jerk limit as a multiple of the joint's acceleration limit \[1/s\]: the joint
    /// reaches its full acceleration from zero in 1/this seconds. Default +∞: no jerk limit
    /// for joints without an explicit one.
    pub jerk_per_acceleration: f64,
    /// What to do with mimic joints.
    pub mimic: MimicPolicy,
}

impl Default for ModelOptions {
    fn default() -> Self {
        Self {
            base: BaseKind::Fixed,
            locked: Vec::new(),
            velocity_limits: Vec::new(),
            fallback_velocity: f64::INFINITY,
            acceleration_limits: Vec::new(),
            acceleration_per_velocity: 10.0,
            fallback_acceleration: f64::INFINITY,
            jerk_limits: Vec::new(),
            jerk_per_acceleration: f64::INFINITY,
            mimic: MimicPolicy::Follow,
        }
    }
}

/// A joint as described before the model is built (URDF or code).
#[derive(Debug, Clone, PartialEq)]
pub struct JointSpec {
    /// Joint name.
    pub name: String,
    /// Parent link name.
    pub parent: String,
    /// Child link name.
    pub child: String,
    /// Pose of the joint frame in the parent link frame.
    pub origin: Isometry3<f64>,
    /// Motion type.
    pub kind: JointKind,
    /// Limits; the acceleration field may be +∞, then [`ModelOptions`] decides.
    pub limit: JointLimit,
    /// `<mimic>`: master joint name, multiplier, offset.
    pub mimic: Option<(String, f64, f64)>,
}

/// Collects links, joints and frames, then validates them into a [`Robot`].
#[derive(Debug, Clone, Default)]
pub struct RobotBuilder {
    pub(super) name: String,
    pub(super) links: Vec<Link>,
    pub(super) joints: Vec<JointSpec>,
    pub(super) frames: Vec<(String, String, Isometry3<f64>)>,
    pub(super) warnings: Vec<String>,
}

impl RobotBuilder {
    /// A new, empty description.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            ..Default::default()
        }
    }

    /// Adds a link.
    pub fn link(mut self, link: Link) -> Self {
        self.links.push(link);
        self
    }

    /// Adds a joint.
    pub fn joint(mut self, joint: JointSpec) -> Self {
        self.joints.push(joint);
        self
    }

    /// Adds a named frame attached to `link` with pose `offset` in the link frame.
    pub fn frame(
        mut self,
        name: impl Into<String>,
        link: impl Into<String>,
        offset: Isometry3<f64>,
    ) -> Self {
        self.frames.push((name.into(), link.into(), offset));
        self
    }

    /// Records a warning about the description, kept in the model ([`Robot::warnings`]).
    pub fn warn(&mut self, message: impl Into<String>) {
        self.warnings.push(message.into());
    }

    /// Validates the description and builds the immutable model.
    ///
    /// Errors: duplicate or unknown names, a link with two parents, no single root, a cycle,
    /// a non-finite number, a limit with lower > upper or a non-positive speed, a zero axis,
    /// a locked joint that does not exist or is fixed, a joint locked outside its range
    /// ([`Error::StateOutsideLimits`]), a mimic that is rejected by the options, a magnitude
    /// beyond the plausibility bounds of [`plausible`](super::plausible) (a mass, length,
    /// inertia, speed or acceleration no robot has).
    pub fn build(self, options: &ModelOptions) -> Result<Robot> {
        super::build::robot(self, options)
    }
}

/// The immutable robot model.
///
/// Joints are stored in depth-first order from the root (children in the order given), so a
/// joint's parent link is always placed by an earlier joint. q = (base, active joints),
/// q̇ = (base twist, active joint rates); see [`BaseKind`] for the base part.
#[derive(Debug, Clone)]
pub struct Robot {
    pub(crate) name: String,
    pub(crate) base: BaseKind,
    pub(crate) links: Vec<Link>,
    pub(crate) joints: Vec<Joint>,
    pub(crate) root: usize,
    pub(crate) frames: Vec<Frame>,
    /// Joint indices of the active joints, in q order.
    pub(crate) active: Vec<usize>,
    /// For each joint: (velocity index, scale) of the coordinate that drives it, if any.
    pub(crate) drive: Vec<Option<(usize, f64)>>,
    /// For each link: the joint whose child it is (None for the root).
    pub(crate) parent_joint: Vec<Option<usize>>,
    pub(crate) total_mass: f64,
    pub(crate) warnings: Vec<String>,
}

impl Robot {
    /// The robot's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Fixed or floating base.
    pub fn base(&self) -> BaseKind {
        self.base
    }

    /// Number of configuration coordinates: 7 (position, quaternion) for a floating base plus
    /// one per active joint.
    pub fn nq(&self) -> usize {
        self.base_nq() + self.active.len()
    }

    /// Number of velocity coordinates (degrees of freedom): 6 for a floating base plus one per
    /// active joint.
    pub fn nv(&self) -> usize {
        self.base_nv() + self.active.len()
    }

    /// Configuration coordinates of the base: 7 or 0.
    pub fn base_nq(&self) -> usize {
        match self.base {
            BaseKind::Floating => 7,
            BaseKind::Fixed => 0,
        }
    }

    /// Velocity coordinates of the base: 6 or 0.
    pub fn base_nv(&self) -> usize {
        match self.base {
            BaseKind::Floating => 6,
            BaseKind::Fixed => 0,
        }
    }

    /// Number of active joints (joints with a coordinate of their own).
    pub fn n_active(&self) -> usize {
        self.active.len()
    }

    /// All links.
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// All joints, depth-first from the root.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// The active joints in q order.
    pub fn active_joints(&self) -> impl ExactSizeIterator<Item = &Joint> + '_ {
        self.active.iter().map(move |&j| &self.joints[j])
    }

    /// Index of the root link.
    pub fn root_link(&self) -> usize {
        self.root
    }

    /// All frames: first one per link (same names and order as [`Robot::links`]), then the
    /// extra frames.
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }

    /// Warnings about the description (e.g. a URDF `effort="0"`): accepted, but worth a word.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Total mass \[kg\].
    pub fn total_mass(&self) -> f64 {
        self.total_mass
    }

    /// The robot with a frame added: `name`, fixed to the frame `parent` (a link or a frame)
    /// with the pose `offset` in it (translation \[m\], rotation). For a point a URDF has no
    /// link at, e.g. the hand at the end of a forearm link. Errors: an unknown parent (the
    /// error lists the frames), a name a link or frame already has, a non-finite offset.
    pub fn with_frame(mut self, name: &str, parent: &str, offset: Isometry3<f64>) -> Result<Robot> {
        let p = self.frame_id(parent)?;
        super::build::finite_iso(&format!("offset of the frame `{name}`"), &offset)?;
        if self.frames.iter().any(|f| f.name == name) {
            return Err(Error::InvalidSetting {
                name: "frame name".into(),
                value: name.into(),
                expected: "a name no link or frame of the robot has".into(),
            });
        }
        let parent = &self.frames[p.0];
        let frame = Frame {
            name: name.into(),
            link: parent.link,
            offset: parent.offset * offset,
        };
        self.frames.push(frame);
        Ok(self)
    }

    /// The frame called `name`; the error lists the valid names.
    pub fn frame_id(&self, name: &str) -> Result<FrameId> {
        self.frames
            .iter()
            .position(|f| f.name == name)
            .map(FrameId)
            .ok_or_else(|| Error::UnknownName {
                kind: "frame",
                name: name.into(),
                valid: self.frames.iter().map(|f| f.name.clone()).collect(),
            })
    }

    /// Index among the active joints (the joint part of q and q̇) of the joint `name`.
    /// Locked, mimic and fixed joints are not active: the error says so and lists the valid
    /// names.
    pub fn active_joint_index(&self, name: &str) -> Result<usize> {
        match self.active_joints().position(|j| j.name == name) {
            Some(i) => Ok(i),
            None => Err(Error::UnknownName {
                kind: if self.joints.iter().any(|j| j.name == name) {
                    "active joint (this joint is fixed, locked or a mimic)"
                } else {
                    "joint"
                },
                name: name.into(),
                valid: self.active_joints().map(|j| j.name.clone()).collect(),
            }),
        }
    }

    /// Index in q̇ of the active joint `name`.
    pub fn joint_v_index(&self, name: &str) -> Result<usize> {
        Ok(self.base_nv() + self.active_joint_index(name)?)
    }

    /// Index in q of the active joint `name`.
    pub fn joint_q_index(&self, name: &str) -> Result<usize> {
        Ok(self.base_nq() + self.active_joint_index(name)?)
    }

    /// Per-velocity-coordinate limits, nv entries: unbounded for the base, then the limits of
    /// each active joint.
    pub fn dof_limits(&self) -> Vec<JointLimit> {
        let mut v = vec![JointLimit::UNBOUNDED; self.base_nv()];
        v.extend(self.active_joints().map(|j| j.limit));
        v
    }

    /// Names of the velocity coordinates: `base_vx, …, base_wz` then the active joints.
    pub fn dof_names(&self) -> Vec<String> {
        let mut v: Vec<String> = match self.base {
            BaseKind::Floating => [
                "base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz",
            ]
            .iter()
            .map(|s| s.to_string())
            .collect(),
            BaseKind::Fixed => Vec::new(),
        };
        v.extend(self.active_joints().map(|j| j.name.clone()));
        v
    }
}

/// Index of a frame in a [`Robot`], from [`Robot::frame_id`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FrameId(pub usize);
