//! Identification of the full model (eq. 31) from frequency-response data (Section 4.2).
//!
//! Nonlinear least squares over `x = ln[l, K/m, b/m, τ_s, T]` (logarithms keep every
//! parameter positive and make the steps relative) with the residual
//! `rᵢ = H(jωᵢ; x) / Hᵢ − 1` split into real and imaginary parts: for small errors it is the
//! relative magnitude error and the phase error \[rad\], equally weighted at every frequency and
//! insensitive to ±2π phase wrapping. Solved with [`levenberg_marquardt()`].
//!
//! The initial guess is automatic, from the shape of the data:
//! 1. `w_n` = frequency of the largest magnitude;
//! 2. `l` from the lowest-frequency magnitude `M`, with `K/m = l² w_n² + g l`: the IPCJ's
//!    `|H(jω)| = (l w_n² + g)(l ω² + g) / (g |w_n² − ω² + 2jζ w_n ω|)` is a quadratic in `l`;
//! 3. `b/m` from the peak height, `|H(j w_n)| ≈ (K/(m g))(w_n² + g/l) l² / ((b/m) w_n)`;
//! 4. `τ_s` and `T` from the ratio `ρ = Hᵢ / H_IPCJ(jωᵢ)` well above the peak:
//!    `|ρ| = 1/√(1 + τ_s² ω²)` and `arg(ρ (1 + jτ_s ω)) = −2 atan(T ω)`; medians over the points.
//!
//! A second start with the lag and the delay exchanged (`τ_s ↔ 2T`) guards against the two
//! being confused; the better fit is kept.

use nalgebra::{Complex, DVector};
use serde::Serialize;

use super::lm::{levenberg_marquardt, LmSettings, LmStatus};
use super::model::{invalid, FullModelParams, IpcjParams, STANDARD_GRAVITY};
use crate::error::{check_finite, Error, Result};

/// Measured frequency response `y/u` at a set of angular frequencies.
#[derive(Debug, Clone, PartialEq)]
pub struct FrequencyData {
    /// Angular frequencies \[rad/s\], positive, any order.
    pub omega: Vec<f64>,
    /// Complex response `y/u (jω)` \[m/rad\], one per frequency.
    pub response: Vec<Complex<f64>>,
}

impl FrequencyData {
    /// From Bode data: magnitudes \[m/rad\] and phases \[rad\] at angular frequencies \[rad/s\].
    /// Errors if the lengths differ or a value is not finite.
    pub fn from_bode(omega: &[f64], magnitude: &[f64], phase: &[f64]) -> Result<Self> {
        crate::error::check_dim("FrequencyData magnitude", omega.len(), magnitude.len())?;
        crate::error::check_dim("FrequencyData phase", omega.len(), phase.len())?;
        for (i, (m, p)) in magnitude.iter().zip(phase).enumerate() {
            check_finite(|| format!("magnitude[{i}] [m/rad]"), *m)?;
            check_finite(|| format!("phase[{i}] [rad]"), *p)?;
        }
        Ok(Self {
            omega: omega.to_vec(),
            response: magnitude
                .iter()
                .zip(phase)
                .map(|(m, p)| Complex::from_polar(*m, *p))
                .collect(),
        })
    }

    /// Checks lengths, finiteness, positive frequencies and non-zero responses, and that there
    /// are at least `min_points` distinct frequencies.
    pub fn validate(&self, min_points: usize) -> Result<()> {
        crate::error::check_dim(
            "FrequencyData response",
            self.omega.len(),
            self.response.len(),
        )?;
        for (i, (w, h)) in self.omega.iter().zip(&self.response).enumerate() {
            check_finite(|| format!("omega[{i}] [rad/s]"), *w)?;
            check_finite(|| format!("response[{i}].re [m/rad]"), h.re)?;
            check_finite(|| format!("response[{i}].im [m/rad]"), h.im)?;
            if *w <= 0.0 {
                return Err(invalid(&format!("omega[{i}] [rad/s]"), *w, "> 0"));
            }
            if h.norm() <= 0.0 {
                return Err(invalid(
                    &format!("|response[{i}]| [m/rad]"),
                    0.0,
                    "> 0 (the fit is relative to the measured response)",
                ));
            }
        }
        let mut sorted = self.omega.clone();
        sorted.sort_by(f64::total_cmp);
        sorted.dedup();
        if sorted.len() < min_points {
            return Err(Error::InsufficientData {
                what: "IPCJ identification".into(),
                message: format!(
                    "{} distinct frequencies given, at least {min_points} needed for the 5 \
                     parameters (l, K/m, b/m, τ_s, T)",
                    sorted.len()
                ),
            });
        }
        Ok(())
    }
}

