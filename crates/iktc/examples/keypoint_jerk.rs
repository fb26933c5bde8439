//! Where the joint jerk of a keypoint retargeting comes from: runs the keypoint controller of
//! a clip (a built-in name, or a motion file) on a built-in robot (default `g1`), and splits
//! the joints' squared jerk `‖(q̈_k − q̈_{k−1}) / Δt‖²` \[rad²/s⁶\] over the clip's ticks by
//! what changed from tick k − 1 to tick k: a foot's stance; IKTC's correction (it began,
//! ended, or the level corrected from changed); nothing, with the same level corrected on
//! both ticks; nothing, uncorrected on both. Prints, per kind, the ticks, their share of the squared jerk and their
//! RMS jerk \[rad/s³\] over the active joints, e.g.
//!
//! `cargo run --release -p iktc --example keypoint_jerk -- humanoid3d_punch g1`
//!
//! The controller is the library's ([`keypoint_controller`]: the start posture as the posture
//! level's reference, 300 settling ticks on the first frame), not the command line's (which
//! takes the posture references from the joint route), so its figures differ somewhat from
//! `iktc retarget`'s.

use std::path::Path;

use iktc::motion::{load_motion, MotionOptions, DEFAULT_MAX_GAP};
use iktc::profile::RobotProfile;
use iktc::retarget::{builtin_motion, keypoint_controller, KeypointSettings};

/// Settling ticks on the first frame before the clip (1.5 s at the default 200 Hz).
const SETTLE_TICKS: usize = 300;

/// The kinds of tick the squared jerk is split over.
const KINDS: [&str; 4] = [
    "stance changed",
    "correction began/ended/moved",
    "same level corrected",
    "uncorrected",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let clip = args.next().unwrap_or_else(|| "humanoid3d_punch".into());
    let robot = args.next().unwrap_or_else(|| "g1".into());
    let profile = RobotProfile::builtin(&robot)?;
    let motion = if Path::new(&clip).is_file() {
        load_motion(Path::new(&clip), &MotionOptions::default())?
    } else {
        builtin_motion(&clip)?
    };
    let kp = motion.keypoints(DEFAULT_MAX_GAP)?;
    let s = KeypointSettings::default();
    let mut c = keypoint_controller(&profile, &kp, None, &s)?;
    for _ in 0..SETTLE_TICKS {
        c.tick(0, true)?;
        c.integrate()?;
    }
    let base = c.state().qd.len() - profile.robot()?.n_active();
    let joints = c.state().qd.len() - base;
    let mut previous: Option<(Vec<f64>, [bool; 2], Option<usize>)> = None;
    // Per kind: the sum of squared jerks and the ticks.
    let mut sums = [(0.0_f64, 0_usize); 4];
    for k in 0..c.ticks() {
        let corrected = c.tick(k, false)?.corrected_from;
        let qdd: Vec<f64> = c.qdd().iter().skip(base).copied().collect();
        let stance = c.stance();
        if let Some((last, last_stance, last_corrected)) = &previous {
            let squared: f64 = qdd
                .iter()
                .zip(last)
                .map(|(a, b)| ((a - b) / s.dt).powi(2))
                .sum();
            let kind = if stance != *last_stance {
                0
            } else if corrected != *last_corrected {
                1
            } else if corrected.is_some() {
                2
            } else {
                3
            };
            sums[kind].0 += squared;
            sums[kind].1 += 1;
        }
        previous = Some((qdd, stance, corrected));
        c.integrate()?;
    }
    let total: f64 = sums.iter().map(|(e, _)| e).sum();
    let ticks: usize = sums.iter().map(|(_, m)| m).sum();
    let rms = |e: f64, m: usize| (e / (m.max(1) * joints.max(1)) as f64).sqrt();
    println!(
        "{clip} on {robot}: {ticks} ticks, RMS jerk {:.0} rad/s³",
        rms(total, ticks)
    );
    for (kind, (e, m)) in KINDS.iter().zip(sums) {
        println!(
            "  {kind:28} {m:5} ticks  {:5.1} % of the squared jerk  RMS {:7.0} rad/s³",
            100.0 * e / total.max(f64::MIN_POSITIVE),
            rms(e, m)
        );
    }
    Ok(())
}
