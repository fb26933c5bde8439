//! Zero-phase low-pass filtering of sampled trajectories (motion capture data before it is
//! differentiated).
//!
//! Captured positions carry noise at the frame rate: on the shared DeepMimic clips the change of
//! the wrists' second differences reverses its sign on 49–56 % of the frames (on 77 % for
//! independent noise in every frame, on none for a smooth motion sampled finely), so a
//! reference acceleration taken from them zigzags at the frame rate, and so does every joint
//! that follows it. Biomechanics low-passes marker data before
//! differentiating it, at about 6 Hz for walking (Winter, *Biomechanics and Motor Control of
//! Human Movement*, 4th ed. 2009, §3.4); faster movements keep more.
//!
//! ## Method
//!
//! A second-order Butterworth low-pass with cut-off `f_c` at the sample period `T`, by the
//! bilinear transform with the cut-off prewarped, `K = tan(π f_c T)`:
//!
//! `b = (K², 2K², K²) / d`, `a = (1, 2(K² − 1) / d, (1 − √2 K + K²) / d)`,
//! `d = 1 + √2 K + K²`,
//!
//! run forward and then backward over the samples (`filtfilt`): the phase cancels, and the
//! magnitude is `|H(f)|² = 1 / (1 + (tan(π f T) / K)⁴)`, 1 at `f = 0`, ½ at `f = f_c`
//! (−6 dB), falling as `f⁻⁴` above. Before each pass the samples are extended by their odd
//! reflection about the end they leave (`2 x₀ − x_k`), [`PAD_PERIODS`] cut-off periods long, and
//! the filter starts in the steady state of the first padded sample, so a constant and a
//! straight line come out unchanged and the ends carry no start-up transient.

use crate::error::{Error, Result};

/// Length of the odd reflection added at each end, in periods of the cut-off \[–\]. The
/// section's poles decay as `exp(−ω_c t / √2)` (`ω_c = 2π f_c`), by `e⁻¹³` over three periods:
/// what is left of the start-up transient of a straight line (its lag, `√2 / ω_c` times its
/// slope) is below 10⁻⁷ of a slope of 1 unit/s.
pub(crate) const PAD_PERIODS: f64 = 3.0;

/// The second-order Butterworth sections of [`lowpass`]: `(b₀, b₁, b₂, a₁, a₂)`.
fn coefficients(cutoff: f64, period: f64) -> (f64, f64, f64, f64, f64) {
    let k = (std::f64::consts::PI * cutoff * period).tan();
    let k2 = k * k;
    let d = 1.0 + std::f64::consts::SQRT_2 * k + k2;
    let b0 = k2 / d;
    (
        b0,
        2.0 * b0,
        b0,
        2.0 * (k2 - 1.0) / d,
        (1.0 - std::f64::consts::SQRT_2 * k + k2) / d,
    )
}

/// One pass of the section over `x` in place (direct form II transposed), starting in the
/// steady state of a constant input equal to `x[0]`.
fn pass(x: &mut [f64], c: (f64, f64, f64, f64, f64)) {
    let (b0, b1, b2, a1, a2) = c;
    let Some(&x0) = x.first() else {
        return;
    };
    // A constant u gives y = u (unit gain at f = 0); then z₂ = (b₂ − a₂) u and
    // z₁ = (b₁ − a₁) u + z₂.
    let mut z2 = (b2 - a2) * x0;
    let mut z1 = (b1 - a1) * x0 + z2;
    for v in x.iter_mut() {
        let u = *v;
        let y = b0 * u + z1;
        z1 = b1 * u - a1 * y + z2;
        z2 = b2 * u - a2 * y;
        *v = y;
    }
}

