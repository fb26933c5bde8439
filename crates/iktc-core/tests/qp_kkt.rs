//! The QP solver on problems with known answers (closed forms, hand computations) and KKT
//! conditions checked directly on many seeded random solutions, without an oracle.

mod common;
use common::qp as qp_common;
use common::rng;

use iktc_core::solver::{Hessian, QpConstraint, QpProblem, QpSettings, QpStatus, QpWorkspace};
use nalgebra::{DMatrix, DVector};
use qp_common::{kkt, random_problem_sized, random_spd, solve, Kind, LARGE, SMALL};
use rand::Rng;

/// Agreement with closed forms computed by nalgebra's LU/Cholesky: rounding of two different
/// O(n³) factorisations of matrices with condition numbers up to ~1e3, n ≤ 20.
const CLOSED_FORM_TOL: f64 = 1e-10;
/// KKT residuals relative to their natural scale (see `qp_common::Kkt`): rounding of O(n)
/// Givens updates, n ≤ 60.
const STATIONARITY_TOL: f64 = 1e-9;
/// Primal violation beyond `feasibility_tolerance` and complementarity gap per unit multiplier:
/// rounding of `A x` on active rows.
const PRIMAL_SLACK: f64 = 1e-9;

fn empty(n: usize) -> DMatrix<f64> {
    DMatrix::zeros(0, n)
}

#[test]
fn unconstrained_minimum_is_minus_h_inverse_c() {
    let mut r = rng(1);
    for n in 1..=20 {
        let h = random_spd(&mut r, n);
        let c: Vec<f64> = (0..n).map(|_| r.random_range(-3.0..3.0)).collect();
        let e = empty(n);
        let p = QpProblem {
            hessian: Hessian::Dense(h.as_view()),
            c: &c,
            a_eq: e.as_view(),
            b_eq: &[],
            a_in: e.as_view(),
            lower: &[],
            upper: &[],
        };
        let mut ws = QpWorkspace::new(n, 0, 0);
        let mut x = DVector::zeros(n);
        let rep = ws.solve(&p, &QpSettings::default(), &mut x).unwrap();
        let expected = -h
            .clone()
            .lu()
            .solve(&DVector::from_column_slice(&c))
            .unwrap();
        assert_eq!(rep.status, QpStatus::Optimal);
        assert_eq!(rep.iterations, 0);
        assert!((&x - &expected).amax() <= CLOSED_FORM_TOL * (1.0 + expected.amax()));
        let f = 0.5 * x.dot(&(&h * &x)) + DVector::from_column_slice(&c).dot(&x);
        assert!((rep.objective - f).abs() <= CLOSED_FORM_TOL * (1.0 + f.abs()));
    }
}

/// `min ½‖x‖² + cᵀx  s.t.  l ≤ x ≤ u` is solved by `x = clamp(−c, l, u)`, with multiplier
/// `y = x + c` on each clamped coordinate.
#[test]
fn identity_with_box_is_a_clamp() {
    let mut r = rng(2);
    for n in 1..=30 {
        let c: Vec<f64> = (0..n).map(|_| r.random_range(-3.0..3.0)).collect();
        let l: Vec<f64> = (0..n).map(|_| r.random_range(-2.0..0.0)).collect();
        let u: Vec<f64> = (0..n).map(|_| r.random_range(0.0..2.0)).collect();
        let a = DMatrix::<f64>::identity(n, n);
        let e = empty(n);
        let p = QpProblem {
            hessian: Hessian::Identity,
            c: &c,
            a_eq: e.as_view(),
            b_eq: &[],
            a_in: a.as_view(),
            lower: &l,
            upper: &u,
        };
        let mut ws = QpWorkspace::new(n, 0, n);
        let mut x = DVector::zeros(n);
        let rep = ws.solve(&p, &QpSettings::default(), &mut x).unwrap();
        assert_eq!(rep.status, QpStatus::Optimal);
        let mut clamped = 0;
        for i in 0..n {
            let expected = (-c[i]).clamp(l[i], u[i]);
            assert!((x[i] - expected).abs() <= 1e-14, "coordinate {i}");
            let y = ws.multipliers_in()[i];
            assert!((y - (expected + c[i])).abs() <= 1e-14);
            if expected != -c[i] {
                clamped += 1;
            }
        }
        // each clamped coordinate is added once and never dropped
        assert_eq!(rep.active_count, clamped);
        assert_eq!(rep.iterations, clamped);
    }
}

