//! IKTC, GF and clamp per tick, in one run: the 3R arm's shape (three 1-row levels) and a
//! JVRC-1-sized problem (38 dofs, the five levels of Table 1: 12, 2, 3, 1, 20), with random but
//! reproducible Jacobians, with and without an active correction.

#[path = "../tests/common/mod.rs"]
mod common;
use common::rng;
use common::solver as solver_common;
use solver_common::*;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use iktc_core::solver::{Method, Solver, SolverSettings};
use nalgebra::DVector;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    for (name, n, dims) in [
        ("3r", 3usize, vec![1usize, 1, 1]),
        ("38dof", 38, vec![12, 2, 3, 1, 20]),
    ] {
        let mut r = rng(7);
        let levels = random_levels(&mut r, n, &dims);
        let mut s = Solver::new(n, &dims, SolverSettings::default()).unwrap();
        let mut q0 = DVector::zeros(n);
        s.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        let inactive = wide_box(n);
        let active = box_violated_by(&mut r, &q0, 5.0, if n > 3 { 3 } else { 1 }, 0.5);
        let mut q = DVector::zeros(n);
        let rep = s.solve(Method::Iktc, &levels, &active, &mut q).unwrap();
        eprintln!(
            "{name}: correction from level {:?}, {} QP(s)",
            rep.corrected_from, rep.qp_solves
        );
        let mut g = c.benchmark_group(format!("solve_{name}"));
        for (case, bx) in [("no_correction", &inactive), ("correction", &active)] {
            for m in [Method::Iktc, Method::Cascade, Method::Clamp] {
                g.bench_function(BenchmarkId::new(m.name(), case), |b| {
                    b.iter(|| {
                        s.solve(m, black_box(&levels), black_box(bx), &mut q)
                            .unwrap();
                    })
                });
            }
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
