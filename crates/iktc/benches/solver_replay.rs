//! The solver alone on the problems of the default walking imitation run, replayed: the task
//! equations and acceleration boxes of every tick are recorded once (closed loop with the
//! default settings), then each solver variant solves the same sequence in order. Because the
//! closed loop is sensitive to rounding (a different QP path moves the robot elsewhere), this
//! is the fair way to compare variants: same problems, one run, reported as ratios.

use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::limits::AccelerationBox;
use iktc::solver::{Method, Solver, SolverSettings};
use iktc::task::TaskEquation;
use nalgebra::DVector;

#[path = "common/walking.rs"]
mod walking_common;
use walking_common::{imitation_setup, walking_setup};

/// The (levels, box) of every tick of the default walking imitation run.
fn record() -> Vec<(Vec<TaskEquation>, AccelerationBox)> {
    let (robot, refs) = imitation_setup();
    let (mut wc, mut plants) = walking_setup(&robot, &refs);
    let mut out = Vec::with_capacity(wc.ticks());
    for k in 0..wc.ticks() {
        let dev = plants.measure();
        let wt = wc.tick(k, dev).expect("tick");
        let im = wc.imitation();
        out.push((im.equations().to_vec(), im.acceleration_box().clone()));
        plants.step(k, &wc, &wt).expect("plant step");
        wc.integrate().expect("integrate");
    }
    out
}

fn bench(c: &mut Criterion) {
    let seq = record();
    let n = seq[0].1.nv();
    let dims: Vec<usize> = seq[0].0.iter().map(|l| l.dim()).collect();
    let variants = [
        ("default", SolverSettings::default()),
        (
            "no_screen",
            SolverSettings {
                screen: false,
                ..SolverSettings::default()
            },
        ),
        (
            "cold",
            SolverSettings {
                warm_start: false,
                ..SolverSettings::default()
            },
        ),
    ];
    // Interleaved passes: the variants take turns over the whole sequence, so that the
    // machine's slow spells hit all of them alike; the median pass of each, per tick.
    let rounds = 25;
    let mut passes: Vec<Vec<f64>> = vec![Vec::with_capacity(rounds); variants.len()];
    let mut solvers: Vec<Solver> = variants
        .iter()
        .map(|(_, st)| Solver::new(n, &dims, *st).expect("solver"))
        .collect();
    let mut q = DVector::zeros(n);
    for _ in 0..rounds {
        for (s, times) in solvers.iter_mut().zip(passes.iter_mut()) {
            let start = Instant::now();
            for (levels, bx) in &seq {
                let _ = std::hint::black_box(s.solve(Method::Iktc, levels, bx, &mut q));
            }
            times.push(start.elapsed().as_secs_f64() * 1e6 / seq.len() as f64);
        }
    }
    let medians: Vec<f64> = passes
        .iter()
        .map(|t| iktc::sim::percentile(t, 0.5))
        .collect();
    for ((name, _), m) in variants.iter().zip(&medians) {
        eprintln!(
            "solver_replay/{name}: interleaved passes: median {m:.2} µs per tick, {:.3} × {}",
            m / medians[0],
            variants[0].0
        );
    }
    let mut group = c.benchmark_group("solver_replay");
    for (name, settings) in variants {
        let mut totals = (0, 0, 0, 0);
        {
            let mut s = Solver::new(n, &dims, settings).expect("solver");
            let mut q = DVector::zeros(n);
            for (levels, bx) in &seq {
                let r = s.solve(Method::Iktc, levels, bx, &mut q).expect("solve");
                totals.0 += r.qp_solves;
                totals.1 += r.qp_iterations;
                totals.2 += r.screened_infeasible;
                totals.3 += r.qp_warm_started;
            }
        }
        eprintln!(
            "solver_replay/{name}: {} ticks, {} QPs ({} warm-started), {} QP iterations, {} levels screened",
            seq.len(),
            totals.0,
            totals.3,
            totals.1,
            totals.2
        );
        let mut s = Solver::new(n, &dims, settings).expect("solver");
        let mut q = DVector::zeros(n);
        group.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                let mut k = 0;
                for _ in 0..iters {
                    if k == seq.len() {
                        k = 0;
                    }
                    let (levels, bx) = &seq[k];
                    let start = Instant::now();
                    let _ = std::hint::black_box(s.solve(Method::Iktc, levels, bx, &mut q));
                    total += start.elapsed();
                    k += 1;
                }
                total
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
