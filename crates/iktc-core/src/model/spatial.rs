//! Spatial (6D) motion vectors in world axes and the SE(3) exponential.
//!
//! A [`Motion`] is a twist or a spatial acceleration expressed at the world origin in world axes
//! (Featherstone's spatial notation): an angular part ω \[rad/s\] and a linear part v_O \[m/s\], the
//! velocity of the (possibly fictitious) body point that coincides with the world origin. The
//! velocity of a body point at p \[m\] is then v_p = v_O + ω × p.

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

/// A spatial motion vector (twist \[rad/s, m/s\] or spatial acceleration \[rad/s², m/s²\]) at the
/// world origin, in world axes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Motion {
    /// Angular part ω.
    pub angular: Vector3<f64>,
    /// Linear part: velocity (or acceleration) of the body point at the world origin.
    pub linear: Vector3<f64>,
}

impl Motion {
    /// The zero motion.
    pub const ZERO: Motion = Motion {
        angular: Vector3::new(0.0, 0.0, 0.0),
        linear: Vector3::new(0.0, 0.0, 0.0),
    };

    /// Builds a motion from its angular and linear parts.
    pub fn new(angular: Vector3<f64>, linear: Vector3<f64>) -> Self {
        Self { angular, linear }
    }

    /// Scales both parts by `s`.
    #[inline]
    pub fn scaled(&self, s: f64) -> Self {
        Self::new(self.angular * s, self.linear * s)
    }

    /// Spatial cross product for motion vectors, `self ×ₘ other`:
    /// (ω₁, v₁) × (ω₂, v₂) = (ω₁ × ω₂, ω₁ × v₂ + v₁ × ω₂).
    /// `V ×ₘ S` is the time derivative of a motion axis S fixed in a body moving with twist V.
    #[inline]
    pub fn cross(&self, other: &Motion) -> Motion {
        Motion::new(
            self.angular.cross(&other.angular),
            self.angular.cross(&other.linear) + self.linear.cross(&other.angular),
        )
    }

    /// Velocity \[m/s\] of the body point at `p` \[m\] (world): v_O + ω × p.
    #[inline]
    pub fn point_velocity(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.linear + self.angular.cross(p)
    }
}

impl std::ops::Add for Motion {
    type Output = Motion;
    #[inline]
    fn add(self, o: Motion) -> Motion {
        Motion::new(self.angular + o.angular, self.linear + o.linear)
    }
}

impl std::ops::AddAssign for Motion {
    #[inline]
    fn add_assign(&mut self, o: Motion) {
        self.angular += o.angular;
        self.linear += o.linear;
    }
}

/// Skew-symmetric matrix \[w\]× with \[w\]× v = w × v.
pub fn skew(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// Below this rotation angle \[rad\] the SE(3) exponential uses Taylor series instead of the
/// closed form, whose coefficients lose precision as θ → 0 (relative error ≈ ε/θ²).
const SMALL_ANGLE: f64 = 1e-4;

/// The SE(3) exponential of a body twist ξ = (v \[m\], ω \[rad\]) (a twist times a duration):
/// exp(ξ^) = (R, t) with R = exp(\[ω\]×) (Rodrigues) and
/// t = (I + (1 − cos θ)/θ² \[ω\]× + (θ − sin θ)/θ³ \[ω\]×²) v, θ = ‖ω‖.
pub fn se3_exp(v: &Vector3<f64>, w: &Vector3<f64>) -> Isometry3<f64> {
    let theta2 = w.norm_squared();
    let theta = theta2.sqrt();
    let (b, c) = if theta < SMALL_ANGLE {
        // (1 − cos θ)/θ² = 1/2 − θ²/24 + …, (θ − sin θ)/θ³ = 1/6 − θ²/120 + …
        (0.5 - theta2 / 24.0, 1.0 / 6.0 - theta2 / 120.0)
    } else {
        (
            (1.0 - theta.cos()) / theta2,
            (theta - theta.sin()) / (theta2 * theta),
        )
    };
    let wx = skew(w);
    let vmat = Matrix3::identity() + wx * b + wx * wx * c;
    Isometry3::from_parts(
        Translation3::from(vmat * v),
        UnitQuaternion::from_scaled_axis(*w),
    )
}

/// The SO(3) logarithm as a rotation vector \[rad\] (axis × angle, angle in \[0, π\]).
pub fn so3_log(r: &UnitQuaternion<f64>) -> Vector3<f64> {
    r.scaled_axis()
}
