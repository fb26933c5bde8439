//! The support-phase timeline of a plan and the ZMP reference on it.
//!
//! For a plan of `n` footsteps the timeline is
//! `DSP₀ (initial) · SSP₁ · DSP₁ · SSP₂ · … · DSPₙ₋₁ · SSPₙ · DSPₙ (final)`, starting at `t = 0`.
//! Phase `i` covers `[start, end)`; after the last phase the final stance holds.
//!
//! ZMP reference (the choice of Kajita et al. 2003, with smoothed shifts): in single support
//! it rests at the centre of the stance sole; in double support it moves from the previous
//! support point `a` to the next `b` by the quintic smoothstep
//! `p(t) = a + (b − a) s(τ)`, `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵`, `τ = (t − t_s)/(t_e − t_s)` clamped to
//! `[0, 1]` (zero velocity and acceleration at both ends). The shift `[t_s, t_e]` is the whole
//! DSP between two steps, the last [`WalkSettings::dsp_duration`] of the initial DSP (from the
//! midpoint between the feet to the first stance foot) and the first `dsp_duration` of the
//! final DSP (back to the midpoint). The segment `a b` lies in the support polygon (the convex
//! hull of both soles), so the reference does.

use serde::Serialize;

use super::footstep::{Footstep, FootstepPlan, Pose2};
use super::settings::{Side, WalkSettings};
use crate::error::Result;

/// A support phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Phase {
    /// Both feet on the ground.
    DoubleSupport,
    /// One foot on the ground, the other swinging.
    SingleSupport {
        /// The foot on the ground.
        stance: Side,
    },
}

/// One phase of the timeline with everything needed to evaluate it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PhaseInterval {
    /// The phase.
    pub phase: Phase,
    /// Start time \[s\] (inclusive).
    pub start: f64,
    /// End time \[s\] (exclusive, except for the last phase).
    pub end: f64,
    /// Left foot pose at the start of the phase.
    pub left: Pose2,
    /// Right foot pose at the start of the phase.
    pub right: Pose2,
    /// In single support: the touch-down pose of the swinging foot at `end`; in double
    /// support: `None`.
    pub swing_target: Option<Pose2>,
    /// Index of the footstep (in [`FootstepPlan::steps`]) that is being taken (SSP) or that
    /// was last taken (DSP; `None` for the initial DSP).
    pub step: Option<usize>,
    /// ZMP reference at the start of the shift `(x, y)` \[m\].
    pub zmp_from: (f64, f64),
    /// ZMP reference at the end of the shift `(x, y)` \[m\].
    pub zmp_to: (f64, f64),
    /// Start of the ZMP shift \[s\].
    pub shift_start: f64,
    /// End of the ZMP shift \[s\] (`== shift_start` when there is no shift, in SSP).
    pub shift_end: f64,
}

impl PhaseInterval {
    /// Pose of foot `side` at the start of the phase.
    pub fn foot(&self, side: Side) -> Pose2 {
        match side {
            Side::Left => self.left,
            Side::Right => self.right,
        }
    }

    /// The swinging foot in single support, `None` in double support.
    pub fn swing_side(&self) -> Option<Side> {
        match self.phase {
            Phase::DoubleSupport => None,
            Phase::SingleSupport { stance } => Some(stance.opposite()),
        }
    }

    /// ZMP reference at `t` \[s\] (clamped to the shift), `(x, y)` \[m\].
    pub fn zmp_reference(&self, t: f64) -> (f64, f64) {
        let s = smoothstep(self.shift_start, self.shift_end, t).0;
        (
            self.zmp_from.0 + s * (self.zmp_to.0 - self.zmp_from.0),
            self.zmp_from.1 + s * (self.zmp_to.1 - self.zmp_from.1),
        )
    }
}

/// Quintic smoothstep from `t0` to `t1` at `t`: `(s, ds/dt, d²s/dt²)` with
/// `s = 10τ³ − 15τ⁴ + 6τ⁵`, `τ = (t − t0)/(t1 − t0)` clamped to `[0, 1]`; `(0, 0, 0)` before,
/// `(1, 0, 0)` after. Its first and second derivatives vanish at both ends. If `t1 ≤ t0`:
/// a step at `t0`.
pub fn smoothstep(t0: f64, t1: f64, t: f64) -> (f64, f64, f64) {
    let d = t1 - t0;
    if d <= 0.0 || !d.is_finite() {
        return (if t >= t0 { 1.0 } else { 0.0 }, 0.0, 0.0);
    }
    let tau = (t - t0) / d;
    if tau <= 0.0 {
        (0.0, 0.0, 0.0)
    } else if tau >= 1.0 {
        (1.0, 0.0, 0.0)
    } else {
        // Evaluated in this order by every user (the imitation's COM settle, the walking
        // COM blend, swing feet): the closed loops are rounding-sensitive.
        let s = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
        let ds = 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / d;
        let dds = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / (d * d);
        (s, ds, dds)
    }
}

