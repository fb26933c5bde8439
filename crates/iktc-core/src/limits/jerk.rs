//! Optional jerk limits: a fourth source of bound, on how much the commanded acceleration may
//! change from one tick to the next.
//!
//! **The source.** A dof with a jerk limit `j_max` \[rad/s³\] keeps its command within
//! `j_max Δt` of the previous tick's `q̈₋`:
//!
//! ```text
//! q̈₋ − j_max Δt ≤ q̈ ≤ q̈₋ + j_max Δt.
//! ```
//!
//! Under the paper's constant-acceleration integration the command is a staircase, so this
//! bounds the size of each step: the finite-difference jerk `(q̈ − q̈₋)/Δt` stays within
//! `±j_max`. Servo drives have such limits (a step of commanded acceleration is a step of
//! motor current).
//!
//! **Why the box never empties because of it.** The jerk source is applied last, to the
//! interval `[L, U]` that the position, velocity, viability and acceleration sources leave after
//! their own conflict resolution ([`intersect`](super::intersect)), and it has the lowest
//! precedence: if `[L, U]` meets the jerk interval the box is their intersection; if not, the
//! box is the single point of `[L, U]` nearest to the jerk interval (`U` when the jerk interval
//! lies above it, `L` when below), so the jerk limit is exceeded by the least amount and
//! [`DroppedSources::jerk`](super::DroppedSources) says so. Every other limit is kept exactly
//! as without a jerk limit, and the box is empty only when `[L, U]` already was.
//!
//! The viability argument of [`viable`](super::viable) and [`quiet`](super::quiet) is thus
//! unchanged: a state that can stop inside its range under `±a_stop` still can, because every
//! acceleration the box admits is one that box admitted before. The jerk limit is not part of
//! the stopping profile, so near a limit it can be exceeded: braking that starts while the
//! joint still accelerates toward the limit needs a step of `q̈` larger than `j_max Δt` when
//! `j_max < (|q̈₋| + a_stop)/Δt`. How often that happens is in the report
//! ([`AccelerationBox::dropped`](super::AccelerationBox)); a smaller
//! [`braking_fraction`](super::ViableSettings::braking_fraction) starts braking earlier and
//! makes it rarer.

use crate::error::{check_all_finite, check_dim, Result};

use super::acceleration_box::AccelerationBox;
use super::intersect::{give_way, DofBounds};
use super::joint_limits::JointLimits;
use super::source::BoundSource;

/// The interval `[q̈₋ − j_max Δt, q̈₋ + j_max Δt]` \[rad/s²\] for the previous command
/// `previous` = `q̈₋` \[rad/s²\], the jerk limit `jerk_max` \[rad/s³\] (`+inf`: no limit) and the
/// period `dt` \[s\].
pub fn jerk_interval(previous: f64, jerk_max: f64, dt: f64) -> (f64, f64) {
    if jerk_max == f64::INFINITY {
        return (f64::NEG_INFINITY, f64::INFINITY);
    }
    let step = jerk_max * dt;
    (previous - step, previous + step)
}

/// The interval `resolved` of the other sources with the jerk source applied (module docs):
/// their intersection when it is not empty, otherwise the point of `resolved` nearest to the
/// jerk interval `[jerk_lower, jerk_upper]` \[rad/s²\], with `dropped.jerk` set. An empty
/// `resolved` is returned unchanged.
pub fn apply_jerk(resolved: DofBounds, jerk_lower: f64, jerk_upper: f64) -> DofBounds {
    let (mut out, gave_way) = give_way(resolved, jerk_lower, jerk_upper, BoundSource::Jerk);
    out.dropped.jerk |= gave_way;
    out
}

/// Applies the jerk limits of `limits` to a box computed by
/// [`compute_box`](super::compute_box) for the same limits and period, given the previous
/// tick's command `previous_qdd` \[rad/s²\] (one entry per velocity dof) and the period `dt`
/// \[s\] (module docs). Records the jerk source of each dof in `out.sources`. Dofs without a
/// jerk limit are left as they are. Allocates nothing.
///
/// # Errors
/// [`Error::DimensionMismatch`](crate::Error::DimensionMismatch) when a length differs from
/// `limits.nv()`; [`Error::NonFinite`](crate::Error::NonFinite) for a NaN or infinite entry of
/// `previous_qdd`. On error `out` is left unchanged.
pub fn limit_jerk(
    limits: &JointLimits,
    previous_qdd: &[f64],
    dt: f64,
    out: &mut AccelerationBox,
) -> Result<()> {
    let nv = limits.nv();
    check_dim(
        "previous_qdd (one entry per velocity dof)",
        nv,
        previous_qdd.len(),
    )?;
    out.check_consistent(nv)?;
    check_all_finite("previous_qdd", previous_qdd)?;
    for (i, (dof, &previous)) in limits.dofs().iter().zip(previous_qdd).enumerate() {
        if dof.jerk_max == f64::INFINITY {
            continue;
        }
        let (lower, upper) = jerk_interval(previous, dof.jerk_max, dt);
        let Some(resolved) = out.get(i) else {
            continue;
        };
        let mut sources = out.sources[i];
        sources.lower.jerk = lower;
        sources.upper.jerk = upper;
        out.set(i, sources, apply_jerk(resolved, lower, upper));
    }
    Ok(())
}

impl JointLimits {
    /// Whether any dof has a jerk limit.
    pub fn has_jerk_limits(&self) -> bool {
        self.dofs().iter().any(|d| d.jerk_max < f64::INFINITY)
    }
}

#[cfg(test)]
mod tests {
    use super::{apply_jerk, jerk_interval};
    use crate::limits::{BoundSource, DofBounds, DroppedSources};

    fn interval(lower: f64, upper: f64) -> DofBounds {
        DofBounds {
            lower,
            upper,
            lower_source: BoundSource::Position,
            upper_source: BoundSource::Velocity,
            dropped: DroppedSources::default(),
        }
    }

    #[test]
    fn the_jerk_interval_is_centred_on_the_previous_command() {
        assert_eq!(jerk_interval(2.0, 100.0, 0.01), (1.0, 3.0));
        assert_eq!(
            jerk_interval(2.0, f64::INFINITY, 0.01),
            (f64::NEG_INFINITY, f64::INFINITY)
        );
    }

    /// Overlap: the intersection, with the jerk named where it binds; apart: the nearest end
    /// of the other sources' interval, jerk marked dropped; empty: unchanged.
    #[test]
    fn the_jerk_source_intersects_or_gives_way_by_the_least_amount() {
        let b = apply_jerk(interval(-1.0, 1.0), -0.5, 2.0);
        assert_eq!((b.lower, b.upper), (-0.5, 1.0));
        assert_eq!(
            (b.lower_source, b.upper_source),
            (BoundSource::Jerk, BoundSource::Velocity)
        );
        assert!(!b.dropped.jerk);
        let above = apply_jerk(interval(-1.0, 1.0), 1.5, 3.0);
        assert_eq!((above.lower, above.upper), (1.0, 1.0));
        assert_eq!(above.lower_source, BoundSource::Velocity);
        assert!(above.dropped.jerk);
        let below = apply_jerk(interval(-1.0, 1.0), -4.0, -2.0);
        assert_eq!((below.lower, below.upper), (-1.0, -1.0));
        assert_eq!(below.upper_source, BoundSource::Position);
        assert!(below.dropped.jerk);
        let empty = interval(1.0, -1.0);
        assert_eq!(apply_jerk(empty, -0.5, 0.5), empty);
    }
}
