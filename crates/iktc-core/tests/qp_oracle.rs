//! The dual active-set QP solver against an independent oracle (clarabel, an interior-point
//! solver) on seeded random problems of varied sizes and kinds.

mod common;
use common::qp as qp_common;

use iktc_core::solver::{QpConstraint, QpSettings, QpStatus};
use nalgebra::DVector;
use qp_common::{
    clarabel_solve, kkt, random_problem_sized, scale_rows, solve, tight_rows, Kind, OwnedQp, Sizes,
    Verdict, LARGE, SMALL,
};

/// Agreement of `x` with the oracle, relative to `1 + ‖x‖∞`. Clarabel stops at a relative
/// duality gap and infeasibility of 1e-11; on an SPD objective the error in `x` is of the order
/// of the square root of the objective error over λ_min(H) (λ_min down to 1e-3 here), and
/// interior points converge slowly on degenerate vertices. The largest error seen on these
/// seeds is 7e-8; 1e-6 keeps a margin of ten and still catches a wrong active set.
const X_TOL: f64 = 1e-6;
/// Agreement of the objective with the oracle's (both evaluated by the test at the returned x),
/// relative to `1 + |f|`: first order in the oracle's remaining infeasibility (1e-11
/// relative); largest seen 7e-12.
const OBJ_TOL: f64 = 1e-9;
/// Stationarity residual of our solution, relative to the size of the terms that cancel
/// (see `Kkt::stationarity`): rounding over O(n) Givens updates of O(n) terms, n ≤ 60.
const STATIONARITY_TOL: f64 = 1e-9;
/// Primal violation accepted beyond `feasibility_tolerance`: rounding of `A x` on active rows.
const PRIMAL_SLACK: f64 = 1e-9;
/// Largest fraction of problems on which the oracle may end unclear (not solved, not infeasible).
const MAX_UNCLEAR_FRACTION: f64 = 0.02;

#[derive(Debug, Default)]
struct Stats {
    solved: usize,
    infeasible: usize,
    unclear: usize,
    max_dx: f64,
    max_dobj: f64,
    max_stat: f64,
    max_iterations: usize,
    /// Optima where more rows are tight than are active (degenerate vertices).
    degenerate_optima: usize,
    /// Solves that skipped a redundant equality.
    with_redundant_equalities: usize,
    /// Solves that dropped a constraint (iterations > active set size).
    with_drops: usize,
}

fn named_constraint_violated(p: &OwnedQp, x: &DVector<f64>, c: QpConstraint, tol: f64) -> bool {
    match c {
        QpConstraint::Equality { row } => {
            let v: f64 = p
                .a_eq
                .row(row)
                .iter()
                .zip(x.iter())
                .map(|(a, b)| a * b)
                .sum();
            (v - p.b_eq[row]).abs() > tol
        }
        QpConstraint::Lower { row } => {
            let v: f64 = p
                .a_in
                .row(row)
                .iter()
                .zip(x.iter())
                .map(|(a, b)| a * b)
                .sum();
            p.l[row] - v > tol
        }
        QpConstraint::Upper { row } => {
            let v: f64 = p
                .a_in
                .row(row)
                .iter()
                .zip(x.iter())
                .map(|(a, b)| a * b)
                .sum();
            v - p.u[row] > tol
        }
    }
}

fn run(kind: Kind, count: u64, seed0: u64) -> Stats {
    run_with(kind, count, seed0, SMALL, false)
}

