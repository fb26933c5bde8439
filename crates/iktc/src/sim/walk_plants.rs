//! The simulated compliant robot under the [`WalkingController`]: one IPCJ plant per plane
//! ([`SimPlant`], Section 4), driven each tick by the commanded COM's deviation from the nominal
//! COM in the local frame of Figure 11 over the pendulum length, `u = R(ψ)ᵀ (c − c_nom) / l`
//! \[rad\]; its model switches with the support phase, and a push is an impulse on it. It
//! gives the measured ZMP deviation `(x̃, ỹ)` \[m\] the damping controller reads.

use nalgebra::{Rotation2, Vector2};

use crate::balance::{CaseParams, Plane, PlantParams, SimPlant, SimSettings, SupportPhase};
use crate::error::Result;
use crate::sim::{Push, WalkImitateConfig, WalkTick, WalkingController};

/// The two plants of a walking run and the phase their models are for.
#[derive(Debug, Clone)]
pub struct WalkPlants {
    plants: [SimPlant; 2],
    cases: CaseParams,
    phase: SupportPhase,
    pendulum_length: f64,
    push: Option<(usize, Push)>,
}

impl WalkPlants {
    /// The plants of `wc`'s walk for a robot of `mass` \[kg\]: double-support models, the
    /// noise, seeds (x: `cfg.seed`, y: `cfg.seed + 1`) and push of `cfg`, one control period
    /// of `cfg.imitate.dt` per step.
    pub fn new(wc: &WalkingController, mass: f64, cfg: &WalkImitateConfig) -> Result<Self> {
        let dt = cfg.imitate.dt;
        let cases = *wc.cases();
        let sim = SimSettings {
            control_period: dt,
            seed: cfg.seed,
            ..SimSettings::default()
        };
        let plant = |plane, seed| {
            SimPlant::new(
                PlantParams::from_model(
                    *cases.get(plane, SupportPhase::Double),
                    mass,
                    cfg.noise_std,
                ),
                &SimSettings { seed, ..sim },
            )
        };
        Ok(Self {
            plants: [
                plant(Plane::Xz, cfg.seed)?,
                plant(Plane::Yz, cfg.seed.wrapping_add(1))?,
            ],
            cases,
            phase: SupportPhase::Double,
            pendulum_length: wc.pendulum_length(),
            push: cfg.push.map(|p| ((p.time / dt).round() as usize, p)),
        })
    }

    /// The measured ZMP deviation `(x̃, ỹ)` in the local frame \[m\] (delayed, with noise).
    pub fn measure(&mut self) -> [f64; 2] {
        [self.plants[0].measure(), self.plants[1].measure()]
    }

    /// One control period after tick `k` of `wc` decided `wt`: the models switched to `wt`'s
    /// phase, the push applied at its tick (its impulse turned into the local frame), the
    /// plants advanced with the commanded COM. Errors: a non-finite command or push.
    pub fn step(&mut self, k: usize, wc: &WalkingController, wt: &WalkTick) -> Result<()> {
        let rot = Rotation2::new(wt.local_yaw);
        let com = wc.imitation().kinematics().com();
        let d_local = rot.inverse() * (Vector2::new(com.x, com.y) - wt.com_nominal);
        if wt.phase != self.phase {
            for (p, plane) in self.plants.iter_mut().zip(Plane::BOTH) {
                p.switch_model(*self.cases.get(plane, wt.phase))?;
            }
            self.phase = wt.phase;
        }
        if let Some((tick, p)) = self.push {
            if tick == k {
                let j = rot.inverse() * Vector2::new(p.impulse[0], p.impulse[1]);
                self.plants[0].push(j.x)?;
                self.plants[1].push(j.y)?;
            }
        }
        for (i, p) in self.plants.iter_mut().enumerate() {
            p.advance(d_local[i] / self.pendulum_length)?;
        }
        Ok(())
    }
}
