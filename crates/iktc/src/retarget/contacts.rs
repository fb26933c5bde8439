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
//! A foot that slides on the ground, slowly enough to count as on it or in a flight shorter
//! than `min_phase`, is not held through the slide ([`split_slides`]): once the captured
//! ankle is further than `max_slide` \[m\], horizontally, from where the stance (or its last
//! part) began, the stance ends there and a flight of `min_phase` follows, after which a new
//! stance begins, where both the part before and the rest after are at least `min_phase`
//! long. The robot steps where the captured person slides: a held foot cannot slide (the
//! first level holds it), and one held through a slide is left up to the slide's length
//! behind the captured foot while the body above follows it (CMU 131_01 slides a foot 22 cm
//! in 0.2 s; G1's knee and ankle then missed theirs by up to 33 cm). Shorter parts are not
//! split off: a dancer's shuffle of quick steps (DeepMimic's `humanoid3d_dance_b`) would
//! otherwise leave no stance at all.
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
//!
//! A foot's yaw is held the same way, except over a stance in which the captured foot turns
//! by more than [`PIVOT_TURN`]: there the foot pivots, its yaw following the captured one
//! (averaged over [`PIVOT_SMOOTHING`], at most [`PIVOT_RATE`]), and `H₁`, `H₂` are the yaws at
//! the stance's ends ([`hold_turning`]). The feet's x and y are held at the sole's centre, so
//! a pivoting foot turns about it ([`super::plan`]).

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

/// Ends a stance of `c` (per frame) wherever the captured `ankle` (per frame \[m\]) has moved
/// further than `max_slide` \[m\] horizontally from where the stance or its last part began,
/// with a flight of `gap` frames from that frame on; the stance's rest starts a new part at
/// the flight's end (see the module documentation). A split is made only where the part
/// before it and the stance's rest after the flight are each at least `gap` frames long: a
/// shuffle of quick short steps stays one held stance, as before.
pub(crate) fn split_slides(
    c: &mut [bool],
    ankle: &[nalgebra::Vector3<f64>],
    max_slide: f64,
    gap: usize,
) {
    for (a, b) in runs(c) {
        let mut start = ankle[a].xy();
        let mut part = a;
        let mut f = a;
        while f < b {
            let end = (f + gap.max(1)).min(b);
            let long = f - part >= gap && b - end >= gap;
            if long && (ankle[f].xy() - start).norm() > max_slide {
                c[f..end].iter_mut().for_each(|x| *x = false);
                if end < b {
                    start = ankle[end].xy();
                }
                part = end;
                f = end;
            } else {
                f += 1;
            }
        }
    }
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
    let values = stances
        .iter()
        .map(|&(s, e)| {
            let h = stance_value.unwrap_or(track[s..e].iter().sum::<f64>() / (e - s) as f64);
            vec![h; e - s]
        })
        .collect();
    shape(track, &stances, values);
}

/// Smallest turn of a foot over one of its stances for the foot to pivot \[rad\]: a foot whose
/// captured yaw spans less over a stance is held at the stance's mean yaw (the captured yaw's
/// jitter, a few degrees, would twist the held foot for nothing); one that spans more turns
/// with it, about its sole's centre (a dancer spinning on a foot: DeepMimic's
/// `humanoid3d_dance_a` turns a full circle in 1.6 s, its left foot 4.9 rad over one stance).
pub const PIVOT_TURN: f64 = 0.35;

/// Window of the moving average of a pivoting foot's yaw \[s\]: the captured toe's direction
/// jitters by a few degrees from frame to frame.
pub(crate) const PIVOT_SMOOTHING: f64 = 0.1;

