//! Timing and geometry settings of a walk, and the [`Side`] of a foot.

use serde::Serialize;

use crate::error::{Error, Result};

/// Which foot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Side {
    /// The left foot (at `+y` of the body in the nominal stance).
    Left,
    /// The right foot (at `−y` of the body in the nominal stance).
    Right,
}

impl Side {
    /// The other foot.
    pub fn opposite(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }

    /// Sign of the lateral offset of this foot from the body centre line: `+1` left, `−1` right.
    pub fn lateral_sign(self) -> f64 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }
}

/// Timing and geometry of a walk: durations of the support phases, foot placement, swing
/// height and sole size.
///
/// Defaults describe a slow, safe gait of an adult-size humanoid (hip joints 0.192 m apart on
/// JVRC-1): 0.7 s single support, 0.1 s double support, 0.19 m between the foot centres, 5 cm
/// swing height, 0.22 m × 0.12 m soles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WalkSettings {
    /// Duration of one single-support phase (SSP, the swing of one foot) \[s\], `> 0`.
    /// Shorter steps walk faster but need larger COM accelerations and swing-foot speeds.
    pub ssp_duration: f64,
    /// Duration of one double-support phase between two steps (DSP) \[s\], `> 0`. The ZMP
    /// reference moves from one foot to the next during it; shorter means a faster ZMP shift
    /// and a larger preview-control tracking error at the transition.
    pub dsp_duration: f64,
    /// Duration of the first double-support phase \[s\], `≥ dsp_duration`. The ZMP reference
    /// rests between the feet, then moves to the first stance foot during the last
    /// `dsp_duration` of it. Longer lets the COM start from rest without a transient.
    pub initial_dsp_duration: f64,
    /// Duration of the last double-support phase \[s\], `≥ dsp_duration`. The ZMP reference
    /// moves back between the feet during the first `dsp_duration` of it, then rests. Longer
    /// lets the COM come to rest before the pattern ends.
    pub final_dsp_duration: f64,
    /// Distance between the centres of the two feet across the walking direction \[m\], `> sole_width`
    /// (the soles must not overlap).
    pub foot_separation: f64,
    /// Peak height of the swing foot above the ground \[m\], `≥ 0`.
    pub swing_height: f64,
    /// Length of the rectangular sole along the foot's x axis \[m\], `> 0`; the sole is
    /// centred on the foot frame. Defines the support polygon.
    pub sole_length: f64,
    /// Width of the rectangular sole along the foot's y axis \[m\], `> 0`.
    pub sole_width: f64,
    /// The foot that swings first in the generated plans.
    pub first_swing: Side,
}

impl Default for WalkSettings {
    fn default() -> Self {
        Self {
            ssp_duration: 0.7,
            dsp_duration: 0.1,
            initial_dsp_duration: 1.0,
            final_dsp_duration: 1.5,
            foot_separation: 0.19,
            swing_height: 0.05,
            sole_length: 0.22,
            sole_width: 0.12,
            first_swing: Side::Left,
        }
    }
}

/// An [`Error::InvalidSetting`] for a numeric setting.
pub(crate) fn invalid(name: &str, value: f64, expected: &str) -> Error {
    Error::InvalidSetting {
        name: name.to_string(),
        value: value.to_string(),
        expected: expected.to_string(),
    }
}

/// Checks that `value` is finite and `> 0`.
pub(crate) fn check_positive(name: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid(name, value, "a finite number > 0"))
    }
}

/// Checks that `value` is finite and `≥ 0`.
pub(crate) fn check_non_negative(name: &str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(invalid(name, value, "a finite number >= 0"))
    }
}

impl WalkSettings {
    /// Checks every field: durations and sizes finite and positive, the initial and final
    /// double supports at least as long as `dsp_duration`, feet wider apart than the sole.
    pub fn validate(&self) -> Result<()> {
        check_positive("WalkSettings::ssp_duration [s]", self.ssp_duration)?;
        check_positive("WalkSettings::dsp_duration [s]", self.dsp_duration)?;
        check_positive(
            "WalkSettings::initial_dsp_duration [s]",
            self.initial_dsp_duration,
        )?;
        check_positive(
            "WalkSettings::final_dsp_duration [s]",
            self.final_dsp_duration,
        )?;
        if self.initial_dsp_duration < self.dsp_duration {
            return Err(invalid(
                "WalkSettings::initial_dsp_duration [s]",
                self.initial_dsp_duration,
                &format!(">= dsp_duration = {}", self.dsp_duration),
            ));
        }
        if self.final_dsp_duration < self.dsp_duration {
            return Err(invalid(
                "WalkSettings::final_dsp_duration [s]",
                self.final_dsp_duration,
                &format!(">= dsp_duration = {}", self.dsp_duration),
            ));
        }
        check_positive("WalkSettings::sole_length [m]", self.sole_length)?;
        check_positive("WalkSettings::sole_width [m]", self.sole_width)?;
        check_positive("WalkSettings::foot_separation [m]", self.foot_separation)?;
        if self.foot_separation <= self.sole_width {
            return Err(invalid(
                "WalkSettings::foot_separation [m]",
                self.foot_separation,
                &format!(
                    "> sole_width = {} (soles must not overlap)",
                    self.sole_width
                ),
            ));
        }
        check_non_negative("WalkSettings::swing_height [m]", self.swing_height)?;
        Ok(())
    }
}
