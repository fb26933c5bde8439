//! The walking experiment's settings for a robot: the imitation's from the profile, the walking
//! timing, step and push from the key `walk`, the push scaled to the robot's mass.

use super::build::{check_number, profile_error};
use super::schema::RobotProfile;
use crate::error::Result;
use crate::model::Robot;
use crate::sim::{Push, WalkImitateConfig};

/// The change of COM velocity of the default push \[m/s\] (forward, along world x): the paper's
/// experiment pushes the 62.4 kg JVRC-1 with 5 N·s; a robot without a key `walk.push` gets the
/// impulse that changes its COM velocity as much, `m · Δv` \[N·s\].
pub const DEFAULT_PUSH_VELOCITY_CHANGE: f64 = 5.0 / 62.4;

/// Time of the default push \[s\]: in the second single support of the default four steps.
const DEFAULT_PUSH_TIME: f64 = 2.15;

impl RobotProfile {
    /// Checks the numbers of the key `walk` (lengths and durations `> 0`, the swing height
    /// `≥ 0`, the push finite with a time `≥ 0`).
    pub(super) fn check_walk(&self) -> Result<()> {
        let w = &self.walk;
        for (key, v, positive) in [
            ("walk.step_length", w.step_length, false),
            ("walk.swing_height", w.swing_height, false),
            ("walk.ssp_duration", w.ssp_duration, true),
            ("walk.dsp_duration", w.dsp_duration, true),
        ] {
            if let Some(v) = v {
                if positive {
                    check_number(key, v, v > 0.0, "a value > 0 [s]")?;
                } else {
                    check_number(key, v, v >= 0.0, "a value >= 0 [m]")?;
                }
            }
        }
        if let Some(p) = &w.push {
            check_number("walk.push.time", p.time, p.time >= 0.0, "a time >= 0 [s]")?;
            if !p.impulse.iter().all(|x| x.is_finite()) {
                return Err(profile_error(
                    "walk.push.impulse",
                    format!("{:?}", p.impulse),
                    "expected two finite numbers [N·s]",
                ));
            }
        }
        Ok(())
    }

    /// The walking imitation's settings for this robot: `base` with the imitation's
    /// robot-specific fields from [`imitate_config`](Self::imitate_config), the walking keys
    /// the profile gives (`walk.step_length`, `walk.swing_height`, `walk.ssp_duration`,
    /// `walk.dsp_duration`) and its push: `walk.push`, else a forward impulse
    /// `m · DEFAULT_PUSH_VELOCITY_CHANGE` \[N·s\] at 2.15 s with `m` the robot's mass \[kg\]
    /// (5 N·s for JVRC-1's 62.4 kg). `base.push = None` stays without a push.
    ///
    /// Errors: those of [`imitate_config`](Self::imitate_config).
    pub fn walk_config(&self, robot: &Robot, base: WalkImitateConfig) -> Result<WalkImitateConfig> {
        let w = &self.walk;
        let mut cfg = WalkImitateConfig {
            imitate: self.imitate_config(base.imitate.clone())?,
            ..base
        };
        cfg.step_length = w.step_length.unwrap_or(cfg.step_length);
        cfg.walk.swing_height = w.swing_height.unwrap_or(cfg.walk.swing_height);
        cfg.walk.ssp_duration = w.ssp_duration.unwrap_or(cfg.walk.ssp_duration);
        cfg.walk.dsp_duration = w.dsp_duration.unwrap_or(cfg.walk.dsp_duration);
        if cfg.push.is_some() {
            cfg.push = Some(match w.push {
                Some(p) => Push {
                    time: p.time,
                    impulse: p.impulse,
                },
                None => Push {
                    time: DEFAULT_PUSH_TIME,
                    impulse: [robot.total_mass() * DEFAULT_PUSH_VELOCITY_CHANGE, 0.0],
                },
            });
        }
        Ok(cfg)
    }
}
