//! The limits of each velocity degree of freedom: position range, velocity and acceleration.

use crate::error::{check_all_finite, check_dim, Error, Result};

use super::integrator::StepExtremes;

/// The limits of one velocity degree of freedom (one entry of `q̇`).
///
/// A missing limit is written as an infinity: `position_min = -inf` / `position_max = +inf`
/// for an unbounded side (continuous joints, floating-base dofs), `velocity_max = +inf` and
/// `acceleration_max = +inf` for no velocity or acceleration limit. Build the value with a
/// struct literal or [`DofLimits::unlimited`]; [`JointLimits::new`] validates it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DofLimits {
    /// Lower end of the position range, `q_min` \[rad\] or \[m\]; `-inf` for none.
    pub position_min: f64,
    /// Upper end of the position range, `q_max` \[rad\] or \[m\]; `+inf` for none.
    pub position_max: f64,
    /// Largest speed in either direction, `v_max > 0` \[rad/s\] or \[m/s\]; `+inf` for none.
    pub velocity_max: f64,
    /// Largest acceleration in either direction, `a_max > 0` \[rad/s²\] or \[m/s²\]; `+inf` for
    /// none.
    pub acceleration_max: f64,
    /// Largest change of the commanded acceleration per second, `j_max > 0` \[rad/s³\] or
    /// \[m/s³\]; `+inf` for none (the default: URDF has none; a robot profile's `jerk` key
    /// sets it). See [`limit_jerk`](super::limit_jerk).
    pub jerk_max: f64,
}

impl DofLimits {
    /// A degree of freedom without any limit (all five entries infinite), e.g. a floating-base
    /// dof.
    pub fn unlimited() -> Self {
        Self {
            position_min: f64::NEG_INFINITY,
            position_max: f64::INFINITY,
            velocity_max: f64::INFINITY,
            acceleration_max: f64::INFINITY,
            jerk_max: f64::INFINITY,
        }
    }

    /// Checks the entries, naming the dof as `what` in the error.
    ///
    /// Rules: no NaN ([`Error::NonFinite`]); `position_min ≤ position_max`, `position_min < +inf`
    /// and `position_max > -inf` ([`Error::InvalidLimit`]); `velocity_max > 0` and
    /// `acceleration_max > 0` and `jerk_max > 0`, `+inf` allowed ([`Error::InvalidSetting`]).
    pub fn validate(&self, what: &str) -> Result<()> {
        let fields = [
            ("position_min", self.position_min),
            ("position_max", self.position_max),
            ("velocity_max", self.velocity_max),
            ("acceleration_max", self.acceleration_max),
            ("jerk_max", self.jerk_max),
        ];
        for (name, value) in fields {
            if value.is_nan() {
                return Err(Error::NonFinite {
                    what: format!("{what}.{name}"),
                    value,
                });
            }
        }
        if self.position_min > self.position_max
            || self.position_min == f64::INFINITY
            || self.position_max == f64::NEG_INFINITY
        {
            return Err(Error::InvalidLimit {
                what: format!("{what} position range [rad or m]"),
                lower: self.position_min,
                upper: self.position_max,
            });
        }
        for (name, value, unit) in [
            ("velocity_max", self.velocity_max, "[rad/s]"),
            ("acceleration_max", self.acceleration_max, "[rad/s²]"),
            ("jerk_max", self.jerk_max, "[rad/s³]"),
        ] {
            // NaN was rejected above: this catches zero and negative values.
            if value <= 0.0 {
                return Err(Error::InvalidSetting {
                    name: format!("{what}.{name}"),
                    value: value.to_string(),
                    expected: format!("a positive value {unit}, or +inf for no limit"),
                });
            }
        }
        Ok(())
    }

    /// How far the position range `[q_min, q_max]` is left by a motion whose extreme positions
    /// are `extremes` (see [`peak_in_step`](super::peak_in_step)) \[rad\] or \[m\]:
    /// `max(0, extremes.max − q_max, q_min − extremes.min)`. Zero when the motion stays inside.
    pub fn excursion(&self, extremes: StepExtremes) -> f64 {
        let above = extremes.max - self.position_max;
        let below = self.position_min - extremes.min;
        above.max(below).max(0.0)
    }
}

/// The limits of all `nv` velocity degrees of freedom of a robot, validated.
///
/// One entry per entry of `q̇` (floating-base dofs first when there are any, with infinite
/// limits). Plain data, independent of the robot model. Changing an entry goes through
/// [`JointLimits::set`], which validates it, so a `JointLimits` is always consistent.
#[derive(Debug, Clone, PartialEq)]
pub struct JointLimits {
    dofs: Vec<DofLimits>,
    /// One name per dof, for errors (`dof[i]` unless named).
    names: Vec<String>,
}

