//! `QpWorkspace::solve` allocates nothing once the workspace exists.
//!
//! A counting global allocator (`counting_alloc`) wraps the system one; it is per test binary,
//! hence this file.

use common::qp as qp_common;

use iktc_core::solver::{QpSettings, QpStatus, QpWorkspace};
use nalgebra::DVector;
use qp_common::{random_problem_sized, Kind, LARGE};

mod common;
use common::alloc as counting_alloc;
use counting_alloc::allocations;

#[global_allocator]
static GLOBAL: counting_alloc::Counting = counting_alloc::Counting;

#[test]
fn solve_does_not_allocate() {
    let settings = QpSettings::default();
    let mut ws = QpWorkspace::new(60, 120, 120);
    let kinds = [
        Kind::Generic,
        Kind::Identity,
        Kind::Degenerate,
        Kind::NearlyInfeasible,
        Kind::Infeasible,
    ];
    let mut statuses = [0usize; 3];
    for seed in 0..100u64 {
        let p = random_problem_sized(seed, kinds[(seed % 5) as usize], LARGE);
        let problem = p.view();
        let mut x = DVector::zeros(p.n());
        let before = allocations();
        let report = ws.solve(&problem, &settings, &mut x);
        let after = allocations();
        let report = report.expect("valid problem");
        assert_eq!(after, before, "seed {seed}: solve allocated");
        // the accessors do not allocate either
        let before = allocations();
        let n = ws.active_set().len() + ws.multipliers_eq().len() + ws.multipliers_in().len();
        assert_eq!(allocations(), before);
        assert!(n >= report.active_count);
        statuses[match report.status {
            QpStatus::Optimal => 0,
            QpStatus::Infeasible { .. } => 1,
            QpStatus::MaxIterations => 2,
            QpStatus::Inaccurate { .. } => 3,
        }] += 1;
    }
    // both outcomes were exercised
    assert!(statuses[0] > 0 && statuses[1] > 0, "{statuses:?}");
}

#[test]
fn the_counter_sees_allocations() {
    let before = allocations();
    let v: Vec<u64> = std::hint::black_box(Vec::with_capacity(16));
    assert!(allocations() > before);
    drop(v);
}
