//! The dominant oscillatory mode of a response by Prony's method: its damping ratio and
//! natural frequency, read from a closed loop that has several modes.
//!
//! A single damped sinusoid fitted to a whole push response ([`super::analyse_response`])
//! is pulled by the other modes the push excites: on the identified model of the MuJoCo G1
//! under its own damping controller, whose dominant pair is at ζ = 0.72 by construction, such
//! a fit reads 0.52 (the real lag pole and the observer's faster pair). Prony's method fits
//! all modes at once and returns the one that carries the most energy:
//!
//! 1. `y` is low-passed by a moving average of [`PronySettings::smoothing`] samples, applied
//!    twice (a linear filter scales each mode's amplitude and keeps its pole), and every
//!    [`PronySettings::decimation`]-th filtered sample is kept (period `h`);
//! 2. the linear prediction `y_k = Σ_{i=1..p} a_i y_{k−i} + c` (`p` =
//!    [`PronySettings::order`]) is fitted by least squares; the roots `z_i` of
//!    `z^p − Σ a_i z^{p−i}` are the modes, `s_i = ln(z_i)/h`;
//! 3. their amplitudes `c_i` are the least-squares fit of `y_k = Σ c_i z_i^k + c₀`, and of
//!    the oscillatory pairs the one with the largest energy `Σ_k |c_i z_i^k|²` is returned,
//!    `ζ = −Re s / |s|`, `ω_n = |s|`.
//!
//! A pair counts as oscillatory only if it turns by at least half a cycle over the record
//! (`|Im s| · T ≥ π`): two real decays of nearly equal rates can come out of the fit as a
//! barely complex pair of large, cancelling amplitudes (design 0.5 on MuJoCo 4.0.1:
//! −9.25 ± 0.62j rad/s over 2 s, energy 8.3 against the 5.55 rad/s pair's 0.075), which is no
//! oscillation.

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use super::model::{invalid, Modal};
use super::poly::Polynomial;
use crate::error::{check_all_finite, check_dim, Error, Result};

/// Settings of [`dominant_mode`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PronySettings {
    /// Length of the moving average, applied twice, that low-passes the response \[samples\].
    /// Default 8 (40 ms at 5 ms: passes the IPCJ mode near 5 rad/s and a second one near
    /// 30 rad/s, removes the contact and servo ripple above); longer averages blur the faster
    /// mode.
    pub smoothing: usize,
    /// Every this-many-th filtered sample is kept \[samples\]. Default 4 (20 ms at 5 ms;
    /// Nyquist 157 rad/s).
    pub decimation: usize,
    /// Order of the linear prediction \[–\]. Default 8: a damped closed loop has the IPCJ pair,
    /// the observer's pair, the lag and Padé poles (and a physical plant a second resonance);
    /// lower orders merge modes and bias ζ.
    pub order: usize,
}

impl Default for PronySettings {
    fn default() -> Self {
        Self {
            smoothing: 8,
            decimation: 4,
            order: 8,
        }
    }
}

impl PronySettings {
    /// Checks ranges: each setting at least 1.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("PronySettings::smoothing", self.smoothing),
            ("PronySettings::decimation", self.decimation),
            ("PronySettings::order", self.order),
        ] {
            if v == 0 {
                return Err(invalid(name, 0.0, ">= 1"));
            }
        }
        Ok(())
    }
}

/// Largest relative spread of the sample intervals accepted as uniform sampling \[–\].
const UNIFORM_TOLERANCE: f64 = 1e-6;

/// Checks the settings and the samples (same lengths, finite, enough for the smoothing,
/// decimation and order, uniformly spaced); returns the sample step \[s\].
fn uniform_step(t: &[f64], y: &[f64], settings: &PronySettings) -> Result<f64> {
    settings.validate()?;
    check_dim("response samples y", t.len(), y.len())?;
    check_all_finite("response times t [s]", t)?;
    check_all_finite("response samples y", y)?;
    let p = settings.order;
    let s = settings.smoothing;
    let too_few = |n: usize| Error::InsufficientData {
        what: "dominant mode (Prony)".into(),
        message: format!(
            "{n} samples; the smoothing ({s}, twice), decimation ({}) and order ({p}) need at \
             least {}",
            settings.decimation,
            2 * (s - 1) + settings.decimation * (2 * p + 1) + 1
        ),
    };
    // After the two averages and the decimation: 2p + 2 samples, so that the prediction's
    // p + 1 unknowns have p + 2 equations.
    let filtered_len = |n: usize| (n + 2).saturating_sub(2 * s).div_ceil(settings.decimation);
    if t.len() < 2 || filtered_len(t.len()) < 2 * p + 2 {
        return Err(too_few(t.len()));
    }
    let dt = t[1] - t[0];
    let uniform = t
        .windows(2)
        .all(|w| ((w[1] - w[0]) - dt).abs() <= UNIFORM_TOLERANCE * dt.abs());
    if !(dt > 0.0 && uniform) {
        return Err(invalid(
            "response times t [s]: their step",
            dt,
            "> 0 and constant (uniform samples)",
        ));
    }
    Ok(dt)
}