impl JointLimits {
    /// Validates every entry (see [`DofLimits::validate`]) and builds the limits.
    ///
    /// # Errors
    /// The first invalid entry, named `dof[i]`.
    pub fn new(dofs: Vec<DofLimits>) -> Result<Self> {
        for (i, dof) in dofs.iter().enumerate() {
            dof.validate(&format!("dof[{i}]"))?;
        }
        let names = default_names(dofs.len());
        Ok(Self { dofs, names })
    }

    /// `nv` degrees of freedom without any limit.
    pub fn unlimited(nv: usize) -> Self {
        Self {
            dofs: vec![DofLimits::unlimited(); nv],
            names: default_names(nv),
        }
    }

    /// Names the dofs (e.g. the joint names), for the errors of [`check_state`](Self::check_state).
    ///
    /// # Errors
    /// [`Error::DimensionMismatch`] unless there is one name per dof.
    pub fn with_names(mut self, names: Vec<String>) -> Result<Self> {
        check_dim(
            "JointLimits names (one per dof)",
            self.dofs.len(),
            names.len(),
        )?;
        self.names = names;
        Ok(self)
    }

    /// The name of dof `index` (`dof[i]` unless named with [`with_names`](Self::with_names)).
    pub fn name(&self, index: usize) -> Option<&str> {
        self.names.get(index).map(String::as_str)
    }

    /// Checks that a state lies inside the limits: every position in its range
    /// `q_min ≤ q ≤ q_max` \[rad or m\] and every speed `|q̇| ≤ v_max` \[rad/s or m/s\]. A run
    /// calls this on its start state unless it is asked to recover
    /// ([`OutsideLimits`](super::OutsideLimits)): from such a state at rest the viable bounds
    /// keep every limit (see [`viable`](super::viable)). A state moving toward a limit faster
    /// than it can brake is inside these limits yet not viable; runs start at rest.
    ///
    /// `positions`: one entry per velocity dof (as for [`compute_box`](super::compute_box));
    /// `velocities`: `q̇`.
    ///
    /// # Errors
    /// [`Error::StateOutsideLimits`] for the first dof outside, naming it, its value and its
    /// interval; [`Error::DimensionMismatch`] / [`Error::NonFinite`] for bad input.
    pub fn check_state(&self, positions: &[f64], velocities: &[f64]) -> Result<()> {
        let nv = self.dofs.len();
        check_dim("positions (one per velocity dof)", nv, positions.len())?;
        check_dim("velocities (one per velocity dof)", nv, velocities.len())?;
        check_all_finite("positions", positions)?;
        check_all_finite("velocities", velocities)?;
        for (i, ((dof, &q), &qd)) in self.dofs.iter().zip(positions).zip(velocities).enumerate() {
            let outside =
                |quantity: &str, value: f64, lower: f64, upper: f64| Error::StateOutsideLimits {
                    joint: self.names.get(i).cloned().unwrap_or_default(),
                    quantity: quantity.to_string(),
                    value,
                    lower,
                    upper,
                };
            if q < dof.position_min || q > dof.position_max {
                return Err(outside(
                    "position [rad or m]",
                    q,
                    dof.position_min,
                    dof.position_max,
                ));
            }
            if qd.abs() > dof.velocity_max {
                return Err(outside(
                    "velocity [rad/s or m/s]",
                    qd,
                    -dof.velocity_max,
                    dof.velocity_max,
                ));
            }
        }
        Ok(())
    }

    /// The number of velocity degrees of freedom `nv`.
    pub fn nv(&self) -> usize {
        self.dofs.len()
    }

    /// The limits of every dof, in `q̇` order.
    pub fn dofs(&self) -> &[DofLimits] {
        &self.dofs
    }

    /// The limits of dof `index`, if it exists.
    pub fn get(&self, index: usize) -> Option<&DofLimits> {
        self.dofs.get(index)
    }

    /// Replaces the limits of dof `index` (e.g. to narrow a joint's range, as the paper does in
    /// Section 5.3), after validating them.
    ///
    /// # Errors
    /// [`Error::DimensionMismatch`] if `index ≥ nv`; the validation errors of
    /// [`DofLimits::validate`].
    pub fn set(&mut self, index: usize, limits: DofLimits) -> Result<()> {
        let nv = self.dofs.len();
        let what = format!("dof[{index}]");
        limits.validate(&what)?;
        match self.dofs.get_mut(index) {
            Some(slot) => {
                *slot = limits;
                Ok(())
            }
            None => Err(Error::DimensionMismatch {
                what: format!("JointLimits::set index {index} (must be below nv)"),
                expected: nv,
                got: index,
            }),
        }
    }
}

fn default_names(nv: usize) -> Vec<String> {
    (0..nv).map(|i| format!("dof[{i}]")).collect()
}