/// Low-passes `x`, sampled every `period` \[s\], with the zero-phase Butterworth filter of the
/// module documentation at `cutoff` \[Hz\]. Allocates the padded copy.
///
/// Errors: a cut-off or period that is not positive and finite, or a cut-off at or above the
/// Nyquist frequency `1 / (2 period)` (nothing to filter: pass the samples on unfiltered
/// instead), or a non-finite sample.
pub fn lowpass(x: &[f64], period: f64, cutoff: f64) -> Result<Vec<f64>> {
    let invalid = |name: &str, value: f64, expected: String| Error::InvalidSetting {
        name: name.into(),
        value: value.to_string(),
        expected,
    };
    if !(period.is_finite() && period > 0.0) {
        return Err(invalid("sample period", period, "a period > 0 [s]".into()));
    }
    let nyquist = 0.5 / period;
    if !(cutoff.is_finite() && cutoff > 0.0 && cutoff < nyquist) {
        return Err(invalid(
            "low-pass cut-off",
            cutoff,
            format!("a frequency in (0, {nyquist}) [Hz], below the samples' Nyquist frequency"),
        ));
    }
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: format!("sample {i} of a trajectory to low-pass"),
            value: x[i],
        });
    }
    let n = x.len();
    if n < 2 {
        return Ok(x.to_vec());
    }
    let pad = ((PAD_PERIODS / (cutoff * period)).ceil() as usize).min(n - 1);
    let mut y = Vec::with_capacity(n + 2 * pad);
    let (first, last) = (x[0], x[n - 1]);
    y.extend((1..=pad).rev().map(|k| 2.0 * first - x[k]));
    y.extend_from_slice(x);
    y.extend((1..=pad).map(|k| 2.0 * last - x[n - 1 - k]));
    let c = coefficients(cutoff, period);
    pass(&mut y, c);
    y.reverse();
    pass(&mut y, c);
    y.reverse();
    Ok(y[pad..pad + n].to_vec())
}

/// Checks an optional cut-off setting `smoothing` \[Hz\]: none, or finite and > 0.
pub fn check_smoothing(smoothing: Option<f64>) -> Result<()> {
    match smoothing {
        Some(fc) if !(fc.is_finite() && fc > 0.0) => Err(Error::InvalidSetting {
            name: "smoothing".into(),
            value: fc.to_string(),
            expected: "a cut-off frequency > 0 [Hz], or none".into(),
        }),
        _ => Ok(()),
    }
}