/// The roots of the linear prediction `y_k = Σ a_i y_{k−i} + c`, k = p … n−1, of order `p`
/// fitted to the filtered record `yf`.
fn prediction_roots(yf: &[f64], p: usize) -> Result<Vec<Complex<f64>>> {
    let n = yf.len();
    let rows = n - p;
    let mut a = DMatrix::<f64>::zeros(rows, p + 1);
    let mut b = DVector::<f64>::zeros(rows);
    for (r, k) in (p..n).enumerate() {
        for i in 0..p {
            a[(r, i)] = yf[k - 1 - i];
        }
        a[(r, p)] = 1.0;
        b[r] = yf[k];
    }
    let coef = least_squares(a, b)?;
    let mut poly = vec![1.0];
    poly.extend(coef.iter().take(p).map(|ai| -ai));
    Ok(Polynomial::new(&poly).roots())
}

/// The amplitudes of `y_k = Σ c_i z_i^k + c₀` over the filtered record `yf` (the last entry
/// is `c₀`).
fn amplitudes(yf: &[f64], z: &[Complex<f64>]) -> Result<DVector<Complex<f64>>> {
    let n = yf.len();
    let mut v = DMatrix::<Complex<f64>>::zeros(n, z.len() + 1);
    for (j, zj) in z.iter().enumerate() {
        let mut zk = Complex::new(1.0, 0.0);
        for k in 0..n {
            v[(k, j)] = zk;
            zk *= zj;
        }
    }
    for k in 0..n {
        v[(k, z.len())] = Complex::new(1.0, 0.0);
    }
    let yc = DVector::from_iterator(n, yf.iter().map(|x| Complex::new(*x, 0.0)));
    least_squares(v, yc)
}

/// The dominant oscillatory mode (damping ratio ζ \[–\], natural frequency ω_n \[rad/s\]) of
/// the response `y` sampled at the uniformly spaced times `t` \[s\], by Prony's method (see
/// the [module documentation](self)); `None` if no pair of the fit turns by half a cycle over
/// the record. Errors: `t` and `y` of different lengths, not finite, `t` not increasing
/// uniformly, or too few samples for the settings.
pub fn dominant_mode(t: &[f64], y: &[f64], settings: &PronySettings) -> Result<Option<Modal>> {
    let dt = uniform_step(t, y, settings)?;
    let (p, s) = (settings.order, settings.smoothing);
    let yf: Vec<f64> = moving_average(&moving_average(y, s), s)
        .into_iter()
        .step_by(settings.decimation)
        .collect();
    let n = yf.len();
    let h = dt * settings.decimation as f64;
    let z = prediction_roots(&yf, p)?;
    let c = amplitudes(&yf, &z)?;
    let span = h * (n - 1) as f64;
    let mut best: Option<(f64, Complex<f64>)> = None;
    for (zi, ci) in z.iter().zip(c.iter()) {
        if zi.im <= 0.0 || zi.arg() / h * span < std::f64::consts::PI {
            continue;
        }
        let mut zk = Complex::new(1.0, 0.0);
        let mut energy = 0.0;
        for _ in 0..n {
            energy += (ci * zk).norm_sqr();
            zk *= zi;
        }
        if best.is_none_or(|(e, _)| energy > e) {
            best = Some((energy, zi.ln() / h));
        }
    }
    Ok(best.map(|(_, s)| Modal {
        natural_frequency: s.norm(),
        damping_ratio: -s.re / s.norm(),
    }))
}

/// The moving average of `len` samples over the positions where it fits whole
/// (`x.len() − len + 1` values).
fn moving_average(x: &[f64], len: usize) -> Vec<f64> {
    x.windows(len)
        .map(|w| w.iter().sum::<f64>() / len as f64)
        .collect()
}

