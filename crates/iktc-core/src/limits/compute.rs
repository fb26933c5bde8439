//! From joint limits and the current state to the acceleration box of one control tick.

use crate::error::{check_all_finite, check_dim, check_finite, Error, Result};

use super::acceleration_box::AccelerationBox;
use super::approach::{apply_approach, approach_interval};
use super::intersect::{intersect, DofBounds};
use super::joint_limits::{DofLimits, JointLimits};
use super::method::{BoundMethod, OutsideLimits};
use super::paper::paper_sources;
use super::quiet::quiet_sources;
use super::source::{BoundSource, DofBoundSources, DroppedSources};
use super::viable::{recovery_acceleration, viable_sources};

/// Computes the acceleration box `b_l ≤ q̈ ≤ b_u` (paper eqs. 13–14) for one control period.
///
/// For each dof `i` the sources of bound are computed separately ([`paper_sources`] for
/// [`BoundMethod::Paper`], eq. 14; [`viable_sources`] for [`BoundMethod::Viable`], errata §3.1
/// after Del Prete, RA-L 2018), then intersected with conflict resolution ([`intersect`]).
/// With [`OutsideLimits::Recover`] a dof outside its position range gets the single
/// recovery acceleration instead ([`BoundSource::Recovery`] on both sides).
/// Everything is written into `out`, including every source value, the binding source of each
/// side and the dropped sources. An empty box is a status ([`AccelerationBox::is_empty`]), not
/// an error. Allocates nothing.
///
/// * `position`: `q` per velocity dof \[rad\] or \[m\], length `nv` (for a floating base, any
///   finite value: its limits are infinite);
/// * `velocity`: `q̇` \[rad/s\] or \[m/s\], length `nv`;
/// * `dt`: the control period `Δt` \[s\], finite and positive; the bounds assume the
///   constant-acceleration integrator
///   ([`integrate_constant_acceleration`](super::integrate_constant_acceleration)) over `Δt`.
///
/// # Errors
/// [`Error::InvalidSetting`] for a bad method setting or `dt ≤ 0`; [`Error::NonFinite`] for a
/// NaN or infinite `dt`, position or velocity; [`Error::DimensionMismatch`] when a length
/// differs from `limits.nv()`. On error `out` is left unchanged.
pub fn compute_box(
    limits: &JointLimits,
    method: &BoundMethod,
    position: &[f64],
    velocity: &[f64],
    dt: f64,
    out: &mut AccelerationBox,
) -> Result<()> {
    method.validate()?;
    check_time_step(dt)?;
    let nv = limits.nv();
    check_dim("position (one entry per velocity dof)", nv, position.len())?;
    check_dim("velocity (one entry per velocity dof)", nv, velocity.len())?;
    out.check_consistent(nv)?;
    check_all_finite("position", position)?;
    check_all_finite("velocity", velocity)?;

    for (i, ((dof, &q), &qd)) in limits.dofs().iter().zip(position).zip(velocity).enumerate() {
        let sources = sources_unchecked(dof, method, q, qd, dt);
        out.set(i, sources, resolve(dof, method, &sources, q, qd, dt));
    }
    Ok(())
}

/// The interval of one dof: the intersection of its sources; the recovery acceleration when
/// the method asks for recovery and the dof is outside its range; for
/// [`BoundMethod::Viable`] or [`BoundMethod::Quiet`] and a zero-width range, the single acceleration `−q̇/Δt` that
/// stops the joint within the step (its only viable state is at rest on the range, where
/// this is 0; off it by a solver tolerance, stopping keeps the deviation from growing, which
/// the bounds of a widened range would not).
fn resolve(
    dof: &DofLimits,
    method: &BoundMethod,
    sources: &DofBoundSources,
    q: f64,
    qd: f64,
    dt: f64,
) -> DofBounds {
    if let BoundMethod::Viable(settings) | BoundMethod::Quiet(settings) = method {
        if settings.outside == OutsideLimits::Recover {
            if let Some(x) = recovery_acceleration(dof, settings, q, qd, dt) {
                return DofBounds {
                    lower: x,
                    upper: x,
                    lower_source: BoundSource::Recovery,
                    upper_source: BoundSource::Recovery,
                    dropped: DroppedSources::default(),
                };
            }
        }
        if dof.position_min == dof.position_max {
            let stop = -qd / dt;
            return DofBounds {
                lower: stop,
                upper: stop,
                lower_source: BoundSource::Position,
                upper_source: BoundSource::Position,
                dropped: DroppedSources::default(),
            };
        }
    }
    apply_approach(
        intersect(sources, method),
        sources.lower.approach,
        sources.upper.approach,
    )
}

/// The sources and the resolved interval of a single dof; the one-dof version of
/// [`compute_box`], for tests, reports and single-joint studies.
///
/// `q` \[rad\], `qd` \[rad/s\], `dt` \[s\]. The limits are validated here as well.
///
/// # Errors
/// As [`compute_box`], and the errors of [`DofLimits::validate`].
pub fn compute_dof(
    limits: &DofLimits,
    method: &BoundMethod,
    q: f64,
    qd: f64,
    dt: f64,
) -> Result<(DofBoundSources, DofBounds)> {
    limits.validate("dof")?;
    method.validate()?;
    check_time_step(dt)?;
    check_finite(|| "position".to_string(), q)?;
    check_finite(|| "velocity".to_string(), qd)?;
    let sources = sources_unchecked(limits, method, q, qd, dt);
    Ok((sources, resolve(limits, method, &sources, q, qd, dt)))
}

fn sources_unchecked(
    dof: &DofLimits,
    method: &BoundMethod,
    q: f64,
    qd: f64,
    dt: f64,
) -> DofBoundSources {
    let (mut sources, settings) = match method {
        BoundMethod::Paper => return paper_sources(dof, q, qd, dt),
        BoundMethod::Viable(settings) => (viable_sources(dof, settings, q, qd, dt), settings),
        BoundMethod::Quiet(settings) => (quiet_sources(dof, settings, q, qd, dt), settings),
    };
    if settings.approach_rate > 0.0 {
        let (lower, upper) = approach_interval(dof, q, qd, method.approach_rate_at(dt));
        sources.lower.approach = lower;
        sources.upper.approach = upper;
    }
    sources
}

fn check_time_step(dt: f64) -> Result<()> {
    check_finite(|| "dt (control period) [s]".to_string(), dt)?;
    if dt > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidSetting {
            name: "dt (control period)".to_string(),
            value: dt.to_string(),
            expected: "a positive time step [s]".to_string(),
        })
    }
}
