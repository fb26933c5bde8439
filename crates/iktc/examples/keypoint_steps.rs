//! Runs the keypoint retargeting of a built-in clip on G1 for a repeatable instruction count:
//! the settling ticks, then every tick of the clip inside [`timed`], which a profiler can
//! select, e.g.
//!
//! `valgrind --tool=callgrind --toggle-collect='*timed*' target/release/examples/keypoint_steps humanoid3d_walk`
//!
//! and divide the instructions collected by the number of ticks printed. The argument picks
//! the clip (default `humanoid3d_walk`); the checksum line compares answers before and after
//! a change.

use iktc::motion::DEFAULT_MAX_GAP;
use iktc::profile::RobotProfile;
use iktc::retarget::{builtin_motion, keypoint_controller, KeypointController, KeypointSettings};

/// Every tick of the clip; a separate function so that a profiler can collect it alone.
#[inline(never)]
fn timed(c: &mut KeypointController) -> iktc::Result<usize> {
    let mut fallbacks = 0;
    for k in 0..c.ticks() {
        c.tick(k, false)?;
        c.integrate()?;
        fallbacks += usize::from(std::hint::black_box(c.used_fallback()));
    }
    Ok(fallbacks)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let clip = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "humanoid3d_walk".into());
    let profile = RobotProfile::builtin("g1")?;
    let kp = builtin_motion(&clip)?.keypoints(DEFAULT_MAX_GAP)?;
    let s = KeypointSettings::default();
    let mut c = keypoint_controller(&profile, &kp, None, &s)?;
    let settle = (s.settle_time / s.dt).round() as usize;
    let trace = std::env::var_os("KP_TICKS").is_some();
    for k in 0..settle {
        c.tick(0, true)?;
        if trace {
            println!("settle {k} {:.15e}", c.qdd().norm());
        }
        c.integrate()?;
    }
    if let Some(limit) = std::env::var("KP_TICKS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
    {
        // The first `limit` ticks only, with every tick's q̈ norm (to compare two builds).
        for k in 0..limit.min(c.ticks()) {
            c.tick(k, false)?;
            println!("{k} {:.15e}", c.qdd().norm());
            c.integrate()?;
        }
        return Ok(());
    }
    if std::env::var_os("KP_STATS").is_some() {
        return stats(&mut c);
    }
    let fallbacks = timed(&mut c)?;
    let st = c.state();
    println!(
        "{clip}: {settle} settling ticks, {} timed ticks, {fallbacks} GF ticks, |q| {:.12e} |qd| {:.12e}",
        c.ticks(),
        st.q.norm(),
        st.qd.norm()
    );
    Ok(())
}

/// With `KP_STATS` set: the levels' sizes and ranks, IKTC's corrections and QPs per tick
/// (instead of the timed run).
fn stats(c: &mut KeypointController) -> Result<(), Box<dyn std::error::Error>> {
    use std::collections::BTreeMap;
    let mut shapes: BTreeMap<String, usize> = BTreeMap::new();
    let (mut qps, mut warm, mut screened, mut corrected) = (0, 0, 0, 0);
    for k in 0..c.ticks() {
        let r = c.tick(k, false)?.clone();
        let dims: Vec<usize> = c.controller().level_dims().collect();
        *shapes
            .entry(format!(
                "dims {dims:?} ranks {:?} from {:?}",
                r.ranks, r.corrected_from
            ))
            .or_default() += 1;
        qps += r.qp_solves;
        warm += r.qp_warm_started;
        screened += r.screened_infeasible;
        corrected += usize::from(r.corrected_from.is_some());
        c.integrate()?;
    }
    for (s, n) in shapes {
        println!("{n:5} {s}");
    }
    println!(
        "ticks {} corrected {corrected} qps {qps} warm {warm} screened {screened}",
        c.ticks()
    );
    Ok(())
}
