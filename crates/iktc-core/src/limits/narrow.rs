//! Joint ranges narrowed inside the joints' own (the paper narrows the left knee and hip roll in
//! Section 5.3, Fig. 20, so that the pelvis tasks get corrected): one type for the robot
//! profile's key `narrow`, the scenario settings and the run records.

use serde::{Deserialize, Serialize};

use super::joint_limits::{DofLimits, JointLimits};
use crate::error::{Error, Result};

/// A joint's position range narrowed to `[lower, upper]` \[rad or m\], inside its own range.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NarrowedJoint {
    /// Active joint name.
    pub joint: String,
    /// New lower limit \[rad or m\].
    pub lower: f64,
    /// New upper limit \[rad or m\].
    pub upper: f64,
}

impl NarrowedJoint {
    /// Checks that the range is finite and not empty (`lower ≤ upper`).
    ///
    /// # Errors
    /// [`Error::InvalidSetting`] naming `what` (e.g. `narrow.L_KNEE`) and the range.
    pub fn validate(&self, what: &str) -> Result<()> {
        if self.lower.is_finite() && self.upper.is_finite() && self.lower <= self.upper {
            Ok(())
        } else {
            Err(Error::InvalidSetting {
                name: what.into(),
                value: format!("[{}, {}]", self.lower, self.upper),
                expected: "finite [lower, upper] with lower <= upper [rad]".into(),
            })
        }
    }
}

impl JointLimits {
    /// These limits with each narrowed joint's position range replaced by its narrowed one.
    /// Joints are found by their dof names ([`JointLimits::with_names`]); velocity and
    /// acceleration limits are kept.
    ///
    /// # Errors
    /// [`Error::InvalidSetting`] for an empty or non-finite range, a joint no dof is named
    /// after (listing the names), or a range that is not inside the joint's own.
    pub fn narrowed(mut self, narrow: &[NarrowedJoint]) -> Result<Self> {
        for n in narrow {
            let what = format!("narrowed range of {}", n.joint);
            n.validate(&what)?;
            let index = (0..self.nv())
                .find(|&i| self.name(i) == Some(n.joint.as_str()))
                .ok_or_else(|| Error::InvalidSetting {
                    name: what.clone(),
                    value: n.joint.clone(),
                    expected: format!(
                        "a joint of the robot; joints are {}",
                        crate::error::name_list(
                            &(0..self.nv())
                                .filter_map(|i| self.name(i))
                                .collect::<Vec<_>>()
                        )
                    ),
                })?;
            let own = self.dofs()[index];
            if n.lower < own.position_min || n.upper > own.position_max {
                return Err(Error::InvalidSetting {
                    name: what,
                    value: format!("[{}, {}]", n.lower, n.upper),
                    expected: format!(
                        "a range inside the joint's own [{}, {}] rad",
                        own.position_min, own.position_max
                    ),
                });
            }
            self.set(
                index,
                DofLimits {
                    position_min: n.lower,
                    position_max: n.upper,
                    ..own
                },
            )?;
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> JointLimits {
        let dof = |lo: f64, hi: f64| DofLimits {
            position_min: lo,
            position_max: hi,
            velocity_max: 2.0,
            acceleration_max: 20.0,
            jerk_max: f64::INFINITY,
        };
        JointLimits::new(vec![dof(-1.0, 1.0), dof(0.0, 2.0)])
            .unwrap()
            .with_names(vec!["A".into(), "B".into()])
            .unwrap()
    }

    fn narrow(joint: &str, lower: f64, upper: f64) -> NarrowedJoint {
        NarrowedJoint {
            joint: joint.into(),
            lower,
            upper,
        }
    }

    #[test]
    fn only_the_named_joints_position_range_changes() {
        let l = limits().narrowed(&[narrow("B", 0.5, 1.5)]).unwrap();
        assert_eq!(l.dofs()[0], limits().dofs()[0]);
        let b = l.dofs()[1];
        assert_eq!((b.position_min, b.position_max), (0.5, 1.5));
        assert_eq!((b.velocity_max, b.acceleration_max), (2.0, 20.0));
    }

    #[test]
    fn bad_ranges_and_unknown_joints_are_errors_naming_them() {
        for (n, needle) in [
            (narrow("B", 1.5, 0.5), "lower <= upper"),
            (narrow("B", f64::NAN, 0.5), "finite"),
            (narrow("B", -0.5, 1.0), "inside the joint's own [0, 2]"),
            (narrow("B", 0.5, 2.5), "inside the joint's own [0, 2]"),
            (narrow("C", 0.0, 0.1), "joints are A, B"),
        ] {
            let e = limits()
                .narrowed(std::slice::from_ref(&n))
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle) && e.contains(&n.joint), "{e}");
        }
    }

    #[test]
    fn a_range_equal_to_the_own_one_is_accepted() {
        let l = limits().narrowed(&[narrow("A", -1.0, 1.0)]).unwrap();
        assert_eq!(l, limits());
    }
}
