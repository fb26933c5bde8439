//! Plausibility of captured human motion: what a file may hold before it is retargeted.
//!
//! A reader accepts any finite number; a capture of a human does not hold any. These checks
//! refuse what no human capture holds — a frame interval outside the capture rates in use,
//! joint angles of a million degrees, body points kilometres away or faster than any human
//! limb moves, a body standing 40 m tall after its unit was decided — with an error naming
//! the file, the frame and the channel or body point.

use nalgebra::Vector3;

use super::keypoints::Keypoints;
use crate::error::{Error, Result};
use crate::resources::fmt_value;

/// Lowest capture rate accepted \[Hz\]: 1 Hz. Motion sampled more slowly than once a second
/// misses every step (a step lasts about 0.5 s).
pub const MIN_CAPTURE_RATE: f64 = 1.0;

/// Highest capture rate accepted \[Hz\]: 2000 Hz, the top rate of optical motion capture
/// cameras at reduced resolution (Vicon Vantage, Qualisys Arqus specifications); human motion
/// is captured at 60–480 Hz, and inertial suits sample at up to 1000 Hz.
pub const MAX_CAPTURE_RATE: f64 = 2000.0;

/// Largest magnitude of a joint angle read from a file \[deg\]: 10⁶° (2778 turns). Unwrapped
/// Euler angles of a spinning root accumulate whole turns (a 0.5 turn/s pirouette for an
/// hour is 1800 turns); beyond this the angle's f64 rounding (ulp 1.2e-10° at 10⁶°) is still
/// negligible, but no capture gets there.
pub const MAX_ANGLE_DEG: f64 = 1e6;

/// Largest distance of a body point from the capture's origin \[m\]: 10 km. Optical capture
/// volumes span tens of metres; inertial suits worn outdoors drift over a few kilometres.
pub const MAX_DISTANCE: f64 = 1e4;

/// Largest speed of a body point between two frames \[m/s\]: 50 m/s. The fastest body point
/// of any human movement is the hand at a baseball pitch's release, at the ball's speed
/// (the record pitch, A. Chapman 2010, 105.8 mph = 47.3 m/s); kicks reach about 25 m/s at the
/// foot and punches about 15 m/s at the fist.
pub const MAX_BODY_POINT_SPEED: f64 = 50.0;

/// Largest magnitude of a position read from a file, before its unit is decided \[file
/// units\]: 10⁷, [`MAX_DISTANCE`] in millimetres (the smallest unit a file is read in).
pub const MAX_FILE_COORDINATE: f64 = 1e7;

/// Checks a position coordinate `value` \[file units\] read from `source` against
/// [`MAX_FILE_COORDINATE`]; `where_` names the frame and channel in the error.
pub fn check_coordinate(source: &str, where_: impl FnOnce() -> String, value: f64) -> Result<()> {
    if value.abs() <= MAX_FILE_COORDINATE {
        Ok(())
    } else {
        Err(implausible(
            source,
            format!(
                "{}: position {} beyond ±{} file units (motion::MAX_FILE_COORDINATE, 10 km in \
                 millimetres)",
                where_(),
                fmt_value(value),
                fmt_value(MAX_FILE_COORDINATE)
            ),
        ))
    }
}

/// Range of the ankles-to-head height of a standing body after the unit decision \[m\]:
/// 0.3 to 3.0 m, wider than human stature (about 0.45 m at birth to 2.72 m, the tallest
/// recorded, R. Wadlow) less the ankle height.
pub const STANDING_HEIGHT_RANGE: (f64, f64) = (0.3, 3.0);

/// Relative rounding allowed on a frame interval at the ends of the capture rates \[–\]:
/// frame times written as `k / rate` in decimal differ from `1 / rate` by a few ulps.
const TIME_ROUNDING: f64 = 1e-6;

fn implausible(source: &str, message: String) -> Error {
    Error::Parse {
        source_name: source.into(),
        line: 0,
        message,
    }
}

/// Checks every frame interval of `times` \[s\] against the capture rates
/// [`MIN_CAPTURE_RATE`]`..=`[`MAX_CAPTURE_RATE`]; the error names `source` and the frame.
pub fn check_frame_times(source: &str, times: &[f64]) -> Result<()> {
    let (shortest, longest) = (1.0 / MAX_CAPTURE_RATE, 1.0 / MIN_CAPTURE_RATE);
    let (low, high) = (
        shortest * (1.0 - TIME_ROUNDING),
        longest * (1.0 + TIME_ROUNDING),
    );
    for (f, w) in times.windows(2).enumerate() {
        let dt = w[1] - w[0];
        if !(dt.is_finite() && (low..=high).contains(&dt)) {
            return Err(implausible(
                source,
                format!(
                    "frame {}: frame time {} s (t = {} s after {} s), expected {shortest} to \
                     {longest} s (capture rates {MIN_CAPTURE_RATE} to {MAX_CAPTURE_RATE} Hz, \
                     motion::MIN_CAPTURE_RATE / MAX_CAPTURE_RATE)",
                    f + 1,
                    fmt_value(dt),
                    fmt_value(w[1]),
                    fmt_value(w[0])
                ),
            ));
        }
    }
    Ok(())
}

