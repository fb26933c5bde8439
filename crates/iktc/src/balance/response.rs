//! Metrics of a ZMP response after a push: peak, settling time, and damping ratio and natural
//! frequency of its dominant mode.
//!
//! The dominant mode is fitted over a window after the push by
//! `y(t) ≈ e^{−ζ w τ} (a cos(w √(1−ζ²) τ) + b sin(w √(1−ζ²) τ))`, `τ = t − t₀`, by variable
//! projection (`a`, `b` by linear least squares for each `(ζ, w)`): a coarse grid over
//! `(ζ, w)` then [`levenberg_marquardt()`] on `(logit ζ, ln w)`. The window starts a little
//! after the push so that the fastest modes (lag, delay) have died out. With
//! [`ResponseSettings::modes`] = 2 the sum of two such modes is fitted (the grid then moves the
//! pair `(ζ, w)`, `(ζ, r w)` together before the free refinement) and the
//! mode is reported: this is the closed loop's controller mode, the other its observer mode.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::lm::{levenberg_marquardt, LmSettings};
use super::model::invalid;
use crate::error::{check_dim, check_finite, Error, Result};

/// Settings of the response analysis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ResponseSettings {
    /// The response has settled when it stays within this fraction of its peak \[–\].
    pub settle_fraction: f64,
    /// … or within this many noise standard deviations, whichever is larger \[–\]; keeps noise
    /// spikes from counting as not settled (5σ: about one false alarm in 3·10⁶ samples).
    pub noise_sigmas: f64,
    /// Start of the fit window after the push \[s\]; long enough for the fast modes to vanish.
    pub fit_delay: f64,
    /// Length of the fit window \[s\]; a few periods of the slowest mode expected.
    pub fit_window: f64,
    /// Grid of damping ratios tried before refining \[–\]: this many points in (0, 1).
    pub grid_damping: usize,
    /// Grid of natural frequencies tried \[rad/s\]: log-spaced between these two…
    pub grid_min_frequency: f64,
    /// …and this \[rad/s\].
    pub grid_max_frequency: f64,
    /// …with this many points \[–\].
    pub grid_frequency: usize,
    /// Number of damped modes fitted together \[–\], 1 or 2 (see the module documentation).
    /// Fitting the observer's mode too keeps it from biasing the controller's.
    pub modes: usize,
    /// Frequency of the second mode as a multiple of the first's \[–\]: the observer's pole
    /// scale, [`super::design::DiscreteSettings::observer_pole_scale`].
    pub second_mode_ratio: f64,
    /// The refining solver.
    pub lm: LmSettings,
}

impl Default for ResponseSettings {
    fn default() -> Self {
        Self {
            settle_fraction: 0.05,
            noise_sigmas: 5.0,
            fit_delay: 0.1,
            fit_window: 2.0,
            grid_damping: 24,
            grid_min_frequency: 1.0,
            grid_max_frequency: 200.0,
            grid_frequency: 60,
            modes: 1,
            second_mode_ratio: 2.0,
            lm: LmSettings::default(),
        }
    }
}

impl ResponseSettings {
    /// Checks ranges.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("ResponseSettings::settle_fraction", self.settle_fraction),
            ("ResponseSettings::fit_window [s]", self.fit_window),
            (
                "ResponseSettings::grid_min_frequency [rad/s]",
                self.grid_min_frequency,
            ),
            (
                "ResponseSettings::grid_max_frequency [rad/s]",
                self.grid_max_frequency,
            ),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "finite and > 0"));
            }
        }
        for (name, v) in [
            ("ResponseSettings::noise_sigmas", self.noise_sigmas),
            ("ResponseSettings::fit_delay [s]", self.fit_delay),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(name, v, "finite and >= 0"));
            }
        }
        if self.grid_damping < 2 || self.grid_frequency < 2 {
            return Err(invalid(
                "ResponseSettings::grid_damping/grid_frequency",
                self.grid_damping.min(self.grid_frequency) as f64,
                ">= 2",
            ));
        }
        if !(self.modes == 1 || self.modes == 2) {
            return Err(invalid(
                "ResponseSettings::modes",
                self.modes as f64,
                "1 or 2",
            ));
        }
        if !(self.second_mode_ratio.is_finite() && self.second_mode_ratio > 1.0) {
            return Err(invalid(
                "ResponseSettings::second_mode_ratio",
                self.second_mode_ratio,
                "> 1",
            ));
        }
        self.lm.validate()
    }
}

