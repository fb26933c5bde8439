//! Reading a [`Robot`] from URDF text.

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use super::joint::{JointKind, JointLimit};
use super::robot::{JointSpec, Link, ModelOptions, Robot, RobotBuilder};
use crate::error::{Error, Result};

fn pose(p: &urdf_rs::Pose) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
        // URDF rpy: R = Rz(yaw) · Ry(pitch) · Rx(roll), which is nalgebra's convention.
        UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
    )
}

/// Turns a parsed URDF into a builder (links, joints; no model options applied yet).
fn builder_from_urdf(u: &urdf_rs::Robot) -> Result<RobotBuilder> {
    let mut b = RobotBuilder::new(u.name.clone());
    for l in &u.links {
        let origin = pose(&l.inertial.origin);
        let i = &l.inertial.inertia;
        let inertia_local = Matrix3::new(
            i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz,
        );
        let r = origin.rotation.to_rotation_matrix();
        b = b.link(Link {
            name: l.name.clone(),
            mass: l.inertial.mass.value,
            com: origin.translation.vector,
            inertia: r.matrix() * inertia_local * r.matrix().transpose(),
        });
    }
    for j in &u.joints {
        let axis_raw = Vector3::new(j.axis.xyz[0], j.axis.xyz[1], j.axis.xyz[2]);
        let axis = || -> Result<Unit<Vector3<f64>>> {
            crate::error::check_all_finite(
                &format!("axis of joint `{}`", j.name),
                axis_raw.as_slice(),
            )?;
            Unit::try_new(axis_raw, f64::EPSILON).ok_or_else(|| Error::Urdf {
                message: format!("joint `{}` has a zero axis", j.name),
            })
        };
        let l = &j.limit;
        // A velocity of 0 is what URDF parsers give for a missing value: read it as "none".
        let velocity = if l.velocity > 0.0 {
            l.velocity
        } else {
            f64::INFINITY
        };
        let (kind, lower, upper) = match j.joint_type {
            urdf_rs::JointType::Revolute => (JointKind::Revolute { axis: axis()? }, l.lower, l.upper),
            urdf_rs::JointType::Continuous => (
                JointKind::Revolute { axis: axis()? },
                f64::NEG_INFINITY,
                f64::INFINITY,
            ),
            urdf_rs::JointType::Prismatic => (JointKind::Prismatic { axis: axis()? }, l.lower, l.upper),
            urdf_rs::JointType::Fixed => (JointKind::Fixed, f64::NEG_INFINITY, f64::INFINITY),
            ref other => {
                return Err(Error::Urdf {
                    message: format!(
                        "joint `{}` has type {other:?}, which iktc does not support (expected revolute, continuous, prismatic or fixed; a floating root is chosen with ModelOptions::base)",
                        j.name
                    ),
                })
            }
        };
        b = b.joint(JointSpec {
            name: j.name.clone(),
            parent: j.parent.link.clone(),
            child: j.child.link.clone(),
            origin: pose(&j.origin),
            kind,
            limit: JointLimit {
                lower,
                upper,
                velocity,
                acceleration: if l.acceleration > 0.0 {
                    l.acceleration
                } else {
                    f64::INFINITY
                },
                effort: if l.effort >= 0.0 {
                    l.effort
                } else {
                    f64::INFINITY
                },
            },
            mimic: j.mimic.as_ref().map(|m| {
                (
                    m.joint.clone(),
                    m.multiplier.unwrap_or(1.0),
                    m.offset.unwrap_or(0.0),
                )
            }),
        });
    }
    Ok(b)
}

impl Robot {
    /// Reads a robot from URDF text (revolute, continuous, prismatic and fixed joints).
    ///
    /// A malformed document, an unsupported joint type, an inconsistent tree or a bad number is
    /// an [`Error`]; see [`RobotBuilder::build`].
    pub fn from_urdf_str(text: &str, options: &ModelOptions) -> Result<Robot> {
        // The XML parser rejects a trailing NUL, which some exported files carry.
        let text = text.trim_end_matches('\0');
        let u = urdf_rs::read_from_string(text).map_err(|e| Error::Urdf {
            message: format!("cannot parse the URDF: {e}"),
        })?;
        builder_from_urdf(&u)?.build(options)
    }

    /// Reads a robot from a URDF file.
    pub fn from_urdf_file(path: &std::path::Path, options: &ModelOptions) -> Result<Robot> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::Urdf {
            message: format!("cannot read {}: {e}", path.display()),
        })?;
        Self::from_urdf_str(&text, options)
    }
}
