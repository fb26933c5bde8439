//! A simulated robot to test the damping controller on: one IPCJ plane with the sensor lag, a
//! *true* time delay (a delay line, not the Padé term), sensor noise and pushes on the COM.
//!
//! The IPCJ and the lag (three states `[θ, θ̇, z]`) are integrated exactly over substeps of
//! `h = Δt / substeps` with the command held (zero-order hold). The lag output `z` goes
//! through a delay line sampled every `h` and read by linear interpolation, so any delay is
//! possible; Gaussian noise is added to the delayed ZMP. A push is a horizontal force impulse
//! `J` \[N·s\] at the COM: the angular momentum `m l² θ̇` about the joint jumps by `J l`, so
//! `θ̇ += J / (m l)`.
//!
//! Noise comes from [`NoiseSource`], a small deterministic generator (SplitMix64, Steele et
//! al., OOPSLA 2014, with the Box–Muller transform), so the library needs no random-number
//! crate and every run is reproducible from its seed.

use nalgebra::{DMatrix, Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use super::model::{invalid, FullModelParams};
use crate::error::{check_finite, Result};

/// The true plant of one plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlantParams {
    /// IPCJ, lag `τ_s` and Padé `T` (the Padé term itself is *not* simulated).
    pub model: FullModelParams,
    /// Robot mass `m` \[kg\]; only the push needs it.
    pub mass: f64,
    /// True output delay \[s\]; `2T` is the delay the Padé term of the model approximates.
    pub delay: f64,
    /// Standard deviation of the ZMP sensor noise \[m\].
    pub noise_std: f64,
}

impl PlantParams {
    /// The plant the model describes: delay `2T`, with the given mass \[kg\] and noise \[m\].
    pub fn from_model(model: FullModelParams, mass: f64, noise_std: f64) -> Self {
        Self {
            model,
            mass,
            delay: 2.0 * model.pade,
            noise_std,
        }
    }

    /// Checks ranges.
    pub fn validate(&self) -> Result<()> {
        self.model.validate()?;
        if !(self.mass.is_finite() && self.mass > 0.0) {
            return Err(invalid("PlantParams::mass [kg]", self.mass, "> 0"));
        }
        for (name, v) in [
            ("PlantParams::delay [s]", self.delay),
            ("PlantParams::noise_std [m]", self.noise_std),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(name, v, ">= 0"));
            }
        }
        Ok(())
    }
}

/// Settings of the simulation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SimSettings {
    /// Control period `Δt` \[s\]: one [`SimPlant::advance`] call.
    pub control_period: f64,
    /// Integration substeps per control period \[–\] (≥ 1); they set the delay line's
    /// resolution `Δt/substeps`. The integration itself is exact at any value.
    pub substeps: usize,
    /// Seed of the sensor noise.
    pub seed: u64,
}

impl Default for SimSettings {
    fn default() -> Self {
        Self {
            control_period: 0.005,
            substeps: 5,
            seed: 1,
        }
    }
}

impl SimSettings {
    /// Checks ranges.
    pub fn validate(&self) -> Result<()> {
        if !(self.control_period.is_finite() && self.control_period > 0.0) {
            return Err(invalid(
                "SimSettings::control_period [s]",
                self.control_period,
                "> 0",
            ));
        }
        if self.substeps == 0 {
            return Err(invalid("SimSettings::substeps", 0.0, ">= 1"));
        }
        Ok(())
    }
}

/// One simulated plane. Construction allocates the delay line; stepping allocates nothing.
#[derive(Debug, Clone, PartialEq)]
pub struct SimPlant {
    params: PlantParams,
    ad: Matrix3<f64>,
    bd: Vector3<f64>,
    h: f64,
    substeps: usize,
    state: Vector3<f64>,
    /// Ring buffer of the lag output, one sample per substep.
    line: Vec<f64>,
    head: usize,
    noise: NoiseSource,
    time: f64,
}

impl SimPlant {
    /// A plant at rest at the origin.
    pub fn new(params: PlantParams, settings: &SimSettings) -> Result<Self> {
        params.validate()?;
        settings.validate()?;
        let h = settings.control_period / settings.substeps as f64;
        let (ad, bd) = discretize(&params.model, h);
        let len = (params.delay / h).ceil() as usize + 2;
        Ok(Self {
            params,
            ad,
            bd,
            h,
            substeps: settings.substeps,
            state: Vector3::zeros(),
            line: vec![0.0; len],
            head: 0,
            noise: NoiseSource::new(settings.seed),
            time: 0.0,
        })
    }

