//! A configuration file (JSON or TOML): joint values by name, base pose, velocities; and the
//! [`State`] it describes.
//!
//! ```
//! use iktc::model::{jvrc1, ModelOptions, StateConfig};
//!
//! let robot = jvrc1(&ModelOptions::default())?;
//! let cfg = StateConfig::from_toml_str(
//!     "joints = { R_KNEE = 0.5 }\nbase_velocity = [0.1, 0, 0, 0, 0, 0]",
//!     "example.toml",
//! )?;
//! let state = cfg.state(&robot)?;
//! assert_eq!(state.joint(&robot, "R_KNEE")?, 0.5);
//! # Ok::<(), iktc::Error>(())
//! ```

use std::collections::BTreeMap;

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use serde::Deserialize;

use super::{BaseKind, Robot};
use super::{State, QUATERNION_NORM_TOLERANCE};
use crate::error::{check_all_finite, check_finite, Error, Result};

/// The contents of a configuration file. Unknown keys are errors.
#[derive(Deserialize, Debug, Default, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StateConfig {
    /// Joint positions \[rad or m\] by name; missing joints stay at the neutral value.
    #[serde(default)]
    pub joints: BTreeMap<String, f64>,
    /// Floating-base pose.
    pub base: Option<BasePose>,
    /// Joint rates \[rad/s or m/s\] by name.
    #[serde(default)]
    pub velocities: BTreeMap<String, f64>,
    /// Base body twist (vx, vy, vz \[m/s\], wx, wy, wz \[rad/s\], base axes): exactly 6 values.
    pub base_velocity: Option<Vec<f64>>,
}

/// A base pose in a configuration file.
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BasePose {
    /// Position \[m\]: exactly 3 values.
    pub position: Vec<f64>,
    /// Unit quaternion (x, y, z, w): exactly 4 values; default the identity.
    #[serde(default = "identity_quat")]
    pub orientation: Vec<f64>,
}

fn identity_quat() -> Vec<f64> {
    vec![0.0, 0.0, 0.0, 1.0]
}

/// Largest magnitude accepted for a position, rate or base coordinate in a configuration
/// \[rad, m, rad/s or m/s\]: beyond it, kinematics overflow (a value of 1e308 gives drifts of
/// −∞). 1e6 is far beyond any joint range or speed.
pub const MAX_CONFIG_MAGNITUDE: f64 = 1e6;

fn exactly<const N: usize>(what: &str, v: &[f64]) -> Result<[f64; N]> {
    let a: [f64; N] = v.try_into().map_err(|_| Error::DimensionMismatch {
        what: what.into(),
        expected: N,
        got: v.len(),
    })?;
    check_all_finite(what, &a)?;
    check_magnitude(what, &a)?;
    Ok(a)
}

fn check_magnitude(what: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| x.abs() > MAX_CONFIG_MAGNITUDE) {
        None => Ok(()),
        Some(i) => Err(Error::InvalidSetting {
            name: format!("{what}[{i}]"),
            value: crate::resources::fmt_value(v[i]),
            expected: format!(
                "a magnitude of at most {MAX_CONFIG_MAGNITUDE:e} (MAX_CONFIG_MAGNITUDE)"
            ),
        }),
    }
}

impl StateConfig {
    /// Parses JSON text; `source_name` names it in errors.
    #[cfg(feature = "json")]
    pub fn from_json_str(text: &str, source_name: &str) -> Result<Self> {
        serde_json::from_str(text).map_err(|e| Error::Parse {
            source_name: source_name.into(),
            line: e.line(),
            message: e.to_string(),
        })
    }

    /// Parses TOML text; `source_name` names it in errors.
    #[cfg(feature = "toml")]
    pub fn from_toml_str(text: &str, source_name: &str) -> Result<Self> {
        toml::from_str(text).map_err(|e| Error::Parse {
            source_name: source_name.into(),
            line: e.span().map_or(0, |s| {
                1 + text.get(..s.start).map_or(0, |t| t.matches('\n').count())
            }),
            message: e.message().to_string(),
        })
    }

    /// The state this configuration describes on `robot`: the neutral state with the given
    /// joints, base pose and rates. Errors: an unknown joint, a non-finite value or one beyond
    /// [`MAX_CONFIG_MAGNITUDE`], a base pose or rate on a fixed-base robot, a base velocity that
    /// is not 6 values, a position that is not 3, an orientation that is not a unit quaternion
    /// of 4 values.
    pub fn state(&self, robot: &Robot) -> Result<State> {
        let mut s = State::neutral(robot);
        for (n, v) in &self.joints {
            check_finite(|| format!("position of joint `{n}`"), *v)?;
            check_magnitude(&format!("position of joint `{n}`"), &[*v])?;
            s.set_joint(robot, n, *v)?;
        }
        if let Some(b) = &self.base {
            let p = exactly::<3>("base.position", &b.position)?;
            let [x, y, z, w] = exactly::<4>("base.orientation", &b.orientation)?;
            let q = Quaternion::new(w, x, y, z);
            let n = q.norm();
            if (n - 1.0).abs() >= QUATERNION_NORM_TOLERANCE {
                return Err(Error::InvalidSetting {
                    name: "base.orientation".into(),
                    value: format!("{:?}", b.orientation),
                    expected: format!(
                        "a unit quaternion (x, y, z, w): norm 1 within {QUATERNION_NORM_TOLERANCE} (got {n})"
                    ),
                });
            }
            let pose = Isometry3::from_parts(
                Translation3::new(p[0], p[1], p[2]),
                UnitQuaternion::from_quaternion(q),
            );
            s.set_base_pose(robot, &pose)?;
        }
        for (n, v) in &self.velocities {
            check_finite(|| format!("velocity of `{n}`"), *v)?;
            check_magnitude(&format!("velocity of `{n}`"), &[*v])?;
            s.qd[robot.joint_v_index(n)?] = *v;
        }
        if let Some(v) = &self.base_velocity {
            if robot.base() != BaseKind::Floating {
                return Err(Error::InvalidSetting {
                    name: "base_velocity".into(),
                    value: format!("{v:?}"),
                    expected: "no base velocity: the robot has a fixed base".into(),
                });
            }
            let v = exactly::<6>("base_velocity", v)?;
            for (k, x) in v.iter().enumerate() {
                s.qd[k] = *x;
            }
        }
        s.validate(robot)?;
        Ok(s)
    }
}
