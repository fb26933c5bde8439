//! The whole humanoid control tick on JVRC-1 (n = 38, Table 1 stack): kinematics, references,
//! task linearisation, acceleration box, solve (IKTC or GF) and integration, along the default
//! imitation run (humanoid3d_dance_b, L_KNEE and L_HIP_R narrowed).
//!
//! Criterion reports the mean tick over a sample; afterwards the median and 99th percentile of
//! single ticks over 5 passes of the clip are printed.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::model::{jvrc1, ModelOptions, Robot};
use iktc::motion::{builtin_clip, builtin_map, retarget, RobotReferences};
use iktc::sim::{percentile, ImitateConfig, ImitationController};
use iktc::solver::Method;

fn setup() -> (Robot, RobotReferences) {
    let robot = jvrc1(&ModelOptions::default()).expect("JVRC-1");
    let clip = builtin_clip("humanoid3d_dance_b").expect("clip");
    let map = builtin_map("deepmimic_jvrc1").expect("map");
    let refs = retarget(&clip, &robot, &map)
        .and_then(|r| r.resample(0.005))
        .expect("references");
    (robot, refs)
}

fn bench(c: &mut Criterion) {
    let (robot, refs) = setup();
    let n = refs.len();
    let mut group = c.benchmark_group("humanoid_tick");
    for (name, method) in [("iktc", Method::Iktc), ("gf", Method::Cascade)] {
        let cfg = ImitateConfig {
            method,
            ..ImitateConfig::default()
        };
        let initial = ImitationController::new(&robot, &refs, &cfg).expect("controller");
        group.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let mut ctl = initial.clone();
                let mut k = 0;
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    if k == n {
                        ctl = initial.clone();
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
        // Single-tick distribution.
        let mut ticks = Vec::with_capacity(5 * n);
        for _ in 0..5 {
            let mut ctl = initial.clone();
            for k in 0..n {
                let start = Instant::now();
                let _ = std::hint::black_box(ctl.tick(&robot, k).map(|r| r.qp_solves));
                let _ = ctl.integrate(&robot);
                ticks.push(start.elapsed().as_secs_f64() * 1e6);
            }
        }
        eprintln!(
            "humanoid_tick/{name}: single ticks over 5 passes of {n}: median {:.1} µs, p99 {:.1} µs, max {:.1} µs",
            percentile(&ticks, 0.5),
            percentile(&ticks, 0.99),
            percentile(&ticks, 1.0)
        );
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