    /// Changes the compliance model (a support-phase change) keeping the state, the delay line
    /// and the noise: the pendulum does not jump, its stiffness does. (It recomputes a matrix
    /// exponential: part of the simulated world, not of the control tick.)
    pub fn switch_model(&mut self, model: FullModelParams) -> Result<()> {
        model.validate()?;
        let (ad, bd) = discretize(&model, self.h);
        self.ad = ad;
        self.bd = bd;
        self.params.model = model;
        Ok(())
    }
}

/// Exact zero-order-hold discretisation over `h` \[s\] of the IPCJ with its lag (3 states).
fn discretize(model: &FullModelParams, h: f64) -> (Matrix3<f64>, Vector3<f64>) {
    {
        let ip = model.ipcj.state_space();
        let ts = model.lag;
        let a = Matrix3::new(
            ip.a[(0, 0)],
            ip.a[(0, 1)],
            0.0,
            ip.a[(1, 0)],
            ip.a[(1, 1)],
            0.0,
            ip.c[0] / ts,
            ip.c[1] / ts,
            -1.0 / ts,
        );
        let b = Vector3::new(ip.b[0], ip.b[1], ip.d / ts);
        let mut m = DMatrix::<f64>::zeros(4, 4);
        m.view_mut((0, 0), (3, 3)).copy_from(&(a * h));
        m.view_mut((0, 3), (3, 1)).copy_from(&(b * h));
        let e = m.exp();
        (
            e.fixed_view::<3, 3>(0, 0).into_owned(),
            e.fixed_view::<3, 1>(0, 3).into_owned(),
        )
    }
}

impl SimPlant {
    /// The plant's parameters.
    pub fn params(&self) -> &PlantParams {
        &self.params
    }

    /// Simulated time \[s\].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// True state `[θ, θ̇, z]` \[rad, rad/s, m\].
    pub fn state(&self) -> [f64; 3] {
        self.state.into()
    }

    /// The ZMP at the sensor now, delayed and without noise \[m\].
    pub fn delayed_zmp(&self) -> f64 {
        let steps = self.params.delay / self.h;
        let k = steps.floor();
        let frac = steps - k;
        let a = self.sample_back(k as usize);
        let b = self.sample_back(k as usize + 1);
        (1.0 - frac) * a + frac * b
    }

    /// The measured ZMP now: delayed, plus noise \[m\].
    pub fn measure(&mut self) -> f64 {
        self.delayed_zmp() + self.params.noise_std * self.noise.gaussian()
    }

    /// Advances one control period with the command `u` \[rad\] held. Errors (nothing changed)
    /// if `u` is not finite.
    pub fn advance(&mut self, u: f64) -> Result<()> {
        check_finite(|| "plant command u [rad]".into(), u)?;
        for _ in 0..self.substeps {
            self.state = self.ad * self.state + self.bd * u;
            self.head = (self.head + 1) % self.line.len();
            if let Some(slot) = self.line.get_mut(self.head) {
                *slot = self.state.z;
            }
            self.time += self.h;
        }
        Ok(())
    }

    /// A horizontal force impulse `J` \[N·s\] on the COM: `θ̇ += J/(m l)`.
    pub fn push(&mut self, impulse: f64) -> Result<()> {
        check_finite(|| "push impulse [N·s]".into(), impulse)?;
        self.state.y += impulse / (self.params.mass * self.params.model.ipcj.length);
        Ok(())
    }

    fn sample_back(&self, k: usize) -> f64 {
        let n = self.line.len();
        let i = (self.head + n - (k % n)) % n;
        self.line.get(i).copied().unwrap_or(0.0)
    }
}

/// Deterministic Gaussian noise: SplitMix64 uniforms and the Box–Muller transform.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseSource {
    state: u64,
    spare: Option<f64>,
}

impl NoiseSource {
    /// A generator with the given seed.
    pub fn new(seed: u64) -> Self {
        Self {
            state: seed,
            spare: None,
        }
    }

    /// A uniform number in (0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// A standard normal number.
    pub fn gaussian(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = std::f64::consts::TAU * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}
