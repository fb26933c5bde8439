//! Forward kinematics, frame Jacobians and drifts, centre of mass: computed once per state.
//!
//! ## Convention (one for every frame)
//!
//! A frame's velocity is the 6-vector (v, ω): v \[m/s\] the velocity of the frame's origin and
//! ω \[rad/s\] its angular velocity, **both in world axes** (Pinocchio's `LOCAL_WORLD_ALIGNED`).
//! The frame Jacobian J (6 × nv, rows v then ω) gives (v, ω) = J q̇, and the drift J̇q̇ is the
//! frame's acceleration (p̈, ω̇) when q̈ = 0, so that (p̈, ω̇) = J q̈ + J̇q̇ (paper eq. 3).
//!
//! ## Algorithm
//!
//! One pass from the root: each link's pose, its spatial twist V (at the world origin, world
//! axes) and its bias acceleration A (the spatial acceleration when q̈ = 0):
//! V_c = V_p + S q̇_j and A_c = A_p + V_p ×ₘ (S q̇_j), where S is the joint's spatial axis in
//! world axes (S = (a, p × a) for a revolute joint with world axis a through p, (0, a) for a
//! prismatic one). A body point at p then has velocity v = V_lin + ω × p and bias acceleration
//! a = A_lin + α × p + ω × v. The floating base's six axes are the columns of Ad_T (body twist
//! to spatial twist) and add no bias. The COM Jacobian uses the subtree masses and first
//! moments: column of joint j = (M_j S_lin + S_ang × h_j) / M with M_j, h_j = Σ m_i c_i over the
//! subtree of j.

use nalgebra::{DMatrix, Isometry3, Vector3, Vector6};

use super::joint::JointKind;
use super::robot::{BaseKind, FrameId, Robot};
use super::spatial::Motion;
use super::state::{joint_position, State};
use crate::error::{check_dim, Error, Result};

/// Kinematic quantities of one robot at one state. Made by [`Kinematics::new`] (which sizes
/// every buffer) and refreshed in place, without allocation, by [`Kinematics::update`].
#[derive(Debug, Clone)]
pub struct Kinematics {
    nv: usize,
    nq: usize,
    nlinks: usize,
    link_pose: Vec<Isometry3<f64>>,
    link_vel: Vec<Motion>,
    link_bias: Vec<Motion>,
    /// Spatial axis of each joint times its drive scale (zero for undriven joints).
    joint_axis: Vec<Motion>,
    base_axes: [Motion; 6],
    subtree_mass: Vec<f64>,
    subtree_moment: Vec<Vector3<f64>>,
    com: Vector3<f64>,
    com_vel: Vector3<f64>,
    com_drift: Vector3<f64>,
    total_mass: f64,
}

impl Kinematics {
    /// Sizes the buffers for `robot` and computes the kinematics at `state`.
    pub fn new(robot: &Robot, state: &State) -> Result<Kinematics> {
        let nl = robot.links.len();
        let mut k = Kinematics {
            nv: robot.nv(),
            nq: robot.nq(),
            nlinks: nl,
            link_pose: vec![Isometry3::identity(); nl],
            link_vel: vec![Motion::ZERO; nl],
            link_bias: vec![Motion::ZERO; nl],
            joint_axis: vec![Motion::ZERO; robot.joints.len()],
            base_axes: [Motion::ZERO; 6],
            subtree_mass: vec![0.0; nl],
            subtree_moment: vec![Vector3::zeros(); nl],
            com: Vector3::zeros(),
            com_vel: Vector3::zeros(),
            com_drift: Vector3::zeros(),
            total_mass: robot.total_mass,
        };
        k.update(robot, state)?;
        Ok(k)
    }

