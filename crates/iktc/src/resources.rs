//! Stated maxima on what an input may make iktc allocate or run.
//!
//! A file or a setting can ask for an arbitrary amount of work: a BVH `Frame Time: 1e6`, a
//! control period of 1e-300 s, 10 000 walking steps. Every such request is checked against a
//! maximum *before* anything is allocated; going over is an [`Error::ResourceLimit`] naming the
//! limit, the value asked for and the option that raises it.
//!
//! * [`ReadLimits`] — what a file may hold: XML nesting depth, clip duration and frame count.
//! * [`RunLimits`] — what a run may do: the control period's range and the number of ticks.

use crate::error::{Error, Result};

/// Limits on what a file read by iktc may hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReadLimits {
    /// Deepest element nesting accepted in a URDF \[elements\]. Default 64: a URDF nests 5 deep
    /// (`robot` › `link` › `visual` › `geometry` › `mesh`); the parser recurses once per level,
    /// so the limit also keeps the stack small. Raised with `ReadLimits::max_xml_depth`.
    pub max_xml_depth: usize,
    /// Longest accepted clip \[s\]. Default 3600 s (an hour of capture). Raised with
    /// `ReadLimits::max_clip_duration` (CLI `--max-clip-duration`).
    pub max_clip_duration: f64,
    /// Most frames accepted in a clip \[frames\]. Default 1 000 000 (an hour at 240 Hz is
    /// 864 000). Raised with `ReadLimits::max_clip_frames`.
    pub max_clip_frames: usize,
}

impl Default for ReadLimits {
    fn default() -> Self {
        Self {
            max_xml_depth: 64,
            max_clip_duration: 3600.0,
            max_clip_frames: 1_000_000,
        }
    }
}

impl ReadLimits {
    /// Checks that the limits themselves are usable: a depth ≥ 1, a finite duration > 0, a frame
    /// count ≥ 1.
    pub fn validate(&self) -> Result<()> {
        if self.max_xml_depth == 0 {
            return Err(setting("ReadLimits::max_xml_depth", 0.0, "at least 1"));
        }
        if !(self.max_clip_duration.is_finite() && self.max_clip_duration > 0.0) {
            return Err(setting(
                "ReadLimits::max_clip_duration",
                self.max_clip_duration,
                "a finite duration > 0 [s]",
            ));
        }
        if self.max_clip_frames == 0 {
            return Err(setting("ReadLimits::max_clip_frames", 0.0, "at least 1"));
        }
        Ok(())
    }

    /// Checks a clip's frame count and duration \[s\] against the limits.
    pub fn check_clip(&self, source_name: &str, frames: usize, duration: f64) -> Result<()> {
        self.validate()?;
        check_count(
            &format!("frames in {source_name}"),
            frames,
            self.max_clip_frames,
            "ReadLimits::max_clip_frames",
        )?;
        if !duration.is_finite() {
            return Err(Error::NonFinite {
                what: format!("duration of {source_name} [s]"),
                value: duration,
            });
        }
        if duration > self.max_clip_duration {
            return Err(Error::ResourceLimit {
                what: format!("duration of {source_name} [s]"),
                value: fmt_value(duration),
                limit: fmt_value(self.max_clip_duration),
                option: "ReadLimits::max_clip_duration (CLI --max-clip-duration)".into(),
            });
        }
        Ok(())
    }
}

/// Limits on what one run may do: its control period and its number of ticks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunLimits {
    /// Shortest accepted control period \[s\]. Default 1e-5 s (100 kHz, ten times faster than
    /// any joint servo loop of the robots shipped). Lowered with `RunLimits::min_dt`.
    pub min_dt: f64,
    /// Longest accepted control period \[s\]. Default 0.1 s (10 Hz): a humanoid controlled
    /// more slowly than that falls between two ticks. Raised with `RunLimits::max_dt`.
    pub max_dt: f64,
    /// Most control ticks in one run \[ticks\]. Default 200 000 (1000 s at the default 5 ms);
    /// a run records every tick (≈ 5 kB per tick for JVRC-1), so this also bounds memory at
    /// about 1 GB. Raised with `RunLimits::max_ticks` (CLI `--max-ticks`).
    pub max_ticks: usize,
}

impl Default for RunLimits {
    fn default() -> Self {
        Self {
            min_dt: 1e-5,
            max_dt: 0.1,
            max_ticks: 200_000,
        }
    }
}

impl RunLimits {
    /// Checks that the limits themselves are usable: `0 < min_dt ≤ max_dt`, both finite, and
    /// `max_ticks ≥ 1`.
    pub fn validate(&self) -> Result<()> {
        if !(self.min_dt.is_finite() && self.min_dt > 0.0) {
            return Err(setting(
                "RunLimits::min_dt",
                self.min_dt,
                "a finite period > 0 [s]",
            ));
        }
        if !(self.max_dt.is_finite() && self.max_dt >= self.min_dt) {
            return Err(setting(
                "RunLimits::max_dt",
                self.max_dt,
                &format!("a finite period >= min_dt = {} [s]", self.min_dt),
            ));
        }
        if self.max_ticks == 0 {
            return Err(setting("RunLimits::max_ticks", 0.0, "at least 1"));
        }
        Ok(())
    }

