//! Largest magnitudes a model accepts: a number beyond these is a typo or a corrupted file
//! (a mass of 1e308 kg makes the total mass +∞ and every COM NaN), not a robot.
//!
//! Each bound is far above any humanoid or arm (JVRC-1: links up to 10.4 kg, origins within
//! 0.5 m, inertias below 0.2 kg·m², speeds up to 12.6 rad/s) and far below where sums and
//! products of them overflow.

use nalgebra::{Isometry3, Vector3};

use super::robot::{JointSpec, Link};
use crate::error::{Error, Result};

/// Largest mass of one link \[kg\] (100 t).
pub const MAX_LINK_MASS: f64 = 1e5;
/// Largest distance of an origin, a centre of mass or a frame offset from its link frame \[m\].
pub const MAX_LENGTH: f64 = 1e3;
/// Largest entry of a link's inertia matrix \[kg·m²\].
pub const MAX_INERTIA: f64 = 1e5;
/// Largest finite joint velocity limit \[rad/s\] or \[m/s\].
pub const MAX_JOINT_SPEED: f64 = 1e4;
/// Largest finite joint acceleration limit \[rad/s²\] or \[m/s²\].
pub const MAX_JOINT_ACCELERATION: f64 = 1e7;

fn too_large(what: String, value: f64, max: f64, unit: &str) -> Error {
    Error::InvalidSetting {
        name: what,
        value: crate::resources::fmt_value(value),
        expected: format!("a magnitude of at most {max:e} {unit} (iktc's plausibility bound)"),
    }
}

fn check_length(what: String, v: &Vector3<f64>) -> Result<()> {
    let n = v.norm();
    if n > MAX_LENGTH {
        return Err(too_large(what, n, MAX_LENGTH, "m"));
    }
    Ok(())
}

/// Checks a link's mass (≤ [`MAX_LINK_MASS`]), centre of mass (≤ [`MAX_LENGTH`] from the link
/// frame) and inertia (entries ≤ [`MAX_INERTIA`], diagonal ≥ 0). Call after the finiteness
/// checks.
pub(crate) fn check_link(l: &Link) -> Result<()> {
    if l.mass > MAX_LINK_MASS {
        return Err(too_large(
            format!("mass of link `{}`", l.name),
            l.mass,
            MAX_LINK_MASS,
            "kg",
        ));
    }
    check_length(format!("centre of mass of link `{}`", l.name), &l.com)?;
    if let Some(v) = l.inertia.iter().find(|v| v.abs() > MAX_INERTIA) {
        return Err(too_large(
            format!("inertia of link `{}`", l.name),
            *v,
            MAX_INERTIA,
            "kg·m²",
        ));
    }
    if let Some(v) = l.inertia.diagonal().iter().find(|v| **v < 0.0) {
        return Err(Error::InvalidSetting {
            name: format!("inertia of link `{}`", l.name),
            value: crate::resources::fmt_value(*v),
            expected: "diagonal moments of inertia >= 0 [kg·m²]".into(),
        });
    }
    Ok(())
}

/// Checks a joint's origin (≤ [`MAX_LENGTH`]) and its finite speed and acceleration limits
/// (≤ [`MAX_JOINT_SPEED`], ≤ [`MAX_JOINT_ACCELERATION`]). Call after the finiteness checks.
pub(crate) fn check_joint(s: &JointSpec) -> Result<()> {
    check_length(
        format!("origin of joint `{}`", s.name),
        &s.origin.translation.vector,
    )?;
    for (what, v, max, unit) in [
        (
            "velocity",
            s.limit.velocity,
            MAX_JOINT_SPEED,
            "rad/s or m/s",
        ),
        (
            "acceleration",
            s.limit.acceleration,
            MAX_JOINT_ACCELERATION,
            "rad/s² or m/s²",
        ),
    ] {
        if v.is_finite() && v > max {
            return Err(too_large(
                format!("{what} limit of joint `{}`", s.name),
                v,
                max,
                unit,
            ));
        }
    }
    Ok(())
}

/// Checks a frame offset (≤ [`MAX_LENGTH`]).
pub(crate) fn check_frame(name: &str, offset: &Isometry3<f64>) -> Result<()> {
    check_length(
        format!("offset of frame `{name}`"),
        &offset.translation.vector,
    )
}
