//! The keypoint retargeting tick on G1 (n = 35; feet, COM, pelvis, hands, elbows and torso,
//! posture: references, kinematics, box, IKTC with its GF fallback, integration) along
//! humanoid3d_dance_b, beside the joint route's imitation tick (Table 1 stack) on the same
//! robot and clip.
//!
//! Criterion reports the mean tick over a sample; afterwards the median of single ticks over
//! 3 passes of the clip is printed for both.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::motion::builtin_clip;
use iktc::profile::RobotProfile;
use iktc::retarget::{builtin_motion, keypoint_controller, KeypointController, KeypointSettings};
use iktc::sim::{imitation_references, percentile, ImitateConfig, ImitationController};

const CLIP: &str = "humanoid3d_dance_b";

fn keypoints(profile: &RobotProfile) -> KeypointController {
    let kp = builtin_motion(CLIP)
        .and_then(|m| m.keypoints(iktc::motion::DEFAULT_MAX_GAP))
        .expect("keypoints");
    let mut ctl =
        keypoint_controller(profile, &kp, None, &KeypointSettings::default()).expect("controller");
    // Settled on the first frame, as a run starts the clip.
    for _ in 0..300 {
        let _ = ctl.tick(0, true);
        let _ = ctl.integrate();
    }
    ctl
}

fn bench(c: &mut Criterion) {
    let profile = RobotProfile::builtin("g1").expect("g1");
    let robot = profile.robot().expect("robot");
    let initial = keypoints(&profile);
    let cfg = ImitateConfig {
        narrow: Vec::new(),
        ..profile
            .imitate_config(ImitateConfig::default())
            .expect("config")
    };
    let map = profile.retarget_map("deepmimic", &robot).expect("map");
    let clip = builtin_clip(CLIP).expect("clip");
    let refs = imitation_references(&robot, &clip, &map, &cfg).expect("references");
    let imitation = ImitationController::new(&robot, &refs, &cfg).expect("imitation");
    let n = initial.ticks();
    let mut group = c.benchmark_group("retarget_tick");
    let keypoint_tick = |ctl: &mut KeypointController, k: usize| {
        let _ = std::hint::black_box(ctl.tick(k, false).map(|r| r.qp_solves));
        let _ = ctl.integrate();
    };
    let imitation_tick = |ctl: &mut ImitationController, k: usize| {
        let _ = std::hint::black_box(ctl.tick(k).map(|r| r.qp_solves));
        let _ = ctl.integrate();
    };
    group.bench_function("keypoints_g1", |b| {
        b.iter_custom(|iters| {
            timed(&initial, n, iters as usize, keypoint_tick)
                .iter()
                .sum()
        })
    });
    group.bench_function("imitation_g1", |b| {
        b.iter_custom(|iters| {
            timed(&imitation, refs.len(), iters as usize, imitation_tick)
                .iter()
                .sum()
        })
    });
    group.finish();
    let us = |d: Vec<Duration>| -> Vec<f64> { d.iter().map(|t| t.as_secs_f64() * 1e6).collect() };
    let kp_ticks = us(timed(&initial, n, 3 * n, keypoint_tick));
    let im_ticks = us(timed(
        &imitation,
        refs.len(),
        3 * refs.len(),
        imitation_tick,
    ));
    eprintln!(
        "retarget_tick: single ticks over 3 passes of {CLIP} on G1: keypoints median {:.1} µs (p99 {:.1}), imitation median {:.1} µs (p99 {:.1})",
        percentile(&kp_ticks, 0.5),
        percentile(&kp_ticks, 0.99),
        percentile(&im_ticks, 0.5),
        percentile(&im_ticks, 0.99)
    );
}

/// The time of each of `count` ticks of a clip of `n` ticks, restarting from `initial` at its
/// end.
fn timed<C: Clone>(
    initial: &C,
    n: usize,
    count: usize,
    mut tick: impl FnMut(&mut C, usize),
) -> Vec<Duration> {
    let mut ctl = initial.clone();
    let mut k = 0;
    (0..count)
        .map(|_| {
            if k == n {
                ctl = initial.clone();
                k = 0;
            }
            let start = Instant::now();
            tick(&mut ctl, k);
            k += 1;
            start.elapsed()
        })
        .collect()
}

criterion_group!(benches, bench);
criterion_main!(benches);
