//! The solvers allocate nothing per tick (counting global allocator, own test binary).

mod common;
use common::rng;
use common::solver as solver_common;
use solver_common::*;

use iktc::solver::*;
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
