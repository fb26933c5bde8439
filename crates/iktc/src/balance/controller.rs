//! The damping controller of one plane (Figure 14): observer on the full model plus state
//! feedback, run once per control tick without allocation.

use nalgebra::Vector4;
use serde::Serialize;

use super::design::DiscreteDesign;
use crate::error::{check_finite, Result};

/// What one controller tick returns.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BalanceCommand {
    /// Command angle `u` \[rad\] sent to the plant (through the COM reference).
    pub u: f64,
    /// COM reference offset `Δc = l (u − u_ref)` \[m\] for the kinematic controller.
    pub com_offset: f64,
    /// Filtered state estimate `x̄ = [θ, θ̇, z, p]` \[rad, rad/s, m, m\].
    pub estimate: [f64; 4],
}

/// One plane's damping controller: current-estimator observer and state feedback
/// ([`DiscreteDesign`]). All state is fixed-size; [`DampingController::step`] allocates nothing.
///
/// Inputs are deviations from the nominal posture: `u_ref` \[rad\] is the reference COM offset
/// divided by `l`, `y` \[m\] the measured ZMP minus its nominal value, both in the case's local
/// frame (Figure 11).
#[derive(Debug, Clone, PartialEq)]
pub struct DampingController {
    design: DiscreteDesign,
    /// Predicted state `x̂(k | k−1)`.
    predicted: Vector4<f64>,
}

impl DampingController {
    /// A controller at rest (zero state estimate).
    pub fn new(design: DiscreteDesign) -> Self {
        Self {
            design,
            predicted: Vector4::zeros(),
        }
    }

    /// The design it runs.
    pub fn design(&self) -> &DiscreteDesign {
        &self.design
    }

    /// The predicted state `x̂(k | k−1)` \[rad, rad/s, m, m\].
    pub fn predicted_state(&self) -> [f64; 4] {
        self.predicted.into()
    }

    /// Sets the predicted state (used to hand over between cases).
    pub fn set_predicted_state(&mut self, x: [f64; 4]) {
        self.predicted = Vector4::from(x);
    }

    /// Resets the estimate to zero.
    pub fn reset(&mut self) {
        self.predicted = Vector4::zeros();
    }

    /// One tick: correct with `y` \[m\], command `u = N_d u_ref − K_d x̄` \[rad\], predict with
    /// the same `u`. Errors (state unchanged) if an input is not finite.
    pub fn step(&mut self, u_ref: f64, y: f64) -> Result<BalanceCommand> {
        let (cmd, filtered) = self.correct(u_ref, y)?;
        self.predict(&filtered, cmd.u);
        Ok(cmd)
    }

    /// Correction half of a tick: `x̄ = x̂ + M (y − C x̂)` and the command from it.
    pub(crate) fn correct(&self, u_ref: f64, y: f64) -> Result<(BalanceCommand, Vector4<f64>)> {
        check_finite(|| "u_ref [rad]".into(), u_ref)?;
        check_finite(|| "measured ZMP y [m]".into(), y)?;
        let d = &self.design;
        let innovation = y - (d.c * self.predicted)[0];
        let filtered = self.predicted + d.observer_gain * innovation;
        let u = d.feedforward * u_ref - (d.gain * filtered)[0];
        Ok((
            BalanceCommand {
                u,
                com_offset: d.params.ipcj.length * (u - u_ref),
                estimate: filtered.into(),
            },
            filtered,
        ))
    }

    /// Prediction half of a tick: `x̂⁺ = A_d x̄ + B_d u_applied`.
    pub(crate) fn predict(&mut self, filtered: &Vector4<f64>, u_applied: f64) {
        let d = &self.design;
        self.predicted = d.ad * filtered + d.bd * u_applied;
    }
}