/// Checks a joint angle `degrees` \[deg\] read from `source` against [`MAX_ANGLE_DEG`];
/// `where_` names the frame and channel in the error.
pub fn check_angle(source: &str, where_: impl FnOnce() -> String, degrees: f64) -> Result<()> {
    if degrees.abs() <= MAX_ANGLE_DEG {
        Ok(())
    } else {
        Err(implausible(
            source,
            format!(
                "{}: angle {}° beyond ±{}° (motion::MAX_ANGLE_DEG)",
                where_(),
                fmt_value(degrees),
                fmt_value(MAX_ANGLE_DEG)
            ),
        ))
    }
}

/// Checks the ankles-to-head vector `v` \[m\] of a standing body (after the unit decision)
/// against [`STANDING_HEIGHT_RANGE`]; `unit` names the unit decided.
pub fn check_standing_height(source: &str, v: &Vector3<f64>, unit: &str) -> Result<()> {
    let h = v.norm();
    let (lo, hi) = STANDING_HEIGHT_RANGE;
    if h.is_finite() && (lo..=hi).contains(&h) {
        Ok(())
    } else {
        Err(implausible(
            source,
            format!(
                "the body stands {} m from ankles to head in {unit}, expected {lo} to {hi} m \
                 (motion::STANDING_HEIGHT_RANGE); give the unit (--units)",
                fmt_value(h)
            ),
        ))
    }
}

/// Checks every body point of `kp` \[m\]: finite, within [`MAX_DISTANCE`] of the origin and
/// moving slower than [`MAX_BODY_POINT_SPEED`] between consecutive frames; the error names
/// the file, the frame and the body point.
pub fn check_keypoints(kp: &Keypoints) -> Result<()> {
    let n = kp.points.len();
    if n == 0 {
        return Ok(());
    }
    for (i, p) in kp.positions.iter().enumerate() {
        let (f, point) = (i / n, kp.points[i % n]);
        let d = p.norm();
        if !(d.is_finite() && d <= MAX_DISTANCE) {
            return Err(implausible(
                &kp.source,
                format!(
                    "frame {f}, {point}: position ({}, {}, {}) m is {} m from the origin, \
                     beyond {} m (motion::MAX_DISTANCE)",
                    fmt_value(p.x),
                    fmt_value(p.y),
                    fmt_value(p.z),
                    fmt_value(d),
                    fmt_value(MAX_DISTANCE)
                ),
            ));
        }
        if f == 0 {
            continue;
        }
        let dt = kp.times[f] - kp.times[f - 1];
        let speed = (p - kp.positions[i - n]).norm() / dt;
        if speed.is_nan() || speed > MAX_BODY_POINT_SPEED {
            return Err(implausible(
                &kp.source,
                format!(
                    "frame {f}, {point}: speed {} m/s from frame {} (moved {} m in {} s), \
                     above the {MAX_BODY_POINT_SPEED} m/s of any human body point \
                     (motion::MAX_BODY_POINT_SPEED)",
                    fmt_value(speed),
                    f - 1,
                    fmt_value((p - kp.positions[i - n]).norm()),
                    fmt_value(dt)
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_times_outside_the_capture_rates_are_refused() {
        assert!(check_frame_times("c", &[0.0, 0.01, 0.02]).is_ok());
        // 1 Hz and 2000 Hz are inside, with their rounding.
        assert!(check_frame_times("c", &[0.0, 1.0, 1.0005]).is_ok());
        assert!(check_frame_times("c", &[0.0, 0.000_499_9]).is_err());
        assert!(check_frame_times("c", &[0.0, 1.000_01]).is_err());
        for bad in [1e-9, 1e-300, 1.5, 0.0, -0.01, f64::NAN] {
            let e = check_frame_times("clip.bvh", &[0.0, 0.01, 0.01 + bad]).unwrap_err();
            let text = e.to_string();
            assert!(
                text.contains("clip.bvh") && text.contains("frame 2"),
                "{text}"
            );
        }
    }

    #[test]
    fn angles_beyond_the_bound_are_refused() {
        assert!(check_angle("c", || "x".into(), -720.0).is_ok());
        assert!(check_angle("c", || "x".into(), MAX_ANGLE_DEG).is_ok());
        let e = check_angle("c.bvh", || "frame 3, Hips Zrotation".into(), 1e308).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("frame 3, Hips Zrotation") && text.contains("1e308"),
            "{text}"
        );
        assert!(check_angle("c", || "x".into(), f64::NAN).is_err());
    }

    #[test]
    fn standing_heights_outside_the_human_range_are_refused() {
        assert!(check_standing_height("c", &Vector3::new(0.0, 0.0, 1.6), "m").is_ok());
        for h in [0.017, 160.0, 1e308] {
            assert!(check_standing_height("c", &Vector3::new(0.0, 0.0, h), "m").is_err());
        }
    }
}
