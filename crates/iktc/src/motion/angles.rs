//! Small helpers on angles: wrapping, nearest equivalents and unwrapping of tracks.

use std::f64::consts::{PI, TAU};

/// Wraps an angle \[rad\] into (−π, π].
///
/// Non-finite input is returned unchanged (the callers check finiteness first).
pub fn wrap_to_pi(angle: f64) -> f64 {
    if !angle.is_finite() {
        return angle;
    }
    let mut a = angle.rem_euclid(TAU); // [0, 2π)
    if a > PI {
        a -= TAU;
    }
    a
}

/// The angle equivalent to `angle` modulo 2π that is nearest to `reference` \[rad\]:
/// `angle + 2πk` with the integer `k` minimising `|angle + 2πk − reference|`.
pub fn nearest_equivalent(angle: f64, reference: f64) -> f64 {
    if !angle.is_finite() || !reference.is_finite() {
        return angle;
    }
    angle + TAU * ((reference - angle) / TAU).round()
}

/// Unwraps an angle track in place: every sample after the first is replaced by its equivalent
/// modulo `period` nearest to the (already unwrapped) sample before it, so that no step between
/// consecutive samples exceeds `period / 2` in magnitude.
///
/// `period` is 360 for a track in degrees and 2π for one in radians. This is the usual phase
/// unwrapping, θ'_k = θ_k + period·round((θ'_{k−1} − θ_k)/period); it must run before a track is
/// differentiated, otherwise a wrap through ±180° shows up as a spike of ±360°/Δt.
/// Non-finite samples are left unchanged and do not serve as reference.
pub fn unwrap_track(track: &mut [f64], period: f64) {
    if !(period.is_finite() && period > 0.0) {
        return;
    }
    let mut previous: Option<f64> = None;
    for value in track.iter_mut() {
        if !value.is_finite() {
            continue;
        }
        if let Some(p) = previous {
            *value += period * ((p - *value) / period).round();
        }
        previous = Some(*value);
    }
}