/// Settings of the identification.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IdentifySettings {
    /// Gravity \[m/s²\], known, not identified.
    pub gravity: f64,
    /// Fewest distinct frequencies accepted \[–\] (≥ 3: five parameters, two numbers a point).
    /// More makes the fit better determined and the residual a meaningful check.
    pub min_points: usize,
    /// Points above this multiple of the resonance frequency set the initial `τ_s`, `T` \[–\].
    /// Higher keeps the IPCJ's own phase out of the estimate but leaves fewer points.
    pub high_frequency_factor: f64,
    /// Initial `τ_s` when no point lies above the resonance \[s\].
    pub fallback_lag: f64,
    /// Initial `T` when no point lies above the resonance \[s\].
    pub fallback_pade: f64,
    /// Initial `l` when the low-frequency magnitude gives none \[m\].
    pub fallback_length: f64,
    /// Initial damping ratio when the peak gives none \[–\].
    pub fallback_damping_ratio: f64,
    /// The least-squares solver.
    pub lm: LmSettings,
}

impl Default for IdentifySettings {
    fn default() -> Self {
        Self {
            gravity: STANDARD_GRAVITY,
            min_points: 6,
            high_frequency_factor: 2.0,
            fallback_lag: 0.01,
            fallback_pade: 0.005,
            fallback_length: 1.0,
            fallback_damping_ratio: 0.1,
            lm: LmSettings::default(),
        }
    }
}

impl IdentifySettings {
    /// Checks the settings' ranges.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("IdentifySettings::gravity [m/s²]", self.gravity),
            (
                "IdentifySettings::high_frequency_factor",
                self.high_frequency_factor,
            ),
            ("IdentifySettings::fallback_lag [s]", self.fallback_lag),
            ("IdentifySettings::fallback_pade [s]", self.fallback_pade),
            (
                "IdentifySettings::fallback_length [m]",
                self.fallback_length,
            ),
            (
                "IdentifySettings::fallback_damping_ratio",
                self.fallback_damping_ratio,
            ),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "finite and > 0"));
            }
        }
        if self.min_points < 3 {
            return Err(invalid(
                "IdentifySettings::min_points",
                self.min_points as f64,
                ">= 3",
            ));
        }
        self.lm.validate()
    }
}

/// One identified parameter with its unit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterEstimate {
    /// Name and symbol, e.g. `"l (pendulum length)"`.
    pub name: &'static str,
    /// Unit, e.g. `"m"`.
    pub unit: &'static str,
    /// Estimated value.
    pub value: f64,
    /// One-sigma standard error from the fit's Jacobian and residual (linearised) \[unit\].
    pub std_error: f64,
}

/// The result of an identification.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identification {
    /// Identified parameters of the full model.
    pub params: FullModelParams,
    /// The automatic initial guess the fit started from.
    pub initial_guess: FullModelParams,
    /// The parameters with units and standard errors, in the order l, K/m, b/m, τ_s, T.
    pub estimates: Vec<ParameterEstimate>,
    /// RMS of `|H_model/H_measured − 1|` over the frequencies \[–\].
    pub rms_relative_error: f64,
    /// RMS magnitude error \[dB\].
    pub rms_magnitude_error_db: f64,
    /// RMS phase error \[deg\].
    pub rms_phase_error_deg: f64,
    /// Solver iterations of the kept start.
    pub iterations: usize,
    /// Why the solver stopped.
    pub status: LmStatus,
}

