//! compute_box for nv = 38 (JVRC-1: 6 floating-base dofs + 32 joints), both methods.

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::limits::{compute_box, AccelerationBox, BoundMethod, DofLimits, JointLimits};
use rand::{Rng, SeedableRng};
use std::hint::black_box;

fn bench_compute_box(c: &mut Criterion) {
    let nv = 38;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(38);
    let mut dofs = vec![DofLimits::unlimited(); 6];
    for _ in 6..nv {
        let q_min = rng.random_range(-2.5..-0.1);
        dofs.push(DofLimits {
            position_min: q_min,
            position_max: q_min + rng.random_range(0.5..4.0),
            velocity_max: rng.random_range(2.0..10.0),
            acceleration_max: rng.random_range(10.0..100.0),
            jerk_max: f64::INFINITY,
        });
    }
    let limits = match JointLimits::new(dofs.clone()) {
        Ok(l) => l,
        Err(e) => panic!("bench limits: {e}"),
    };
    // A state spread over the ranges, some joints close to a limit and moving toward it.
    let position: Vec<f64> = dofs
        .iter()
        .map(|d| {
            if d.position_min.is_finite() {
                d.position_min + rng.random_range(0.02..0.98) * (d.position_max - d.position_min)
            } else {
                rng.random_range(-1.0..1.0)
            }
        })
        .collect();
    let velocity: Vec<f64> = (0..nv).map(|_| rng.random_range(-1.5..1.5)).collect();
    let mut out = AccelerationBox::new(nv);
    let mut group = c.benchmark_group("compute_box_nv38");
    for (name, method) in [
        ("paper", BoundMethod::Paper),
        ("viable", BoundMethod::viable()),
        ("quiet", BoundMethod::quiet()),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| {
                let result = compute_box(
                    black_box(&limits),
                    black_box(&method),
                    black_box(&position),
                    black_box(&velocity),
                    black_box(0.005),
                    &mut out,
                );
                black_box((result, out.upper[37]))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_compute_box);
criterion_main!(benches);
