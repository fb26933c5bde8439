//! Intersecting the sources of one dof, with the conflict resolution of errata §3.1.

use super::method::BoundMethod;
use super::source::{BoundSource, DofBoundSources, DroppedSources, SourceBounds};

/// The acceleration interval of one dof after intersection and conflict resolution \[rad/s²\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DofBounds {
    /// Lower bound `b_l` on `q̈` \[rad/s²\]; `-inf` when nothing bounds it.
    pub lower: f64,
    /// Upper bound `b_u` on `q̈` \[rad/s²\]; `+inf` when nothing bounds it.
    pub upper: f64,
    /// The source that gives `lower`.
    pub lower_source: BoundSource,
    /// The source that gives `upper`.
    pub upper_source: BoundSource,
    /// The sources removed to resolve a conflict.
    pub dropped: DroppedSources,
}

impl DofBounds {
    /// Whether the interval is empty (`lower > upper`).
    pub fn is_empty(&self) -> bool {
        self.lower > self.upper
    }
}

/// Intersects the sources of one dof: `b_u = min` and `b_l = max` over the sources.
///
/// * [`BoundMethod::Paper`]: eq. (14) as printed; an empty interval stays empty.
/// * [`BoundMethod::Viable`] and [`BoundMethod::Quiet`]: if `b_l > b_u`, the acceleration limit is dropped and the
///   intersection `[L, U]` of the other sources is redone; the interval is then the part of
///   `[L, U]` closest to `[−a_max, a_max]`: `[max(L, min(−a_max, U)), min(U, max(a_max, L))]`,
///   a single point (`U` or `L`) when the two do not overlap, so the acceleration limit is
///   exceeded by the least amount (from a viable state only by rounding, see
///   [`viable`](super::viable)); [`DroppedSources::acceleration`] says whether it is. If
///   `[L, U]` is still empty, the viability bound is dropped too. The position and velocity bounds are never dropped: if they conflict, the interval
///   is returned empty, with the sources that conflict (errata §3.1).
///
/// The binding source of a side is the one attaining the bound among those kept; on a tie the
/// first of position, viability, velocity, acceleration is named. A side with no finite bound
/// is [`BoundSource::None`].
pub fn intersect(sources: &DofBoundSources, method: &BoundMethod) -> DofBounds {
    let position_source = match method {
        BoundMethod::Paper => BoundSource::PaperPosition,
        BoundMethod::Viable(_) | BoundMethod::Quiet(_) => BoundSource::Position,
    };
    let mut dropped = DroppedSources::default();
    let mut bounds = intersect_kept(sources, position_source, dropped);
    if let BoundMethod::Viable(_) | BoundMethod::Quiet(_) = method {
        if bounds.is_empty() {
            dropped.acceleration = true;
            bounds = intersect_kept(sources, position_source, dropped);
        }
        if bounds.is_empty() {
            dropped.viability = true;
            bounds = intersect_kept(sources, position_source, dropped);
        }
        if dropped.acceleration {
            bounds = closest_to_acceleration_limit(bounds, sources);
        }
    }
    bounds
}

/// `resolved` = `[L, U]` with a lower-precedence source's interval `[lower, upper]` \[rad/s²\]
/// applied (the approach and the jerk sources): their intersection when it is not empty, the
/// sides it tightens named `source`; otherwise the point of `[L, U]` nearest to it (`U` when
/// the interval lies above, `L` when below), so the source gives way by the least amount and
/// every other limit holds. The flag says whether it gave way. An empty `resolved` is
/// returned unchanged.
pub(crate) fn give_way(
    resolved: DofBounds,
    lower: f64,
    upper: f64,
    source: BoundSource,
) -> (DofBounds, bool) {
    if resolved.is_empty() {
        return (resolved, false);
    }
    let mut out = resolved;
    if lower > resolved.upper {
        out.lower = resolved.upper;
        out.lower_source = resolved.upper_source;
        return (out, true);
    }
    if upper < resolved.lower {
        out.upper = resolved.lower;
        out.upper_source = resolved.lower_source;
        return (out, true);
    }
    if lower > resolved.lower {
        out.lower = lower;
        out.lower_source = source;
    }
    if upper < resolved.upper {
        out.upper = upper;
        out.upper_source = source;
    }
    (out, false)
}

/// The part of a non-empty `[L, U]` closest to `[−a_max, a_max]` (see [`intersect`]); an empty
/// interval is returned unchanged.
fn closest_to_acceleration_limit(relaxed: DofBounds, sources: &DofBoundSources) -> DofBounds {
    if relaxed.is_empty() {
        return relaxed;
    }
    let (acc_lower, acc_upper) = (sources.lower.acceleration, sources.upper.acceleration);
    let mut out = relaxed;
    // Lower: max(L, min(−a_max, U)).
    if acc_lower > relaxed.upper {
        out.lower = relaxed.upper;
        out.lower_source = relaxed.upper_source;
    } else if acc_lower > relaxed.lower {
        out.lower = acc_lower;
        out.lower_source = BoundSource::Acceleration;
    }
    // Upper: min(U, max(a_max, L)).
    if acc_upper < relaxed.lower {
        out.upper = relaxed.lower;
        out.upper_source = relaxed.lower_source;
    } else if acc_upper < relaxed.upper {
        out.upper = acc_upper;
        out.upper_source = BoundSource::Acceleration;
    }
    // Dropped only if the acceleration limit is actually exceeded.
    out.dropped.acceleration = out.lower < acc_lower || out.upper > acc_upper;
    out
}

fn intersect_kept(
    sources: &DofBoundSources,
    position_source: BoundSource,
    dropped: DroppedSources,
) -> DofBounds {
    // Negating the lower side turns its max into a min, so one routine serves both sides.
    let (neg_lower, lower_source) = tightest(&negate(&sources.lower), position_source, dropped);
    let (upper, upper_source) = tightest(&sources.upper, position_source, dropped);
    DofBounds {
        lower: -neg_lower,
        upper,
        lower_source,
        upper_source,
        dropped,
    }
}

fn negate(side: &SourceBounds) -> SourceBounds {
    SourceBounds {
        acceleration: -side.acceleration,
        velocity: -side.velocity,
        position: -side.position,
        viability: -side.viability,
        jerk: -side.jerk,
        approach: -side.approach,
    }
}

/// The smallest kept upper bound of one side and its source (`+inf`, `None` if all infinite).
fn tightest(
    side: &SourceBounds,
    position_source: BoundSource,
    dropped: DroppedSources,
) -> (f64, BoundSource) {
    let candidates = [
        (side.position, position_source, true),
        (side.viability, BoundSource::Viability, !dropped.viability),
        (side.velocity, BoundSource::Velocity, true),
        (
            side.acceleration,
            BoundSource::Acceleration,
            !dropped.acceleration,
        ),
    ];
    let mut best = (f64::INFINITY, BoundSource::None);
    for (value, source, kept) in candidates {
        if kept && value < best.0 {
            best = (value, source);
        }
    }
    best
}
