//! The sinusoidal-response experiment of Section 4.2 on the simulated plant.
//!
//! At each frequency the command `u_k = A sin(ω k Δt)` is sent at the control rate (held
//! between ticks); after a settling time the sampled ZMP is fitted by least squares with
//! `a sin ωt + b cos ωt + c` over a whole number of periods. The response is
//! `(a + j b) / (A · H_zoh(jω))` with `H_zoh(jω) = (1 − e^{−jωΔt})/(jωΔt)`, the fundamental
//! of the held command, so the estimate is of the continuous plant `y/u`.

use nalgebra::{Complex, Matrix3, Vector3};
use serde::Serialize;

use super::identify::FrequencyData;
use super::model::invalid;
use super::sim::{PlantParams, SimPlant, SimSettings};
use crate::error::{Error, Result};

/// Settings of the sine sweep.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SweepSettings {
    /// Lowest frequency \[Hz\].
    pub min_frequency: f64,
    /// Highest frequency \[Hz\]; below the Nyquist frequency of the control rate.
    pub max_frequency: f64,
    /// Number of frequencies, log-spaced \[–\] (≥ 2).
    pub count: usize,
    /// Command amplitude `A` \[rad\]. Larger beats the noise; the model is linear anyway.
    pub amplitude: f64,
    /// Time let pass before measuring at each frequency \[s\]; ≳ 5/(ζ w_n) removes the
    /// transient of the lightly damped pendulum.
    pub settle_time: f64,
    /// Least number of periods measured \[–\].
    pub min_cycles: usize,
    /// Least measuring time \[s\]; longer averages more noise away.
    pub min_measure_time: f64,
}

impl Default for SweepSettings {
    fn default() -> Self {
        Self {
            min_frequency: 0.2,
            max_frequency: 10.0,
            count: 30,
            amplitude: 0.002,
            settle_time: 10.0,
            min_cycles: 10,
            min_measure_time: 4.0,
        }
    }
}

impl SweepSettings {
    /// Checks ranges.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("SweepSettings::min_frequency [Hz]", self.min_frequency),
            ("SweepSettings::max_frequency [Hz]", self.max_frequency),
            ("SweepSettings::amplitude [rad]", self.amplitude),
            ("SweepSettings::min_measure_time [s]", self.min_measure_time),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "finite and > 0"));
            }
        }
        if !(self.settle_time.is_finite() && self.settle_time >= 0.0) {
            return Err(invalid(
                "SweepSettings::settle_time [s]",
                self.settle_time,
                ">= 0",
            ));
        }
        if self.max_frequency < self.min_frequency {
            return Err(Error::InvalidLimit {
                what: "SweepSettings frequency range [Hz]".into(),
                lower: self.min_frequency,
                upper: self.max_frequency,
            });
        }
        if self.count < 2 {
            return Err(invalid("SweepSettings::count", self.count as f64, ">= 2"));
        }
        Ok(())
    }

    /// The log-spaced frequencies \[Hz\].
    pub fn frequencies(&self) -> Vec<f64> {
        let (a, b) = (self.min_frequency.ln(), self.max_frequency.ln());
        let n = self.count.max(2) - 1;
        (0..=n)
            .map(|i| (a + (b - a) * i as f64 / n as f64).exp())
            .collect()
    }
}

/// Runs the sweep on a fresh plant per frequency (noise seed `sim.seed + i`) and returns the
/// measured frequency response.
pub fn sine_sweep(
    plant: &PlantParams,
    sim: &SimSettings,
    settings: &SweepSettings,
) -> Result<FrequencyData> {
    settings.validate()?;
    sim.validate()?;
    let dt = sim.control_period;
    let nyquist = 0.5 / dt;
    if settings.max_frequency >= nyquist {
        return Err(invalid(
            "SweepSettings::max_frequency [Hz]",
            settings.max_frequency,
            &format!("< {nyquist} (Nyquist frequency of the control rate)"),
        ));
    }
    let freqs = settings.frequencies();
    let mut omega = Vec::with_capacity(freqs.len());
    let mut response = Vec::with_capacity(freqs.len());
    for (i, f) in freqs.iter().enumerate() {
        let w = std::f64::consts::TAU * f;
        let mut p = SimPlant::new(
            *plant,
            &SimSettings {
                seed: sim.seed.wrapping_add(i as u64),
                ..*sim
            },
        )?;
        let period = 1.0 / f;
        let cycles = (settings.min_cycles as f64).max((settings.min_measure_time / period).ceil());
        let n_settle = (settings.settle_time / dt).round() as usize;
        let n_meas = (cycles * period / dt).round() as usize;
        let mut normal = Matrix3::<f64>::zeros();
        let mut rhs = Vector3::<f64>::zeros();
        for k in 0..(n_settle + n_meas) {
            let t = k as f64 * dt;
            let y = p.measure();
            if k >= n_settle {
                let phi = Vector3::new((w * t).sin(), (w * t).cos(), 1.0);
                normal += phi * phi.transpose();
                rhs += phi * y;
            }
            p.advance(settings.amplitude * (w * t).sin())?;
        }
        let coef =
            normal
                .cholesky()
                .map(|c| c.solve(&rhs))
                .ok_or_else(|| Error::InsufficientData {
                    what: "sine sweep".into(),
                    message: format!("too few samples at {f} Hz"),
                })?;
        let s = Complex::new(0.0, w * dt);
        let zoh = (Complex::new(1.0, 0.0) - (-s).exp()) / s;
        omega.push(w);
        response.push(Complex::new(coef[0], coef[1]) / (zoh * settings.amplitude));
    }
    Ok(FrequencyData { omega, response })
}