/// Equality-constrained minimum from the KKT system
/// `[H Aᵀ; A 0] [x; −y] = [−c; b]`, solved by LU.
#[test]
fn equalities_match_the_kkt_system() {
    let mut r = rng(3);
    for n in 2..=20 {
        let m = r.random_range(1..=n);
        let h = random_spd(&mut r, n);
        let a = DMatrix::from_fn(m, n, |_, _| r.random_range(-1.0..1.0));
        let b: Vec<f64> = (0..m).map(|_| r.random_range(-1.0..1.0)).collect();
        let c: Vec<f64> = (0..n).map(|_| r.random_range(-3.0..3.0)).collect();
        let mut k = DMatrix::zeros(n + m, n + m);
        k.view_mut((0, 0), (n, n)).copy_from(&h);
        k.view_mut((0, n), (n, m)).copy_from(&a.transpose());
        k.view_mut((n, 0), (m, n)).copy_from(&a);
        let mut rhs = DVector::zeros(n + m);
        for i in 0..n {
            rhs[i] = -c[i];
        }
        for i in 0..m {
            rhs[n + i] = b[i];
        }
        let sol = k.lu().solve(&rhs).unwrap();
        let e = empty(n);
        let p = QpProblem {
            hessian: Hessian::Dense(h.as_view()),
            c: &c,
            a_eq: a.as_view(),
            b_eq: &b,
            a_in: e.as_view(),
            lower: &[],
            upper: &[],
        };
        let mut ws = QpWorkspace::new(n, m, 0);
        let mut x = DVector::zeros(n);
        let rep = ws.solve(&p, &QpSettings::default(), &mut x).unwrap();
        assert_eq!(rep.status, QpStatus::Optimal);
        let scale = 1.0 + sol.amax();
        for i in 0..n {
            assert!((x[i] - sol[i]).abs() <= CLOSED_FORM_TOL * scale);
        }
        for i in 0..m {
            // H x + c = Aᵀ y  ⇔  H x + Aᵀ(−y) = −c
            assert!((ws.multipliers_eq()[i] + sol[n + i]).abs() <= CLOSED_FORM_TOL * scale);
        }
    }
}

/// `x ≥ 1` and `x ≤ 0` on one variable, as two rows: the second row to be added is reported.
#[test]
fn contradictory_rows_are_infeasible_and_named() {
    let a = DMatrix::from_row_slice(2, 1, &[1.0, 1.0]);
    let e = empty(1);
    let p = QpProblem {
        hessian: Hessian::Identity,
        c: &[0.0],
        a_eq: e.as_view(),
        b_eq: &[],
        a_in: a.as_view(),
        lower: &[1.0, f64::NEG_INFINITY],
        upper: &[f64::INFINITY, -0.5],
    };
    let mut ws = QpWorkspace::new(1, 0, 2);
    let mut x = DVector::zeros(1);
    let rep = ws.solve(&p, &QpSettings::default(), &mut x).unwrap();
    // x₀ = 0: row 0 (violated by 1) enters first at x = 1; then row 1 (x ≤ −0.5) is violated,
    // depends on row 0, and releasing row 0 would need a negative dual step.
    assert_eq!(
        rep.status,
        QpStatus::Infeasible {
            constraint: QpConstraint::Upper { row: 1 }
        }
    );
    assert!((x[0] - 1.0).abs() < 1e-15);
}

