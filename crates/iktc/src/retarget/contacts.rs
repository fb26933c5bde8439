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
//! Holding, on a track `x_k` sampled at the control rate (x, y, z or yaw of a foot): in a
//! stance run the reference is the run's mean `H` (or a given value, the sole on the ground);
//! between a stance ending with `H₁` at tick `a` and one starting with `H₂` at tick `b` it goes
//! from hold to hold along the quintic `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵`, `τ = (k − a)/(b − a)`,
//! plus the track's own departure from that progression, faded in and out:
//! `H₁ + (H₂ − H₁) s(τ) + w(τ) (x_k − x_a − (x_b − x_a) s(τ))`, with
//! `w(τ) = s(min(1, τ/r)) s(min(1, (1 − τ)/r))`, `r` = [`SWING_FADE`]. The reference leaves and
//! reaches each hold at rest (zero rate and acceleration: `s`, `w` and the departure's factors
//! vanish with their derivatives there), so a foot lands without sliding into its hold, while
//! mid-swing it follows the captured foot (its lift, its path). Before the first stance and
//! after the last one the track is shifted onto the hold, its departure faded in the same way
//! over the first (last) `r` of the free run.

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

/// The quintic blend `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵` on `τ ∈ [0, 1]` (clamped outside): the
/// position of [`smoothstep`](crate::walk::smoothstep) over a unit interval.
pub(crate) fn quintic(tau: f64) -> f64 {
    crate::walk::smoothstep(0.0, 1.0, tau).0
}

/// Fraction of a swing over which the captured foot's own motion is faded in (and out) \[–\]
/// (see the module documentation): larger values keep the swing closer to the hold-to-hold
/// quintic for longer, smaller ones follow the captured foot sooner with larger accelerations
/// near lift-off and touch-down.
pub const SWING_FADE: f64 = 0.25;

/// The fade `w(τ)` of the module documentation.
fn fade(tau: f64) -> f64 {
    quintic(tau / SWING_FADE) * quintic((1.0 - tau) / SWING_FADE)
}

/// Holds `track` in the stance runs of `contact` and shapes the swings (see the module
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
        let a = e - 1;
        match stances.get(i + 1) {
            Some(&(b, _)) => {
                let span = (b - a) as f64;
                for k in e..b {
                    let tau = (k - a) as f64 / span;
                    let q = quintic(tau);
                    let departure = raw[k] - raw[a] - (raw[b] - raw[a]) * q;
                    track[k] = holds[i] + (holds[i + 1] - holds[i]) * q + fade(tau) * departure;
                }
            }
            None => {
                let span = (track.len() - a) as f64;
                for k in e..track.len() {
                    let w = quintic((k - a) as f64 / (SWING_FADE * span));
                    track[k] = holds[i] + w * (raw[k] - raw[a]);
                }
            }
        }
    }
    // Before the first stance.
    let (b, _) = stances[0];
    let span = (b + 1) as f64;
    for k in 0..b {
        let w = quintic((b - k) as f64 / (SWING_FADE * span));
        track[k] = holds[0] + w * (raw[k] - raw[b]);
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
    fn a_held_track_is_constant_in_stance_and_lands_at_rest() {
        let n = 60;
        let raw: Vec<f64> = (0..n).map(|k| 0.01 * k as f64).collect();
        let contact: Vec<bool> = (0..n).map(|k| !(20..40).contains(&k)).collect();
        let mut t = raw.clone();
        hold(&mut t, &contact, None);
        let m1 = raw[..20].iter().sum::<f64>() / 20.0;
        let m2 = raw[40..].iter().sum::<f64>() / 20.0;
        assert!(t[..20].iter().all(|x| (x - m1).abs() < 1e-15));
        assert!(t[40..].iter().all(|x| (x - m2).abs() < 1e-15));
        // The swing moves forward (the raw track does, and so does the quintic from hold to
        // hold), no faster than the raw step plus the quintic's largest step, and it leaves
        // and reaches the holds at rest: its first and last steps are a tenth of the raw one.
        let bound = 0.01 + 1.875 * (m2 - m1) / 21.0;
        for k in 19..40 {
            let step = t[k + 1] - t[k];
            assert!((0.0..=bound).contains(&step), "{k}: {step}");
        }
        let (first, last) = (t[20] - t[19], t[40] - t[39]);
        assert!(first < 0.001 && last < 0.001, "{first} {last}");
    }

    #[test]
    fn a_swing_keeps_the_captured_lift_mid_swing_and_leaves_the_ground_at_rest() {
        // A foot lifted 0.1 m by a half sine between two stances on the ground.
        let n = 100;
        let contact: Vec<bool> = (0..n).map(|k| !(30..70).contains(&k)).collect();
        let raw: Vec<f64> = (0..n)
            .map(|k| {
                if (30..70).contains(&k) {
                    0.1 * (std::f64::consts::PI * (k as f64 - 29.0) / 41.0).sin()
                } else {
                    0.0
                }
            })
            .collect();
        let mut t = raw.clone();
        hold(&mut t, &contact, Some(0.0));
        // Mid-swing (outside the fades) the lift is the captured one.
        for k in 41..59 {
            assert!((t[k] - raw[k]).abs() < 1e-12, "{k}");
        }
        // Never below the ground, and lift-off and touch-down at rest: the first and last
        // steps are far smaller than the captured ones.
        assert!(t.iter().all(|z| *z >= 0.0));
        let raw_step = raw[30] - raw[29];
        assert!(t[30] - t[29] < 0.05 * raw_step, "{}", t[30] - t[29]);
        assert!(t[69] - t[70] < 0.05 * raw_step, "{}", t[69] - t[70]);
    }
}
