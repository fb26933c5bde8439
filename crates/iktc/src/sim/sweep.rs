//! The robustness sweep: one imitation run per clip × solver × control period,
//! with viable bounds, reduced to what must hold — no limit exceeded (in-step peaks included),
//! the box never empty, the fallbacks counted by kind — and the run checks' verdict.
//!
//! Each case is [`run_imitate`] on the given robot with [`ImitateConfig::default`] except the
//! solver, Δt and [`crate::sim::HealthSettings::keep_going`] (so that a failed check is
//! counted, not raised). `crates/iktc/examples/sweep.rs` runs the whole grid.

use std::collections::BTreeMap;

use serde::Serialize;

use super::imitate::{imitation_references, run_imitate, ImitateConfig};
use crate::error::Result;
use crate::model::Robot;
use crate::motion::{builtin_clip, builtin_map};
use crate::solver::Method;

/// The control periods of the sweep \[s\].
pub const SWEEP_PERIODS: [f64; 5] = [0.002, 0.005, 0.01, 0.02, 0.05];

/// The solvers of the sweep.
pub const SWEEP_METHODS: [Method; 3] = [Method::Iktc, Method::Cascade, Method::Clamp];

/// One case of the sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SweepRow {
    /// Built-in clip.
    pub clip: String,
    /// Solver name.
    pub solver: String,
    /// Control period \[s\].
    pub dt: f64,
    /// Ticks run.
    pub steps: usize,
    /// Largest position excursion beyond a limit, in-step peaks included \[rad\] (≤ 0: none).
    pub position_excursion: f64,
    /// Largest velocity excursion \[rad/s\] (≤ 0: none).
    pub velocity_excursion: f64,
    /// Largest acceleration excursion \[rad/s²\] (≤ 0: none).
    pub acceleration_excursion: f64,
    /// Ticks with an empty box.
    pub empty_box_steps: usize,
    /// Ticks with a fallback, by kind (see [`super::ImitateSummary::fallbacks_by_kind`]).
    pub fallbacks: BTreeMap<String, usize>,
    /// No run check failed.
    pub healthy: bool,
    /// The first failed check, in words (empty if healthy).
    pub first_failure: String,
}

/// Runs one case: `clip` (a built-in DeepMimic clip, retargeted with `deepmimic_jvrc1`) on
/// `robot` with `method` at period `dt` \[s\]. Errors: unknown clip, bad settings, and errors
/// of the run itself (a solver error on a non-finite problem).
pub fn sweep_case(robot: &Robot, clip: &str, method: Method, dt: f64) -> Result<SweepRow> {
    let mut cfg = ImitateConfig {
        method,
        dt,
        ..ImitateConfig::default()
    };
    cfg.health.keep_going = true;
    let c = builtin_clip(clip)?;
    let map = builtin_map("deepmimic_jvrc1")?;
    let refs = imitation_references(robot, &c, &map, &cfg)?;
    let run = run_imitate(robot, &refs, &cfg)?;
    let s = run.summary;
    Ok(SweepRow {
        clip: clip.into(),
        solver: method.name().into(),
        dt,
        steps: s.steps,
        position_excursion: s.worst_position_margin,
        velocity_excursion: s.worst_velocity_margin,
        acceleration_excursion: s.worst_acceleration_margin,
        empty_box_steps: s.empty_box_steps,
        fallbacks: s.fallbacks_by_kind,
        healthy: s.health.healthy,
        first_failure: s
            .health
            .issues
            .first()
            .map_or(String::new(), |i| i.to_string()),
    })
}
