//! The per-tick queries of a walking pattern and the preview stepper allocate nothing,
//! checked with a counting global allocator (its own test binary) that counts only on the
//! test's own thread, so that the harness's threads cannot disturb the count.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use iktc::walk::{
    FootstepPlan, PreviewAxis, PreviewSettings, Side, SupportPolygon, WalkSettings, WalkingPattern,
};

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static ACTIVE: Cell<bool> = const { Cell::new(false) };
}

fn count() {
    if ACTIVE.try_with(Cell::get).unwrap_or(false) {
        ALLOCS.fetch_add(1, Ordering::SeqCst);
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(p, l, n) }
    }
}

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
    let before = ALLOCS.load(Ordering::SeqCst);
    ACTIVE.with(|a| a.set(true));
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
    ACTIVE.with(|a| a.set(false));
    let after = ALLOCS.load(Ordering::SeqCst);
    assert!(acc.is_finite());
    assert_eq!(after - before, 0, "the per-tick queries allocated");
}
