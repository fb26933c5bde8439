//! Frame task: position and/or orientation of a frame, on any subset of its 6 axes.

use nalgebra::{DMatrix, Isometry3, Vector6};

use super::equation::{copy_jacobian_row, write_row, Gains, TaskEquation};
use crate::error::{check_all_finite, Error, Result};
use crate::model::{FrameId, Kinematics, Robot, State};

/// Which of the six axes (x, y, z position in world axes; x, y, z rotation in world axes) a
/// frame task controls.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Axes(pub [bool; 6]);

impl Axes {
    /// All six axes (a foot).
    pub const ALL: Axes = Axes([true; 6]);
    /// Position only.
    pub const POSITION: Axes = Axes([true, true, true, false, false, false]);
    /// Orientation only (pelvis attitude).
    pub const ORIENTATION: Axes = Axes([false, false, false, true, true, true]);
    /// Height only (pelvis height).
    pub const Z: Axes = Axes([false, false, true, false, false, false]);
    /// Number of selected axes.
    pub fn count(&self) -> usize {
        self.0.iter().filter(|b| **b).count()
    }
}

/// Desired pose, twist and acceleration of a frame (world axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameReference {
    /// Desired pose x_d.
    pub pose: Isometry3<f64>,
    /// Desired (v \[m/s\], ω \[rad/s\]) ẋ_d, world axes.
    pub velocity: Vector6<f64>,
    /// Desired (v̇ \[m/s²\], ω̇ \[rad/s²\]) ẍ_d, world axes.
    pub acceleration: Vector6<f64>,
}

impl FrameReference {
    /// The error of a frame at `pose` from this reference, world axes: the position error
    /// `p_d − p` \[m\], then the orientation error `log(R_d Rᵀ)` as a rotation vector \[rad\].
    pub(crate) fn pose_error(&self, pose: &Isometry3<f64>) -> Vector6<f64> {
        let ep = self.pose.translation.vector - pose.translation.vector;
        let er = (self.pose.rotation * pose.rotation.inverse()).scaled_axis();
        Vector6::new(ep.x, ep.y, ep.z, er.x, er.y, er.z)
    }

    /// The acceleration a frame task with `gains` asks of a frame at `pose` moving with
    /// `velocity` (world axes, \[m/s\] then \[rad/s\]): `ẍ_d + k_v(ẋ_d − ẋ) + k_p e`
    /// \[m/s², rad/s²\], its rows' right-hand side before `J̇q̇` is taken off (used by the
    /// retargeting's floor).
    pub fn desired_acceleration(
        &self,
        pose: &Isometry3<f64>,
        velocity: &Vector6<f64>,
        gains: &Gains,
    ) -> Vector6<f64> {
        self.acceleration + gains.kv * (self.velocity - velocity) + gains.kp * self.pose_error(pose)
    }

    /// A pose held still.
    pub fn hold(pose: Isometry3<f64>) -> Self {
        Self {
            pose,
            velocity: Vector6::zeros(),
            acceleration: Vector6::zeros(),
        }
    }
}

/// Frame task: the selected rows of J q̈ = ẍ_d + k_v(ẋ_d − ẋ) + k_p e − J̇q̇, with the position
/// error e = p_d − p in world axes and the orientation error e = log(R_d Rᵀ) as a rotation
/// vector in world axes \[rad\].
#[derive(Debug, Clone)]
pub struct FrameTask {
    frame: FrameId,
    frame_name: String,
    axes: Axes,
    /// CLIK gains.
    pub gains: Gains,
    /// The reference.
    pub reference: FrameReference,
    /// Weight of the task's rows \[–\] (1 unless set): both sides of each row are multiplied
    /// by it, so that in a level shared with other tasks a unit of this task's error costs
    /// `weight²` as much as one of a weight-1 task's.
    weight: f64,
    scratch: DMatrix<f64>,
}

impl FrameTask {
    /// A task on frame `frame` of `robot`, selected `axes`, holding the frame's pose at the
    /// world origin until a reference is set.
    pub fn new(robot: &Robot, frame: &str, axes: Axes, gains: Gains) -> Result<Self> {
        gains.validate()?;
        if axes.count() == 0 {
            return Err(Error::InvalidSetting {
                name: format!("axes of the task on `{frame}`"),
                value: "none".into(),
                expected: "at least one of the six axes".into(),
            });
        }
        Ok(Self {
            frame: robot.frame_id(frame)?,
            frame_name: frame.into(),
            axes,
            gains,
            reference: FrameReference::hold(Isometry3::identity()),
            weight: 1.0,
            scratch: DMatrix::zeros(6, robot.nv()),
        })
    }

    /// Sets the weight of the task's rows ([`FrameTask`]'s `weight`). Errors: a weight that is
    /// not finite and > 0.
    pub fn set_weight(&mut self, weight: f64) -> Result<()> {
        if !(weight.is_finite() && weight > 0.0) {
            return Err(Error::InvalidSetting {
                name: format!("weight of the task on `{}`", self.frame_name),
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

    /// Name of the frame.
    pub fn frame_name(&self) -> &str {
        &self.frame_name
    }

    /// The frame's id.
    pub fn frame(&self) -> FrameId {
        self.frame
    }

    /// The selected axes.
    pub fn axes(&self) -> Axes {
        self.axes
    }

    /// Number of rows.
    pub fn dim(&self) -> usize {
        self.axes.count()
    }

    /// Sets the reference; errors on a non-finite entry.
    pub fn set_reference(&mut self, r: FrameReference) -> Result<()> {
        check_all_finite(
            "frame reference position",
            r.pose.translation.vector.as_slice(),
        )?;
        check_all_finite(
            "frame reference orientation",
            r.pose.rotation.coords.as_slice(),
        )?;
        check_all_finite("frame reference velocity", r.velocity.as_slice())?;
        check_all_finite("frame reference acceleration", r.acceleration.as_slice())?;
        self.reference = r;
        Ok(())
    }

    /// The frame's current value in task coordinates is its pose: see
    /// [`Kinematics::frame_pose`].
    ///
    /// Writes rows `offset..offset + dim()` of `out`. Allocates nothing.
    pub fn linearize(
        &mut self,
        robot: &Robot,
        kin: &Kinematics,
        _state: &State,
        out: &mut TaskEquation,
        offset: usize,
    ) -> Result<()> {
        out.check_room(robot.nv(), offset, self.dim(), || {
            format!("`{}`", self.frame_name)
        })?;
        kin.frame_jacobian(robot, self.frame, &mut self.scratch)?;
        let pose = kin.frame_pose(robot, self.frame)?;
        let vel = kin.frame_velocity(robot, self.frame)?;
        let drift = kin.frame_drift(robot, self.frame)?;
        let e = self.reference.pose_error(&pose);
        let edot = self.reference.velocity - vel;
        let mut r = offset;
        for k in 0..6 {
            if !self.axes.0[k] {
                continue;
            }
            copy_jacobian_row(out, r, &self.scratch, k);
            write_row(
                out,
                r,
                e[k],
                edot[k],
                self.reference.acceleration[k],
                drift[k],
                &self.gains,
            );
            if self.weight != 1.0 {
                let m = out.jacobian.nrows();
                let js = out.jacobian.as_mut_slice();
                for c in 0..robot.nv() {
                    js[c * m + r] *= self.weight;
                }
                out.rhs[r] *= self.weight;
            }
            r += 1;
        }
        Ok(())
    }
}
