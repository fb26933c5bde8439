//! The keypoint retargeting tick on G1 (n = 35; feet, COM, pelvis, hands, elbows and torso,
//! posture: references, kinematics, box, IKTC with its GF fallback, integration) along
//! humanoid3d_dance_b, beside the joint route's imitation tick (Table 1 stack) on the same
//! robot and clip.
//!
//! Criterion reports the mean tick over a sample; afterwards the median of single ticks over
//! 3 passes of the clip is printed for both.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::motion::{
    builtin_clip, motion_from_content, MotionContent, MotionFormat, MotionOptions, DEFAULT_MAX_GAP,
};
use iktc::profile::RobotProfile;
use iktc::retarget::{keypoint_controller, KeypointController, KeypointSettings};
use iktc::sim::{imitation_references, percentile, ImitateConfig, ImitationController};

const CLIP: &str = "humanoid3d_dance_b";

fn keypoints(profile: &RobotProfile) -> KeypointController {
    let clip = builtin_clip(CLIP).expect("clip");
    let motion = motion_from_content(
        CLIP.into(),
        MotionFormat::DeepMimic,
        MotionContent::Skeleton(clip),
        &MotionOptions::default(),
    )
    .expect("motion");
    let kp = motion.keypoints(DEFAULT_MAX_GAP).expect("keypoints");
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
    group.bench_function("keypoints_g1", |b| {
        b.iter_custom(|iters| {
            let mut ctl = initial.clone();
            let (mut k, mut total) = (0, Duration::ZERO);
            for _ in 0..iters {
                if k == n {
                    ctl = initial.clone();
                    k = 0;
                }
                let start = Instant::now();
                let _ = std::hint::black_box(ctl.tick(k, false).map(|r| r.qp_solves));
                let _ = ctl.integrate();
                total += start.elapsed();
                k += 1;
            }
            total
        })
    });
    group.bench_function("imitation_g1", |b| {
        b.iter_custom(|iters| {
            let mut ctl = imitation.clone();
            let (mut k, mut total) = (0, Duration::ZERO);
            for _ in 0..iters {
                if k == refs.len() {
                    ctl = imitation.clone();
                    k = 0;
                }
                let start = Instant::now();
                let _ = std::hint::black_box(ctl.tick(&robot, k).map(|r| r.qp_solves));
                let _ = ctl.integrate(&robot);
                total += start.elapsed();
                k += 1;
            }
            total
        })
    });
    group.finish();
    let (mut kp_ticks, mut im_ticks) = (Vec::new(), Vec::new());
    for _ in 0..3 {
        let mut ctl = initial.clone();
        for k in 0..n {
            let start = Instant::now();
            let _ = std::hint::black_box(ctl.tick(k, false).map(|r| r.qp_solves));
            let _ = ctl.integrate();
            kp_ticks.push(start.elapsed().as_secs_f64() * 1e6);
        }
        let mut ctl = imitation.clone();
        for k in 0..refs.len() {
            let start = Instant::now();
            let _ = std::hint::black_box(ctl.tick(&robot, k).map(|r| r.qp_solves));
            let _ = ctl.integrate(&robot);
            im_ticks.push(start.elapsed().as_secs_f64() * 1e6);
        }
    }
    eprintln!(
        "retarget_tick: single ticks over 3 passes of {CLIP} on G1: keypoints median {:.1} µs (p99 {:.1}), imitation median {:.1} µs (p99 {:.1})",
        percentile(&kp_ticks, 0.5),
        percentile(&kp_ticks, 0.99),
        percentile(&im_ticks, 0.5),
        percentile(&im_ticks, 0.99)
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
