//! ZMP from the two feet's force/torque sensors, eqs. (29)–(30) with the errata's correction.
//!
//! In the local frame `x̃ỹz̃` of Figure 11 (SSP: at the stance foot; DSP: between the feet;
//! `z̃ = 0` at the sole), the total moment about the origin is
//! `τ = Σ_feet (τ_i + p_i × f_i)` (30), with `p_i` the position of foot *i*'s sensor and `f_i`,
//! `τ_i` its measured force and torque, all expressed in the local axes. The ZMP is the point of
//! the ground where the horizontal moment vanishes (29):
//! `x̃_ZMP = −τ_ỹ / Σ f_z`, `ỹ_ZMP = τ_x̃ / Σ f_z`.
//! The full cross product `p × f` includes the sensor height times the tangential force:
//! `(p × f)_x = p_y f_z − p_z f_y`, `(p × f)_y = p_z f_x − p_x f_z` (errata §1, eq. 30).

use nalgebra::{Vector2, Vector3};
use serde::Serialize;

use crate::error::{check_all_finite, check_finite, Result};

use super::model::invalid;

/// One foot's force/torque sensor reading and where the sensor is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootSensor {
    /// Position of the sensor's measuring point in the local frame \[m\]; `z` is its height above
    /// the sole (0 for sensors at sole level).
    pub position: Vector3<f64>,
    /// Force the ground exerts on the foot, local axes \[N\]; `z` is the normal force.
    pub force: Vector3<f64>,
    /// Torque about the measuring point, local axes \[N·m\].
    pub torque: Vector3<f64>,
}

/// Which foot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Foot {
    /// The left foot.
    Left,
    /// The right foot.
    Right,
}

/// Which feet carried load in a ZMP measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum ZmpStatus {
    /// Both feet loaded: the ZMP of the double support.
    BothFeet,
    /// Only this foot loaded; the other one's reading was left out.
    OneFoot(Foot),
    /// No foot loaded: the robot is in the air or the sensors read nothing. No ZMP.
    NoContact,
}

/// Settings of the ZMP computation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ZmpSettings {
    /// A foot whose normal force is at most this is unloaded and left out \[N\]. Higher values
    /// reject sensor offset and noise of a lifted foot; lower values keep a lightly loaded foot.
    pub min_normal_force: f64,
}

impl Default for ZmpSettings {
    fn default() -> Self {
        Self {
            min_normal_force: 5.0,
        }
    }
}

impl ZmpSettings {
    /// Checks that the threshold is finite and non-negative.
    pub fn validate(&self) -> Result<()> {
        check_all_finite("ZmpSettings::min_normal_force", &[self.min_normal_force])?;
        if self.min_normal_force < 0.0 {
            return Err(invalid(
                "ZmpSettings::min_normal_force [N]",
                self.min_normal_force,
                ">= 0",
            ));
        }
        Ok(())
    }
}

/// A measured ZMP.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ZmpMeasurement {
    /// `[x̃, ỹ]` of the ZMP in the local frame \[m\]; `None` when [`ZmpStatus::NoContact`].
    pub position: Option<[f64; 2]>,
    /// Which feet were used.
    pub status: ZmpStatus,
    /// Sum of the used feet's normal forces \[N\].
    pub normal_force: f64,
}

/// ZMP from the left and right foot sensors (eqs. 29–30, corrected). A foot with normal force
/// at most `settings.min_normal_force` is left out; with no loaded foot the status is
/// [`ZmpStatus::NoContact`] and there is no position. Errors only on non-finite input.
pub fn measure_zmp(
    left: &FootSensor,
    right: &FootSensor,
    settings: &ZmpSettings,
) -> Result<ZmpMeasurement> {
    settings.validate()?;
    for (name, s) in [("left", left), ("right", right)] {
        for (what, v) in [
            ("position [m]", &s.position),
            ("force [N]", &s.force),
            ("torque [N·m]", &s.torque),
        ] {
            for (i, x) in v.iter().enumerate() {
                check_finite(|| format!("{name} foot {what}[{i}]"), *x)?;
            }
        }
    }
    let loaded_l = left.force.z > settings.min_normal_force;
    let loaded_r = right.force.z > settings.min_normal_force;
    let status = match (loaded_l, loaded_r) {
        (true, true) => ZmpStatus::BothFeet,
        (true, false) => ZmpStatus::OneFoot(Foot::Left),
        (false, true) => ZmpStatus::OneFoot(Foot::Right),
        (false, false) => {
            return Ok(ZmpMeasurement {
                position: None,
                status: ZmpStatus::NoContact,
                normal_force: 0.0,
            })
        }
    };
    let mut moment = Vector3::zeros();
    let mut fz = 0.0;
    for (s, used) in [(left, loaded_l), (right, loaded_r)] {
        if used {
            moment += s.torque + s.position.cross(&s.force);
            fz += s.force.z;
        }
    }
    let p = Vector2::new(-moment.y / fz, moment.x / fz);
    Ok(ZmpMeasurement {
        position: Some([p.x, p.y]),
        status,
        normal_force: fz,
    })
}