/// The support-phase timeline of a footstep plan.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Timeline {
    phases: Vec<PhaseInterval>,
}

fn midpoint(a: Pose2, b: Pose2) -> (f64, f64) {
    (0.5 * (a.x + b.x), 0.5 * (a.y + b.y))
}

fn centre(p: Pose2) -> (f64, f64) {
    (p.x, p.y)
}

/// The double support after step `i` of `steps`, the feet at `left` and `right`: its ZMP
/// target \[m\] (the next stance foot's centre, or between the feet after the last step), its
/// duration and its ZMP shift's duration \[s\].
fn dsp_after(
    steps: &[Footstep],
    i: usize,
    left: Pose2,
    right: Pose2,
    settings: &WalkSettings,
) -> ((f64, f64), f64, f64) {
    let foot = |l: Pose2, r: Pose2, side: Side| match side {
        Side::Left => l,
        Side::Right => r,
    };
    match steps.get(i + 1) {
        Some(next) => (
            centre(foot(left, right, next.side.opposite())),
            settings.dsp_duration,
            settings.dsp_duration,
        ),
        None => (
            midpoint(left, right),
            settings.final_dsp_duration,
            settings.dsp_duration,
        ),
    }
}

impl Timeline {
    /// Builds the timeline of `plan` with the durations of `settings` (validated).
    pub fn new(plan: &FootstepPlan, settings: &WalkSettings) -> Result<Self> {
        settings.validate()?;
        let steps = plan.steps();
        let mut phases = Vec::with_capacity(2 * steps.len() + 1);
        let (mut left, mut right) = (plan.initial_left(), plan.initial_right());
        let foot = |l: Pose2, r: Pose2, side: Side| match side {
            Side::Left => l,
            Side::Right => r,
        };
        let mut t = 0.0;
        // Initial DSP: rest between the feet, then shift to the first stance foot.
        let mut zmp = midpoint(left, right);
        let t_init = settings.initial_dsp_duration;
        if let Some(first) = steps.first() {
            let target = centre(foot(left, right, first.side.opposite()));
            phases.push(PhaseInterval {
                phase: Phase::DoubleSupport,
                start: t,
                end: t + t_init,
                left,
                right,
                swing_target: None,
                step: None,
                zmp_from: zmp,
                zmp_to: target,
                shift_start: t + t_init - settings.dsp_duration,
                shift_end: t + t_init,
            });
            zmp = target;
            t += t_init;
        }
        for (i, step) in steps.iter().enumerate() {
            let stance = step.side.opposite();
            let t_ssp = settings.ssp_duration;
            phases.push(PhaseInterval {
                phase: Phase::SingleSupport { stance },
                start: t,
                end: t + t_ssp,
                left,
                right,
                swing_target: Some(step.pose),
                step: Some(i),
                zmp_from: zmp,
                zmp_to: zmp,
                shift_start: t,
                shift_end: t,
            });
            t += t_ssp;
            match step.side {
                Side::Left => left = step.pose,
                Side::Right => right = step.pose,
            }
            let (target, duration, shift) = dsp_after(steps, i, left, right, settings);
            phases.push(PhaseInterval {
                phase: Phase::DoubleSupport,
                start: t,
                end: t + duration,
                left,
                right,
                swing_target: None,
                step: Some(i),
                zmp_from: zmp,
                zmp_to: target,
                shift_start: t,
                shift_end: t + shift,
            });
            zmp = target;
            t += duration;
        }
        Ok(Self { phases })
    }

    /// All phases in time order.
    pub fn phases(&self) -> &[PhaseInterval] {
        &self.phases
    }

    /// Total duration \[s\]: the end of the final double support.
    pub fn duration(&self) -> f64 {
        self.phases.last().map_or(0.0, |p| p.end)
    }

    /// Index of the phase containing `t` \[s\]: the one with `start ≤ t < end`; times before 0
    /// (and NaN) map to the first phase, times at or after the end to the last. `O(log n)`,
    /// allocation-free.
    pub fn index_at(&self, t: f64) -> usize {
        let i = self.phases.partition_point(|p| p.end <= t);
        i.min(self.phases.len().saturating_sub(1))
    }

    /// The phase interval containing `t` \[s\] (see [`Timeline::index_at`]).
    pub fn interval_at(&self, t: f64) -> &PhaseInterval {
        // A timeline always has at least the initial and final DSP (plans are non-empty).
        &self.phases[self.index_at(t)]
    }

    /// The support phase at `t` \[s\].
    pub fn phase_at(&self, t: f64) -> Phase {
        self.interval_at(t).phase
    }

    /// ZMP reference at `t` \[s\], `(x, y)` \[m\] (see the module documentation).
    pub fn zmp_reference(&self, t: f64) -> (f64, f64) {
        self.interval_at(t).zmp_reference(t)
    }
}
