//! The walking pattern: a footstep plan turned into references for feet, COM and ZMP at any
//! time, precomputed once.

use nalgebra::Vector3;

use super::footstep::FootstepPlan;
use super::polygon::SupportPolygon;
use super::preview::{CartSample, PreviewController, PreviewSettings};
use super::settings::{invalid, Side, WalkSettings};
use super::swing::{foot_state, FootState};
use super::timeline::{Phase, Timeline};
use crate::error::{check_finite, Result};

/// Largest number of COM samples of a pattern (about 14 h at 5 ms): a guard against
/// durations that would allocate gigabytes.
pub const MAX_PATTERN_SAMPLES: usize = 10_000_000;

/// COM reference: position, velocity and acceleration, world axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComState {
    /// Position \[m\]; `z` is the constant [`PreviewSettings::com_height`].
    pub position: Vector3<f64>,
    /// Velocity \[m/s\] (`z` component 0).
    pub velocity: Vector3<f64>,
    /// Acceleration \[m/s²\] (`z` component 0); continuous in time.
    pub acceleration: Vector3<f64>,
}

/// Everything the pattern prescribes at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WalkSample {
    /// The time \[s\] the sample was taken at (after clamping to `[0, duration]`).
    pub time: f64,
    /// The support phase.
    pub phase: Phase,
    /// The footstep being taken (SSP) or last taken (DSP), `None` before the first.
    pub step: Option<usize>,
    /// Left foot.
    pub left: FootState,
    /// Right foot.
    pub right: FootState,
    /// COM reference from preview control.
    pub com: ComState,
    /// ZMP reference `(x, y)` \[m\].
    pub zmp_reference: (f64, f64),
    /// ZMP of the cart-table model along the COM reference, `p = x − (z_c/g) ẍ` \[m\].
    pub zmp_model: (f64, f64),
}

impl WalkSample {
    /// The state of foot `side`.
    pub fn foot(&self, side: Side) -> &FootState {
        match side {
            Side::Left => &self.left,
            Side::Right => &self.right,
        }
    }
}

/// A complete walking pattern for one footstep plan.
///
/// Built once by [`WalkingPattern::new`]: the [`Timeline`] of the plan, its ZMP reference sampled
/// every `Δt` from `t = 0` to the first sample at or after the end, and the COM of the
/// cart-table model driven by the preview servo ([`PreviewController`]) on `x` and `y`
/// independently, from rest over the initial ZMP reference. Queries at any `t` are
/// allocation-free; between samples the COM follows the exact cubic of the held jerk.
/// Times are clamped to `[0, duration]`: before the start and after the end the robot stands.
#[derive(Debug, Clone)]
pub struct WalkingPattern {
    plan: FootstepPlan,
    settings: WalkSettings,
    controller: PreviewController,
    timeline: Timeline,
    com_x: Vec<CartSample>,
    com_y: Vec<CartSample>,
}

impl WalkingPattern {
    /// Precomputes the pattern of `plan`. Errors on invalid settings, and if the pattern
    /// would need more than [`MAX_PATTERN_SAMPLES`] samples.
    pub fn new(
        plan: &FootstepPlan,
        settings: &WalkSettings,
        preview: &PreviewSettings,
    ) -> Result<Self> {
        let controller = PreviewController::new(preview)?;
        Self::with_controller(plan, settings, controller)
    }

    /// As [`WalkingPattern::new`] with an already designed controller (the Riccati solution
    /// does not depend on the plan).
    pub fn with_controller(
        plan: &FootstepPlan,
        settings: &WalkSettings,
        controller: PreviewController,
    ) -> Result<Self> {
        let timeline = Timeline::new(plan, settings)?;
        let dt = controller.settings().dt;
        let samples = (timeline.duration() / dt).ceil() + 1.0;
        if !samples.is_finite() || samples > MAX_PATTERN_SAMPLES as f64 {
            return Err(invalid(
                "walking pattern duration / dt [samples]",
                samples,
                &format!("<= {MAX_PATTERN_SAMPLES} (shorter plan or durations, or larger dt)"),
            ));
        }
        let n = samples as usize;
        let (mut rx, mut ry) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for k in 0..n {
            let (x, y) = timeline.zmp_reference(k as f64 * dt);
            rx.push(x);
            ry.push(y);
        }
        let com_x = controller.track(&rx)?;
        let com_y = controller.track(&ry)?;
        Ok(Self {
            plan: plan.clone(),
            settings: *settings,
            controller,
            timeline,
            com_x,
            com_y,
        })
    }

    /// The footstep plan.
    pub fn plan(&self) -> &FootstepPlan {
        &self.plan
    }

    /// The walk settings.
    pub fn settings(&self) -> &WalkSettings {
        &self.settings
    }

    /// The preview controller (gains, Riccati solution, cart-table model).
    pub fn controller(&self) -> &PreviewController {
        &self.controller
    }

    /// The support-phase timeline.
    pub fn timeline(&self) -> &Timeline {
        &self.timeline
    }

    /// Duration of the pattern \[s\] (end of the final double support).
    pub fn duration(&self) -> f64 {
        self.timeline.duration()
    }

