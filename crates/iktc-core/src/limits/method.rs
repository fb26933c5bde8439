//! Which formula turns the limits into acceleration bounds, and its settings.

use crate::error::{Error, Result};

/// How joint limits become the acceleration box `b_l ≤ q̈ ≤ b_u`.
///
/// Both variants are kept side by side so that their difference can be seen (errata §3.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BoundMethod {
    /// Proposition 3.1, eq. (14) of the paper, exactly as printed (see [`paper`](super::paper)).
    ///
    /// Not safe in discrete time: the box can empty and the joint overshoot its range
    /// (errata §3.1). No conflict resolution: an empty box is reported as empty.
    Paper,
    /// The discrete-time bounds of Del Prete, *Joint position and velocity bounds in
    /// discrete-time acceleration/torque control of robot manipulators*, IEEE RA-L 3(1), 2018,
    /// as given in errata §3.1 (see [`viable`](super::viable)), with conflict resolution.
    Viable(ViableSettings),
    /// The sources of `Viable` with the continuous braking curve replaced by a discrete braking
    /// profile that ends at rest at a tick (see [`quiet`](super::quiet)): a joint pushed into a
    /// limit comes to rest on it and stays with `q̈ = 0`, where `Viable` chatters. Same settings
    /// (`a_stop = braking_fraction · a_max`) and conflict resolution as `Viable`.
    Quiet(ViableSettings),
}

impl Default for BoundMethod {
    /// [`BoundMethod::Quiet`] with default settings: safe in discrete time, and a joint pushed
    /// into a limit comes to rest on it with `q̈ = 0` instead of chattering.
    fn default() -> Self {
        Self::Quiet(ViableSettings::default())
    }
}

impl BoundMethod {
    /// [`BoundMethod::Viable`] with default settings.
    pub fn viable() -> Self {
        Self::Viable(ViableSettings::default())
    }

    /// [`BoundMethod::Quiet`] with default settings.
    pub fn quiet() -> Self {
        Self::Quiet(ViableSettings::default())
    }

    /// Lower-case name for reports: "paper", "viable", "quiet".
    pub fn name(&self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::Viable(_) => "viable",
            Self::Quiet(_) => "quiet",
        }
    }

    /// Checks the settings of the method.
    ///
    /// # Errors
    /// [`Error::InvalidSetting`] as described in [`ViableSettings::validate`].
    pub fn validate(&self) -> Result<()> {
        match self {
            Self::Paper => Ok(()),
            Self::Viable(settings) | Self::Quiet(settings) => settings.validate(),
        }
    }

    /// The rate of the soft approach to the range ends \[1/s\]
    /// ([`ViableSettings::approach_rate`]); 0 for [`BoundMethod::Paper`], which has none.
    pub fn approach_rate(&self) -> f64 {
        match self {
            Self::Paper => 0.0,
            Self::Viable(s) | Self::Quiet(s) => s.approach_rate,
        }
    }

    /// The rate of the soft approach as used at the control period `dt` \[s\]: the setting,
    /// capped at [`MAX_APPROACH_STEP`]`/dt` \[1/s\]; 0 without it.
    pub fn approach_rate_at(&self, dt: f64) -> f64 {
        self.approach_rate().min(MAX_APPROACH_STEP / dt)
    }

    /// The same method with the soft approach at `rate` \[1/s\] (0 leaves it out).
    ///
    /// # Errors
    /// [`Error::InvalidSetting`] naming `approach_rate` for a rate the settings refuse
    /// ([`ViableSettings::validate`]) or a positive rate with [`BoundMethod::Paper`], whose
    /// bound has no such source.
    pub fn with_approach_rate(self, rate: f64) -> Result<Self> {
        let out = match self {
            Self::Paper if rate == 0.0 => Self::Paper,
            Self::Paper => return Err(Error::InvalidSetting {
                name: "approach_rate".to_string(),
                value: rate.to_string(),
                expected:
                    "0 with the paper's bound (the soft approach needs the viable or quiet bounds)"
                        .to_string(),
            }),
            Self::Viable(s) => Self::Viable(ViableSettings {
                approach_rate: rate,
                ..s
            }),
            Self::Quiet(s) => Self::Quiet(ViableSettings {
                approach_rate: rate,
                ..s
            }),
        };
        out.validate()?;
        Ok(out)
    }

    /// What a run does with a state outside the limits at its start: the setting of
    /// [`ViableSettings::outside`]; always [`OutsideLimits::Error`] for [`BoundMethod::Paper`]
    /// (the paper's bound has no recovery).
    pub fn outside_limits(&self) -> OutsideLimits {
        match self {
            Self::Paper => OutsideLimits::Error,
            Self::Viable(settings) | Self::Quiet(settings) => settings.outside,
        }
    }
}

