//! The humanoid control tick (kinematics, task references and linearisation, bounds, IKTC or
//! GF, integration) allocates nothing, checked with a counting global allocator (its own test
//! binary).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use iktc::model::{jvrc1, ModelOptions};
use iktc::motion::{builtin_clip, builtin_map, retarget};
use iktc::sim::{ImitateConfig, ImitationController};
use iktc::solver::Method;

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::SeqCst);
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

#[test]
fn the_humanoid_tick_allocates_nothing() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    let refs = retarget(&clip, &robot, &map)
        .unwrap()
        .resample(0.005)
        .unwrap();
    for method in [Method::Iktc, Method::Cascade] {
        let cfg = ImitateConfig {
            method,
            ..ImitateConfig::default()
        };
        let mut ctl = ImitationController::new(&robot, &refs, &cfg).unwrap();
        let mut qps = 0;
        let before = ALLOCS.load(Ordering::SeqCst);
        for k in 0..refs.len() {
            qps += ctl.tick(&robot, k).unwrap().qp_solves;
            ctl.integrate(&robot).unwrap();
        }
        let after = ALLOCS.load(Ordering::SeqCst);
        // The run must have exercised the QPs, not only the unconstrained solution.
        assert!(qps > 100, "{} QPs", qps);
        assert_eq!(
            after - before,
            0,
            "{} allocations in {} ticks of {:?}",
            after - before,
            refs.len(),
            method
        );
    }
}