/// Metrics of one response.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ResponseMetrics {
    /// Largest `|y|` after the event \[m\].
    pub peak: f64,
    /// Time of the peak after the event \[s\].
    pub peak_time: f64,
    /// Time after the event from which `|y|` stays within the band \[s\]; `None` if it never
    /// does within the data.
    pub settling_time: Option<f64>,
    /// The settling band used \[m\].
    pub settle_band: f64,
    /// Damping ratio of the fitted (first) mode \[–\].
    pub damping_ratio: f64,
    /// Natural frequency of the fitted (first) mode \[rad/s\].
    pub natural_frequency: f64,
    /// RMS of the fit residual over its window \[m\].
    pub fit_rms: f64,
}

/// The largest `|y|` \[m\] after the event and its time \[s\], the settling band \[m\], and the
/// settling time \[s\] (the first sample after the last one outside the band; `None` when the
/// last sample is outside).
fn peak_and_settling(
    after: &[(f64, f64)],
    noise_std: f64,
    settings: &ResponseSettings,
) -> (f64, f64, f64, Option<f64>) {
    let (peak_time, peak) = after.iter().fold((0.0, 0.0), |acc, (ti, yi)| {
        if yi.abs() > acc.1 {
            (*ti, yi.abs())
        } else {
            acc
        }
    });
    let band = (settings.settle_fraction * peak).max(settings.noise_sigmas * noise_std);
    let last_out = after.iter().rposition(|(_, yi)| yi.abs() > band);
    let settling_time = match last_out {
        None => Some(0.0),
        Some(i) if i + 1 < after.len() => after.get(i + 1).map(|p| p.0),
        Some(_) => None,
    };
    (peak_time, peak, band, settling_time)
}

/// The samples in the fit window (`fit_delay` to `fit_delay + fit_window` \[s\] after the
/// event), times from the window's start; at least 8 needed.
fn fit_window(after: &[(f64, f64)], settings: &ResponseSettings) -> Result<Vec<(f64, f64)>> {
    let window: Vec<(f64, f64)> = after
        .iter()
        .filter(|(ti, _)| {
            *ti >= settings.fit_delay && *ti <= settings.fit_delay + settings.fit_window
        })
        .map(|(ti, yi)| (*ti - settings.fit_delay, *yi))
        .collect();
    if window.len() < 8 {
        return Err(Error::InsufficientData {
            what: "response fit".into(),
            message: format!(
                "{} samples in the fit window, at least 8 needed",
                window.len()
            ),
        });
    }
    Ok(window)
}

/// The grid search over damping ratio and log-spaced natural frequency \[rad/s\]: the
/// `(cost, ζ, ω)` of the lowest cost.
fn grid_search(window: &[(f64, f64)], settings: &ResponseSettings) -> (f64, f64, f64) {
    let two = settings.modes == 2;
    let ratio = settings.second_mode_ratio;
    let mut best = (f64::INFINITY, 0.5, 1.0);
    let (lw0, lw1) = (
        settings.grid_min_frequency.ln(),
        settings.grid_max_frequency.ln(),
    );
    for i in 0..settings.grid_damping {
        let z = (i as f64 + 1.0) / (settings.grid_damping as f64 + 1.0);
        for j in 0..settings.grid_frequency {
            let w = (lw0 + (lw1 - lw0) * j as f64 / (settings.grid_frequency - 1) as f64).exp();
            let modes: &[(f64, f64)] = if two {
                &[(z, w), (z, ratio * w)]
            } else {
                &[(z, w)]
            };
            let c = modes_cost(window, modes);
            if c < best.0 {
                best = (c, z, w);
            }
        }
    }
    best
}

