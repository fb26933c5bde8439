//! The acceleration box `b_l ≤ q̈ ≤ b_u` (paper eqs. 13–14), with where each side comes from.

use nalgebra::DVector;

use crate::error::{check_all_finite, check_dim, Error, Result};

use super::intersect::DofBounds;
use super::source::{BoundSource, DofBoundSources, DroppedSources};

/// The box `b_l ≤ q̈ ≤ b_u` on the joint accelerations, one entry per velocity dof, and the
/// record of how it was obtained.
///
/// Plain data, filled by [`compute_box`](super::compute_box); sized once with
/// [`AccelerationBox::new`] and reused every control tick. A dof whose `lower > upper` is
/// *empty*: no acceleration satisfies its limits (only position and velocity bounds conflict
/// after the conflict resolution of [`BoundMethod::Viable`](super::BoundMethod); any sources
/// under [`BoundMethod::Paper`](super::BoundMethod)). That is a status for the solver, not an
/// error.
#[derive(Debug, Clone, PartialEq)]
pub struct AccelerationBox {
    /// `b_l` \[rad/s²\] (or \[m/s²\] for prismatic and base translation dofs); `-inf` when
    /// unbounded.
    pub lower: DVector<f64>,
    /// `b_u` \[rad/s²\]; `+inf` when unbounded.
    pub upper: DVector<f64>,
    /// Which source gives each entry of `lower`, after conflict resolution.
    pub lower_source: Vec<BoundSource>,
    /// Which source gives each entry of `upper`, after conflict resolution.
    pub upper_source: Vec<BoundSource>,
    /// Which sources were dropped for each dof to resolve a conflict.
    pub dropped: Vec<DroppedSources>,
    /// The value of every source of each dof before intersection \[rad/s²\].
    pub sources: Vec<DofBoundSources>,
}

impl AccelerationBox {
    /// An unbounded box for `nv` dofs (`lower = -inf`, `upper = +inf`).
    pub fn new(nv: usize) -> Self {
        Self {
            lower: DVector::from_element(nv, f64::NEG_INFINITY),
            upper: DVector::from_element(nv, f64::INFINITY),
            lower_source: vec![BoundSource::None; nv],
            upper_source: vec![BoundSource::None; nv],
            dropped: vec![DroppedSources::default(); nv],
            sources: vec![DofBoundSources::default(); nv],
        }
    }

    /// The number of dofs `nv`.
    pub fn nv(&self) -> usize {
        self.lower.len()
    }

    /// Whether any dof has `lower > upper`.
    pub fn is_empty(&self) -> bool {
        self.empty_dofs().next().is_some()
    }

