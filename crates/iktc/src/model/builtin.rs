//! Built-in robots: the planar 3R arm of the paper's Section 3.3, JVRC-1 and the Unitree G1.
//!
//! The humanoids' URDFs live in the crate's `data/robots/` with their notices
//! (`data/NOTICE.md`); their robot profiles (feet, pelvis, posture, locks) are in
//! [`crate::profile`].

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

use super::joint::{JointKind, JointLimit};
#[cfg(feature = "urdf")]
use super::robot::BaseKind;
use super::robot::{JointSpec, Link, ModelOptions, Robot, RobotBuilder};
use crate::error::{Error, Result};

/// The JVRC-1 URDF (AIST; BSD 2-Clause, see the crate's `data/NOTICE.md`), embedded.
#[cfg(feature = "urdf")]
pub const JVRC1_URDF: &str = include_str!("../../data/robots/jvrc1/jvrc1.urdf");

/// The Unitree G1 URDF, 29 joints (`g1_29dof_rev_1_0.urdf`, Unitree Robotics; BSD 3-Clause,
/// see the crate's `data/robots/g1/LICENSE` and `data/NOTICE.md`), embedded. Its visual
/// geometry references meshes that are not shipped: loading reads only the kinematics and the
/// inertials.
#[cfg(feature = "urdf")]
pub const G1_URDF: &str = include_str!("../../data/robots/g1/g1_29dof_rev_1_0.urdf");

/// The Unitree G1 MuJoCo model, 29 joints (`g1_29dof_rev_1_0.xml`, Unitree Robotics; BSD
/// 3-Clause, see the crate's `data/robots/g1/LICENSE` and `data/NOTICE.md`), embedded: the
/// same robot as [`G1_URDF`], with the feet's contact spheres, joint force ranges and
/// actuators of MuJoCo. Its mesh geoms name files that are not shipped (every body has its
/// own inertial, so a simulation may drop them).
#[cfg(feature = "mjcf")]
pub const G1_MJCF: &str = include_str!("../../data/robots/g1/g1_29dof_rev_1_0.xml");

/// The names accepted by [`builtin_robot`].
#[cfg(feature = "urdf")]
pub const BUILTIN_ROBOTS: &[&str] = &["planar3r", "jvrc1", "g1"];
/// The names accepted by [`builtin_robot`].
#[cfg(not(feature = "urdf"))]
pub const BUILTIN_ROBOTS: &[&str] = &["planar3r"];

/// The finger joints of JVRC-1, locked at 0 rad by [`jvrc1`].
#[cfg(feature = "urdf")]
pub const JVRC1_FINGERS: &[&str] = &[
    "R_UTHUMB",
    "R_LTHUMB",
    "R_UINDEX",
    "R_LINDEX",
    "R_ULITTLE",
    "R_LLITTLE",
    "L_UTHUMB",
    "L_LTHUMB",
    "L_UINDEX",
    "L_LINDEX",
    "L_ULITTLE",
    "L_LLITTLE",
];

/// The planar 3R arm of Section 3.3: three revolute joints about z, unit links along x, joint
/// ranges q1 ∈ \[60°, 180°\], q2, q3 ∈ \[−120°, 120°\], 180°/s and 1800°/s² for every joint. Each
/// link has 1 kg at its middle. Frame `tip` is the end of the third link.
pub fn planar3r() -> Robot {
    let deg = std::f64::consts::PI / 180.0;
    let ranges = [(60.0, 180.0), (-120.0, 120.0), (-120.0, 120.0)];
    let mut b = RobotBuilder::new("planar3r").link(Link::massless("base"));
    for i in 1..=3 {
        b = b.link(Link {
            name: format!("link{i}"),
            mass: 1.0,
            com: Vector3::new(0.5, 0.0, 0.0),
            inertia: Matrix3::from_diagonal(&Vector3::new(0.0, 1.0 / 12.0, 1.0 / 12.0)),
        });
        let (lo, hi) = ranges[i - 1];
        b = b.joint(JointSpec {
            name: format!("q{i}"),
            parent: if i == 1 {
                "base".into()
            } else {
                format!("link{}", i - 1)
            },
            child: format!("link{i}"),
            origin: Isometry3::from_parts(
                Translation3::new(if i == 1 { 0.0 } else { 1.0 }, 0.0, 0.0),
                UnitQuaternion::identity(),
            ),
            kind: JointKind::Revolute {
                axis: Vector3::z_axis(),
            },
            limit: JointLimit {
                lower: lo * deg,
                upper: hi * deg,
                velocity: 180.0 * deg,
                acceleration: 1800.0 * deg,
                jerk: f64::INFINITY,
                effort: f64::INFINITY,
            },
            mimic: None,
        });
    }
    b = b.frame("tip", "link3", Isometry3::translation(1.0, 0.0, 0.0));
    // Every number above is finite and every name unique: building cannot fail.
    match b.build(&ModelOptions::default()) {
        Ok(r) => r,
        Err(e) => unreachable!("the built-in planar 3R model is valid: {e}"),
    }
}

/// JVRC-1 with a floating base and its fingers locked at 0 rad: 6 + 32 = 38 degrees of
/// freedom. Extra options (acceleration limits, more locked joints) come from `options`; its
/// `base` is overridden to floating.
#[cfg(feature = "urdf")]
pub fn jvrc1(options: &ModelOptions) -> Result<Robot> {
    let mut o = options.clone();
    o.base = BaseKind::Floating;
    for f in JVRC1_FINGERS {
        if !o.locked.iter().any(|(n, _)| n == f) {
            o.locked.push((f.to_string(), 0.0));
        }
    }
    Robot::from_urdf_str(JVRC1_URDF, &o)
}

/// The Unitree G1 (29 joints) with a floating base: 6 + 29 = 35 degrees of freedom. Extra
/// options come from `options`; its `base` is overridden to floating.
#[cfg(feature = "urdf")]
pub fn g1(options: &ModelOptions) -> Result<Robot> {
    let mut o = options.clone();
    o.base = BaseKind::Floating;
    Robot::from_urdf_str(G1_URDF, &o)
}

/// A built-in robot by name (`planar3r`, `jvrc1`, `g1`) with default options.
pub fn builtin_robot(name: &str) -> Result<Robot> {
    match name {
        "planar3r" => Ok(planar3r()),
        #[cfg(feature = "urdf")]
        "jvrc1" => jvrc1(&ModelOptions::default()),
        #[cfg(feature = "urdf")]
        "g1" => g1(&ModelOptions::default()),
        _ => Err(Error::UnknownName {
            kind: "built-in robot",
            name: name.into(),
            valid: BUILTIN_ROBOTS.iter().map(|s| s.to_string()).collect(),
        }),
    }
}