    /// Recomputes everything for a new state of the same robot. Allocates nothing.
    ///
    /// Errors: a state of the wrong size or with a non-finite entry, or a robot other than the
    /// one these buffers were made for.
    pub fn update(&mut self, robot: &Robot, state: &State) -> Result<()> {
        if robot.links.len() != self.nlinks || robot.nv() != self.nv || robot.nq() != self.nq {
            return Err(Error::DimensionMismatch {
                what: "robot of Kinematics::update (links)".into(),
                expected: self.nlinks,
                got: robot.links.len(),
            });
        }
        state.validate(robot)?;
        let q = state.q.as_slice();
        let qd = state.qd.as_slice();
        let root = robot.root;
        let base = state.base_pose(robot);
        self.link_pose[root] = base;
        self.link_vel[root] = Motion::ZERO;
        self.link_bias[root] = Motion::ZERO;
        if robot.base == BaseKind::Floating {
            let r = base.rotation.to_rotation_matrix();
            let p = base.translation.vector;
            let mut v = Motion::ZERO;
            for k in 0..3 {
                let e = r.matrix().column(k).into_owned();
                self.base_axes[k] = Motion::new(Vector3::zeros(), e);
                self.base_axes[3 + k] = Motion::new(e, p.cross(&e));
            }
            for (axis, rate) in self.base_axes.iter().zip(&qd[..6]) {
                v += axis.scaled(*rate);
            }
            self.link_vel[root] = v;
        }
        for (k, j) in robot.joints.iter().enumerate() {
            let x = self.link_pose[j.parent] * j.origin;
            let qj = joint_position(robot, &j.role, q);
            self.link_pose[j.child] = x * j.kind.transform(qj);
            let vp = self.link_vel[j.parent];
            let ap = self.link_bias[j.parent];
            match (robot.drive[k], j.kind) {
                (
                    Some((iv, scale)),
                    JointKind::Revolute { axis } | JointKind::Prismatic { axis },
                ) => {
                    let a = x.rotation * axis.into_inner();
                    let s = if matches!(j.kind, JointKind::Revolute { .. }) {
                        Motion::new(a, x.translation.vector.cross(&a))
                    } else {
                        Motion::new(Vector3::zeros(), a)
                    }
                    .scaled(scale);
                    self.joint_axis[k] = s;
                    let sv = s.scaled(qd[iv]);
                    self.link_vel[j.child] = vp + sv;
                    self.link_bias[j.child] = ap + vp.cross(&sv);
                }
                _ => {
                    self.joint_axis[k] = Motion::ZERO;
                    self.link_vel[j.child] = vp;
                    self.link_bias[j.child] = ap;
                }
            }
        }
        // Centre of mass, its velocity and drift; subtree masses and first moments.
        let mut c = Vector3::zeros();
        let mut cv = Vector3::zeros();
        let mut ca = Vector3::zeros();
        for (i, l) in robot.links.iter().enumerate() {
            let p = self.link_pose[i] * nalgebra::Point3::from(l.com);
            let (v, a) = point_motion(&self.link_vel[i], &self.link_bias[i], &p.coords);
            c += p.coords * l.mass;
            cv += v * l.mass;
            ca += a * l.mass;
            self.subtree_mass[i] = l.mass;
            self.subtree_moment[i] = p.coords * l.mass;
        }
        for j in robot.joints.iter().rev() {
            let (m, h) = (self.subtree_mass[j.child], self.subtree_moment[j.child]);
            self.subtree_mass[j.parent] += m;
            self.subtree_moment[j.parent] += h;
        }
        let mtot = self.total_mass;
        if mtot > 0.0 {
            self.com = c / mtot;
            self.com_vel = cv / mtot;
            self.com_drift = ca / mtot;
        } else {
            self.com = Vector3::zeros();
            self.com_vel = Vector3::zeros();
            self.com_drift = Vector3::zeros();
        }
        Ok(())
    }

    /// World pose of link `i` (index into [`Robot::links`]).
    pub fn link_pose(&self, i: usize) -> Option<&Isometry3<f64>> {
        self.link_pose.get(i)
    }

    /// World pose of every link, in the order of [`Robot::links`].
    pub fn link_poses(&self) -> &[Isometry3<f64>] {
        &self.link_pose
    }

    /// World pose of a frame.
    pub fn frame_pose(&self, robot: &Robot, f: FrameId) -> Result<Isometry3<f64>> {
        let fr = frame(robot, f)?;
        Ok(self.link_pose[fr.link] * fr.offset)
    }

    /// Velocity (v \[m/s\], ω \[rad/s\]) of a frame, world axes: J q̇.
    pub fn frame_velocity(&self, robot: &Robot, f: FrameId) -> Result<Vector6<f64>> {
        let fr = frame(robot, f)?;
        let p = (self.link_pose[fr.link] * fr.offset).translation.vector;
        let v = &self.link_vel[fr.link];
        Ok(stack(&v.point_velocity(&p), &v.angular))
    }

