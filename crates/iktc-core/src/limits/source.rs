//! The separate sources of an acceleration bound, and which one binds.

/// Which limit a side of the acceleration box comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum BoundSource {
    /// No limit applies to this side: the bound is infinite.
    #[default]
    None,
    /// The acceleration limit `±a_max`.
    Acceleration,
    /// The velocity limit: `q̇⁺ = q̇ + Δt q̈` within `±v_max`.
    Velocity,
    /// The discrete-time position bound of [`BoundMethod::Viable`](super::BoundMethod):
    /// the position stays in range over the whole step, in-step peak included.
    Position,
    /// The viability bound of [`BoundMethod::Viable`](super::BoundMethod): the next state can
    /// still stop inside the range braking at `a_stop`.
    Viability,
    /// The third term of the paper's eq. (14), `(±√(2 a_max d) − q̇)/Δt`, used by
    /// [`BoundMethod::Paper`](super::BoundMethod).
    PaperPosition,
    /// The joint is outside its position range and being brought back
    /// ([`OutsideLimits::Recover`](super::OutsideLimits)): both sides are the recovery
    /// acceleration of [`recovery_acceleration`](super::viable::recovery_acceleration).
    Recovery,
    /// The jerk limit: `q̈` within `j_max Δt` of the previous tick's `q̈`
    /// ([`limit_jerk`](super::limit_jerk)).
    Jerk,
    /// The soft approach to a range end of [`ViableSettings::approach_rate`](super::ViableSettings):
    /// `q̈ ≤ ω² (q_max − q) − 2ω q̇` (mirrored below), see [`approach`](super::approach).
    Approach,
}

/// Which sources conflict resolution removed for one dof (both sides).
///
/// Only [`BoundMethod::Viable`](super::BoundMethod) and `Quiet` drop sources: first the acceleration
/// limit, then the viability bound; position and velocity bounds are never dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct DroppedSources {
    /// The acceleration limit was dropped: the box lets `|q̈|` exceed `a_max`.
    pub acceleration: bool,
    /// The viability bound was dropped as well: the next state may be unable to stop inside
    /// the range.
    pub viability: bool,
    /// The jerk limit was relaxed ([`limit_jerk`](super::limit_jerk)): the interval of the other
    /// sources lies outside `q̈₋ ± j_max Δt`, and the point of it nearest to that interval is
    /// taken.
    pub jerk: bool,
    /// The soft approach to a range end gave way ([`approach`](super::approach)): the other
    /// sources' interval lies outside the approach interval, and the point of it nearest to
    /// that interval is taken (a joint moving faster than the approach allows brakes at the
    /// other limits instead).
    pub approach: bool,
}

impl DroppedSources {
    /// Whether any source was dropped.
    pub fn any(&self) -> bool {
        self.acceleration || self.viability || self.jerk || self.approach
    }
}

/// The value of every source of bound on one side of one dof \[rad/s²\].
///
/// On the upper side each entry is an upper bound on `q̈` (`+inf` when that limit does not
/// apply); on the lower side a lower bound (`-inf` when it does not apply). A source that the
/// method does not use is infinite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SourceBounds {
    /// From the acceleration limit: `±a_max`.
    pub acceleration: f64,
    /// From the velocity limit: `(±v_max − q̇)/Δt`.
    pub velocity: f64,
    /// From the position range: [`BoundSource::Position`] for `Viable`,
    /// [`BoundSource::PaperPosition`] for `Paper`.
    pub position: f64,
    /// From viability (`Viable` only; infinite for `Paper`).
    pub viability: f64,
    /// From the jerk limit: `q̈₋ ± j_max Δt` ([`limit_jerk`](super::limit_jerk)); infinite
    /// when the dof has no jerk limit or the box was computed without one.
    pub jerk: f64,
    /// From the soft approach to the range end: `ω² (q_max − q) − 2ω q̇` on the upper side,
    /// `−ω² (q − q_min) − 2ω q̇` on the lower ([`approach`](super::approach)); infinite when
    /// [`ViableSettings::approach_rate`](super::ViableSettings) is 0 or the range end is.
    pub approach: f64,
}

impl SourceBounds {
    /// Every source absent on the upper side (`+inf`).
    pub const UPPER_NONE: Self = Self::all(f64::INFINITY);
    /// Every source absent on the lower side (`-inf`).
    pub const LOWER_NONE: Self = Self::all(f64::NEG_INFINITY);

    const fn all(value: f64) -> Self {
        Self {
            acceleration: value,
            velocity: value,
            position: value,
            viability: value,
            jerk: value,
            approach: value,
        }
    }
}

/// Every source of bound of one dof, before intersection \[rad/s²\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DofBoundSources {
    /// Lower bounds on `q̈`, one per source.
    pub lower: SourceBounds,
    /// Upper bounds on `q̈`, one per source.
    pub upper: SourceBounds,
}

impl Default for DofBoundSources {
    /// No bound at all.
    fn default() -> Self {
        Self {
            lower: SourceBounds::LOWER_NONE,
            upper: SourceBounds::UPPER_NONE,
        }
    }
}
