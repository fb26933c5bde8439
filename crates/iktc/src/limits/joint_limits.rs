//! The limits of each velocity degree of freedom: position range, velocity and acceleration.

use crate::error::{Error, Result};

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
}

impl DofLimits {
    /// A degree of freedom without any limit (all four entries infinite), e.g. a floating-base
    /// dof.
    pub fn unlimited() -> Self {
        Self {
            position_min: f64::NEG_INFINITY,
            position_max: f64::INFINITY,
            velocity_max: f64::INFINITY,
            acceleration_max: f64::INFINITY,
        }
    }

    /// Checks the entries, naming the dof as `what` in the error.
    ///
    /// Rules: no NaN ([`Error::NonFinite`]); `position_min ≤ position_max`, `position_min < +inf`
    /// and `position_max > -inf` ([`Error::InvalidLimit`]); `velocity_max > 0` and
    /// `acceleration_max > 0`, `+inf` allowed ([`Error::InvalidSetting`]).
    pub fn validate(&self, what: &str) -> Result<()> {
        let fields = [
            ("position_min", self.position_min),
            ("position_max", self.position_max),
            ("velocity_max", self.velocity_max),
            ("acceleration_max", self.acceleration_max),
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
        Ok(Self { dofs })
    }

    /// `nv` degrees of freedom without any limit.
    pub fn unlimited(nv: usize) -> Self {
        Self {
            dofs: vec![DofLimits::unlimited(); nv],
        }
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
