//! The four identified cases (`x̃z̃`/`ỹz̃` plane × SSP/DSP, Section 4.2) and the two-plane
//! controller that switches between them smoothly when the support phase changes.
//!
//! Hand-over: on a phase change each plane's new controller starts from the old one's state
//! estimate (the states mean the same: `θ, θ̇`, lag, Padé), and for
//! [`BalanceSettings::blend_time`] both run on the same measurements while the command is
//! cross-faded `u = (1 − α) u_old + α u_new` with `α = s²(3 − 2s)`, `s` going 0 → 1; both
//! observers are driven by the command actually applied. A change back during a blend reverses
//! it from where it is, so the command never jumps.

use serde::{Deserialize, Serialize};

use super::controller::{BalanceCommand, DampingController};
use super::design::{design_discrete, DiscreteDesign, DiscreteSettings, PoleSpec};
use super::model::{invalid, FullModelParams, IpcjParams, STANDARD_GRAVITY};
use crate::error::Result;

/// The plane of an IPCJ (Figure 11).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Plane {
    /// The `x̃z̃` plane (forward–backward sway; ZMP `x̃`).
    Xz,
    /// The `ỹz̃` plane (sideways sway; ZMP `ỹ`).
    Yz,
}

impl Plane {
    /// Both planes, in the order used by arrays `[x̃, ỹ]`.
    pub const BOTH: [Plane; 2] = [Plane::Xz, Plane::Yz];

    fn index(self) -> usize {
        match self {
            Plane::Xz => 0,
            Plane::Yz => 1,
        }
    }
}

/// The support phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum SupportPhase {
    /// Single support (SSP): one foot on the ground; local frame at the stance foot.
    Single,
    /// Double support (DSP): both feet; local frame between the feet.
    Double,
}

impl SupportPhase {
    fn index(self) -> usize {
        match self {
            SupportPhase::Single => 0,
            SupportPhase::Double => 1,
        }
    }
}

/// Model parameters of the four cases.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CaseParams {
    /// `x̃z̃` plane, single support.
    pub xz_ssp: FullModelParams,
    /// `x̃z̃` plane, double support.
    pub xz_dsp: FullModelParams,
    /// `ỹz̃` plane, single support.
    pub yz_ssp: FullModelParams,
    /// `ỹz̃` plane, double support.
    pub yz_dsp: FullModelParams,
}

impl CaseParams {
    /// A synthetic robot (Hubo's identified values are not published; errata §2.2): `l = 0.8` m,
    /// `τ_s = 0.02` s, `T = 0.01` s in every case, and open-loop `(w_n/2π, ζ)`:
    /// `ỹz̃`-DSP (2.0 Hz, 0.05) — the errata's reference plant —, `x̃z̃`-DSP (2.5 Hz, 0.06),
    /// `ỹz̃`-SSP (1.2 Hz, 0.04), `x̃z̃`-SSP (1.5 Hz, 0.05): softer on one foot.
    pub fn synthetic() -> Result<Self> {
        let tau = std::f64::consts::TAU;
        let case = |f: f64, z: f64| -> Result<FullModelParams> {
            Ok(FullModelParams {
                ipcj: IpcjParams::from_modal(0.8, tau * f, z, STANDARD_GRAVITY)?,
                lag: 0.02,
                pade: 0.01,
            })
        };
        Ok(Self {
            xz_ssp: case(1.5, 0.05)?,
            xz_dsp: case(2.5, 0.06)?,
            yz_ssp: case(1.2, 0.04)?,
            yz_dsp: case(2.0, 0.05)?,
        })
    }

    /// The parameters of one case.
    pub fn get(&self, plane: Plane, phase: SupportPhase) -> &FullModelParams {
        match (plane, phase) {
            (Plane::Xz, SupportPhase::Single) => &self.xz_ssp,
            (Plane::Xz, SupportPhase::Double) => &self.xz_dsp,
            (Plane::Yz, SupportPhase::Single) => &self.yz_ssp,
            (Plane::Yz, SupportPhase::Double) => &self.yz_dsp,
        }
    }

    /// Checks every case.
    pub fn validate(&self) -> Result<()> {
        for p in [&self.xz_ssp, &self.xz_dsp, &self.yz_ssp, &self.yz_dsp] {
            p.validate()?;
        }
        Ok(())
    }
}

/// Settings of the two-plane balance controller.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BalanceSettings {
    /// Desired poles, the same in all four cases.
    pub poles: PoleSpec,
    /// Control period and observer speed.
    pub discrete: DiscreteSettings,
    /// Duration of the cross-fade after a support-phase change \[s\]; 0 switches at once.
    /// Longer is smoother but keeps the wrong case's controller in the loop for longer.
    pub blend_time: f64,
}

impl Default for BalanceSettings {
    fn default() -> Self {
        Self {
            poles: PoleSpec::default(),
            discrete: DiscreteSettings::default(),
            blend_time: 0.1,
        }
    }
}

