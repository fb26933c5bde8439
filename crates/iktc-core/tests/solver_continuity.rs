//! IKTC's correction QP with the continuity term (`SolverSettings::continuity`, the solver's
//! `continuity` module notes): `min ½‖Δh‖² + ½μ‖q̈ − q̈₋‖²` under the constraints of eq. (23).
//! Checked against the correction without it, on random problems: the same corrected level
//! (feasibility does not depend on the objective), the box and the levels above kept, a
//! q̈ nearer the last command and an objective no worse (both are feasible for the same
//! constraints, and each is the minimiser of its own objective).

mod common;
use common::rng;
use common::solver as solver_common;
use solver_common::*;

use iktc_core::solver::*;
use nalgebra::DVector;

/// The QP's feasibility tolerance, as the other solver tests use it \[rad/s²\].
const BOX_TOLERANCE: f64 = 1e-8;
/// Rounding allowed when comparing objectives and distances of two QP optima \[–\], relative.
const OPTIMUM_ROUNDING: f64 = 1e-7;

fn objective(
    rep: &SolveReport,
    from: usize,
    q: &DVector<f64>,
    prev: &DVector<f64>,
    mu: f64,
) -> f64 {
    let dh: f64 = rep.corrections[from..]
        .iter()
        .map(|c| c.norm_squared())
        .sum();
    0.5 * dh + 0.5 * mu * (q - prev).norm_squared()
}

#[test]
fn the_continuity_term_keeps_the_level_and_the_box_and_moves_q_toward_the_last_command() {
    let mut r = rng(77);
    let dims = [6, 4, 8];
    let n = 30;
    let mut nearer = 0;
    for case in 0..200 {
        let mu = [0.1, 1.0, 10.0][case % 3];
        let plain = SolverSettings::default();
        let smooth = SolverSettings {
            continuity: mu,
            ..SolverSettings::default()
        };
        let (mut s0, mut s1) = (
            Solver::new(n, &dims, plain).unwrap(),
            Solver::new(n, &dims, smooth).unwrap(),
        );
        // The previous command: the same for both, from an unconstrained solve.
        let first = random_levels(&mut r, n, &dims);
        let mut prev = DVector::zeros(n);
        s0.solve(Method::Prioritized, &first, &wide_box(n), &mut prev)
            .unwrap();
        let mut same = DVector::zeros(n);
        s1.solve(Method::Prioritized, &first, &wide_box(n), &mut same)
            .unwrap();
        assert_eq!(prev, same);
        // This tick: a box the prioritized solution leaves.
        let levels = random_levels(&mut r, n, &dims);
        let mut q0 = DVector::zeros(n);
        Solver::new(n, &dims, plain)
            .unwrap()
            .solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        let bx = box_violated_by(&mut r, &q0, 2.0, 1 + case % 4, 0.5);
        let (mut a, mut b) = (DVector::zeros(n), DVector::zeros(n));
        let ra = s0
            .solve(Method::Iktc, &levels, &bx, &mut a)
            .unwrap()
            .clone();
        let rb = s1
            .solve(Method::Iktc, &levels, &bx, &mut b)
            .unwrap()
            .clone();
        let from = ra.corrected_from.expect("a correction was needed");
        assert_eq!(rb.corrected_from, Some(from), "case {case}");
        assert!(
            bx.contains(b.as_slice(), BOX_TOLERANCE).unwrap(),
            "case {case}"
        );
        for i in 0..from {
            assert!(
                rb.task_error_norms[i] < BOX_TOLERANCE,
                "case {case}: level {i}"
            );
        }
        // Each corrected level carries its correction as its error (eq. 19, Σm < n).
        for i in from..dims.len() {
            let diff = (&rb.task_errors[i] - &rb.corrections[i]).norm();
            assert!(
                diff < 1e-7 * (1.0 + rb.corrections[i].norm()),
                "case {case} level {i}"
            );
        }
        // The minimiser of f + μg has g no larger than the minimiser of f has, and its own
        // objective no larger than that of the other feasible point.
        let (da, db) = ((&a - &prev).norm(), (&b - &prev).norm());
        assert!(
            db <= da * (1.0 + OPTIMUM_ROUNDING) + BOX_TOLERANCE,
            "case {case}: {db} > {da}"
        );
        let (fa, fb) = (
            objective(&ra, from, &a, &prev, mu),
            objective(&rb, from, &b, &prev, mu),
        );
        assert!(
            fb <= fa * (1.0 + OPTIMUM_ROUNDING) + BOX_TOLERANCE,
            "case {case}: {fb} > {fa}"
        );
        nearer += usize::from(db < da * (1.0 - 1e-3));
    }
    assert!(
        nearer > 100,
        "the term should change most answers ({nearer} of 200)"
    );
}

#[test]
fn a_negative_or_non_finite_continuity_weight_is_an_error_naming_it() {
    for mu in [-1.0, f64::NAN, f64::INFINITY] {
        let s = SolverSettings {
            continuity: mu,
            ..SolverSettings::default()
        };
        let e = Solver::new(4, &[2], s).unwrap_err().to_string();
        assert!(e.contains("continuity"), "{e}");
    }
}