    /// The one check of a control period `dt` \[s\]: finite, positive and within
    /// `[min_dt, max_dt]`. `name` names the setting in the error (`"dt"`, `"--dt"`).
    pub fn check_dt(&self, name: &str, dt: f64) -> Result<f64> {
        self.validate()?;
        if dt.is_finite() && dt >= self.min_dt && dt <= self.max_dt {
            Ok(dt)
        } else {
            Err(Error::InvalidSetting {
                name: name.into(),
                value: fmt_value(dt),
                expected: format!(
                    "a control period in [{}, {}] s (RunLimits::min_dt / max_dt)",
                    self.min_dt, self.max_dt
                ),
            })
        }
    }

    /// The number of ticks `round(duration / dt)` (at least 1) of a run of `duration` \[s\] at
    /// `dt` \[s\], after [`RunLimits::check_dt`]; an error if it exceeds `max_ticks` or if the
    /// duration is not finite and ≥ 0. Computed in floating point and compared before any
    /// conversion, so no huge count is ever formed.
    pub fn ticks(&self, what: &str, duration: f64, dt: f64) -> Result<usize> {
        self.check_dt("dt", dt)?;
        if !(duration.is_finite() && duration >= 0.0) {
            return Err(setting(
                &format!("duration of {what} [s]"),
                duration,
                "a finite duration >= 0 [s]",
            ));
        }
        let n = (duration / dt).round().max(1.0);
        if n > self.max_ticks as f64 {
            return Err(Error::ResourceLimit {
                what: format!(
                    "ticks of {what} ({} s at dt = {} s)",
                    fmt_value(duration),
                    fmt_value(dt)
                ),
                value: format!("{n:.0}"),
                limit: self.max_ticks.to_string(),
                option: "RunLimits::max_ticks (CLI --max-ticks)".into(),
            });
        }
        Ok(n as usize)
    }

    /// Checks a tick count already formed (e.g. by a walking pattern) against `max_ticks`.
    pub fn check_ticks(&self, what: &str, ticks: usize) -> Result<usize> {
        check_count(
            &format!("ticks of {what}"),
            ticks,
            self.max_ticks,
            "RunLimits::max_ticks (CLI --max-ticks)",
        )?;
        Ok(ticks)
    }
}

/// `v` as text: plain decimals, or scientific notation below 1e-5 or from 1e7 on in magnitude
/// (so that `1e-300` does not print as 300 digits).
pub fn fmt_value(v: f64) -> String {
    if v != 0.0 && v.is_finite() && (v.abs() < 1e-5 || v.abs() >= 1e7) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

fn setting(name: &str, value: f64, expected: &str) -> Error {
    Error::InvalidSetting {
        name: name.into(),
        value: fmt_value(value),
        expected: expected.into(),
    }
}

/// An error if `count > limit`, naming `what` and the `option` that raises the limit.
pub fn check_count(what: &str, count: usize, limit: usize, option: &str) -> Result<()> {
    if count > limit {
        Err(Error::ResourceLimit {
            what: what.into(),
            value: count.to_string(),
            limit: limit.to_string(),
            option: option.into(),
        })
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_bounded_before_conversion() {
        let l = RunLimits::default();
        assert_eq!(l.ticks("run", 2.0, 0.005), Ok(400));
        assert!(matches!(
            l.ticks("run", 1e6, 0.005),
            Err(Error::ResourceLimit { .. })
        ));
        // dt below min_dt, NaN, infinite: the range error.
        for dt in [1e-300, 1e-7, f64::NAN, f64::INFINITY, -0.005, 0.0, 10.0] {
            assert!(
                matches!(l.check_dt("dt", dt), Err(Error::InvalidSetting { .. })),
                "{dt}"
            );
        }
        // A duration shorter than one period still runs one tick.
        assert_eq!(l.ticks("run", 0.001, 0.005), Ok(1));
    }

    #[test]
    fn clip_limits() {
        let l = ReadLimits::default();
        assert!(l.check_clip("c", 100, 10.0).is_ok());
        assert!(matches!(
            l.check_clip("c", 100, 1e6),
            Err(Error::ResourceLimit { .. })
        ));
        assert!(matches!(
            l.check_clip("c", 2_000_000, 1.0),
            Err(Error::ResourceLimit { .. })
        ));
        assert!(matches!(
            l.check_clip("c", 2, f64::INFINITY),
            Err(Error::NonFinite { .. })
        ));
    }
}
