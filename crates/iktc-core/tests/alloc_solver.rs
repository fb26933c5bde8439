//! The solvers allocate nothing per tick (counting global allocator, own test binary).

mod common;
use common::rng;
use common::solver as solver_common;
use solver_common::*;

use iktc_core::solver::*;
use nalgebra::DVector;

use common::alloc as counting_alloc;
use counting_alloc::allocations as count;

#[global_allocator]
static A: counting_alloc::Counting = counting_alloc::Counting;

#[test]
fn solvers_allocate_nothing() {
    let dims = [12, 2, 3, 1, 20];
    let mut r = rng(41);
    let levels = random_levels(&mut r, 38, &dims);
    let mut s = Solver::new(38, &dims, SolverSettings::default()).unwrap();
    let mut q0 = DVector::zeros(38);
    s.solve(Method::Prioritized, &levels, &wide_box(38), &mut q0)
        .unwrap();
    let bx = box_violated_by(&mut r, &q0, 5.0, 3, 0.5);
    let mut q = DVector::zeros(38);
    for m in [
        Method::Iktc,
        Method::Cascade,
        Method::Clamp,
        Method::Prioritized,
    ] {
        s.solve(m, &levels, &bx, &mut q).unwrap();
        let before = count();
        let rep = s.solve(m, &levels, &bx, &mut q).unwrap();
        let qps = rep.qp_solves;
        let after = count();
        assert_eq!(
            after - before,
            0,
            "{m:?} allocated {} times",
            after - before
        );
        if m == Method::Iktc {
            assert!(qps >= 1, "the box must force a correction");
        }
    }
}

/// IKTC with the continuity term, and a box with jerk limits, allocate nothing either.
#[test]
fn continuity_and_jerk_limits_allocate_nothing() {
    use iktc_core::limits::{limit_jerk, AccelerationBox, DofLimits, JointLimits};
    let dims = [12, 2, 3, 1, 20];
    let mut r = rng(42);
    let levels = random_levels(&mut r, 38, &dims);
    let settings = SolverSettings {
        continuity: 1.0,
        ..SolverSettings::default()
    };
    let mut s = Solver::new(38, &dims, settings).unwrap();
    let mut q0 = DVector::zeros(38);
    s.solve(Method::Prioritized, &levels, &wide_box(38), &mut q0)
        .unwrap();
    let bx = box_violated_by(&mut r, &q0, 5.0, 3, 0.5);
    let mut q = DVector::zeros(38);
    s.solve(Method::Iktc, &levels, &bx, &mut q).unwrap();
    let before = count();
    let rep = s.solve(Method::Iktc, &levels, &bx, &mut q).unwrap();
    let qps = rep.qp_solves;
    assert_eq!(count() - before, 0);
    assert!(qps >= 1, "the box must force a correction");
    let limits = JointLimits::new(vec![
        DofLimits {
            jerk_max: 100.0,
            ..DofLimits::unlimited()
        };
        38
    ])
    .unwrap();
    let mut jerked = AccelerationBox::new(38);
    let prev = vec![0.5; 38];
    let before = count();
    limit_jerk(&limits, &prev, 0.005, &mut jerked).unwrap();
    assert_eq!(count() - before, 0);
}
