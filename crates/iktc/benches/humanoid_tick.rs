//! The whole humanoid control tick on JVRC-1 (n = 38, Table 1 stack): kinematics, references,
//! task linearisation, acceleration box, solve (IKTC or GF) and integration, along the default
//! imitation run (humanoid3d_dance_b, L_KNEE and L_HIP_R narrowed), with the imitation's
//! defaults, without their soft approach to the range ends, and with Algorithm 2 as printed
//! under the viable bounds.
//!
//! Criterion reports the mean tick over a sample; afterwards the median and 99th percentile of
//! single ticks over 5 passes of the clip are printed.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::sim::{percentile, ImitateConfig, ImitationController};
use iktc::solver::Method;

#[path = "common/walking.rs"]
mod walking_common;
use walking_common::{imitation_setup as setup, walking_setup};

fn bench(c: &mut Criterion) {
    let (robot, refs) = setup();
    let n = refs.len();
    let mut group = c.benchmark_group("humanoid_tick");
    // `iktc` and `gf` with the imitation's defaults (quiet bounds with the soft approach; IKTC
    // with a level hold); `iktc_no_approach`: the defaults without the soft approach (the cost
    // of its source in the box, and of the different path it takes); `iktc_viable_alg2`:
    // Algorithm 2 as printed with the viable bounds.
    for (name, method, printed, approach) in [
        ("iktc", Method::Iktc, false, true),
        ("gf", Method::Cascade, false, true),
        ("iktc_no_approach", Method::Iktc, false, false),
        ("iktc_viable_alg2", Method::Iktc, true, false),
    ] {
        let mut cfg = ImitateConfig {
            method,
            ..ImitateConfig::default()
        };
        if !approach {
            cfg.bounds = cfg.bounds.with_approach_rate(0.0).expect("rate 0");
        }
        if printed {
            cfg.bounds = iktc::limits::BoundMethod::viable();
            cfg.solver.level_hold = 1;
            cfg.solver.continuity = 0.0;
        }
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
                    let _ = std::hint::black_box(ctl.tick(k).map(|r| r.qp_solves));
                    let _ = ctl.integrate();
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
                let _ = std::hint::black_box(ctl.tick(k).map(|r| r.qp_solves));
                let _ = ctl.integrate();
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

/// The walking tick: walking pattern, damping controller and IK, with the ZMP of the
/// simulated compliant robot fed back (the plant's step is outside the timed region).
fn bench_walk(c: &mut Criterion) {
    use iktc::sim::{WalkPlants, WalkingController};
    let (robot, refs) = setup();
    let (initial, plants0) = walking_setup(&robot, &refs);
    let n = initial.ticks();
    // One pass: returns the time of each tick [µs].
    let pass = |wc: &mut WalkingController,
                plants: &mut WalkPlants,
                ticks: &mut Vec<f64>,
                k: usize|
     -> Duration {
        let dev = plants.measure();
        let start = Instant::now();
        let wt = std::hint::black_box(wc.tick(k, dev)).expect("tick");
        wc.integrate().expect("integrate");
        let el = start.elapsed();
        ticks.push(el.as_secs_f64() * 1e6);
        plants.step(k, wc, &wt).expect("plant step");
        el
    };
    c.bench_function("humanoid_tick/walking_iktc", |b| {
        b.iter_custom(|iters| {
            let (mut wc, mut plants) = (initial.clone(), plants0.clone());
            let mut scratch = Vec::new();
            let mut k = 0;
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                if k == n {
                    wc = initial.clone();
                    plants = plants0.clone();
                    k = 0;
                }
                scratch.clear();
                total += pass(&mut wc, &mut plants, &mut scratch, k);
                k += 1;
            }
            total
        })
    });
    let mut ticks = Vec::with_capacity(3 * n);
    for _ in 0..3 {
        let (mut wc, mut plants) = (initial.clone(), plants0.clone());
        for k in 0..n {
            pass(&mut wc, &mut plants, &mut ticks, k);
        }
    }
    eprintln!(
        "humanoid_tick/walking_iktc: single ticks over 3 passes of {n}: median {:.1} µs, p99 {:.1} µs, max {:.1} µs",
        percentile(&ticks, 0.5),
        percentile(&ticks, 0.99),
        percentile(&ticks, 1.0)
    );
}

criterion_group!(benches, bench, bench_walk);
criterion_main!(benches);