/// The largest `ω Δt` \[–\] of the soft approach ([`ViableSettings::approach_rate`]): `2 − √2`,
/// up to which both eigenvalues of the discrete approach lie in `[0, 1)` ([`approach`](super::approach));
/// a faster [`approach_rate`](ViableSettings::approach_rate) is taken as `MAX_APPROACH_STEP/Δt`.
pub const MAX_APPROACH_STEP: f64 = 2.0 - std::f64::consts::SQRT_2;

/// What to do with a joint whose position is outside its range (a posture, a lock, a narrowed
/// range or a URDF range that excludes the start state).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OutsideLimits {
    /// Refuse: a run checks its start state with
    /// [`JointLimits::check_state`](super::JointLimits::check_state) and stops with
    /// [`Error::StateOutsideLimits`] naming the joint, its value and its range.
    #[default]
    Error,
    /// Recover: while a joint is outside its range, its box is the single acceleration of
    /// [`recovery_acceleration`](super::viable::recovery_acceleration) (toward the range at the
    /// acceleration limit, arriving at rest on the range's end, no other limit crossed), with
    /// [`BoundSource::Recovery`](super::BoundSource::Recovery) as the source of both sides.
    Recover,
}

/// Settings of [`BoundMethod::Viable`] and [`BoundMethod::Quiet`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViableSettings {
    /// The braking acceleration assumed by the viability bound, as a fraction of the joint's
    /// acceleration limit: `a_stop = braking_fraction · a_max` \[–\], in `(0, 1]`.
    ///
    /// Default 0.5 (errata §3.1). The viability bound keeps the next state able to stop before
    /// the range ends while braking at `a_stop`. At `a_stop = a_max` a joint that sits on its
    /// braking curve needs every bit of its acceleration authority to stay there, so joints
    /// coupled to it through the tasks have none left (in the 3R run it chatters at the limit
    /// and loses higher-priority tasks); a smaller fraction starts braking earlier and more
    /// gently, trading some reachable speed near the range ends for that authority. Too small
    /// a fraction makes the joint crawl toward its limits.
    pub braking_fraction: f64,
    /// What to do with a joint outside its position range (default: refuse at the start).
    pub outside: OutsideLimits,
    /// The rate `ω` \[1/s\] of the soft approach to the range ends
    /// ([`approach`](super::approach)): `q̈ ≤ ω² (q_max − q) − 2ω q̇` and its mirror, at lower
    /// precedence than every limit. 0 (the default) leaves it out. The rate used is at most
    /// [`MAX_APPROACH_STEP`]`/Δt` (117 /s at Δt = 5 ms), the fastest at which the discrete
    /// approach does not alternate tick by tick.
    pub approach_rate: f64,
}

impl Default for ViableSettings {
    fn default() -> Self {
        Self {
            braking_fraction: 0.5,
            outside: OutsideLimits::Error,
            approach_rate: 0.0,
        }
    }
}

impl ViableSettings {
    /// Checks that `braking_fraction` is finite and in `(0, 1]` and `approach_rate` finite and
    /// `≥ 0`.
    ///
    /// # Errors
    /// [`Error::InvalidSetting`] naming `braking_fraction` or `approach_rate`.
    pub fn validate(&self) -> Result<()> {
        let f = self.braking_fraction;
        if !(self.approach_rate.is_finite() && self.approach_rate >= 0.0) {
            return Err(Error::InvalidSetting {
                name: "ViableSettings::approach_rate".to_string(),
                value: self.approach_rate.to_string(),
                expected: "a finite rate >= 0 [1/s] (0: no soft approach)".to_string(),
            });
        }
        if f.is_finite() && f > 0.0 && f <= 1.0 {
            Ok(())
        } else {
            Err(Error::InvalidSetting {
                name: "ViableSettings::braking_fraction".to_string(),
                value: f.to_string(),
                expected: "a fraction of the acceleration limit in (0, 1] [–] (default 0.5)"
                    .to_string(),
            })
        }
    }
}
