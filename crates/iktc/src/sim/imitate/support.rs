//! Foot soles and the support polygon of a double-support stance.

use nalgebra::{Isometry3, Point3};

use crate::walk::{Pose2, SupportPolygon, MAX_SOLES};

use crate::error::{Error, Result};

/// The sole of each foot: a rectangle under the ankle frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SupportSettings {
    /// Sole length along the foot's x axis \[m\] (JVRC-1: 0.2, nominal).
    pub sole_length: f64,
    /// Sole width along the foot's y axis \[m\] (JVRC-1: 0.1, nominal).
    pub sole_width: f64,
    /// Forward offset of the sole's centre from the ankle \[m\] (default 0).
    pub sole_offset_x: f64,
    /// Height of the ankle frame above the sole \[m\] (JVRC-1: 0.1, nominal); the run starts
    /// with the lowest sole on z = 0.
    pub ankle_height: f64,
}

impl Default for SupportSettings {
    fn default() -> Self {
        Self {
            sole_length: 0.2,
            sole_width: 0.1,
            sole_offset_x: 0.0,
            ankle_height: 0.1,
        }
    }
}

impl SupportSettings {
    /// Checks that the sizes are finite and positive (the offset finite).
    pub fn validate(&self) -> Result<()> {
        for (n, v) in [
            ("sole_length", self.sole_length),
            ("sole_width", self.sole_width),
            ("ankle_height", self.ankle_height),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::InvalidSetting {
                    name: format!("support.{n}"),
                    value: v.to_string(),
                    expected: "a finite length > 0 [m]".into(),
                });
            }
        }
        if !self.sole_offset_x.is_finite() {
            return Err(Error::InvalidSetting {
                name: "support.sole_offset_x".into(),
                value: self.sole_offset_x.to_string(),
                expected: "a finite offset [m]".into(),
            });
        }
        Ok(())
    }
}

/// The sole of the foot whose ankle frame has pose `ankle`, on the ground: the centre of its
/// rectangle (`ankle · (sole_offset_x, 0, −ankle_height)` projected on z = 0) \[m\] and the
/// heading of the foot's x axis, `atan2(R₂₁, R₁₁)` \[rad\] (the feet are held flat).
pub fn sole_pose(ankle: &Isometry3<f64>, settings: &SupportSettings) -> Pose2 {
    let c = ankle * Point3::new(settings.sole_offset_x, 0.0, -settings.ankle_height);
    let r = ankle.rotation.to_rotation_matrix();
    Pose2::new(c.x, c.y, r[(1, 0)].atan2(r[(0, 0)]))
}

/// The support polygon of the feet at poses `feet` (ankle frames): the convex hull of their
/// sole rectangles on the ground, [`SupportPolygon::set_hull_of_sole_poses`] (foot yaw
/// included). Errors: no foot, or more than [`MAX_SOLES`].
pub fn support_polygon(
    feet: &[Isometry3<f64>],
    settings: &SupportSettings,
) -> Result<SupportPolygon> {
    if feet.is_empty() || feet.len() > MAX_SOLES {
        return Err(Error::InvalidSetting {
            name: "feet".into(),
            value: format!("{} frames", feet.len()),
            expected: format!(
                "1 to {MAX_SOLES} foot frames (the support polygon is the hull of their soles)"
            ),
        });
    }
    let mut soles = [Pose2::default(); MAX_SOLES];
    for (slot, foot) in soles.iter_mut().zip(feet) {
        *slot = sole_pose(foot, settings);
    }
    let mut p = SupportPolygon::default();
    p.set_hull_of_sole_poses(
        &soles[..feet.len()],
        settings.sole_length,
        settings.sole_width,
    );
    Ok(p)
}
