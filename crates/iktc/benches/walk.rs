//! Walking-pattern generation: controller design (Riccati + preview gains), precomputing a
//! 6-step pattern, one per-tick query, one online preview-servo tick.

use criterion::{criterion_group, criterion_main, Criterion};
use iktc::walk::{
    FootstepPlan, PreviewAxis, PreviewController, PreviewSettings, SupportPolygon, WalkSettings,
    WalkingPattern,
};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let walk = WalkSettings::default();
    let preview = PreviewSettings::default();
    let plan = FootstepPlan::forward(6, 0.2, &walk).expect("plan");
    c.bench_function("walk_design_preview_controller", |b| {
        b.iter(|| black_box(PreviewController::new(black_box(&preview)).expect("design")))
    });
    let ctrl = PreviewController::new(&preview).expect("design");
    c.bench_function("walk_pattern_forward_6_steps", |b| {
        b.iter(|| {
            black_box(
                WalkingPattern::with_controller(black_box(&plan), &walk, ctrl.clone())
                    .expect("pattern"),
            )
        })
    });
    let pattern = WalkingPattern::with_controller(&plan, &walk, ctrl.clone()).expect("pattern");
    let mut t = 0.0;
    let mut poly = SupportPolygon::default();
    c.bench_function("walk_sample_and_polygon", |b| {
        b.iter(|| {
            t = (t + 0.0137) % pattern.duration();
            let s = pattern.sample(black_box(t)).expect("sample");
            pattern.support_polygon_into(t, &mut poly).expect("polygon");
            black_box((s, poly.vertices().len()))
        })
    });
    let reference = vec![0.1; 400];
    let mut axis = PreviewAxis::at_rest(0.0);
    c.bench_function("walk_preview_axis_step", |b| {
        b.iter(|| black_box(axis.step(&ctrl, black_box(0.1), black_box(&reference))))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