/// Each parameter's estimate with its standard error from the linearised covariance of the
/// fit of `m` residuals.
fn parameter_estimates(
    params: &FullModelParams,
    fit: &super::lm::LmResult,
    m: usize,
) -> Vec<ParameterEstimate> {
    // Linearised covariance of ln p: σ² (JᵀJ)⁻¹, σ² = ‖r‖² / (m − n).
    let dof = (m as f64 - 5.0).max(1.0);
    let sigma2 = 2.0 * fit.cost / dof;
    let cov = (fit.jacobian.transpose() * &fit.jacobian).try_inverse();
    let values = [
        params.ipcj.length,
        params.ipcj.stiffness_per_mass,
        params.ipcj.damping_per_mass,
        params.lag,
        params.pade,
    ];
    let names = [
        ("l (pendulum length)", "m"),
        ("K/m (stiffness per mass)", "N·m/(rad·kg)"),
        ("b/m (damping per mass)", "N·m·s/(rad·kg)"),
        ("τ_s (lag time constant)", "s"),
        ("T (Padé parameter, delay 2T)", "s"),
    ];
    names
        .iter()
        .zip(values)
        .enumerate()
        .map(|(i, ((name, unit), value))| ParameterEstimate {
            name,
            unit,
            value,
            std_error: cov
                .as_ref()
                .map_or(f64::NAN, |c| value * (sigma2 * c[(i, i)]).max(0.0).sqrt()),
        })
        .collect()
}

/// The fit's error sums over the data: squared relative error, squared magnitude error
/// \[dB²\] and squared phase error \[deg²\].
fn fit_errors(data: &FrequencyData, params: &FullModelParams) -> (f64, f64, f64) {
    let (mut rel, mut db, mut deg) = (0.0, 0.0, 0.0);
    for (w, h) in data.omega.iter().zip(&data.response) {
        let ratio = params.frequency_response(*w) / *h;
        rel += (ratio - 1.0).norm_sqr();
        db += (20.0 * ratio.norm().log10()).powi(2);
        deg += ratio.arg().to_degrees().powi(2);
    }
    (rel, db, deg)
}

/// Identifies the full model's parameters from frequency-response data (Section 4.2).
/// Errors if the data are too few, not finite, or the settings invalid.
pub fn identify(data: &FrequencyData, settings: &IdentifySettings) -> Result<Identification> {
    settings.validate()?;
    data.validate(settings.min_points)?;
    let guess = initial_guess(data, settings)?;
    let g = settings.gravity;
    let m = 2 * data.omega.len();
    let residual = |x: &DVector<f64>, r: &mut DVector<f64>| -> Result<()> {
        let p = from_log(x, g);
        p.validate()?;
        for (i, (w, h)) in data.omega.iter().zip(&data.response).enumerate() {
            let e = p.frequency_response(*w) / *h - 1.0;
            r[2 * i] = e.re;
            r[2 * i + 1] = e.im;
        }
        Ok(())
    };
    let swapped = FullModelParams {
        ipcj: guess.ipcj,
        lag: 2.0 * guess.pade,
        pade: 0.5 * guess.lag,
    };
    let mut best = None;
    for start in [guess, swapped] {
        let fit = levenberg_marquardt(residual, to_log(&start), m, &settings.lm)?;
        if best
            .as_ref()
            .is_none_or(|b: &super::lm::LmResult| fit.cost < b.cost)
        {
            best = Some(fit);
        }
    }
    let fit = best.ok_or_else(|| Error::InsufficientData {
        what: "IPCJ identification".into(),
        message: "no start point".into(),
    })?;
    let params = from_log(&fit.x, g);
    params.validate()?;
    let estimates = parameter_estimates(&params, &fit, m);
    let (rel, db, deg) = fit_errors(data, &params);
    let n = data.omega.len() as f64;
    Ok(Identification {
        params,
        initial_guess: guess,
        estimates,
        rms_relative_error: (rel / n).sqrt(),
        rms_magnitude_error_db: (db / n).sqrt(),
        rms_phase_error_deg: (deg / n).sqrt(),
        iterations: fit.iterations,
        status: fit.status,
    })
}