/// Fastest a pivoting foot's reference turns \[rad/s\]: the captured turn is followed at this
/// rate at most and caught up with when it slows. Turning a held foot as fast as a dancer
/// does (CMU 131_01: 4.6–4.9 rad/s) takes more of the legs' joint box than balance leaves:
/// the held foot's level is corrected and its sole dips below the ground. Turning it much
/// slower than the dancer twists the legs under the spinning body and drags the other,
/// landing foot into the ground. At the default the deepest sole over the shared clips that
/// pivot (131_01, `scaled_131_02`, `humanoid3d_dance_a`, `humanoid3d_punch`; G1 and JVRC-1)
/// is 0.070 mm; `book/src/retarget-defaults.md` has the other rates measured.
pub(crate) const PIVOT_RATE: f64 = 4.0;

/// Holds a foot's yaw `track` \[rad\] in the stance runs of `contact` as [`hold`] does, except
/// that a stance over which the track spans more than `min_turn` \[rad\] follows it (the foot
/// pivots): averaged over `2 half + 1` ticks within the stance, and from the stance's first
/// tick on changing by at most `max_step` \[rad\] per tick.
pub(crate) fn hold_turning(
    track: &mut [f64],
    contact: &[bool],
    min_turn: f64,
    half: usize,
    max_step: f64,
) {
    let stances = runs(contact);
    let values = stances
        .iter()
        .map(|&(s, e)| {
            let run = &track[s..e];
            let (lo, hi) = run
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                    (a.min(*x), b.max(*x))
                });
            let n = run.len();
            if hi - lo <= min_turn {
                return vec![run.iter().sum::<f64>() / n as f64; n];
            }
            let mut out = run.to_vec();
            moving_average(&mut out, half);
            for k in 1..n {
                out[k] = out[k - 1] + (out[k] - out[k - 1]).clamp(-max_step, max_step);
            }
            out
        })
        .collect();
    shape(track, &stances, values);
}

/// Replaces each sample of `x` by the mean of the samples within `half` of it (the window
/// shrinks at the ends).
pub(crate) fn moving_average<T>(x: &mut [T], half: usize)
where
    T: Copy + std::iter::Sum + std::ops::Div<f64, Output = T>,
{
    if half == 0 || x.len() < 2 {
        return;
    }
    let src = x.to_vec();
    let n = src.len();
    for (k, out) in x.iter_mut().enumerate() {
        let (a, b) = (k.saturating_sub(half), (k + half).min(n - 1));
        *out = src[a..=b].iter().copied().sum::<T>() / (b - a + 1) as f64;
    }
}

