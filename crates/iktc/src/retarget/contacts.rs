//! Foot contacts detected from the clip, and the feet's references that hold a stance foot
//! where it touched down.
//!
//! Detection, per foot and source frame `f` (aligned clip, \[m\], \[m/s\]): the foot is on the
//! ground when its ankle is within `contact_height` of the clip's lowest ankle height and
//! moves slower than `contact_speed` (central differences), or its toe is within
//! `contact_height` of the lowest toe height and slower than `contact_speed`. Then runs shorter
//! than `min_phase` \[s\] are removed: first short contacts, then short flights between
//! contacts.
//!
//! Holding, on a track `x_k` sampled at the control rate (x, y, yaw of a foot): in a stance run
//! the reference is the run's mean `H`; between a stance ending with `H₁` at tick `a` and one
//! starting with `H₂` at tick `b` it is the track shifted by a blend of both offsets,
//! `x_k + (1 − s(τ)) (H₁ − x_a) + s(τ) (H₂ − x_b)`, `τ = (k − a)/(b − a)`,
//! `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵` (C² at both ends: the swing leaves and reaches the held pose).

/// Contact detection per source frame for one foot (see the module documentation); `ankle`
/// and `toe` are positions per frame \[m\], `times` the frame times \[s\].
pub(crate) fn detect(
    times: &[f64],
    ankle: &[nalgebra::Vector3<f64>],
    toe: Option<&[nalgebra::Vector3<f64>]>,
    ground: [f64; 2],
    height: f64,
    speed: f64,
) -> Vec<bool> {
    let n = times.len();
    let on = |track: &[nalgebra::Vector3<f64>], g: f64, f: usize| {
        let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
        let v = if b > a && times[b] > times[a] {
            (track[b] - track[a]).norm() / (times[b] - times[a])
        } else {
            0.0
        };
        track[f].z - g < height && v < speed
    };
    (0..n)
        .map(|f| on(ankle, ground[0], f) || toe.is_some_and(|t| on(t, ground[1], f)))
        .collect()
}

/// Removes runs of `value` shorter than `min_len` samples that have the other value on both
/// sides (or, for `value == true`, anywhere).
pub(crate) fn remove_short(c: &mut [bool], value: bool, min_len: usize) {
    let n = c.len();
    let mut i = 0;
    while i < n {
        if c[i] != value {
            i += 1;
            continue;
        }
        let start = i;
        while i < n && c[i] == value {
            i += 1;
        }
        let inner = start > 0 && i < n;
        if i - start < min_len && (value || inner) {
            c[start..i].iter_mut().for_each(|x| *x = !value);
        }
    }
}

/// The runs `[start, end)` where `c` is true.
pub(crate) fn runs(c: &[bool]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        if c[i] {
            let s = i;
            while i < c.len() && c[i] {
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}

/// The quintic blend `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵` on `τ ∈ [0, 1]`.
pub(crate) fn quintic(tau: f64) -> f64 {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}

/// Holds `track` in the stance runs of `contact` and blends the swings (see the module
/// documentation); `stance_value`, if given, replaces the run mean (the sole on the ground).
pub(crate) fn hold(track: &mut [f64], contact: &[bool], stance_value: Option<f64>) {
    let stances = runs(contact);
    if stances.is_empty() {
        return;
    }
    let raw = track.to_vec();
    let holds: Vec<f64> = stances
        .iter()
        .map(|&(s, e)| stance_value.unwrap_or(raw[s..e].iter().sum::<f64>() / (e - s) as f64))
        .collect();
    for (i, &(s, e)) in stances.iter().enumerate() {
        track[s..e].iter_mut().for_each(|x| *x = holds[i]);
        // The swing after this stance, up to the next one (or the end).
        let next = stances.get(i + 1).copied();
        let a = e - 1;
        let end = next.map_or(track.len(), |n| n.0);
        let o1 = holds[i] - raw[a];
        let o2 = next.map(|(b, _)| holds[i + 1] - raw[b]);
        for k in e..end {
            track[k] = match (o2, next) {
                (Some(o2), Some((b, _))) => {
                    let s = quintic((k - a) as f64 / (b - a) as f64);
                    raw[k] + (1.0 - s) * o1 + s * o2
                }
                _ => raw[k] + o1,
            };
        }
    }
    // Before the first stance.
    let (b, _) = stances[0];
    let o = holds[0] - raw[b];
    for k in 0..b {
        track[k] = raw[k] + o;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_runs_are_removed_and_long_ones_kept() {
        let mut c = [
            true, false, true, true, true, false, false, false, true, true,
        ];
        remove_short(&mut c, false, 2); // the single flight at 1 is filled
        assert_eq!(c[..5], [true; 5]);
        remove_short(&mut c, true, 3); // the final pair of contacts is dropped
        assert_eq!(runs(&c), vec![(0, 5)]);
    }

    #[test]
    fn a_held_track_is_constant_in_stance_and_continuous_at_the_ends_of_a_swing() {
        let n = 60;
        let raw: Vec<f64> = (0..n).map(|k| 0.01 * k as f64).collect();
        let contact: Vec<bool> = (0..n).map(|k| !(20..40).contains(&k)).collect();
        let mut t = raw.clone();
        hold(&mut t, &contact, None);
        let m1 = raw[..20].iter().sum::<f64>() / 20.0;
        let m2 = raw[40..].iter().sum::<f64>() / 20.0;
        assert!(t[..20].iter().all(|x| (x - m1).abs() < 1e-15));
        assert!(t[40..].iter().all(|x| (x - m2).abs() < 1e-15));
        // The swing starts at the first hold and ends at the second, with steps no larger
        // than the raw track's step plus the blend's largest step.
        let blend_step = (m2 - raw[40] - (m1 - raw[19])).abs() * 1.875 / 21.0;
        for k in 19..41 {
            assert!((t[k + 1] - t[k]).abs() <= 0.01 + blend_step + 1e-12, "{k}");
        }
    }
}
