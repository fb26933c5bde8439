//! One controller tick (observer update plus feedback) of the damping controller: one plane,
//! and the two-plane controller with both cases.

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::balance::{
    design_discrete, BalanceController, BalanceSettings, CaseParams, DampingController,
    DiscreteSettings, PoleSpec, SupportPhase,
};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let cases = CaseParams::synthetic().expect("synthetic cases");
    let design = design_discrete(
        &cases.yz_dsp,
        &PoleSpec::default(),
        &DiscreteSettings::default(),
    )
    .expect("design");
    let mut one = DampingController::new(design);
    let mut k = 0u32;
    c.bench_function("balance_step_one_plane", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            let y = 1e-3 * f64::from(k % 7);
            black_box(one.step(black_box(0.0), black_box(y)))
        })
    });
    let mut both =
        BalanceController::new(&cases, &BalanceSettings::default(), SupportPhase::Double)
            .expect("controller");
    c.bench_function("balance_step_two_planes", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            let y = 1e-3 * f64::from(k % 7);
            black_box(both.step(SupportPhase::Double, [0.0, 0.0], black_box([y, -y])))
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
