//! Joints of a kinematic tree.

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

/// How a joint moves its child link relative to its parent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointKind {
    /// Rotation about a unit axis (in the joint frame) by q \[rad\]. URDF `revolute` and
    /// `continuous` (a continuous joint has an infinite position range).
    Revolute {
        /// Unit rotation axis in the joint frame.
        axis: Unit<Vector3<f64>>,
    },
    /// Translation along a unit axis (in the joint frame) by q \[m\].
    Prismatic {
        /// Unit translation axis in the joint frame.
        axis: Unit<Vector3<f64>>,
    },
    /// No motion.
    Fixed,
}

impl JointKind {
    /// The motion of the joint for coordinate `q` \[rad\] or \[m\], as a transform from the joint
    /// frame to the child link frame.
    #[inline]
    pub fn transform(&self, q: f64) -> Isometry3<f64> {
        match self {
            JointKind::Revolute { axis } => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(axis, q),
            ),
            JointKind::Prismatic { axis } => Isometry3::from_parts(
                Translation3::from(axis.into_inner() * q),
                UnitQuaternion::identity(),
            ),
            JointKind::Fixed => Isometry3::identity(),
        }
    }

    /// Short name for printing: "revolute", "prismatic", "fixed".
    pub fn name(&self) -> &'static str {
        match self {
            JointKind::Revolute { .. } => "revolute",
            JointKind::Prismatic { .. } => "prismatic",
            JointKind::Fixed => "fixed",
        }
    }
}

/// Limits of one joint, in the joint's own unit (\[rad\] for revolute, \[m\] for prismatic).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct JointLimit {
    /// Lowest position \[rad\] or \[m\]; −∞ when unbounded (continuous joints).
    pub lower: f64,
    /// Highest position \[rad\] or \[m\]; +∞ when unbounded.
    pub upper: f64,
    /// Largest speed \[rad/s\] or \[m/s\]; +∞ when unbounded.
    pub velocity: f64,
    /// Largest acceleration \[rad/s²\] or \[m/s²\]; URDF has none: it comes from
    /// [`ModelOptions`](crate::model::ModelOptions).
    pub acceleration: f64,
    /// Largest jerk (rate of change of the acceleration) \[rad/s³\] or \[m/s³\]; URDF has
    /// none: it comes from [`ModelOptions`](crate::model::ModelOptions), +∞ by default.
    pub jerk: f64,
    /// Largest effort \[N·m\] or \[N\]; informative only (the IK is kinematic).
    pub effort: f64,
}

impl JointLimit {
    /// No limit at all.
    pub const UNBOUNDED: JointLimit = JointLimit {
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
        velocity: f64::INFINITY,
        acceleration: f64::INFINITY,
        jerk: f64::INFINITY,
        effort: f64::INFINITY,
    };
}

/// What a joint does in the model once built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointRole {
    /// The joint has its own coordinate: index into the joint part of q and q̇.
    Active {
        /// Index of the joint's coordinate among the active joints (0-based).
        index: usize,
    },
    /// The joint is held at a value \[rad\] or \[m\] and drops out of q.
    Locked {
        /// The value it is held at.
        value: f64,
    },
    /// The joint follows another (URDF `<mimic>`): q = multiplier · q_master + offset.
    Mimic {
        /// Index of the master's coordinate among the active joints.
        master: usize,
        /// Multiplier of the master's coordinate.
        multiplier: f64,
        /// Offset \[rad\] or \[m\].
        offset: f64,
    },
    /// A fixed joint.
    Fixed,
}

/// One joint of the tree: it connects `parent` to `child` through `origin` then its motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// The joint's name.
    pub name: String,
    /// Index of the parent link.
    pub parent: usize,
    /// Index of the child link.
    pub child: usize,
    /// Pose of the joint frame in the parent link frame.
    pub origin: Isometry3<f64>,
    /// How the joint moves.
    pub kind: JointKind,
    /// Its limits.
    pub limit: JointLimit,
    /// Its role in the built model.
    pub role: JointRole,
}