/// Puts `values[i]` into stance run `stances[i]` of `track` and shapes the free runs between
/// and around them (the module documentation, with `H₁` the value at the end of the stance
/// before and `H₂` the one at the start of the stance after).
fn shape(track: &mut [f64], stances: &[(usize, usize)], values: Vec<Vec<f64>>) {
    if stances.is_empty() {
        return;
    }
    let raw = track.to_vec();
    let first = |i: usize| values[i][0];
    let last = |i: usize| values[i][values[i].len() - 1];
    for (i, &(s, e)) in stances.iter().enumerate() {
        track[s..e].copy_from_slice(&values[i]);
        // The swing after this stance, up to the next one (or the end).
        let a = e - 1;
        match stances.get(i + 1) {
            Some(&(b, _)) => {
                let span = (b - a) as f64;
                let (h1, h2) = (last(i), first(i + 1));
                for k in e..b {
                    let tau = (k - a) as f64 / span;
                    let q = quintic(tau);
                    let departure = raw[k] - raw[a] - (raw[b] - raw[a]) * q;
                    track[k] = h1 + (h2 - h1) * q + fade(tau) * departure;
                }
            }
            None => {
                let span = (track.len() - a) as f64;
                for k in e..track.len() {
                    let w = quintic((k - a) as f64 / (SWING_FADE * span));
                    track[k] = last(i) + w * (raw[k] - raw[a]);
                }
            }
        }
    }
    // Before the first stance.
    let (b, _) = stances[0];
    let span = (b + 1) as f64;
    for k in 0..b {
        let w = quintic((b - k) as f64 / (SWING_FADE * span));
        track[k] = first(0) + w * (raw[k] - raw[b]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// The heights are measured from each track's own ground: a still toe 8 cm up over a
    /// lowest toe height of 5 cm is 3 cm above it, within the 5 cm contact height (on); 11
    /// cm up it is 6 cm above (off). The ankle, 1 m above its ground of 0, never counts; a
    /// still ankle 3 cm above a ground of 2 cm is 1 cm above it (on), 8 cm above it 6 cm
    /// (off). Speeds are 0 (still tracks).
    #[test]
    fn contact_heights_are_measured_from_each_tracks_ground() {
        let times = [0.0, 0.1, 0.2];
        let still = |z: f64| vec![Vector3::new(0.0, 0.0, z); 3];
        let high_ankle = still(1.0);
        let detect_toe =
            |z: f64| detect(&times, &high_ankle, Some(&still(z)), [0.0, 0.05], 0.05, 0.4);
        assert_eq!(detect_toe(0.08), vec![true; 3]);
        assert_eq!(detect_toe(0.11), vec![false; 3]);
        let detect_ankle = |z: f64| detect(&times, &still(z), None, [0.02, 0.0], 0.05, 0.4);
        assert_eq!(detect_ankle(0.03), vec![true; 3]);
        assert_eq!(detect_ankle(0.08), vec![false; 3]);
    }

    /// Speeds are central differences (one-sided at the clip's ends). A foot on the ground
    /// moving 5 cm per 0.1 s frame, with frame times from 1 s on, moves at 0.5 m/s at every
    /// frame: on below a limit of 0.6 m/s, off at 0.4 m/s. A foot still for three frames and
    /// then 1 m further for three: the central differences at frames 2 and 3 span the jump,
    /// 1 m in 0.2 s = 5 m/s (off at 1 m/s); at the others it is 0 (on).
    #[test]
    fn contact_speeds_are_central_differences() {
        let times: Vec<f64> = (0..6).map(|k| 1.0 + 0.1 * k as f64).collect();
        let moving: Vec<Vector3<f64>> = (0..6)
            .map(|k| Vector3::new(0.05 * k as f64, 0.0, 0.0))
            .collect();
        let on = |speed: f64| detect(&times, &moving, None, [0.0, 0.0], 0.05, speed);
        assert_eq!(on(0.6), vec![true; 6]);
        assert_eq!(on(0.4), vec![false; 6]);
        let times: Vec<f64> = (0..6).map(|k| 0.1 * k as f64).collect();
        let jump: Vec<Vector3<f64>> = (0..6)
            .map(|k| Vector3::new(if k < 3 { 0.0 } else { 1.0 }, 0.0, 0.0))
            .collect();
        let c = detect(&times, &jump, None, [0.0, 0.0], 0.05, 1.0);
        assert_eq!(c, [true, true, false, false, true, true]);
    }

    /// Both limits are strict: a still ankle exactly `contact_height` above its ground (0.5 m
    /// over 0.25 m with a 0.5 m limit) is off, and one 0.01 m lower on; an ankle on the ground
    /// moving exactly at `contact_speed` (0.25 m per 0.5 s, 0.5 m/s at every frame) is off at
    /// a 0.5 m/s limit and on at 0.51 m/s. Every number is exact in binary.
    #[test]
    fn a_foot_exactly_at_a_limit_is_off() {
        let times = [0.0, 0.5, 1.0];
        let still = |z: f64| vec![Vector3::new(0.0, 0.0, z); 3];
        assert_eq!(
            detect(&times, &still(0.75), None, [0.25, 0.0], 0.5, 1.0),
            [false; 3]
        );
        assert_eq!(
            detect(&times, &still(0.74), None, [0.25, 0.0], 0.5, 1.0),
            [true; 3]
        );
        let moving: Vec<Vector3<f64>> = (0..3)
            .map(|k| Vector3::new(0.25 * k as f64, 0.0, 0.0))
            .collect();
        assert_eq!(
            detect(&times, &moving, None, [0.0, 0.0], 0.5, 0.5),
            [false; 3]
        );
        assert_eq!(
            detect(&times, &moving, None, [0.0, 0.0], 0.5, 0.51),
            [true; 3]
        );
    }

    /// Frames whose neighbours share their time (repeated time stamps, a one-frame clip) have
    /// no measured speed: a foot on the ground there is judged by its height alone, on, even
    /// though it moves 1 m between the frames.
    #[test]
    fn frames_without_time_between_them_are_judged_by_height() {
        let moving: Vec<Vector3<f64>> = (0..3).map(|k| Vector3::new(k as f64, 0.0, 0.0)).collect();
        assert_eq!(
            detect(&[0.0; 3], &moving, None, [0.0, 0.0], 0.05, 0.4),
            [true; 3]
        );
        let one = [Vector3::new(0.0, 0.0, 0.0)];
        assert_eq!(detect(&[0.0], &one, None, [0.0, 0.0], 0.05, 0.4), [true]);
    }

    /// A stance of 40 frames whose ankle is still for 10 frames, slides 1 cm a frame along x
    /// (and rises, which does not count) for 10, then is still again; and a still stance.
    fn sliding() -> (Vec<bool>, Vec<Vector3<f64>>) {
        let n = 50;
        let c: Vec<bool> = (0..n).map(|f| !(40..45).contains(&f)).collect();
        let x = |f: usize| 0.01 * (f.clamp(10, 20) - 10) as f64;
        let ankle = (0..n)
            .map(|f| {
                if f < 40 {
                    Vector3::new(x(f), 0.3, 0.1 * x(f))
                } else {
                    Vector3::new(1.0, 0.3, 0.0)
                }
            })
            .collect();
        (c, ankle)
    }

    /// The stance ends at the first frame further than `max_slide` from its start (frame 16:
    /// 6 cm with 5.5 cm allowed), a flight of `gap` frames follows, and the rest is a new
    /// stance; the still stance after it is left alone. With 10 cm allowed (the whole slide)
    /// nothing changes; from a new part's start the slide is measured afresh (2.5 cm allowed:
    /// each part ends at the first frame 3 cm from its start). Allowances between the frames'
    /// 1 cm steps keep rounding out of the comparisons.
    #[test]
    fn a_stance_that_slides_is_split_where_it_slid_too_far() {
        let (c0, ankle) = sliding();
        let mut c = c0.clone();
        split_slides(&mut c, &ankle, 0.055, 4);
        assert_eq!(runs(&c), vec![(0, 16), (20, 40), (45, 50)]);
        let mut c = c0.clone();
        split_slides(&mut c, &ankle, 0.1, 4);
        assert_eq!(c, c0);
        let mut c = c0.clone();
        split_slides(&mut c, &ankle, 0.025, 2);
        // Starts 0 (x 0), 15 (x 0.05: frame 13 is 3 cm out, flight 13-14), then frame 18
        // (x 0.08) is 3 cm from 15: flight 18-19, new part at 20 (x 0.1), still to the end.
        assert_eq!(runs(&c), vec![(0, 13), (15, 18), (20, 40), (45, 50)]);
    }

    /// No part shorter than `gap` is split off. With 5.5 cm allowed and a gap of 8 frames the
    /// split is at frame 16 as with 4, and with 12 (the rest after the flight exactly 12
    /// frames); with a gap of 17 there is none (the rest after the flight would be 6 frames). With 0.5 cm allowed and a gap of 12 the slide passes it at
    /// frame 11, when the part is 11 frames long, and the split waits for frame 12; a later
    /// part is measured from its own start. A gap of 0 still ends the stance for one frame.
    #[test]
    fn no_stance_part_shorter_than_the_gap_is_split_off() {
        let (c0, ankle) = sliding();
        let split = |d: f64, gap: usize| {
            let mut c = c0.clone();
            split_slides(&mut c, &ankle, d, gap);
            runs(&c)
        };
        assert_eq!(split(0.055, 8), vec![(0, 16), (24, 40), (45, 50)]);
        assert_eq!(split(0.055, 17), runs(&c0));
        // The rest after the flight exactly `gap` long (frames 28–39) still splits.
        assert_eq!(split(0.055, 12), vec![(0, 16), (28, 40), (45, 50)]);
        assert_eq!(split(0.005, 12), vec![(0, 12), (24, 40), (45, 50)]);
        // A later part too short where the slide passes the allowance again: with 2.5 cm and
        // a gap of 4 the first split is at 13, the second part starts at 17 (7 cm), the slide
        // is 3 cm on at frame 20, 3 frames into the part, and the split waits for frame 21.
        assert_eq!(split(0.025, 4), vec![(0, 13), (17, 21), (25, 40), (45, 50)]);
        assert_eq!(split(0.055, 0)[..2], [(0, 16), (17, 40)]);
    }

    /// With a gap of 0 a slide at a stance's last frame, the clip's last, ends the stance
    /// there for that frame: frames 0–3 still, frame 4 10 cm on (5 cm allowed).
    #[test]
    fn a_slide_at_the_clips_last_frame_ends_the_stance_there() {
        let mut c = vec![true; 5];
        let ankle: Vec<Vector3<f64>> = (0..5)
            .map(|f| Vector3::new(if f < 4 { 0.0 } else { 0.1 }, 0.0, 0.0))
            .collect();
        split_slides(&mut c, &ankle, 0.05, 0);
        assert_eq!(c, [true, true, true, true, false]);
    }

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

    /// Only runs shorter than `min_len` go: a flight exactly `min_len` long stays, and so
    /// does a short flight at either end of the clip (the other value on one side only); a
    /// short contact goes wherever it is, at the ends too.
    #[test]
    fn runs_of_exactly_min_len_and_flights_at_the_ends_stay() {
        let (t, f) = (true, false);
        let mut c = [f, t, t, t, f, f, t, t, t, f];
        remove_short(&mut c, false, 2);
        assert_eq!(c, [f, t, t, t, f, f, t, t, t, f]);
        remove_short(&mut c, false, 3);
        assert_eq!(c, [f, t, t, t, t, t, t, t, t, f]);
        let mut c = [t, f, f, f, t, t, f, f, f, t];
        remove_short(&mut c, true, 2);
        assert_eq!(c, [f, f, f, f, t, t, f, f, f, f]);
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

    /// The centred mean over `2 half + 1` samples, the window cut at the ends: a spike of 3
    /// among zeros spreads to thirds with `half = 1` (the ends' windows of two hold zeros
    /// only), and with `half = 2` to 3/3, 3/4, 3/5, 3/4, 3/3; two samples average to their
    /// mean; `half = 0` leaves the samples.
    #[test]
    fn the_moving_average_is_centred_and_shrinks_at_the_ends() {
        let average = |x: &[f64], half: usize| {
            let mut y = x.to_vec();
            moving_average(&mut y, half);
            y
        };
        let spike = [0.0, 0.0, 3.0, 0.0, 0.0];
        assert_eq!(average(&spike, 1), [0.0, 1.0, 1.0, 1.0, 0.0]);
        assert_eq!(average(&spike, 2), [1.0, 0.75, 0.6, 0.75, 1.0]);
        assert_eq!(average(&spike, 0), spike);
        assert_eq!(average(&[0.0, 2.0], 1), [1.0, 1.0]);
        assert_eq!(average(&[5.0], 3), [5.0]);
    }

    /// Before the first stance and after the last one the track keeps the captured motion
    /// shifted onto the hold (0.5), its departure from the stance's end tick faded in over
    /// `SWING_FADE` of the free run. A stance on ticks 0–4 of 25 (captured at 1), then a ramp
    /// `1 + (k − 4)`: the free run counts 25 − 4 = 21 ticks from the stance's last tick 4, so
    /// tick `k` is `0.5 + s((k − 4) / 5.25) (k − 4)`, `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵` clamped to 1
    /// from τ = 1 on. Mirrored, a stance on ticks 20–24 after a ramp down to it: the free run
    /// counts 20 + 1 ticks up to the stance's first tick 20, and tick `k` is
    /// `0.5 + s((20 − k) / 5.25) (20 − k)`.
    #[test]
    fn outside_the_stances_the_captured_motion_fades_in_over_a_quarter_of_the_run() {
        let n = 25;
        let s = |tau: f64| {
            let tau = tau.min(1.0);
            tau.powi(3) * (10.0 - 15.0 * tau + 6.0 * tau * tau)
        };
        // The stance's ticks, and its tick next to the free run.
        for (stance, end) in [(0..5, 4.0), (20..25, 20.0)] {
            let d = |k: usize| {
                if stance.contains(&k) {
                    0.0
                } else {
                    (k as f64 - end).abs()
                }
            };
            let raw: Vec<f64> = (0..n).map(|k| 1.0 + d(k)).collect();
            let contact: Vec<bool> = (0..n).map(|k| stance.contains(&k)).collect();
            let mut t = raw.clone();
            hold(&mut t, &contact, Some(0.5));
            for (k, x) in t.iter().enumerate() {
                let expected = 0.5 + s(d(k) / 5.25) * d(k);
                assert!((x - expected).abs() < 1e-12, "{k}: {x} {expected}");
            }
        }
    }

    /// A stance whose yaw turns by 2 rad (at 4 rad/s) is followed no faster than the step
    /// allowed, monotonically, and reaches the turn before the stance ends; one whose yaw
    /// jitters by ±0.1 rad is held at its mean; the swing between starts from where the
    /// first stance ended, at rest.
    #[test]
    fn a_turning_stance_is_followed_at_a_bounded_rate_and_a_jittery_one_held() {
        let (n, dt) = (400, 0.005);
        let contact: Vec<bool> = (0..n).map(|k| !(200..260).contains(&k)).collect();
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        use rand::{Rng, SeedableRng};
        let raw: Vec<f64> = (0..n)
            .map(|k| {
                if k < 200 {
                    // 4 rad/s from tick 20 to tick 120, then still.
                    (4.0 * dt * (k as f64 - 20.0)).clamp(0.0, 2.0)
                } else {
                    2.0 + rng.random_range(-0.1..0.1)
                }
            })
            .collect();
        let mut t = raw.clone();
        let max_step = 2.5 * dt;
        hold_turning(&mut t, &contact, PIVOT_TURN, 10, max_step);
        for k in 1..200 {
            let step = t[k] - t[k - 1];
            assert!((0.0..=max_step + 1e-15).contains(&step), "{k}: {step}");
        }
        assert!((t[199] - 2.0).abs() < 1e-12, "{}", t[199]);
        let m = raw[260..].iter().sum::<f64>() / (n - 260) as f64;
        assert!(t[260..].iter().all(|x| (x - m).abs() < 1e-15));
        assert!(
            (t[200] - t[199]).abs() < 0.1 * max_step,
            "{}",
            t[200] - t[199]
        );
        // A slow turn (1 rad/s, within the rate): inside the stance, a window's length from
        // its ends, the centred average of a ramp is the ramp itself.
        let contact = vec![true; n];
        let raw: Vec<f64> = (0..n).map(|k| dt * k as f64).collect();
        let mut t = raw.clone();
        hold_turning(&mut t, &contact, PIVOT_TURN, 10, max_step);
        for k in 10..n - 10 {
            assert!((t[k] - raw[k]).abs() < 1e-12, "{k}: {} {}", t[k], raw[k]);
        }
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
