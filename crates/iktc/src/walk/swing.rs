//! Foot trajectories: stance feet at rest, swing feet on quintic / sextic polynomials.
//!
//! Over a single support `[t₀, t₁]`, `T = t₁ − t₀`, `τ = (t − t₀)/T`, the swinging foot goes
//! from its lift-off pose `(x₀, y₀, ψ₀)` to its touch-down pose `(x₁, y₁, ψ₁)`:
//!
//! * horizontally and in heading by the quintic smoothstep (minimum-jerk profile, Flash &
//!   Hogan 1985): `x(t) = x₀ + (x₁ − x₀) s(τ)`, `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵`, likewise `y`, `ψ`;
//!   `s' = 30τ²(1 − τ)²`, `s'' = 60τ(1 − τ)(1 − 2τ)`: zero velocity and acceleration at
//!   lift-off and touch-down;
//! * vertically by the sextic `z(t) = 64 h τ³(1 − τ)³` (`h` = [`WalkSettings::swing_height`](super::WalkSettings::swing_height)),
//!   peak `h` at `τ = ½`, `z' = 192 h τ²(1 − τ)²(1 − 2τ)/T`,
//!   `z'' = 384 h τ(1 − τ)(1 − 5τ + 5τ²)/T²`: triple roots at both ends, so zero height,
//!   vertical velocity and vertical acceleration at lift-off and touch-down.
//!
//! Position, velocity and acceleration are therefore continuous over the whole timeline
//! (`C²`), a foot at rest in every other phase. The foot frame is the sole centre on the
//! ground (`z = 0` in stance), with roll and pitch zero.

use nalgebra::{Rotation3, Vector3};

use super::footstep::Pose2;
use super::settings::Side;
use super::timeline::{smoothstep, PhaseInterval};

/// Pose, velocity and acceleration of a foot (sole-centre frame, world axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootState {
    /// Position of the sole centre \[m\] (`z = 0` on the ground).
    pub position: Vector3<f64>,
    /// Heading, rotation about the world z axis \[rad\] (roll = pitch = 0).
    pub yaw: f64,
    /// Linear velocity \[m/s\], world axes.
    pub linear_velocity: Vector3<f64>,
    /// Angular velocity \[rad/s\], world axes: `(0, 0, ψ̇)`.
    pub angular_velocity: Vector3<f64>,
    /// Linear acceleration \[m/s²\], world axes.
    pub linear_acceleration: Vector3<f64>,
    /// Angular acceleration \[rad/s²\], world axes: `(0, 0, ψ̈)`.
    pub angular_acceleration: Vector3<f64>,
}

impl FootState {
    /// A foot at rest at `pose` on the ground.
    pub fn at_rest(pose: &Pose2) -> Self {
        Self {
            position: Vector3::new(pose.x, pose.y, 0.0),
            yaw: pose.yaw,
            linear_velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            linear_acceleration: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
        }
    }

    /// Orientation of the foot frame in the world, `R_z(ψ)`.
    pub fn rotation(&self) -> Rotation3<f64> {
        Rotation3::from_axis_angle(&Vector3::z_axis(), self.yaw)
    }

    /// The state of a point fixed in the foot frame at `offset` \[m\] (foot axes) from the
    /// sole centre, e.g. the ankle joint above it, with the same orientation. Rigid-body
    /// kinematics with `r = R_z(ψ) offset`: `p' = p + r`, `v' = v + ω × r`,
    /// `a' = a + α × r + ω × (ω × r)`; `ω`, `α` unchanged.
    pub fn offset(&self, offset: &Vector3<f64>) -> FootState {
        let r = self.rotation() * offset;
        let w = self.angular_velocity;
        FootState {
            position: self.position + r,
            linear_velocity: self.linear_velocity + w.cross(&r),
            linear_acceleration: self.linear_acceleration
                + self.angular_acceleration.cross(&r)
                + w.cross(&w.cross(&r)),
            ..*self
        }
    }

    /// The 6D velocity `(v, ω)` \[m/s, rad/s\], world axes.
    pub fn twist(&self) -> [f64; 6] {
        let (v, w) = (self.linear_velocity, self.angular_velocity);
        [v.x, v.y, v.z, w.x, w.y, w.z]
    }

    /// The 6D acceleration `(a, α)` \[m/s², rad/s²\], world axes (the time derivative of
    /// [`FootState::twist`]).
    pub fn acceleration(&self) -> [f64; 6] {
        let (a, al) = (self.linear_acceleration, self.angular_acceleration);
        [a.x, a.y, a.z, al.x, al.y, al.z]
    }
}

/// Sextic swing-height profile `z = 64 h τ³(1 − τ)³` over `[t0, t1]` at `t` (clamped):
/// `(z, ż, z̈)` \[m, m/s, m/s²\].
pub fn swing_height_profile(t0: f64, t1: f64, height: f64, t: f64) -> (f64, f64, f64) {
    let d = t1 - t0;
    if d <= 0.0 || !d.is_finite() {
        return (0.0, 0.0, 0.0);
    }
    let tau = ((t - t0) / d).clamp(0.0, 1.0);
    let u = tau * (1.0 - tau);
    let z = 64.0 * height * u * u * u;
    let dz = 192.0 * height * u * u * (1.0 - 2.0 * tau) / d;
    let ddz = 384.0 * height * u * (1.0 - 5.0 * tau + 5.0 * tau * tau) / (d * d);
    (z, dz, ddz)
}

/// State of foot `side` at `t` \[s\] within `phase` (`t` is clamped to the phase): the swing
/// trajectory of the module documentation if `side` swings in `phase`, else at rest.
pub fn foot_state(phase: &PhaseInterval, side: Side, swing_height: f64, t: f64) -> FootState {
    let from = phase.foot(side);
    let target = match (phase.swing_side(), phase.swing_target) {
        (Some(s), Some(target)) if s == side => target,
        _ => return FootState::at_rest(&from),
    };
    let t = t.clamp(phase.start, phase.end);
    let (s, ds, dds) = smoothstep(phase.start, phase.end, t);
    let (z, dz, ddz) = swing_height_profile(phase.start, phase.end, swing_height, t);
    let (dx, dy, dpsi) = (target.x - from.x, target.y - from.y, target.yaw - from.yaw);
    FootState {
        position: Vector3::new(from.x + s * dx, from.y + s * dy, z),
        yaw: from.yaw + s * dpsi,
        linear_velocity: Vector3::new(ds * dx, ds * dy, dz),
        angular_velocity: Vector3::new(0.0, 0.0, ds * dpsi),
        linear_acceleration: Vector3::new(dds * dx, dds * dy, ddz),
        angular_acceleration: Vector3::new(0.0, 0.0, dds * dpsi),
    }
}