impl BalanceSettings {
    /// Checks every part.
    pub fn validate(&self) -> Result<()> {
        self.poles.validate()?;
        self.discrete.validate()?;
        if !(self.blend_time.is_finite() && self.blend_time >= 0.0) {
            return Err(invalid(
                "BalanceSettings::blend_time [s]",
                self.blend_time,
                ">= 0",
            ));
        }
        Ok(())
    }
}

/// What one tick of the two-plane controller returns; arrays are `[x̃z̃, ỹz̃]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BalanceOutput {
    /// Command angles `u` \[rad\].
    pub u: [f64; 2],
    /// COM reference offsets `Δc = l (u − u_ref)` \[m\] in the local frame.
    pub com_offset: [f64; 2],
    /// The support phase whose controllers are (becoming) active.
    pub phase: SupportPhase,
    /// Weight of the active phase's controllers in the command \[–\]: 1 when settled, below 1
    /// during a hand-over.
    pub blend: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Blend {
    from: SupportPhase,
    done: usize,
}

/// The damping controller of both planes and both support phases (Sections 4.2–4.3).
#[derive(Debug, Clone, PartialEq)]
pub struct BalanceController {
    /// `[plane][phase]`.
    controllers: [[DampingController; 2]; 2],
    active: SupportPhase,
    blend: Option<Blend>,
    blend_steps: usize,
}

impl BalanceController {
    /// Designs the four controllers; starts in `phase`, at rest.
    pub fn new(
        cases: &CaseParams,
        settings: &BalanceSettings,
        phase: SupportPhase,
    ) -> Result<Self> {
        settings.validate()?;
        cases.validate()?;
        let d = |plane, ph| -> Result<DampingController> {
            let design: DiscreteDesign =
                design_discrete(cases.get(plane, ph), &settings.poles, &settings.discrete)?;
            Ok(DampingController::new(design))
        };
        Ok(Self {
            controllers: [
                [
                    d(Plane::Xz, SupportPhase::Single)?,
                    d(Plane::Xz, SupportPhase::Double)?,
                ],
                [
                    d(Plane::Yz, SupportPhase::Single)?,
                    d(Plane::Yz, SupportPhase::Double)?,
                ],
            ],
            active: phase,
            blend: None,
            blend_steps: (settings.blend_time / settings.discrete.control_period).round() as usize,
        })
    }

    /// The controller of one case.
    pub fn controller(&self, plane: Plane, phase: SupportPhase) -> &DampingController {
        &self.controllers[plane.index()][phase.index()]
    }

    /// One control tick in support phase `phase`, with references `u_ref` \[rad\] and measured
    /// ZMP deviations `zmp` \[m\], both `[x̃, ỹ]` in that phase's local frame. Allocates nothing.
    /// Errors (state unchanged) on non-finite input.
    pub fn step(
        &mut self,
        phase: SupportPhase,
        u_ref: [f64; 2],
        zmp: [f64; 2],
    ) -> Result<BalanceOutput> {
        for (i, v) in u_ref.iter().chain(zmp.iter()).enumerate() {
            crate::error::check_finite(|| format!("BalanceController::step input[{i}]"), *v)?;
        }
        if phase != self.active {
            self.switch(phase);
        }
        let n = self.blend_steps.max(1);
        let alpha = match self.blend {
            Some(b) => {
                let s = ((b.done + 1) as f64 / n as f64).min(1.0);
                s * s * (3.0 - 2.0 * s)
            }
            None => 1.0,
        };
        let mut out = BalanceOutput {
            u: [0.0; 2],
            com_offset: [0.0; 2],
            phase: self.active,
            blend: alpha,
        };
        let active = self.active.index();
        for plane in Plane::BOTH {
            let p = plane.index();
            let (y, r) = (zmp[p], u_ref[p]);
            let pair = &mut self.controllers[p];
            let (new_cmd, new_x) = pair[active].correct(r, y)?;
            let cmd: BalanceCommand = match self.blend {
                Some(b) => {
                    let from = b.from.index();
                    let (old_cmd, old_x) = pair[from].correct(r, y)?;
                    let u = (1.0 - alpha) * old_cmd.u + alpha * new_cmd.u;
                    pair[from].predict(&old_x, u);
                    BalanceCommand {
                        u,
                        com_offset: (1.0 - alpha) * old_cmd.com_offset + alpha * new_cmd.com_offset,
                        estimate: new_cmd.estimate,
                    }
                }
                None => new_cmd,
            };
            pair[active].predict(&new_x, cmd.u);
            out.u[p] = cmd.u;
            out.com_offset[p] = cmd.com_offset;
        }
        if let Some(b) = self.blend.as_mut() {
            b.done += 1;
            if b.done >= n {
                self.blend = None;
            }
        }
        Ok(out)
    }

    fn switch(&mut self, phase: SupportPhase) {
        let n = self.blend_steps;
        let old = self.active;
        self.blend = match self.blend {
            Some(b) if b.from == phase => Some(Blend {
                from: old,
                done: n.saturating_sub(b.done),
            }),
            _ => {
                for pair in self.controllers.iter_mut() {
                    let x = pair[old.index()].predicted_state();
                    pair[phase.index()].set_predicted_state(x);
                }
                (n > 0).then_some(Blend { from: old, done: 0 })
            }
        };
        self.active = phase;
    }
}