/// The least-squares solution of `a x = b` of least norm, singular values below
/// `max(rows, cols) · ε` of the largest dropped (as numpy's `lstsq`).
fn least_squares<T: nalgebra::ComplexField<RealField = f64>>(
    a: DMatrix<T>,
    b: DVector<T>,
) -> Result<DVector<T>> {
    let (rows, cols) = a.shape();
    let svd = a.svd(true, true);
    let largest = svd.singular_values.iter().copied().fold(0.0, f64::max);
    let eps = largest * rows.max(cols) as f64 * f64::EPSILON;
    svd.solve(&b, eps).map_err(|m| Error::InsufficientData {
        what: "dominant mode (Prony)".into(),
        message: m.into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 0.005;

    fn times() -> Vec<f64> {
        (0..400).map(|k| k as f64 * DT).collect()
    }

    fn mode(t: f64, zeta: f64, wn: f64, amp: f64, phase: f64) -> f64 {
        amp * (-zeta * wn * t).exp() * (wn * (1.0 - zeta * zeta).sqrt() * t + phase).cos()
    }

    fn estimate(y: &[f64]) -> Modal {
        dominant_mode(&times(), y, &PronySettings::default())
            .unwrap()
            .expect("an oscillatory pair")
    }

    fn assert_mode(m: Modal, zeta: f64, wn: f64) {
        assert!(
            (m.damping_ratio - zeta).abs() <= 0.01,
            "{m:?} against ζ = {zeta}"
        );
        assert!(
            (m.natural_frequency - wn).abs() <= 0.01 * wn,
            "{m:?} against ω_n = {wn}"
        );
    }

    #[test]
    fn a_damped_sinusoid_on_an_offset_is_recovered() {
        for (zeta, wn) in [(0.15, 4.8), (0.55, 4.5), (0.72, 5.0)] {
            let y: Vec<f64> = times()
                .iter()
                .map(|&t| 0.003 + mode(t, zeta, wn, 0.02, 0.4))
                .collect();
            assert_mode(estimate(&y), zeta, wn);
        }
    }

    #[test]
    fn the_dominant_mode_of_several_is_picked() {
        // A damped closed loop after a push: the designed pair, the observer's pair at twice
        // its frequency, a real lag pole, a lightly damped faster resonance and an offset.
        let y: Vec<f64> = times()
            .iter()
            .map(|&t| {
                0.002
                    + mode(t, 0.72, 4.9, 0.02, 0.3)
                    + mode(t, 0.72, 9.8, -0.006, 1.0)
                    + 0.008 * (-6.0 * t).exp()
                    + mode(t, 0.15, 30.0, 0.001, 0.0)
            })
            .collect();
        assert_mode(estimate(&y), 0.72, 4.9);
    }

    #[test]
    fn a_pair_that_does_not_turn_half_a_cycle_is_no_oscillation() {
        // −9.25 ± 0.62j rad/s turns a tenth of a cycle in 2 s; it outweighs the designed pair
        // in energy.
        let y: Vec<f64> = times()
            .iter()
            .map(|&t| {
                0.002
                    + 0.05 * (-9.25 * t).exp() * (0.62 * t + 0.2).cos()
                    + mode(t, 0.7, 5.5, 0.02, 0.5)
            })
            .collect();
        assert_mode(estimate(&y), 0.7, 5.5);
    }

    #[test]
    fn bad_input_is_an_error_naming_it() {
        let t = times();
        let y = vec![0.0; t.len()];
        let s = PronySettings::default();
        let e = dominant_mode(&t, &y[1..], &s).unwrap_err().to_string();
        assert!(e.contains("response samples y"), "{e}");
        let e = dominant_mode(&t[..40], &y[..40], &s)
            .unwrap_err()
            .to_string();
        assert!(e.contains("40 samples") && e.contains("at least"), "{e}");
        let mut bent = t.clone();
        bent[10] += 0.001;
        let e = dominant_mode(&bent, &y, &s).unwrap_err().to_string();
        assert!(e.contains("response times t"), "{e}");
        let mut nan = y.clone();
        nan[3] = f64::NAN;
        assert!(dominant_mode(&t, &nan, &s).is_err());
        let e = dominant_mode(&t, &y, &PronySettings { order: 0, ..s })
            .unwrap_err()
            .to_string();
        assert!(e.contains("PronySettings::order"), "{e}");
    }
}
