//! The robot's state (q, q̇) and its integration over a control period.

use nalgebra::{DVector, Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use super::joint::JointRole;
use super::robot::{BaseKind, Robot};
use super::spatial::se3_exp;
use crate::error::{check_all_finite, check_dim, Error, Result};

/// A quaternion whose norm differs from 1 by more than this (relative) is rejected as input
/// rather than silently normalised: it is a sign of garbage, not of round-off.
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// Configuration and velocity, laid out as described in [`Robot`].
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Configuration, length `nq`: base position \[m\] and quaternion (x, y, z, w) if floating,
    /// then active joint positions \[rad\] or \[m\].
    pub q: DVector<f64>,
    /// Velocity, length `nv`: base body twist (linear \[m/s\], angular \[rad/s\], base axes) if
    /// floating, then active joint rates \[rad/s\] or \[m/s\].
    pub qd: DVector<f64>,
}

impl State {
    /// The neutral state: base at the world origin with identity orientation, every joint at
    /// 0 (or at the nearest end of its range when 0 is outside it), zero velocity.
    pub fn neutral(robot: &Robot) -> State {
        let mut q = DVector::zeros(robot.nq());
        if robot.base() == BaseKind::Floating {
            q[6] = 1.0;
        }
        for (i, j) in robot.active_joints().enumerate() {
            q[robot.base_nq() + i] = 0.0_f64.clamp(j.limit.lower, j.limit.upper);
        }
        State {
            q,
            qd: DVector::zeros(robot.nv()),
        }
    }

    /// Checks sizes, finiteness and the base quaternion's norm.
    pub fn validate(&self, robot: &Robot) -> Result<()> {
        check_dim("q", robot.nq(), self.q.len())?;
        check_dim("q̇", robot.nv(), self.qd.len())?;
        check_all_finite("q", self.q.as_slice())?;
        check_all_finite("q̇", self.qd.as_slice())?;
        if robot.base() == BaseKind::Floating {
            let n = self.q.fixed_rows::<4>(3).norm();
            if (n - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
                return Err(Error::InvalidSetting {
                    name: "base quaternion q[3..7]".into(),
                    value: format!("norm {n}"),
                    expected: "a unit quaternion (x, y, z, w)".into(),
                });
            }
        }
        Ok(())
    }

    /// Pose of the root link in the world (identity for a fixed base).
    pub fn base_pose(&self, robot: &Robot) -> Isometry3<f64> {
        match robot.base() {
            BaseKind::Fixed => Isometry3::identity(),
            BaseKind::Floating => base_pose_from_q(self.q.as_slice()),
        }
    }

    /// Sets the pose of the root link (floating base only).
    pub fn set_base_pose(&mut self, robot: &Robot, pose: &Isometry3<f64>) -> Result<()> {
        if robot.base() != BaseKind::Floating {
            return Err(Error::InvalidSetting {
                name: "base pose".into(),
                value: "given".into(),
                expected: "a floating-base robot (this one has a fixed base)".into(),
            });
        }
        check_all_finite("base position", pose.translation.vector.as_slice())?;
        check_all_finite("base orientation", pose.rotation.coords.as_slice())?;
        self.q
            .fixed_rows_mut::<3>(0)
            .copy_from(&pose.translation.vector);
        self.q
            .fixed_rows_mut::<4>(3)
            .copy_from(&pose.rotation.coords);
        Ok(())
    }

    /// Position \[rad\] or \[m\] of the active joint `name`.
    pub fn joint(&self, robot: &Robot, name: &str) -> Result<f64> {
        Ok(self.q[robot.joint_q_index(name)?])
    }

    /// Sets the position \[rad\] or \[m\] of the active joint `name`.
    pub fn set_joint(&mut self, robot: &Robot, name: &str, value: f64) -> Result<()> {
        crate::error::check_finite(|| format!("value of joint `{name}`"), value)?;
        let i = robot.joint_q_index(name)?;
        self.q[i] = value;
        Ok(())
    }

    /// The position coordinate of every velocity coordinate (nv entries): 0 for the base
    /// (whose position has no limit), then the active joint positions. This is the `position`
    /// argument the acceleration bounds expect.
    pub fn dof_positions(&self, robot: &Robot, out: &mut [f64]) -> Result<()> {
        check_dim("dof positions", robot.nv(), out.len())?;
        let (nb, nqb) = (robot.base_nv(), robot.base_nq());
        out[..nb].fill(0.0);
        out[nb..].copy_from_slice(&self.q.as_slice()[nqb..]);
        Ok(())
    }

    /// Advances the state by `dt` \[s\] under a constant acceleration `qdd` (length nv):
    /// joints q⁺ = q + Δt q̇ + ½Δt² q̈, q̇⁺ = q̇ + Δt q̈ (exact); the floating base
    /// T⁺ = T · exp(Δt ν + ½Δt² ν̇) on SE(3) with the body twist ν⁺ = ν + Δt ν̇ (exact when
    /// ν̇ = 0, second order otherwise). This is the integrator the acceleration bounds assume.
    pub fn integrate(&mut self, robot: &Robot, qdd: &DVector<f64>, dt: f64) -> Result<()> {
        check_dim("q̈", robot.nv(), qdd.len())?;
        check_all_finite("q̈", qdd.as_slice())?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::InvalidSetting {
                name: "dt".into(),
                value: dt.to_string(),
                expected: "a positive, finite period [s]".into(),
            });
        }
        let (nb, nqb) = (robot.base_nv(), robot.base_nq());
        if robot.base() == BaseKind::Floating {
            let t = base_pose_from_q(self.q.as_slice());
            let v = Vector3::new(self.qd[0], self.qd[1], self.qd[2]);
            let w = Vector3::new(self.qd[3], self.qd[4], self.qd[5]);
            let a = Vector3::new(qdd[0], qdd[1], qdd[2]);
            let al = Vector3::new(qdd[3], qdd[4], qdd[5]);
            let step = se3_exp(
                &(v * dt + a * (0.5 * dt * dt)),
                &(w * dt + al * (0.5 * dt * dt)),
            );
            let mut t1 = t * step;
            t1.rotation.renormalize();
            self.q
                .fixed_rows_mut::<3>(0)
                .copy_from(&t1.translation.vector);
            self.q.fixed_rows_mut::<4>(3).copy_from(&t1.rotation.coords);
            for k in 0..6 {
                self.qd[k] += dt * qdd[k];
            }
        }
        for k in 0..robot.n_active() {
            let (iv, iq) = (nb + k, nqb + k);
            self.q[iq] += dt * self.qd[iv] + 0.5 * dt * dt * qdd[iv];
            self.qd[iv] += dt * qdd[iv];
        }
        Ok(())
    }
}

/// Position of every joint (active, locked, mimic or fixed) for configuration `q`.
#[inline]
pub(crate) fn joint_position(robot: &Robot, role: &JointRole, q: &[f64]) -> f64 {
    match *role {
        JointRole::Active { index } => q[robot.base_nq() + index],
        JointRole::Locked { value } => value,
        JointRole::Mimic {
            master,
            multiplier,
            offset,
        } => multiplier * q[robot.base_nq() + master] + offset,
        JointRole::Fixed => 0.0,
    }
}

fn base_pose_from_q(q: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(q[0], q[1], q[2]),
        UnitQuaternion::from_quaternion(Quaternion::new(q[6], q[3], q[4], q[5])),
    )
}
