//! Centre-of-mass task on any subset of x, y, z.

use nalgebra::{DMatrix, Vector3};

use super::equation::{copy_jacobian_row, write_row, Gains, TaskEquation};
use crate::error::{check_all_finite, Error, Result};
use crate::model::{Kinematics, Robot, State};

/// Desired COM position \[m\], velocity \[m/s\] and acceleration \[m/s²\], world axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComReference {
    /// c_d \[m\].
    pub position: Vector3<f64>,
    /// ċ_d \[m/s\].
    pub velocity: Vector3<f64>,
    /// c̈_d \[m/s²\].
    pub acceleration: Vector3<f64>,
}

impl ComReference {
    /// A COM position \[m\] held still (zero velocity and acceleration).
    pub fn hold(position: Vector3<f64>) -> Self {
        Self {
            position,
            velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
        }
    }
}

/// COM task: the selected rows of J_c q̈ = c̈_d + k_v(ċ_d − ċ) + k_p(c_d − c) − J̇_c q̇.
#[derive(Debug, Clone)]
pub struct ComTask {
    axes: [bool; 3],
    /// CLIK gains.
    pub gains: Gains,
    /// The reference.
    pub reference: ComReference,
    scratch: DMatrix<f64>,
}

impl ComTask {
    /// A COM task on the selected world axes (x, y, z); e.g. `\[true, true, false\]` for the
    /// horizontal plane of Table 1.
    ///
    /// Errors: bad gains, no axis, a robot whose total mass is not > 0 \[kg\] (its COM is
    /// undefined).
    pub fn new(robot: &Robot, axes: [bool; 3], gains: Gains) -> Result<Self> {
        gains.validate()?;
        if !axes.iter().any(|a| *a) {
            return Err(Error::InvalidSetting {
                name: "axes of the COM task".into(),
                value: "none".into(),
                expected: "at least one of x, y, z".into(),
            });
        }
        let mass = robot.total_mass();
        if !(mass.is_finite() && mass > 0.0) {
            return Err(Error::InvalidSetting {
                name: "total mass of the robot (a centre-of-mass task) [kg]".into(),
                value: crate::resources::fmt_value(mass),
                expected: "a mass > 0: give the links <inertial> masses in the URDF".into(),
            });
        }
        Ok(Self {
            axes,
            gains,
            reference: ComReference {
                position: Vector3::zeros(),
                velocity: Vector3::zeros(),
                acceleration: Vector3::zeros(),
            },
            scratch: DMatrix::zeros(3, robot.nv()),
        })
    }

    /// Number of rows.
    pub fn dim(&self) -> usize {
        self.axes.iter().filter(|a| **a).count()
    }

    /// Sets the reference; errors on a non-finite entry.
    pub fn set_reference(&mut self, r: ComReference) -> Result<()> {
        check_all_finite("COM reference position", r.position.as_slice())?;
        check_all_finite("COM reference velocity", r.velocity.as_slice())?;
        check_all_finite("COM reference acceleration", r.acceleration.as_slice())?;
        self.reference = r;
        Ok(())
    }

    /// Writes rows `offset..offset + dim()` of `out`. Allocates nothing.
    pub fn linearize(
        &mut self,
        robot: &Robot,
        kin: &Kinematics,
        _state: &State,
        out: &mut TaskEquation,
        offset: usize,
    ) -> Result<()> {
        out.check_room(robot.nv(), offset, self.dim(), || "the COM".to_string())?;
        kin.com_jacobian(robot, &mut self.scratch)?;
        let e = self.reference.position - kin.com();
        let edot = self.reference.velocity - kin.com_velocity();
        let d = kin.com_drift();
        let mut r = offset;
        for k in 0..3 {
            if !self.axes[k] {
                continue;
            }
            copy_jacobian_row(out, r, &self.scratch, k);
            write_row(
                out,
                r,
                e[k],
                edot[k],
                self.reference.acceleration[k],
                d[k],
                &self.gains,
            );
            r += 1;
        }
        Ok(())
    }
}
