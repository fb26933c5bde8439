//! Built-in robots: JVRC-1 and the Unitree G1 (and, from the core, the planar 3R arm of the
//! paper's Section 3.3).
//!
//! The humanoids' URDFs live in the crate's `data/robots/` with their notices
//! (`data/NOTICE.md`); their robot profiles (feet, pelvis, posture, locks) are in
//! [`crate::profile`].

use super::Robot;
#[cfg(feature = "urdf")]
use super::{BaseKind, ModelOptions, RobotFiles};
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
        "planar3r" => Ok(super::planar3r()),
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
