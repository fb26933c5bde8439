//! The humanoid control tick (kinematics, task references and linearisation, bounds, IKTC or
//! GF, integration) allocates nothing, checked with a counting global allocator (its own test
//! binary).

use iktc::model::{jvrc1, ModelOptions};
use iktc::motion::{builtin_clip, builtin_map};
use iktc::sim::{
    imitation_references, ImitateConfig, ImitationController, WalkImitateConfig, WalkingController,
};
use iktc::solver::Method;

#[path = "../../iktc-core/tests/common/mod.rs"]
mod common;
use common::alloc as counting_alloc;
use counting_alloc::allocations;

#[global_allocator]
static A: counting_alloc::Counting = counting_alloc::Counting;

/// JVRC-1 and the references of the default imitation run.
fn setup() -> (iktc::model::Robot, iktc::motion::RobotReferences) {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let clip = builtin_clip("humanoid3d_dance_b").unwrap();
    let map = builtin_map("deepmimic_jvrc1").unwrap();
    let refs = imitation_references(&robot, &clip, &map, &ImitateConfig::default()).unwrap();
    (robot, refs)
}

#[test]
fn the_humanoid_tick_allocates_nothing() {
    let (robot, refs) = setup();
    for method in [Method::Iktc, Method::Cascade] {
        let cfg = ImitateConfig {
            method,
            ..ImitateConfig::default()
        };
        let mut ctl = ImitationController::new(&robot, &refs, &cfg).unwrap();
        let mut qps = 0;
        let before = allocations();
        for k in 0..refs.len() {
            qps += ctl.tick(k).unwrap().qp_solves;
            ctl.integrate().unwrap();
        }
        let after = allocations();
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

#[test]
fn the_walking_tick_allocates_nothing() {
    let (robot, refs) = setup();
    let mut wc =
        WalkingController::new(&robot, &refs, &WalkImitateConfig::jvrc1().unwrap()).unwrap();
    let n = wc.ticks();
    let before = allocations();
    let mut single = 0;
    for k in 0..n {
        // A small measured ZMP deviation keeps the damping controller busy.
        let zmp = [
            1e-3 * (0.01 * k as f64).sin(),
            -1e-3 * (0.013 * k as f64).cos(),
        ];
        let t = wc.tick(k, zmp).unwrap();
        if t.phase == iktc::balance::SupportPhase::Single {
            single += 1;
        }
        wc.integrate().unwrap();
    }
    let after = allocations();
    assert!(
        single > 100,
        "the walk must include single support ({single} ticks)"
    );
    assert_eq!(
        after - before,
        0,
        "{} allocations in {n} walking ticks",
        after - before
    );
}

/// A clone of a controller is as preallocated as the original (a derived `Vec` clone keeps only
/// the length: the solver's active-set and screen buffers would then allocate, and the screen
/// would see a full row list and stop remembering), and it computes the same ticks.
#[test]
fn a_cloned_controller_allocates_nothing_and_matches_the_original() {
    let (robot, refs) = setup();
    let mut original = ImitationController::new(&robot, &refs, &ImitateConfig::default()).unwrap();
    let mut clone = original.clone();
    let (mut screened, mut qps) = (0, 0);
    let before = allocations();
    for k in 0..refs.len() {
        let a = original.tick(k).unwrap().clone_counts();
        let b = clone.tick(k).unwrap().clone_counts();
        assert_eq!(a, b, "tick {k}: the clone solved differently");
        assert_eq!(original.qdd(), clone.qdd(), "tick {k}");
        screened += b.1;
        qps += b.0;
        original.integrate().unwrap();
        clone.integrate().unwrap();
    }
    let after = allocations();
    assert!(qps > 100, "{qps} QPs");
    assert!(
        screened > 50,
        "the clone's screen must fire ({screened} levels)"
    );
    assert_eq!(after - before, 0, "{} allocations", after - before);
}

trait Counts {
    /// (QPs, screened levels, QP iterations, corrected level).
    fn clone_counts(&self) -> (usize, usize, usize, Option<usize>);
}

impl Counts for iktc::solver::SolveReport {
    fn clone_counts(&self) -> (usize, usize, usize, Option<usize>) {
        (
            self.qp_solves,
            self.screened_infeasible,
            self.qp_iterations,
            self.corrected_from,
        )
    }
}