    /// The indices of the dofs with `lower > upper`.
    pub fn empty_dofs(&self) -> impl Iterator<Item = usize> + '_ {
        self.lower
            .iter()
            .zip(self.upper.iter())
            .enumerate()
            .filter(|(_, (lower, upper))| lower > upper)
            .map(|(i, _)| i)
    }

    /// The indices of the dofs being brought back into their range
    /// ([`BoundSource::Recovery`], under [`OutsideLimits::Recover`](super::OutsideLimits)).
    pub fn recovering_dofs(&self) -> impl Iterator<Item = usize> + '_ {
        self.lower_source
            .iter()
            .enumerate()
            .filter(|(_, s)| **s == BoundSource::Recovery)
            .map(|(i, _)| i)
    }

    /// Whether any dof had a source dropped by conflict resolution.
    pub fn any_dropped(&self) -> bool {
        self.dropped.iter().any(DroppedSources::any)
    }

    /// The interval of dof `index` and its sources, if the dof exists.
    pub fn get(&self, index: usize) -> Option<DofBounds> {
        Some(DofBounds {
            lower: *self.lower.get(index)?,
            upper: *self.upper.get(index)?,
            lower_source: *self.lower_source.get(index)?,
            upper_source: *self.upper_source.get(index)?,
            dropped: *self.dropped.get(index)?,
        })
    }

    /// The largest amount by which `qdd` leaves the box \[rad/s²\]:
    /// `max_i max(b_l,i − q̈_i, q̈_i − b_u,i, 0)`. Positive for every `qdd` when the box is
    /// empty.
    ///
    /// # Errors
    /// [`Error::DimensionMismatch`] if `qdd.len() != nv`; [`Error::NonFinite`] for a NaN or
    /// infinite entry.
    pub fn max_violation(&self, qdd: &[f64]) -> Result<f64> {
        check_dim("qdd (joint accelerations)", self.nv(), qdd.len())?;
        check_all_finite("qdd", qdd)?;
        let mut worst = 0.0_f64;
        for ((&a, &lower), &upper) in qdd.iter().zip(self.lower.iter()).zip(self.upper.iter()) {
            worst = worst.max(lower - a).max(a - upper);
        }
        Ok(worst)
    }

    /// Whether `b_l − tol ≤ q̈ ≤ b_u + tol` for every dof.
    ///
    /// `tolerance` \[rad/s²\] ≥ 0 is explicit because what is acceptable depends on the caller
    /// (a QP solution carries its own residual; a test of exact arithmetic wants rounding only).
    ///
    /// # Errors
    /// As [`max_violation`](Self::max_violation); [`Error::InvalidSetting`] if `tolerance` is
    /// negative or not finite.
    pub fn contains(&self, qdd: &[f64], tolerance: f64) -> Result<bool> {
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(Error::InvalidSetting {
                name: "AccelerationBox::contains tolerance".to_string(),
                value: tolerance.to_string(),
                expected: "a finite value ≥ 0 [rad/s²]".to_string(),
            });
        }
        Ok(self.max_violation(qdd)? <= tolerance)
    }

    /// Writes dof `index`; the caller guarantees `index < nv`.
    pub(super) fn set(&mut self, index: usize, sources: DofBoundSources, bounds: DofBounds) {
        if let (Some(l), Some(u), Some(ls), Some(us), Some(d), Some(s)) = (
            self.lower.get_mut(index),
            self.upper.get_mut(index),
            self.lower_source.get_mut(index),
            self.upper_source.get_mut(index),
            self.dropped.get_mut(index),
            self.sources.get_mut(index),
        ) {
            *l = bounds.lower;
            *u = bounds.upper;
            *ls = bounds.lower_source;
            *us = bounds.upper_source;
            *d = bounds.dropped;
            *s = sources;
        }
    }

    /// Checks that every per-dof vector has length `nv` (the fields are public).
    pub(super) fn check_consistent(&self, nv: usize) -> Result<()> {
        check_dim("AccelerationBox::lower", nv, self.lower.len())?;
        check_dim("AccelerationBox::upper", nv, self.upper.len())?;
        check_dim("AccelerationBox::lower_source", nv, self.lower_source.len())?;
        check_dim("AccelerationBox::upper_source", nv, self.upper_source.len())?;
        check_dim("AccelerationBox::dropped", nv, self.dropped.len())?;
        check_dim("AccelerationBox::sources", nv, self.sources.len())
    }
}

#[cfg(test)]
mod tests {
    use super::AccelerationBox;
    use nalgebra::DVector;

    fn boxed(lower: &[f64], upper: &[f64]) -> AccelerationBox {
        let mut b = AccelerationBox::new(lower.len());
        b.lower = DVector::from_column_slice(lower);
        b.upper = DVector::from_column_slice(upper);
        b
    }

    /// A zero-width interval (lower = upper, a joint held) is not empty; lower > upper is.
    #[test]
    fn only_crossed_intervals_are_empty() {
        let b = boxed(&[0.0, 1.0, -2.0, 3.0], &[0.0, 2.0, -2.0, 2.5]);
        assert_eq!(b.empty_dofs().collect::<Vec<_>>(), [3]);
        assert!(b.is_empty());
        let held = boxed(&[1.0, -1.0], &[1.0, -1.0]);
        assert!(!held.is_empty());
        assert_eq!(held.nv(), 2);
    }

    /// The violation is the largest distance outside the box, 0 inside, and `contains`
    /// compares it with the tolerance inclusively.
    #[test]
    fn violation_is_the_largest_distance_outside() {
        let b = boxed(&[-1.0, 0.0, 2.0], &[1.0, 0.5, 3.0]);
        assert_eq!(b.max_violation(&[0.0, 0.25, 2.5]).ok(), Some(0.0));
        assert_eq!(b.max_violation(&[-1.5, 0.75, 2.5]).ok(), Some(0.5));
        assert_eq!(b.max_violation(&[0.0, 0.0, 5.0]).ok(), Some(2.0));
        assert_eq!(b.contains(&[0.0, 0.0, 3.25], 0.25).ok(), Some(true));
        assert_eq!(b.contains(&[0.0, 0.0, 3.5], 0.25).ok(), Some(false));
        assert!(b.contains(&[0.0, 0.0], 0.0).is_err());
        assert!(b.contains(&[0.0, f64::NAN, 0.0], 0.0).is_err());
        assert!(b.contains(&[0.0, 0.0, 2.5], -1.0).is_err());
        assert!(b.contains(&[0.0, 0.0, 2.5], f64::NAN).is_err());
    }
}
