//! The dual active-set QP solver against an independent oracle (clarabel, an interior-point
//! solver) on seeded random problems of varied sizes and kinds.

mod qp_common;

use iktc::solver::{QpConstraint, QpSettings, QpStatus};
use nalgebra::DVector;
use qp_common::{clarabel_solve, kkt, random_problem, solve, Kind, OwnedQp, Verdict};

/// Agreement of `x` with the oracle, relative to `1 + ‖x‖∞`. Clarabel stops at a relative
/// duality gap of 1e-11; on an SPD objective the error in `x` is of the order of the square root
/// of the objective error scaled by 1/λ_min(H) (λ_min down to 1e-3 here), and interior points
/// on degenerate vertices converge slowly: 1e-5 leaves a margin over the 1e-7 typically seen.
const X_TOL: f64 = 1e-5;
/// Agreement of the objective with the oracle's (evaluated at its x), relative to `1 + |f|`:
/// first order in the oracle's remaining infeasibility (≤ 1e-11 relative), with margin.
const OBJ_TOL: f64 = 1e-7;
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
}

fn named_constraint_violated(p: &OwnedQp, x: &DVector<f64>, c: QpConstraint, tol: f64) -> bool {
    match c {
        QpConstraint::Equality { row } => {
            let v: f64 = p.a_eq.row(row).iter().zip(x.iter()).map(|(a, b)| a * b).sum();
            (v - p.b_eq[row]).abs() > tol
        }
        QpConstraint::Lower { row } => {
            let v: f64 = p.a_in.row(row).iter().zip(x.iter()).map(|(a, b)| a * b).sum();
            p.l[row] - v > tol
        }
        QpConstraint::Upper { row } => {
            let v: f64 = p.a_in.row(row).iter().zip(x.iter()).map(|(a, b)| a * b).sum();
            v - p.u[row] > tol
        }
    }
}

fn run(kind: Kind, count: u64, seed0: u64) -> Stats {
    let settings = QpSettings::default();
    let mut st = Stats::default();
    for seed in seed0..seed0 + count {
        let p = random_problem(seed, kind);
        let (report, x, y_eq, y_in) = solve(&p, &settings);
        st.max_iterations = st.max_iterations.max(report.iterations);
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
                let ymax = y_in.iter().chain(&y_eq).fold(0.0_f64, |a, v| a.max(v.abs()));
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
                assert!((report.objective - f).abs() <= 1e-9 * (1.0 + f.abs()), "{ctx}");
                st.max_stat = st.max_stat.max(k.stationarity);
            }
            QpStatus::Infeasible { constraint } => {
                assert!(
                    named_constraint_violated(&p, &x, constraint, settings.feasibility_tolerance),
                    "{ctx}: the named constraint holds at x"
                );
            }
            QpStatus::MaxIterations => panic!("{ctx}"),
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
    run(Kind::Degenerate, 250, 3_000);
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