    /// Sampling period of the COM trajectory `Δt` \[s\].
    pub fn dt(&self) -> f64 {
        self.controller.settings().dt
    }

    /// The COM samples at `t_k = k Δt` of the `x` axis (state and jerk).
    pub fn com_samples_x(&self) -> &[CartSample] {
        &self.com_x
    }

    /// The COM samples at `t_k = k Δt` of the `y` axis (state and jerk).
    pub fn com_samples_y(&self) -> &[CartSample] {
        &self.com_y
    }

    fn clamp(&self, t: f64) -> Result<f64> {
        check_finite(|| "walking pattern query time t [s]".to_string(), t)?;
        Ok(t.clamp(0.0, self.duration()))
    }

    /// `(x, ẋ, ẍ)` of one axis at `t` (already clamped): the cubic
    /// `x_k + ẋ_k τ + ẍ_k τ²/2 + u_k τ³/6`, `τ = t − k Δt`.
    fn axis_at(samples: &[CartSample], dt: f64, t: f64) -> Vector3<f64> {
        let last = samples.len().saturating_sub(1);
        let k = ((t / dt).floor().max(0.0) as usize).min(last);
        let Some(s) = samples.get(k) else {
            return Vector3::zeros();
        };
        let tau = t - k as f64 * dt;
        let (x, v, a, u) = (s.state[0], s.state[1], s.state[2], s.jerk);
        Vector3::new(
            x + tau * (v + tau * (0.5 * a + tau * u / 6.0)),
            v + tau * (a + 0.5 * tau * u),
            a + tau * u,
        )
    }

    /// COM reference at `t` \[s\]. Errors if `t` is not finite.
    pub fn com(&self, t: f64) -> Result<ComState> {
        let t = self.clamp(t)?;
        Ok(self.com_clamped(t))
    }

    fn com_clamped(&self, t: f64) -> ComState {
        let dt = self.dt();
        let x = Self::axis_at(&self.com_x, dt, t);
        let y = Self::axis_at(&self.com_y, dt, t);
        ComState {
            position: Vector3::new(x[0], y[0], self.controller.settings().com_height),
            velocity: Vector3::new(x[1], y[1], 0.0),
            acceleration: Vector3::new(x[2], y[2], 0.0),
        }
    }

    /// State of foot `side` at `t` \[s\]. Errors if `t` is not finite.
    pub fn foot(&self, side: Side, t: f64) -> Result<FootState> {
        let t = self.clamp(t)?;
        let phase = self.timeline.interval_at(t);
        Ok(foot_state(phase, side, self.settings.swing_height, t))
    }

    /// Support phase at `t` \[s\]. Errors if `t` is not finite.
    pub fn phase_at(&self, t: f64) -> Result<Phase> {
        let t = self.clamp(t)?;
        Ok(self.timeline.phase_at(t))
    }

    /// ZMP reference at `t` \[s\], `(x, y)` \[m\]. Errors if `t` is not finite.
    pub fn zmp_reference(&self, t: f64) -> Result<(f64, f64)> {
        let t = self.clamp(t)?;
        Ok(self.timeline.zmp_reference(t))
    }

    /// Everything at `t` \[s\]; allocation-free. Errors if `t` is not finite.
    pub fn sample(&self, t: f64) -> Result<WalkSample> {
        let t = self.clamp(t)?;
        let phase = self.timeline.interval_at(t);
        let h = self.settings.swing_height;
        let com = self.com_clamped(t);
        let c = self.controller.model().c[2];
        Ok(WalkSample {
            time: t,
            phase: phase.phase,
            step: phase.step,
            left: foot_state(phase, Side::Left, h, t),
            right: foot_state(phase, Side::Right, h, t),
            com,
            zmp_reference: phase.zmp_reference(t),
            zmp_model: (
                com.position.x + c * com.acceleration.x,
                com.position.y + c * com.acceleration.y,
            ),
        })
    }

    /// Writes the support polygon at `t` \[s\] into `out` (counter-clockwise, \[m\]): the
    /// stance sole in single support, the convex hull of both soles in double support.
    /// Allocation-free. Errors if `t` is not finite.
    pub fn support_polygon_into(&self, t: f64, out: &mut SupportPolygon) -> Result<()> {
        let t = self.clamp(t)?;
        let phase = self.timeline.interval_at(t);
        let (l, w) = (self.settings.sole_length, self.settings.sole_width);
        match phase.phase {
            Phase::SingleSupport { stance } => out.set_sole(&phase.foot(stance), l, w),
            Phase::DoubleSupport => out.set_hull_of_soles(&phase.left, &phase.right, l, w),
        }
        Ok(())
    }

    /// The support polygon at `t` \[s\] as a list of vertices `(x, y)` \[m\], counter-clockwise
    /// (allocates; see [`WalkingPattern::support_polygon_into`]).
    pub fn support_polygon(&self, t: f64) -> Result<Vec<(f64, f64)>> {
        let mut p = SupportPolygon::default();
        self.support_polygon_into(t, &mut p)?;
        Ok(p.vertices().to_vec())
    }
}
