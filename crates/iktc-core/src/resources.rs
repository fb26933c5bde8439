//! Stated maxima on what an input may make iktc allocate or run.
//!
//! A file or a setting can ask for an arbitrary amount of work: a BVH `Frame Time: 1e6`, a
//! control period of 1e-300 s, 10 000 walking steps. Every such request is checked against a
//! maximum *before* anything is allocated; going over is an [`Error::ResourceLimit`] naming the
//! limit, the value asked for and the option that raises it.
//!
//! * [`ReadLimits`] — what a file may hold: XML nesting depth, clip duration and frame count.
//! * [`RunLimits`] — what a run may do: the control period's range and the number of ticks.
//! * Constants for what a user asks for directly: the output rate and frames of a written
//!   trajectory ([`MAX_OUTPUT_RATE`], [`MAX_OUTPUT_FRAMES`]), the walking pattern's ZMP
//!   correction passes ([`MAX_ZMP_PASSES`]), the balance fit's iterations
//!   ([`MAX_LM_ITERATIONS`]) and a batch's worker threads ([`MAX_JOBS`]).

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
    /// more slowly than that falls between two ticks. Raised with `RunLimits::max_dt`. The
    /// keypoint route accepts less: periods below `KeypointSettings::max_dt` (0.041 s with
    /// its held feet's gains), beyond which its tracking is unstable.
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

/// Lowest output rate of a written trajectory (`motion.csv`, `motion.npz`) \[Hz\]: 1 Hz,
/// the slowest a motion sampled for training or playback is of any use (a step lasts about
/// 0.5 s).
pub const MIN_OUTPUT_RATE: f64 = 1.0;

/// Highest output rate of a written trajectory \[Hz\]: 100 kHz, the control rate at the
/// shortest accepted control period ([`RunLimits::min_dt`] = 1e-5 s); a faster output only
/// interpolates between ticks.
pub const MAX_OUTPUT_RATE: f64 = 1e5;

/// Most frames in a written trajectory \[frames\]: 1 000 000 (an hour at 240 Hz is 864 000;
/// about 0.5 GB for a 29-joint robot with eight tracked bodies).
pub const MAX_OUTPUT_FRAMES: usize = 1_000_000;

/// Most passes of the walking pattern's ZMP correction \[passes\]. Each pass simulates the
/// whole walk once; the passes stop earlier once one does not shrink the ZMP's largest
/// distance from the support (see `WalkingController::correct_zmp`).
pub const MAX_ZMP_PASSES: usize = 10;

/// Most trial steps of the Levenberg–Marquardt fit of the balance identification
/// (`LmSettings::max_iterations`) \[steps\]: 10 000 (the default is 200; each step evaluates
/// the residual once, and each new Jacobian simulates the identification run twice per
/// parameter).
pub const MAX_LM_ITERATIONS: usize = 10_000;

/// Most worker threads of a batch \[threads\]: 1024. Each worker holds one clip's run in
/// memory (its recorded ticks, up to about 1 GB at [`RunLimits::max_ticks`]) and a thread
/// stack; machines with more than a few hundred hardware threads are rare, and more workers
/// than cores only share them.
pub const MAX_JOBS: usize = 1024;

/// Checks a batch's worker count `jobs` \[threads\] asked for by `name` (e.g. `"--jobs"`):
/// within `1..=`[`MAX_JOBS`].
pub fn check_jobs(name: &str, jobs: usize) -> Result<usize> {
    if (1..=MAX_JOBS).contains(&jobs) {
        Ok(jobs)
    } else {
        Err(Error::InvalidSetting {
            name: name.into(),
            value: jobs.to_string(),
            expected: format!("a worker count in [1, {MAX_JOBS}] threads (resources::MAX_JOBS)"),
        })
    }
}

/// Checks an output rate `rate` \[Hz\] asked for by `name` (e.g. `"--rate"`): finite and within
/// [`MIN_OUTPUT_RATE`]`..=`[`MAX_OUTPUT_RATE`].
pub fn check_output_rate(name: &str, rate: f64) -> Result<f64> {
    if rate.is_finite() && (MIN_OUTPUT_RATE..=MAX_OUTPUT_RATE).contains(&rate) {
        Ok(rate)
    } else {
        Err(setting(
            name,
            rate,
            &format!(
                "an output rate in [{MIN_OUTPUT_RATE}, {}] Hz (resources::MIN_OUTPUT_RATE / MAX_OUTPUT_RATE)",
                fmt_value(MAX_OUTPUT_RATE)
            ),
        ))
    }
}

/// The number of frames `floor(span · rate + slack) + 1` of a trajectory of `span` \[s\]
/// written at `rate` \[Hz\] (checked by [`check_output_rate`] under `name`), `slack` \[frames\]
/// absorbing rounding at the last frame; an error if it exceeds [`MAX_OUTPUT_FRAMES`].
/// Computed in floating point and compared before any conversion.
pub fn output_frames(name: &str, span: f64, rate: f64, slack: f64) -> Result<usize> {
    check_output_rate(name, rate)?;
    if !(span.is_finite() && span >= 0.0) {
        return Err(setting(
            "span of the written trajectory [s]",
            span,
            "a finite duration >= 0 [s]",
        ));
    }
    let n = (span * rate + slack).floor() + 1.0;
    if n > MAX_OUTPUT_FRAMES as f64 {
        return Err(Error::ResourceLimit {
            what: format!(
                "frames written ({} s at {name} {} Hz)",
                fmt_value(span),
                fmt_value(rate)
            ),
            value: format!("{n:.0}"),
            limit: MAX_OUTPUT_FRAMES.to_string(),
            option: format!("a lower {name} (resources::MAX_OUTPUT_FRAMES)"),
        });
    }
    Ok(n as usize)
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
    fn output_rates_and_frames_are_bounded() {
        for bad in [1e12, 1e300, f64::INFINITY, f64::NAN, 0.0, -1.0, 0.5] {
            match check_output_rate("--rate", bad) {
                Err(Error::InvalidSetting { name, .. }) => assert_eq!(name, "--rate"),
                other => panic!("{bad}: {other:?}"),
            }
        }
        assert_eq!(check_output_rate("--rate", 30.0), Ok(30.0));
        // 2 s at 50 Hz: frames at 0, 0.02, ..., 2 s.
        assert_eq!(output_frames("--rate", 2.0, 50.0, 1e-6), Ok(101));
        // An hour at 100 kHz: 3.6e8 frames, over the limit.
        match output_frames("--rate", 3600.0, MAX_OUTPUT_RATE, 1e-6) {
            Err(Error::ResourceLimit { value, .. }) => assert_eq!(value, "360000001"),
            other => panic!("{other:?}"),
        }
    }

    /// The worker count is accepted from 1 to 1024 threads, both ends included; 0 and 1025
    /// are errors naming the flag and the bound.
    #[test]
    fn worker_counts_are_bounded() {
        assert_eq!(MAX_JOBS, 1024);
        for ok in [1, 2, 1024] {
            assert_eq!(check_jobs("--jobs", ok), Ok(ok));
        }
        for bad in [0, 1025, usize::MAX] {
            match check_jobs("--jobs", bad) {
                Err(e @ Error::InvalidSetting { .. }) => {
                    let text = e.to_string();
                    assert!(text.contains("--jobs"), "{text}");
                    assert!(text.contains("[1, 1024] threads"), "{text}");
                    assert!(text.contains(&bad.to_string()), "{text}");
                }
                other => panic!("{bad}: {other:?}"),
            }
        }
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
