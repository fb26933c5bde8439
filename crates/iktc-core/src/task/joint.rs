//! Joint task: positions of a subset of the active joints (the upper body of Table 1).

use nalgebra::DVector;

use super::equation::{write_row, Gains, TaskEquation};
use crate::error::{check_all_finite, check_dim, Error, Result};
use crate::model::{Kinematics, Robot, State};

/// Joint task: for each selected joint i, q̈_i = q̈_d + k_v(q̇_d − q̇) + k_p(q_d − q) (its
/// Jacobian row selects the joint's velocity coordinate; no drift).
#[derive(Debug, Clone)]
pub struct JointTask {
    names: Vec<String>,
    v_index: Vec<usize>,
    q_index: Vec<usize>,
    /// CLIK gains.
    pub gains: Gains,
    /// Desired positions \[rad\] or \[m\], one per selected joint.
    pub position: DVector<f64>,
    /// Desired rates \[rad/s\].
    pub velocity: DVector<f64>,
    /// Desired accelerations \[rad/s²\].
    pub acceleration: DVector<f64>,
    /// Weight w of the task's rows \[–\] (default 1): they read `w q̈_j = w (q̈_d + k_v (q̇_d −
    /// q̇) + k_p (q_d − q))`, which changes nothing where the task has a level of its own and
    /// sets its share of the least-squares compromise in a level shared with other tasks.
    weight: f64,
}

impl JointTask {
    /// A task on the named active joints; the reference starts at zero.
    pub fn new(robot: &Robot, joints: &[&str], gains: Gains) -> Result<Self> {
        gains.validate()?;
        if joints.is_empty() {
            return Err(Error::InvalidSetting {
                name: "joints of a joint task".into(),
                value: "none".into(),
                expected: "at least one active joint".into(),
            });
        }
        let mut v_index = Vec::with_capacity(joints.len());
        let mut q_index = Vec::with_capacity(joints.len());
        for n in joints {
            v_index.push(robot.joint_v_index(n)?);
            q_index.push(robot.joint_q_index(n)?);
        }
        let m = joints.len();
        Ok(Self {
            names: joints.iter().map(|s| s.to_string()).collect(),
            v_index,
            q_index,
            gains,
            position: DVector::zeros(m),
            velocity: DVector::zeros(m),
            acceleration: DVector::zeros(m),
            weight: 1.0,
        })
    }

    /// Sets the weight of the task's rows ([`JointTask`]'s `weight`). Errors: a weight that is
    /// not finite and > 0.
    pub fn set_weight(&mut self, weight: f64) -> Result<()> {
        if !(weight.is_finite() && weight > 0.0) {
            return Err(Error::InvalidSetting {
                name: "weight of a joint task".into(),
                value: weight.to_string(),
                expected: "a finite weight > 0 [–]".into(),
            });
        }
        self.weight = weight;
        Ok(())
    }

    /// The weight of the task's rows \[–\].
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Names of the selected joints, in row order.
    pub fn joint_names(&self) -> &[String] {
        &self.names
    }

    /// Velocity indices of the selected joints, in row order.
    pub fn v_indices(&self) -> &[usize] {
        &self.v_index
    }

    /// Number of rows.
    pub fn dim(&self) -> usize {
        self.names.len()
    }

    /// Sets the reference (positions \[rad\], rates \[rad/s\], accelerations \[rad/s²\]).
    pub fn set_reference(&mut self, q: &[f64], qd: &[f64], qdd: &[f64]) -> Result<()> {
        for (what, v) in [("position", q), ("velocity", qd), ("acceleration", qdd)] {
            // Formatted only on failure: references are set every tick.
            if v.len() != self.dim() {
                check_dim(&format!("joint task reference {what}"), self.dim(), v.len())?;
            }
            if v.iter().any(|x| !x.is_finite()) {
                check_all_finite(&format!("joint task reference {what}"), v)?;
            }
        }
        self.position.copy_from_slice(q);
        self.velocity.copy_from_slice(qd);
        self.acceleration.copy_from_slice(qdd);
        Ok(())
    }

    /// Writes rows `offset..offset + dim()` of `out`. Allocates nothing.
    pub fn linearize(
        &mut self,
        robot: &Robot,
        _kin: &Kinematics,
        state: &State,
        out: &mut TaskEquation,
        offset: usize,
    ) -> Result<()> {
        out.check_room(robot.nv(), offset, self.dim(), || {
            "a joint task".to_string()
        })?;
        // J: the rows offset..offset + dim are zero but for a 1 in each joint's column
        // (column-major J: column c holds entry c of every row).
        let (nv, m, dim) = (robot.nv(), out.jacobian.nrows(), self.dim());
        let js = out.jacobian.as_mut_slice();
        for c in 0..nv {
            js[c * m + offset..c * m + offset + dim].fill(0.0);
        }
        let w = self.weight;
        for (k, &iv) in self.v_index.iter().enumerate() {
            js[iv * m + offset + k] = w;
        }
        for k in 0..dim {
            let (iv, iq) = (self.v_index[k], self.q_index[k]);
            write_row(
                out,
                offset + k,
                self.position[k] - state.q[iq],
                self.velocity[k] - state.qd[iv],
                self.acceleration[k],
                0.0,
                &self.gains,
            );
            out.rhs[offset + k] *= w;
        }
        Ok(())
    }
}