/// Analyses the response `y` \[m\] sampled at times `t` \[s\] (increasing) after an event at
/// `t_event` \[s\]; `noise_std` \[m\] is the sensor noise's standard deviation (0 if none).
pub fn analyse_response(
    t: &[f64],
    y: &[f64],
    t_event: f64,
    noise_std: f64,
    settings: &ResponseSettings,
) -> Result<ResponseMetrics> {
    settings.validate()?;
    check_dim("response samples y", t.len(), y.len())?;
    crate::error::check_all_finite("response times t [s]", t)?;
    crate::error::check_all_finite("response samples y [m]", y)?;
    check_finite(|| "t_event [s]".into(), t_event)?;
    check_finite(|| "noise_std [m]".into(), noise_std)?;
    let after: Vec<(f64, f64)> = t
        .iter()
        .zip(y)
        .filter(|(ti, _)| **ti >= t_event)
        .map(|(ti, yi)| (*ti - t_event, *yi))
        .collect();
    let (peak_time, peak, band, settling_time) = peak_and_settling(&after, noise_std, settings);
    let window = fit_window(&after, settings)?;
    // Grid search, then refinement.
    let two = settings.modes == 2;
    let ratio = settings.second_mode_ratio;
    let best = grid_search(&window, settings);
    let logit = |z: f64| (z / (1.0 - z)).ln();
    let x0 = vec![logit(best.1), best.2.ln()];
    let m = window.len();
    let decode = |x: &DVector<f64>| -> Vec<(f64, f64)> {
        let z = 1.0 / (1.0 + (-x[0]).exp());
        let w = x[1].exp();
        if two {
            vec![(z, w), (z, ratio * w)]
        } else {
            vec![(z, w)]
        }
    };
    let fit = levenberg_marquardt(
        |x: &DVector<f64>, r: &mut DVector<f64>| {
            modes_residual(&window, &decode(x), r);
            Ok(())
        },
        DVector::from_vec(x0),
        m,
        &settings.lm,
    )?;
    let z = 1.0 / (1.0 + (-fit.x[0]).exp());
    let w = fit.x[1].exp();
    Ok(ResponseMetrics {
        peak,
        peak_time,
        settling_time,
        settle_band: band,
        damping_ratio: z,
        natural_frequency: w,
        fit_rms: (2.0 * fit.cost / m as f64).sqrt(),
    })
}

fn basis(t: f64, z: f64, w: f64) -> (f64, f64) {
    let e = (-z * w * t).exp();
    let wd = w * (1.0 - z * z).max(0.0).sqrt();
    (e * (wd * t).cos(), e * (wd * t).sin())
}

/// Least-squares coefficients of the modes' cosine and sine terms, and the fitted values.
fn modes_fit(window: &[(f64, f64)], modes: &[(f64, f64)]) -> (DVector<f64>, Vec<f64>) {
    let k = 2 * modes.len();
    let mut n = DMatrix::<f64>::zeros(k, k);
    let mut r = DVector::<f64>::zeros(k);
    let mut phi = DVector::<f64>::zeros(k);
    for (t, y) in window {
        fill(&mut phi, *t, modes);
        n += &phi * phi.transpose();
        r += &phi * *y;
    }
    let coef = n.cholesky().map_or(DVector::zeros(k), |c| c.solve(&r));
    let fitted = window
        .iter()
        .map(|(t, _)| {
            fill(&mut phi, *t, modes);
            phi.dot(&coef)
        })
        .collect();
    (coef, fitted)
}

fn fill(phi: &mut DVector<f64>, t: f64, modes: &[(f64, f64)]) {
    for (i, (z, w)) in modes.iter().enumerate() {
        let (c, s) = basis(t, *z, *w);
        phi[2 * i] = c;
        phi[2 * i + 1] = s;
    }
}

fn modes_residual(window: &[(f64, f64)], modes: &[(f64, f64)], r: &mut DVector<f64>) {
    let (_, fitted) = modes_fit(window, modes);
    for ((ri, f), (_, y)) in r.iter_mut().zip(fitted).zip(window) {
        *ri = f - y;
    }
}

fn modes_cost(window: &[(f64, f64)], modes: &[(f64, f64)]) -> f64 {
    let (_, fitted) = modes_fit(window, modes);
    fitted
        .iter()
        .zip(window)
        .map(|(f, (_, y))| (f - y).powi(2))
        .sum()
}
