//! Dense dual active-set QP solver on the two shapes of the control tick, with clarabel on the
//! same problems for the ratio.
//!
//! * IKTC correction (paper eq. 23): `H = I`, 20 variables (Δh of the corrected levels),
//!   38 two-sided rows `b_l − q̈* ≤ G Δh ≤ b_u − q̈*`, a handful of them violated at `Δh = 0`.
//! * GF cascade level: `H = JᵀJ + λ²I` (38 variables), 38 box rows, 18 equality rows (the
//!   higher levels' tasks).
//!
//! Run: `cargo bench -p iktc-core --bench qp -- --warm-up-time 1 --measurement-time 3`.

#[path = "../tests/common/mod.rs"]
mod common;
use common::qp as qp_common;
use common::rng;

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use iktc_core::solver::{QpSettings, QpStatus, QpWorkspace};
use nalgebra::{DMatrix, DVector};
use qp_common::{clarabel_solve, random_spd, OwnedQp, Verdict};
use rand::Rng;

/// The IKTC correction QP: `min ½‖Δh‖²  s.t.  l ≤ G Δh ≤ u`, `G` 38 × 20, with `violated` rows
/// whose lower end is above zero (they need a correction).
fn iktc_shape(seed: u64, violated: usize) -> OwnedQp {
    let (n, m) = (20, 38);
    let mut r = rng(seed);
    let g = DMatrix::from_fn(m, n, |_, _| r.random_range(-1.0..1.0));
    let mut l = Vec::with_capacity(m);
    let mut u = Vec::with_capacity(m);
    for i in 0..m {
        if i < violated {
            let lo = r.random_range(0.1..0.5);
            l.push(lo);
            u.push(lo + r.random_range(0.5..1.5));
        } else {
            l.push(-r.random_range(0.5..1.5));
            u.push(r.random_range(0.5..1.5));
        }
    }
    OwnedQp {
        h: None,
        c: vec![0.0; n],
        a_eq: DMatrix::zeros(0, n),
        b_eq: vec![],
        a_in: g,
        l,
        u,
    }
}

/// A GF level: general SPD H (38 × 38), 18 equality rows, box rows on every variable.
fn gf_shape(seed: u64) -> OwnedQp {
    let (n, m_eq) = (38, 18);
    let mut r = rng(seed);
    let h = random_spd(&mut r, n);
    let target = DVector::from_fn(n, |_, _| r.random_range(-3.0..3.0));
    let c = -(&h * &target);
    let x_feas = DVector::from_fn(n, |_, _| r.random_range(-0.5..0.5));
    let a_eq = DMatrix::from_fn(m_eq, n, |_, _| r.random_range(-1.0..1.0));
    let b_eq = (&a_eq * &x_feas).iter().copied().collect();
    OwnedQp {
        h: Some(h),
        c: c.iter().copied().collect(),
        a_eq,
        b_eq,
        a_in: DMatrix::identity(n, n),
        l: vec![-1.0; n],
        u: vec![1.0; n],
    }
}

fn bench_shape(c: &mut Criterion, name: &str, p: &OwnedQp) {
    let settings = QpSettings::default();
    let mut ws = QpWorkspace::new(p.n(), p.a_eq.nrows(), p.a_in.nrows());
    let mut x = DVector::zeros(p.n());
    let report = ws
        .solve(&p.view(), &settings, &mut x)
        .expect("valid problem");
    assert_eq!(report.status, QpStatus::Optimal);
    if let Verdict::Solved { x: xo, .. } = clarabel_solve(p) {
        eprintln!(
            "{name}: n {} m_eq {} m_in {}: {} active, {} iterations, |x − x_clarabel|∞ = {:.1e}",
            p.n(),
            p.a_eq.nrows(),
            p.a_in.nrows(),
            report.active_count,
            report.iterations,
            (&x - &xo).amax()
        );
    }
    let problem = p.view();
    c.bench_function(&format!("{name}/dual_active_set"), |b| {
        b.iter(|| {
            let r = ws.solve(black_box(&problem), &settings, &mut x);
            black_box(r.map(|r| r.objective).unwrap_or(f64::NAN))
        })
    });
    c.bench_function(&format!("{name}/clarabel"), |b| {
        b.iter(|| {
            black_box(matches!(
                clarabel_solve(black_box(p)),
                Verdict::Solved { .. }
            ))
        })
    });
}

fn benches(c: &mut Criterion) {
    bench_shape(c, "iktc_correction_20x38", &iktc_shape(11, 5));
    bench_shape(c, "gf_level_38_eq18_box38", &gf_shape(12));
}

criterion_group!(qp, benches);
criterion_main!(qp);