/// The automatic initial guess described in the module documentation.
pub fn initial_guess(data: &FrequencyData, settings: &IdentifySettings) -> Result<FullModelParams> {
    settings.validate()?;
    data.validate(settings.min_points)?;
    let g = settings.gravity;
    let mut idx: Vec<usize> = (0..data.omega.len()).collect();
    idx.sort_by(|a, b| data.omega[*a].total_cmp(&data.omega[*b]));
    let pts: Vec<(f64, Complex<f64>)> = idx
        .iter()
        .map(|&i| (data.omega[i], data.response[i]))
        .collect();
    let (wn, peak) = pts
        .iter()
        .map(|(w, h)| (*w, h.norm()))
        .fold(
            (0.0, 0.0),
            |acc, (w, m)| if m > acc.1 { (w, m) } else { acc },
        );
    let (w0, h0) = pts.first().map_or((wn, peak), |(w, h)| (*w, h.norm()));
    let mut zeta = settings.fallback_damping_ratio;
    let mut length = settings.fallback_length;
    let mut km = length * length * wn * wn + g * length;
    for _ in 0..3 {
        let den = Complex::new(wn * wn - w0 * w0, 2.0 * zeta * wn * w0).norm();
        let (qa, qb, qc) = (
            wn * wn * w0 * w0,
            g * (wn * wn + w0 * w0),
            g * g - g * h0 * den,
        );
        let disc = qb * qb - 4.0 * qa * qc;
        if qc < 0.0 && disc > 0.0 && qa > 0.0 {
            length = (-qb + disc.sqrt()) / (2.0 * qa);
        }
        km = length * length * wn * wn + g * length;
        let bm = km * (wn * wn + g / length) * length * length / (g * wn * peak);
        let z = bm / (2.0 * wn * length * length);
        zeta = if z.is_finite() && z > 0.0 && z < 1.0 {
            z
        } else {
            settings.fallback_damping_ratio
        };
    }
    let ipcj = IpcjParams {
        length,
        stiffness_per_mass: km,
        damping_per_mass: 2.0 * zeta * wn * length * length,
        gravity: g,
    };
    ipcj.validate()?;
    let mut lags = Vec::new();
    let mut pades = Vec::new();
    for (w, h) in pts
        .iter()
        .filter(|(w, _)| *w > settings.high_frequency_factor * wn)
    {
        let rho = *h / ipcj.frequency_response(*w);
        let tau = ((1.0 / rho.norm_sqr() - 1.0).max(0.0)).sqrt() / w;
        lags.push(tau);
        let phi = (rho * Complex::new(1.0, tau * w)).arg();
        if phi < 0.0 {
            pades.push((-0.5 * phi).tan() / w);
        }
    }
    let lag = median(&mut lags)
        .filter(|v| *v > 0.0)
        .unwrap_or(settings.fallback_lag);
    let pade = median(&mut pades)
        .filter(|v| *v > 0.0)
        .unwrap_or(settings.fallback_pade);
    let p = FullModelParams { ipcj, lag, pade };
    p.validate()?;
    Ok(p)
}

fn median(v: &mut [f64]) -> Option<f64> {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        None
    } else if n % 2 == 1 {
        v.get(n / 2).copied()
    } else {
        Some(0.5 * (v.get(n / 2 - 1)? + v.get(n / 2)?))
    }
}

fn to_log(p: &FullModelParams) -> DVector<f64> {
    DVector::from_vec(vec![
        p.ipcj.length.ln(),
        p.ipcj.stiffness_per_mass.ln(),
        p.ipcj.damping_per_mass.max(f64::MIN_POSITIVE).ln(),
        p.lag.ln(),
        p.pade.ln(),
    ])
}

fn from_log(x: &DVector<f64>, gravity: f64) -> FullModelParams {
    let e = |i: usize| x.get(i).copied().unwrap_or(f64::NAN).exp();
    FullModelParams {
        ipcj: IpcjParams {
            length: e(0),
            stiffness_per_mass: e(1),
            damping_per_mass: e(2),
            gravity,
        },
        lag: e(3),
        pade: e(4),
    }
}