/// [`lowpass`] of a captured track `x` sampled at `times` \[s\] (evenly, at their mean
/// period): the track unchanged when it has fewer than two samples or `cutoff` is at or above
/// its Nyquist frequency (nothing to take out). Errors: as [`lowpass`] for a cut-off that is
/// not finite and > 0 or a non-finite sample; `times` and `x` of different lengths.
pub fn lowpass_track(x: &[f64], times: &[f64], cutoff: f64) -> Result<Vec<f64>> {
    crate::error::check_dim("times of a track to low-pass", x.len(), times.len())?;
    let n = x.len();
    if n < 2 {
        return Ok(x.to_vec());
    }
    let period = (times[n - 1] - times[0]) / (n - 1) as f64;
    if cutoff.is_finite() && cutoff * 2.0 * period >= 1.0 {
        return Ok(x.to_vec());
    }
    lowpass(x, period, cutoff)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sample period of the tests \[s\] (a 60 Hz capture).
    const T: f64 = 1.0 / 60.0;

    fn sine(f: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| (2.0 * std::f64::consts::PI * f * k as f64 * T + 0.3).sin())
            .collect()
    }

    /// Amplitude of the steady part (the middle half) of a filtered sine by least squares on
    /// sin and cos of the same frequency, and its phase shift \[rad\].
    fn fit(y: &[f64], f: f64) -> (f64, f64) {
        let n = y.len();
        let (mut ss, mut sc, mut cc, mut ys, mut yc) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (k, v) in y.iter().enumerate().take(3 * n / 4).skip(n / 4) {
            let w = 2.0 * std::f64::consts::PI * f * k as f64 * T + 0.3;
            let (s, c) = w.sin_cos();
            ss += s * s;
            sc += s * c;
            cc += c * c;
            ys += v * s;
            yc += v * c;
        }
        let det = ss * cc - sc * sc;
        let (a, b) = ((ys * cc - yc * sc) / det, (yc * ss - ys * sc) / det);
        (a.hypot(b), b.atan2(a))
    }

    /// The magnitude is |H|² = 1 / (1 + (tan(π f T) / tan(π f_c T))⁴) and the phase zero,
    /// below, at and above the cut-off.
    #[test]
    fn a_sine_comes_out_scaled_by_the_squared_butterworth_magnitude_with_no_phase() {
        let fc = 6.0;
        for f in [1.0, 3.0, 6.0, 10.0, 20.0] {
            let y = lowpass(&sine(f, 600), T, fc).unwrap();
            let (amp, phase) = fit(&y, f);
            let r = (std::f64::consts::PI * f * T).tan() / (std::f64::consts::PI * fc * T).tan();
            let expected = 1.0 / (1.0 + r.powi(4));
            // The fit over 300 samples of an exact steady state: rounding and the padded
            // ends' remaining transient, far below the 1e-3 asked.
            assert!(
                (amp - expected).abs() < 1e-3,
                "f = {f}: {amp} vs {expected}"
            );
            assert!(
                phase.abs() < 1e-3 || amp < 1e-3,
                "f = {f}: phase {phase} rad"
            );
        }
    }

    /// A constant and a straight line (a subject walking at constant speed) come out unchanged,
    /// ends included: the odd reflection continues them and the filter starts at rest on them.
    /// A line's start-up lag decays over the padding to `√2 / ω_c · e⁻¹³ · slope` (see
    /// [`PAD_PERIODS`]), about 4·10⁻⁸ for the slope of 2 here.
    #[test]
    fn constants_and_straight_lines_pass_unchanged() {
        for (c0, c1) in [(0.7, 0.0), (-1.2, 0.35), (3.0, -2.0)] {
            let x: Vec<f64> = (0..120).map(|k| c0 + c1 * k as f64 * T).collect();
            let y = lowpass(&x, T, 4.0).unwrap();
            for (a, b) in x.iter().zip(&y) {
                assert!((a - b).abs() < 1e-7, "{a} vs {b}");
            }
        }
    }

    /// Noise at the frame rate (alternating samples) is removed: the magnitude at the Nyquist
    /// frequency is 0 (the bilinear transform's zeros at z = −1); what is left inside is the
    /// decayed transient of the step the odd reflection makes (its mean is 2·0.01 off),
    /// `exp(−ω_c t / √2)`: below 10⁻⁸ after 40 frames at 6 Hz.
    #[test]
    fn frame_rate_noise_is_removed() {
        let x: Vec<f64> = (0..200)
            .map(|k| 0.5 + if k % 2 == 0 { 0.01 } else { -0.01 })
            .collect();
        let y = lowpass(&x, T, 6.0).unwrap();
        let worst = y[40..160]
            .iter()
            .map(|v| (v - 0.5).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-8, "{worst}");
    }

    #[test]
    fn bad_settings_and_samples_are_errors() {
        let x = sine(1.0, 50);
        assert!(lowpass(&x, T, 30.0).is_err(), "the cut-off at Nyquist");
        assert!(lowpass(&x, T, 0.0).is_err());
        assert!(lowpass(&x, T, f64::NAN).is_err());
        assert!(lowpass(&x, 0.0, 6.0).is_err());
        let mut bad = x.clone();
        bad[7] = f64::INFINITY;
        let e = lowpass(&bad, T, 6.0).unwrap_err().to_string();
        assert!(e.contains("sample 7"), "{e}");
        assert_eq!(lowpass(&[1.5], T, 6.0).unwrap(), vec![1.5]);
        assert!(lowpass(&[], T, 6.0).unwrap().is_empty());
        for fc in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(check_smoothing(Some(fc)).is_err(), "{fc}");
        }
        assert!(check_smoothing(None).is_ok() && check_smoothing(Some(6.0)).is_ok());
    }

    /// A track's cut-off at or above its Nyquist frequency leaves it as it is; below, it is
    /// [`lowpass`] at the mean period.
    #[test]
    fn a_track_is_low_passed_only_below_its_nyquist_frequency() {
        let x = sine(10.0, 120);
        let times: Vec<f64> = (0..x.len()).map(|k| 0.5 + k as f64 * T).collect();
        assert_eq!(lowpass_track(&x, &times, 30.0).unwrap(), x);
        assert_eq!(lowpass_track(&x, &times, 45.0).unwrap(), x);
        assert_eq!(
            lowpass_track(&x, &times, 6.0).unwrap(),
            lowpass(&x, T, 6.0).unwrap()
        );
        assert!(lowpass_track(&x, &times, 0.0).is_err());
        assert!(lowpass_track(&x, &times[1..], 6.0).is_err());
    }
}
