//! Reading a [`Robot`] from URDF text.

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use std::collections::HashMap;

use super::urdf_check::{check_raw, unnamed_materials_named, RawJoint, RawUrdf};
use super::{JointKind, JointLimit};
use super::{JointSpec, Link, ModelOptions, Robot, RobotBuilder};
use crate::error::{Error, Result};
use crate::resources::ReadLimits;

/// A URDF `<origin>` as an isometry (translation `xyz` \[m\], rotation `rpy` \[rad\]).
pub(crate) fn pose(p: &urdf_rs::Pose) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
        // URDF rpy: R = Rz(yaw) · Ry(pitch) · Rx(roll), which is nalgebra's convention.
        UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
    )
}

/// Turns a parsed URDF into a builder (links, joints; no model options applied yet).
fn builder_from_urdf(u: &urdf_rs::Robot, raw: &HashMap<String, RawJoint>) -> Result<RobotBuilder> {
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
        let raw = raw.get(&j.name).cloned().unwrap_or_default();
        let movable = matches!(
            j.joint_type,
            urdf_rs::JointType::Revolute
                | urdf_rs::JointType::Prismatic
                | urdf_rs::JointType::Continuous
        );
        let l = if movable {
            checked_limit(j, &raw, &mut b)?
        } else {
            JointLimit::UNBOUNDED
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
            limit: JointLimit { lower, upper, ..l },
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

/// The units of a joint's position and velocity, for messages.
fn units(j: &urdf_rs::Joint) -> (&'static str, &'static str) {
    match j.joint_type {
        urdf_rs::JointType::Prismatic => ("m", "m/s"),
        _ => ("rad", "rad/s"),
    }
}

/// The checked limits of a revolute, continuous or prismatic joint (see
/// [`Robot::from_urdf_str_with`](super::RobotFiles::from_urdf_str_with)); warnings go to the builder.
fn checked_limit(j: &urdf_rs::Joint, raw: &RawJoint, b: &mut RobotBuilder) -> Result<JointLimit> {
    let continuous = matches!(j.joint_type, urdf_rs::JointType::Continuous);
    if raw.limit.is_none() && !continuous {
        return Err(Error::Urdf {
            message: format!(
                "joint `{}` ({:?}) has no <limit>; URDF requires one, with lower, upper, effort and velocity, for revolute and prismatic joints",
                j.name, j.joint_type
            ),
        });
    }
    let mut limit = JointLimit::UNBOUNDED;
    if !continuous {
        (limit.lower, limit.upper) = checked_range(j, raw)?;
    }
    if raw.limit.is_some() {
        given_rate_limits(j, raw, b, &mut limit)?;
    }
    Ok(limit)
}

/// The error of the `<limit>` attribute `attr` of joint `j`, its text as written (else
/// `value`), and what was `expected`.
fn bad_limit(
    j: &urdf_rs::Joint,
    raw: &RawJoint,
    attr: &str,
    value: f64,
    expected: String,
) -> Error {
    Error::Urdf {
        message: format!(
            "joint `{}`: <limit {attr}=\"{}\">: expected {expected}",
            j.name,
            raw.limit_attr(attr)
                .map_or_else(|| value.to_string(), str::to_string)
        ),
    }
}

/// The checked range (lower, upper) \[rad or m\] of a revolute or prismatic joint: finite,
/// lower < upper.
fn checked_range(j: &urdf_rs::Joint, raw: &RawJoint) -> Result<(f64, f64)> {
    let l = &j.limit;
    let (pos_unit, _) = units(j);
    for (attr, v) in [("lower", l.lower), ("upper", l.upper)] {
        if !v.is_finite() {
            return Err(bad_limit(
                j,
                raw,
                attr,
                v,
                format!("a finite position [{pos_unit}] (an unbounded revolute joint is type=\"continuous\")"),
            ));
        }
    }
    if l.lower > l.upper {
        return Err(Error::InvalidLimit {
            what: format!("joint `{}` (URDF <limit lower upper>)", j.name),
            lower: l.lower,
            upper: l.upper,
        });
    }
    if l.lower == l.upper {
        return Err(Error::Urdf {
            message: format!(
                "joint `{}` ({:?}) has the zero-width range [{}, {}] {pos_unit} (lower and upper default to 0 when missing); a joint that must not move is type=\"fixed\" or locked (ModelOptions::locked, --lock)",
                j.name, j.joint_type, l.lower, l.upper
            ),
        });
    }
    Ok((l.lower, l.upper))
}

/// Sets the velocity \[rad/s or m/s\], effort \[N·m or N\] and acceleration \[rad/s² or m/s²\]
/// limits of `limit` that the joint's `<limit>` writes, checked; warnings go to the builder.
fn given_rate_limits(
    j: &urdf_rs::Joint,
    raw: &RawJoint,
    b: &mut RobotBuilder,
    limit: &mut JointLimit,
) -> Result<()> {
    let l = &j.limit;
    let (_, vel_unit) = units(j);
    let bad = |attr: &str, value: f64, expected: String| bad_limit(j, raw, attr, value, expected);
    match raw.limit_attr("velocity") {
        Some(_) if !(l.velocity.is_finite() && l.velocity > 0.0) => {
            return Err(bad(
                "velocity",
                l.velocity,
                format!("a finite velocity limit > 0 [{vel_unit}] (a joint that must not move is type=\"fixed\" or locked with --lock)"),
            ))
        }
        Some(_) => limit.velocity = l.velocity,
        None => b.warn(format!(
            "joint `{}`: <limit> has no velocity; read as unbounded (URDF 1.2) unless ModelOptions::fallback_velocity or a robot profile's `velocity.default` sets one",
            j.name
        )),
    }
    if raw.limit_attr("effort").is_some() {
        if !(l.effort.is_finite() && l.effort >= 0.0) {
            return Err(bad(
                "effort",
                l.effort,
                "a finite effort limit >= 0 [N·m or N]".into(),
            ));
        }
        if l.effort == 0.0 {
            b.warn(format!(
                "joint `{}`: <limit effort=\"0\">: URDF allows it; iktc is kinematic and does not use efforts",
                j.name
            ));
        }
        limit.effort = l.effort;
    }
    if raw.limit_attr("acceleration").is_some() {
        if !(l.acceleration.is_finite() && l.acceleration > 0.0) {
            return Err(bad(
                "acceleration",
                l.acceleration,
                format!("a finite acceleration limit > 0 [{vel_unit}²]"),
            ));
        }
        limit.acceleration = l.acceleration;
    }
    Ok(())
}

/// Parses URDF `text` with `urdf-rs` after the raw pass ([`check_raw`]): a trailing NUL
/// (some exported files carry one) is dropped and `<material>` elements without a name are
/// read as unnamed. The one place a URDF is parsed (model, meshes, profile guesses).
pub(crate) fn read_urdf(text: &str, limits: &ReadLimits) -> Result<(urdf_rs::Robot, RawUrdf)> {
    // The XML parser rejects a trailing NUL, which some exported files carry.
    let text = text.trim_end_matches('\0');
    let raw = check_raw(text, limits)?;
    let named;
    let text = if raw.unnamed_materials.is_empty() {
        text
    } else {
        named = unnamed_materials_named(text, &raw.unnamed_materials);
        named.as_str()
    };
    let mut u = urdf_rs::read_from_string(text).map_err(|e| Error::Urdf {
        message: format!("cannot parse the URDF: {e}"),
    })?;
    let mut raw = raw;
    raw.floating_root = drop_floating_root(&mut u);
    Ok((u, raw))
}

/// A `floating` joint from a massless root link (`world`) to its one child is how some
/// exporters mark a floating base: the root link and that joint are dropped, the child becomes
/// the root, and the base is what [`ModelOptions::base`](super::ModelOptions) says, as for
/// any other URDF. Returns the warning to give, or `None` when `u` has no such joint (any other
/// `floating` or `planar` joint stays an error).
fn drop_floating_root(u: &mut urdf_rs::Robot) -> Option<String> {
    let is_child = |name: &str| u.joints.iter().any(|j| j.child.link == name);
    let roots: Vec<usize> = (0..u.links.len())
        .filter(|i| !is_child(&u.links[*i].name))
        .collect();
    let [root] = roots.as_slice() else {
        return None;
    };
    let root_name = u.links[*root].name.clone();
    let from_root: Vec<usize> = (0..u.joints.len())
        .filter(|i| u.joints[*i].parent.link == root_name)
        .collect();
    let [j] = from_root.as_slice() else {
        return None;
    };
    let floating = matches!(u.joints[*j].joint_type, urdf_rs::JointType::Floating);
    if !floating || u.links[*root].inertial.mass.value != 0.0 {
        return None;
    }
    let joint = u.joints.remove(*j);
    u.links.remove(*root);
    Some(format!(
        "joint `{}` (floating) from the massless root link `{root_name}`: read as the base at `{}` (floating or fixed as ModelOptions::base says)",
        joint.name, joint.child.link
    ))
}

// The readers behind `RobotFiles` (its docs say what each checks).
pub(crate) fn from_urdf_str(text: &str, options: &ModelOptions) -> Result<Robot> {
    from_urdf_str_with(text, options, &ReadLimits::default())
}

pub(crate) fn from_urdf_str_with(
    text: &str,
    options: &ModelOptions,
    limits: &ReadLimits,
) -> Result<Robot> {
    let (u, raw) = read_urdf(text, limits)?;
    let mut b = builder_from_urdf(&u, &raw.joints)?;
    if let Some(note) = &raw.floating_root {
        b.warn(note.clone());
    }
    for (joint, tag) in &raw.ignored {
        b.warn(format!("joint `{joint}`: <{tag}> is not URDF; ignored"));
    }
    if !raw.unnamed_materials.is_empty() {
        b.warn(format!(
            "{} <material> element(s) without the `name` URDF requires: read as unnamed",
            raw.unnamed_materials.len()
        ));
    }
    b.build(options)
}

pub(crate) fn from_urdf_file(path: &std::path::Path, options: &ModelOptions) -> Result<Robot> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::Urdf {
        message: format!("cannot read {}: {e}", path.display()),
    })?;
    from_urdf_str(&text, options)
}