    /// Drift J̇q̇ of a frame (p̈ \[m/s²\], ω̇ \[rad/s²\], world axes): its acceleration when q̈ = 0.
    pub fn frame_drift(&self, robot: &Robot, f: FrameId) -> Result<Vector6<f64>> {
        let fr = frame(robot, f)?;
        let p = (self.link_pose[fr.link] * fr.offset).translation.vector;
        let (_, a) = point_motion(&self.link_vel[fr.link], &self.link_bias[fr.link], &p);
        Ok(stack(&a, &self.link_bias[fr.link].angular))
    }

    /// Writes the 6 × nv Jacobian of a frame into `out` (rows v then ω, world axes; see the
    /// module docs). `out` must be 6 × nv. Allocates nothing.
    pub fn frame_jacobian(&self, robot: &Robot, f: FrameId, out: &mut DMatrix<f64>) -> Result<()> {
        check_dim("frame Jacobian rows", 6, out.nrows())?;
        check_dim("frame Jacobian columns (nv)", self.nv, out.ncols())?;
        let fr = frame(robot, f)?;
        let p = (self.link_pose[fr.link] * fr.offset).translation.vector;
        out.as_mut_slice().fill(0.0);
        let mut add = |col: usize, s: &Motion| {
            let lin = s.point_velocity(&p);
            for r in 0..3 {
                out[(r, col)] += lin[r];
                out[(r + 3, col)] += s.angular[r];
            }
        };
        let mut link = fr.link;
        while let Some(k) = robot.parent_joint[link] {
            if let Some((iv, _)) = robot.drive[k] {
                add(iv, &self.joint_axis[k]);
            }
            link = robot.joints[k].parent;
        }
        if robot.base == BaseKind::Floating {
            for k in 0..6 {
                add(k, &self.base_axes[k]);
            }
        }
        Ok(())
    }

    /// Centre of mass \[m\], world.
    pub fn com(&self) -> Vector3<f64> {
        self.com
    }

    /// Velocity of the centre of mass \[m/s\], world.
    pub fn com_velocity(&self) -> Vector3<f64> {
        self.com_vel
    }

    /// Drift of the centre of mass \[m/s²\]: its acceleration when q̈ = 0.
    pub fn com_drift(&self) -> Vector3<f64> {
        self.com_drift
    }

    /// Total mass \[kg\].
    pub fn total_mass(&self) -> f64 {
        self.total_mass
    }

    /// Writes the 3 × nv Jacobian of the centre of mass into `out` (world axes). Allocates
    /// nothing. A massless robot has a zero COM Jacobian.
    pub fn com_jacobian(&self, robot: &Robot, out: &mut DMatrix<f64>) -> Result<()> {
        check_dim("COM Jacobian rows", 3, out.nrows())?;
        check_dim("COM Jacobian columns (nv)", self.nv, out.ncols())?;
        out.as_mut_slice().fill(0.0);
        let mtot = self.total_mass;
        if mtot <= 0.0 {
            return Ok(());
        }
        let mut add = |col: usize, s: &Motion, m: f64, h: &Vector3<f64>| {
            let c = (s.linear * m + s.angular.cross(h)) / mtot;
            for r in 0..3 {
                out[(r, col)] += c[r];
            }
        };
        for (k, j) in robot.joints.iter().enumerate() {
            if let Some((iv, _)) = robot.drive[k] {
                add(
                    iv,
                    &self.joint_axis[k],
                    self.subtree_mass[j.child],
                    &self.subtree_moment[j.child],
                );
            }
        }
        if robot.base == BaseKind::Floating {
            let r = robot.root;
            for k in 0..6 {
                add(
                    k,
                    &self.base_axes[k],
                    self.subtree_mass[r],
                    &self.subtree_moment[r],
                );
            }
        }
        Ok(())
    }
}

fn frame(robot: &Robot, f: FrameId) -> Result<&super::robot::Frame> {
    robot
        .frames
        .get(f.0)
        .ok_or_else(|| Error::DimensionMismatch {
            what: "frame id (number of frames)".into(),
            expected: robot.frames.len(),
            got: f.0,
        })
}

/// Velocity and bias acceleration of the body point at `p` of a body with twist `v` and bias
/// acceleration `a` (spatial, world): v_p = v_O + ω × p, a_p = a_O + α × p + ω × v_p.
#[inline]
fn point_motion(v: &Motion, a: &Motion, p: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let vp = v.point_velocity(p);
    (vp, a.linear + a.angular.cross(p) + v.angular.cross(&vp))
}

#[inline]
fn stack(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector6<f64> {
    Vector6::new(a.x, a.y, a.z, b.x, b.y, b.z)
}
