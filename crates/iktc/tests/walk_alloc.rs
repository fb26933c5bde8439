//! The per-tick queries of a walking pattern and the preview stepper allocate nothing,
//! checked with the shared counting global allocator (its own test binary), which counts only
//! the test's own thread, so that the harness's threads cannot disturb the count.

use iktc::walk::{
    FootstepPlan, PreviewAxis, PreviewSettings, Side, SupportPolygon, WalkSettings, WalkingPattern,
};

#[path = "../../iktc-core/tests/common/mod.rs"]
mod common;
use common::alloc::{allocations, Counting};

#[global_allocator]
static A: Counting = Counting;

#[test]
fn pattern_queries_and_preview_step_allocate_nothing() {
    let w = WalkSettings::default();
    let plan = FootstepPlan::turn(4, 0.2, &w).unwrap();
    let p = WalkingPattern::new(&plan, &w, &PreviewSettings::default()).unwrap();
    let ctrl = p.controller().clone();
    let reference = vec![0.1; 400];
    let mut axis = PreviewAxis::at_rest(0.0);
    let mut poly = SupportPolygon::default();
    let mut acc = 0.0;
    let before = allocations();
    let n = (p.duration() / p.dt()) as usize;
    for k in 0..=n {
        let t = k as f64 * p.dt();
        let s = p.sample(t).unwrap();
        p.support_polygon_into(t, &mut poly).unwrap();
        let f = p.foot(Side::Left, t).unwrap();
        let c = p.com(t).unwrap();
        let z = p.zmp_reference(t).unwrap();
        acc += s.com.position.x + poly.margin(z) + f.position.z + c.velocity.y;
        acc += axis.step(&ctrl, 0.1, &reference);
    }
    let after = allocations();
    assert!(acc.is_finite());
    assert_eq!(after - before, 0, "the per-tick queries allocated");
}