/// Dependent equalities with inconsistent right-hand sides are infeasible; with consistent ones
/// the copy is skipped as redundant.
#[test]
fn dependent_equalities_are_redundant_or_infeasible() {
    let a = DMatrix::from_row_slice(3, 2, &[1.0, 1.0, 1.0, -1.0, 2.0, 2.0]);
    let e = empty(2);
    let settings = QpSettings::default();
    for (b2, feasible) in [(2.0, true), (2.1, false)] {
        let b = [1.0, 0.0, b2];
        let p = QpProblem {
            hessian: Hessian::Identity,
            c: &[0.0, 0.0],
            a_eq: a.as_view(),
            b_eq: &b,
            a_in: e.as_view(),
            lower: &[],
            upper: &[],
        };
        let mut ws = QpWorkspace::new(2, 3, 0);
        let mut x = DVector::zeros(2);
        let rep = ws.solve(&p, &settings, &mut x).unwrap();
        if feasible {
            assert_eq!(rep.status, QpStatus::Optimal);
            assert_eq!(rep.redundant_equalities, 1);
            assert!((x[0] - 0.5).abs() < 1e-15 && (x[1] - 0.5).abs() < 1e-15);
        } else {
            assert_eq!(
                rep.status,
                QpStatus::Infeasible {
                    constraint: QpConstraint::Equality { row: 2 }
                }
            );
        }
    }
}

/// A row with `l = u` acts as an equality; its side in the active set follows the multiplier.
#[test]
fn fixed_row_is_an_equality() {
    let a = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
    let e = empty(2);
    for (c, side_lower) in [([1.0, 1.0], true), ([-1.0, -1.0], false)] {
        let p = QpProblem {
            hessian: Hessian::Identity,
            c: &c,
            a_eq: e.as_view(),
            b_eq: &[],
            a_in: a.as_view(),
            lower: &[0.5],
            upper: &[0.5],
        };
        let mut ws = QpWorkspace::new(2, 0, 1);
        let mut x = DVector::zeros(2);
        let rep = ws.solve(&p, &QpSettings::default(), &mut x).unwrap();
        assert_eq!(rep.status, QpStatus::Optimal);
        assert!((x[0] - 0.25).abs() < 1e-15 && (x[1] - 0.25).abs() < 1e-15);
        // H x + c = a y: 0.25 + c₀ = y
        let y = 0.25 + c[0];
        assert!((ws.multipliers_in()[0] - y).abs() < 1e-15);
        let active = ws.active_set();
        assert_eq!(active.len(), 1);
        let expected = if side_lower {
            QpConstraint::Lower { row: 0 }
        } else {
            QpConstraint::Upper { row: 0 }
        };
        assert_eq!(active[0].constraint, expected);
    }
}

/// `Hessian::Identity` and `Hessian::Dense(I)` give the same answer.
#[test]
fn identity_path_equals_dense_identity() {
    let settings = QpSettings::default();
    for seed in 0..200 {
        let p = random_problem_sized(seed, Kind::Identity, SMALL);
        let mut dense = p.clone();
        dense.h = Some(DMatrix::identity(p.n(), p.n()));
        let (r1, x1, _, y1) = solve(&p, &settings);
        let (r2, x2, _, y2) = solve(&dense, &settings);
        assert_eq!(r1.status, r2.status, "seed {seed}");
        assert_eq!(r1.iterations, r2.iterations, "seed {seed}");
        assert!(
            (&x1 - &x2).amax() <= 1e-12 * (1.0 + x1.amax()),
            "seed {seed}"
        );
        for (a, b) in y1.iter().zip(&y2) {
            assert!((a - b).abs() <= 1e-10 * (1.0 + a.abs()), "seed {seed}");
        }
    }
}