fn run_with(kind: Kind, count: u64, seed0: u64, sizes: Sizes, scaled: bool) -> Stats {
    let settings = QpSettings::default();
    let mut st = Stats::default();
    for seed in seed0..seed0 + count {
        let mut p = random_problem_sized(seed, kind, sizes);
        if scaled {
            scale_rows(&mut p, seed);
        }
        let (report, x, y_eq, y_in) = solve(&p, &settings);
        st.max_iterations = st.max_iterations.max(report.iterations);
        if report.redundant_equalities > 0 {
            st.with_redundant_equalities += 1;
        }
        if report.iterations > report.active_count + report.redundant_equalities {
            st.with_drops += 1;
        }
        let oracle = clarabel_solve(&p);
        let ctx = format!(
            "{kind:?} seed {seed}: n {} m_eq {} m_in {}, report {report:?}, oracle {}",
            p.n(),
            p.a_eq.nrows(),
            p.a_in.nrows(),
            match &oracle {
                Verdict::Solved { objective, .. } => format!("solved f = {objective}"),
                Verdict::Infeasible => "infeasible".into(),
                Verdict::Unclear(s) => format!("unclear {s:?}"),
            }
        );
        // ground truth by construction
        match kind {
            Kind::Infeasible => assert!(
                matches!(report.status, QpStatus::Infeasible { .. }),
                "{ctx}"
            ),
            _ => assert_eq!(report.status, QpStatus::Optimal, "{ctx}"),
        }
        match report.status {
            QpStatus::Optimal => {
                let k = kkt(&p, &x, &y_eq, &y_in);
                let ymax = y_in
                    .iter()
                    .chain(&y_eq)
                    .fold(0.0_f64, |a, v| a.max(v.abs()));
                assert!(k.stationarity <= STATIONARITY_TOL, "{ctx}: {k:?}");
                assert!(
                    k.primal <= settings.feasibility_tolerance + PRIMAL_SLACK,
                    "{ctx}: {k:?}"
                );
                assert!(k.dual_sign == 0.0, "{ctx}: {k:?}");
                assert!(
                    k.complementarity <= PRIMAL_SLACK * (1.0 + ymax),
                    "{ctx}: {k:?}"
                );
                assert!((report.max_violation - k.primal).abs() <= 1e-12 * (1.0 + k.primal));
                let f = p.objective(&x);
                assert!(
                    (report.objective - f).abs() <= 1e-9 * (1.0 + f.abs()),
                    "{ctx}"
                );
                st.max_stat = st.max_stat.max(k.stationarity);
                if tight_rows(&p, &x, 1e-9) > report.active_count + report.redundant_equalities {
                    st.degenerate_optima += 1;
                }
            }
            QpStatus::Infeasible { constraint } => {
                assert!(
                    named_constraint_violated(&p, &x, constraint, settings.feasibility_tolerance),
                    "{ctx}: the named constraint holds at x"
                );
            }
            QpStatus::MaxIterations | QpStatus::Inaccurate { .. } => panic!("{ctx}"),
        }
        match oracle {
            Verdict::Solved { x: xo, objective } => {
                st.solved += 1;
                assert_eq!(report.status, QpStatus::Optimal, "{ctx}");
                let dx = (&x - &xo).amax() / (1.0 + x.amax());
                let f = p.objective(&x);
                let dobj = (f - objective).abs() / (1.0 + f.abs());
                assert!(dx <= X_TOL, "{ctx}: |dx| = {dx:e}");
                assert!(dobj <= OBJ_TOL, "{ctx}: |df| = {dobj:e}");
                st.max_dx = st.max_dx.max(dx);
                st.max_dobj = st.max_dobj.max(dobj);
            }
            Verdict::Infeasible => {
                st.infeasible += 1;
                assert!(
                    matches!(report.status, QpStatus::Infeasible { .. }),
                    "{ctx}"
                );
            }
            Verdict::Unclear(_) => st.unclear += 1,
        }
    }
    eprintln!("{kind:?}: {st:?}");
    assert!(
        (st.unclear as f64) <= MAX_UNCLEAR_FRACTION * count as f64,
        "{kind:?}: oracle unclear on {} of {count}",
        st.unclear
    );
    st
}

#[test]
fn generic_dense_hessian_matches_clarabel() {
    run(Kind::Generic, 300, 1_000);
}

#[test]
fn identity_hessian_matches_clarabel() {
    run(Kind::Identity, 250, 2_000);
}

#[test]
fn degenerate_problems_match_clarabel() {
    let st = run(Kind::Degenerate, 250, 3_000);
    // the kind does what it says
    assert!(st.degenerate_optima >= 25, "{st:?}");
    assert!(st.with_redundant_equalities >= 25, "{st:?}");
    assert!(st.with_drops >= 25, "{st:?}");
}

#[test]
fn large_problems_match_clarabel() {
    run_with(Kind::Generic, 40, 6_000, LARGE, false);
    run_with(Kind::Degenerate, 40, 6_100, LARGE, false);
    run_with(Kind::Identity, 40, 6_200, LARGE, false);
    run_with(Kind::Infeasible, 30, 6_300, LARGE, false);
}

#[test]
fn badly_scaled_rows_match_clarabel() {
    run_with(Kind::Generic, 60, 7_000, SMALL, true);
    run_with(Kind::Degenerate, 60, 7_100, SMALL, true);
    run_with(Kind::Infeasible, 40, 7_200, SMALL, true);
}

#[test]
fn nearly_infeasible_problems_match_clarabel() {
    run(Kind::NearlyInfeasible, 150, 4_000);
}

#[test]
fn infeasible_problems_match_clarabel() {
    let st = run(Kind::Infeasible, 200, 5_000);
    assert!(st.infeasible > 0);
}