/// KKT conditions on many random problems of every kind and size, checked directly.
#[test]
fn kkt_conditions_hold_on_random_solutions() {
    let settings = QpSettings::default();
    let kinds = [
        Kind::Generic,
        Kind::Identity,
        Kind::Degenerate,
        Kind::NearlyInfeasible,
    ];
    let mut checked = 0;
    for seed in 0..1200u64 {
        let kind = kinds[(seed % 4) as usize];
        let sizes = if seed % 3 == 0 { LARGE } else { SMALL };
        let p = random_problem_sized(10_000 + seed, kind, sizes);
        let (rep, x, y_eq, y_in) = solve(&p, &settings);
        assert_eq!(rep.status, QpStatus::Optimal, "seed {seed}");
        let k = kkt(&p, &x, &y_eq, &y_in);
        let ymax = y_in
            .iter()
            .chain(&y_eq)
            .fold(0.0_f64, |a, v| a.max(v.abs()));
        assert!(k.stationarity <= STATIONARITY_TOL, "seed {seed}: {k:?}");
        assert!(
            k.primal <= settings.feasibility_tolerance + PRIMAL_SLACK,
            "seed {seed}: {k:?}"
        );
        assert_eq!(k.dual_sign, 0.0, "seed {seed}: {k:?}");
        assert!(
            k.complementarity <= PRIMAL_SLACK * (1.0 + ymax),
            "seed {seed}: {k:?}"
        );
        checked += 1;
    }
    assert_eq!(checked, 1200);
}

/// A reused workspace gives the same answers as fresh ones, whatever was solved before.
#[test]
fn reused_workspace_matches_fresh_ones() {
    let settings = QpSettings::default();
    let mut ws = QpWorkspace::new(60, 120, 120);
    for seed in 0..150u64 {
        let kind = [Kind::Generic, Kind::Degenerate, Kind::Infeasible][(seed % 3) as usize];
        let sizes = if seed % 2 == 0 { LARGE } else { SMALL };
        let p = random_problem_sized(20_000 + seed, kind, sizes);
        let mut x = DVector::zeros(p.n());
        let rep = ws.solve(&p.view(), &settings, &mut x).unwrap();
        let (fresh, xf, yeq, yin) = solve(&p, &settings);
        assert_eq!(rep, fresh, "seed {seed}");
        assert_eq!(x, xf, "seed {seed}");
        assert_eq!(ws.multipliers_eq(), &yeq[..]);
        assert_eq!(ws.multipliers_in(), &yin[..]);
    }
}

/// With too few iterations allowed the status says so.
#[test]
fn iteration_limit_is_a_status() {
    let p = random_problem_sized(3, Kind::Generic, LARGE);
    let (full, ..) = solve(&p, &QpSettings::default());
    assert!(full.iterations > 2);
    let settings = QpSettings {
        max_iterations: full.iterations - 1,
        ..QpSettings::default()
    };
    let (rep, ..) = solve(&p, &settings);
    assert_eq!(rep.status, QpStatus::MaxIterations);
    assert_eq!(rep.iterations, full.iterations - 1);
}

/// Scaling the objective by s > 0 leaves x unchanged and scales the multipliers by s.
#[test]
fn objective_scaling_scales_multipliers() {
    let settings = QpSettings::default();
    for seed in 0..100u64 {
        let p = random_problem_sized(30_000 + seed, Kind::Generic, SMALL);
        let s = 7.5;
        let mut q = p.clone();
        q.h = q.h.map(|h| h * s);
        q.c.iter_mut().for_each(|v| *v *= s);
        let (r1, x1, _, y1) = solve(&p, &settings);
        let (r2, x2, _, y2) = solve(&q, &settings);
        assert_eq!(r1.status, QpStatus::Optimal);
        assert_eq!(r2.status, QpStatus::Optimal);
        assert!(
            (&x1 - &x2).amax() <= 1e-10 * (1.0 + x1.amax()),
            "seed {seed}"
        );
        for (a, b) in y1.iter().zip(&y2) {
            assert!((s * a - b).abs() <= 1e-8 * (1.0 + b.abs()), "seed {seed}");
        }
    }
}
