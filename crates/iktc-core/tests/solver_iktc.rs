//! IKTC, the cascade (GF) and clamping on random problems.

mod common;
use common::rng;
use common::solver as solver_common;
use solver_common::*;

use iktc_core::solver::*;
use nalgebra::DVector;

const TABLE1: [usize; 5] = [12, 2, 3, 1, 20];

#[test]
fn iktc_equals_the_prioritized_solution_when_the_box_is_inactive() {
    let mut r = rng(31);
    for _ in 0..50 {
        let levels = random_levels(&mut r, 38, &TABLE1);
        let mut s = Solver::new(38, &TABLE1, SolverSettings::default()).unwrap();
        let (mut a, mut b) = (DVector::zeros(38), DVector::zeros(38));
        s.solve(Method::Prioritized, &levels, &wide_box(38), &mut a)
            .unwrap();
        let rep = s
            .solve(Method::Iktc, &levels, &wide_box(38), &mut b)
            .unwrap();
        assert_eq!(rep.qp_solves, 0);
        assert_eq!(rep.corrected_from, None);
        assert_eq!(a, b);
    }
}

#[test]
fn iktc_brings_the_solution_into_the_box_with_the_least_correction_from_the_bottom() {
    let mut r = rng(32);
    let dims = [6, 4, 8];
    let n = 30;
    let mut bottom_only = 0;
    for case in 0..200 {
        let levels = random_levels(&mut r, n, &dims);
        let mut s = Solver::new(n, &dims, SolverSettings::default()).unwrap();
        let mut q0 = DVector::zeros(n);
        s.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        let bx = box_violated_by(&mut r, &q0, 2.0, 1 + case % 4, 0.5);
        let mut q = DVector::zeros(n);
        let rep = s.solve(Method::Iktc, &levels, &bx, &mut q).unwrap().clone();
        assert!(rep.violation_before > 0.4);
        // Inside the box (QP feasibility tolerance).
        assert!(
            rep.violation <= 1e-8,
            "case {case}: violation {}",
            rep.violation
        );
        assert!(bx.contains(q.as_slice(), 1e-8).unwrap());
        let from = rep.corrected_from.expect("a correction was needed");
        // Levels above the corrected ones are untouched: their errors equal those of the
        // prioritized solution (zero here: Σm < n).
        for i in 0..from {
            assert!(
                rep.task_error_norms[i] < 1e-8,
                "case {case}: level {i} error {}",
                rep.task_error_norms[i]
            );
        }
        // A correction of levels from..n_T reproduces q̈: q̈ − q̈0 = Σ g_i Δh_i, and each
        // corrected level carries exactly its correction as its error (eq. 19, Σm < n).
        for i in from..dims.len() {
            let diff = (&rep.task_errors[i] - &rep.corrections[i]).norm();
            assert!(
                diff < 1e-7 * (1.0 + rep.corrections[i].norm()),
                "case {case} level {i}: {diff}"
            );
        }
        if from == dims.len() - 1 {
            bottom_only += 1;
            assert_eq!(rep.qp_solves, 1);
        }
    }
    assert!(
        bottom_only > 20,
        "the test should exercise bottom-only corrections ({bottom_only})"
    );
}

/// Levels reached with no coordinate left (the levels above use all n) have rank 0: they move
/// nothing, and IKTC's correction of them is zero. The solver then leaves them out of the
/// correction QP and of G's product; the answer must equal that of the same problem without
/// those levels, with their corrections zero and their task errors what the others leave.
#[test]
fn levels_with_no_coordinate_left_change_nothing() {
    let mut r = rng(41);
    let n = 12;
    let dims = [6, 4, 3, 5];
    let live = [6, 4, 3];
    let mut corrected = [0usize; 3];
    for case in 0..300 {
        let levels = random_levels(&mut r, n, &dims);
        let mut s = Solver::new(n, &dims, SolverSettings::default()).unwrap();
        let mut s_live = Solver::new(n, &live, SolverSettings::default()).unwrap();
        let mut q0 = DVector::zeros(n);
        s.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        assert_eq!(
            s.report().ranks[3],
            0,
            "case {case}: the last level has no coordinate"
        );
        let bx = box_violated_by(&mut r, &q0, 2.0, 1 + case % 5, 0.5);
        // Twice, so that the second solve starts from the first one's level and active set.
        for pass in 0..2 {
            let mut q = DVector::zeros(n);
            let rep = s.solve(Method::Iktc, &levels, &bx, &mut q).unwrap().clone();
            let mut q_live = DVector::zeros(n);
            let rep_live = s_live
                .solve(Method::Iktc, &levels[..3], &bx, &mut q_live)
                .unwrap()
                .clone();
            let scale = 1.0 + q_live.amax();
            assert!(
                (&q - &q_live).amax() < 1e-9 * scale,
                "case {case} pass {pass}: {:e}",
                (&q - &q_live).amax()
            );
            assert_eq!(rep.fallback, rep_live.fallback, "case {case} pass {pass}");
            assert_eq!(rep.corrected_from, rep_live.corrected_from, "case {case}");
            if let Some(from) = rep.corrected_from {
                corrected[from] += 1;
                assert!(rep.corrections[3].iter().all(|c| *c == 0.0), "case {case}");
                assert!(bx.contains(q.as_slice(), 1e-8).unwrap(), "case {case}");
            }
        }
    }
    // Corrections from every live level were exercised.
    assert!(corrected.iter().all(|c| *c > 10), "{corrected:?}");
}

/// The oracle of IKTC's correction (eq. 23), independent of the correction map: G over all
/// rows from a fresh [`Hierarchy`] (its blocks by the general construction), the QP over all
/// m_i of levels `from..n_T` under the box shifted by the prioritized solution. Asserts that
/// level `from` is feasible and `from + 1` is not, that `q` is the prioritized solution plus
/// G Δh, and that the report's corrections are Δh, level by level.
#[allow(clippy::too_many_arguments)]
fn assert_the_least_correction(
    levels: &[iktc_core::task::TaskEquation],
    dims: &[usize],
    settings: &SolverSettings,
    bx: &iktc_core::limits::AccelerationBox,
    q: &DVector<f64>,
    rep: &SolveReport,
    from: usize,
    case: usize,
) {
    let n = q.len();
    let mut h = Hierarchy::new(n, dims);
    let mut p = DVector::zeros(n);
    h.solve(levels, settings, &mut p).unwrap();
    h.build_g_levels(0, dims.len());
    let lo: Vec<f64> = (0..n).map(|d| bx.lower[d] - p[d]).collect();
    let hi: Vec<f64> = (0..n).map(|d| bx.upper[d] - p[d]).collect();
    let oracle = |i: usize| {
        let off: usize = dims[..i].iter().sum();
        let m: usize = dims[i..].iter().sum();
        let g = h.g().columns(off, m);
        let zeros = vec![0.0; m];
        let a_eq = nalgebra::DMatrix::<f64>::zeros(0, m);
        let problem = QpProblem {
            hessian: Hessian::Identity,
            c: &zeros,
            a_eq: a_eq.rows(0, 0),
            b_eq: &[],
            a_in: g,
            lower: &lo,
            upper: &hi,
        };
        let mut qp = QpWorkspace::new(m, 0, n);
        let mut x = DVector::zeros(m);
        let rep = qp.solve(&problem, &QpSettings::default(), &mut x).unwrap();
        (rep.status == QpStatus::Optimal).then_some(x)
    };
    let x = oracle(from).unwrap_or_else(|| panic!("case {case}: level {from} infeasible"));
    if from + 1 < dims.len() {
        assert!(
            oracle(from + 1).is_none(),
            "case {case}: level {} was feasible",
            from + 1
        );
    }
    let off: usize = dims[..from].iter().sum();
    let m: usize = dims[from..].iter().sum();
    let want = &p + h.g().columns(off, m) * &x;
    let scale = 1.0 + want.amax();
    assert!(
        (q - &want).amax() < 1e-7 * scale,
        "case {case} from {from}: {:e}",
        (q - &want).amax()
    );
    // The same corrections Δh, level by level.
    let mut c = 0;
    for (k, &m) in dims.iter().enumerate().skip(from) {
        let d = (&rep.corrections[k] - x.rows(c, m)).amax();
        assert!(d < 1e-7 * (1.0 + x.amax()), "case {case} level {k}: {d:e}");
        c += m;
    }
}

/// Levels of lower rank than rows: IKTC's QP runs over the r_i corrections of each level that
/// move q̈ (the correction map), not over all m_i. Its answer must be the least correction of
/// eq. (23) over all m_i: checked against that QP solved directly on Algorithm 1's G
/// (Hierarchy::build_g_levels, every column), at the level IKTC chose, which must also be the
/// lowest feasible one. Damped and undamped; levels made rank-deficient by repeated rows and
/// by running out of coordinates.
#[test]
fn the_correction_over_the_row_space_is_the_least_correction_over_all_rows() {
    let mut r = rng(47);
    let n = 14;
    let dims = [5, 4, 6, 7];
    let mut checked = [0usize; 4];
    for case in 0..300 {
        let mut levels = random_levels(&mut r, n, &dims);
        // Level 2 repeats two rows of level 1 and two of its own: rank 2 of 6 (with 5 + 4 = 9
        // above, 5 coordinates left); level 3 gets 3 of its 7.
        let l0 = levels[0].jacobian.rows(0, 2).into_owned();
        levels[2].jacobian.rows_mut(0, 2).copy_from(&l0);
        let own = levels[2].jacobian.rows(2, 2).into_owned();
        levels[2].jacobian.rows_mut(4, 2).copy_from(&own);
        let settings = SolverSettings {
            damping: if case % 2 == 0 {
                Damping::None
            } else {
                Damping::Fixed(0.05)
            },
            ..Default::default()
        };
        let mut s = Solver::new(n, &dims, settings).unwrap();
        let mut q0 = DVector::zeros(n);
        s.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        let ranks = s.report().ranks.clone();
        assert_eq!(ranks, vec![5, 4, 2, 3], "case {case}");
        let bx = box_violated_by(&mut r, &q0, 2.0, 1 + case % 6, 0.5);
        let mut q = DVector::zeros(n);
        let rep = s.solve(Method::Iktc, &levels, &bx, &mut q).unwrap().clone();
        let Some(from) = rep.corrected_from else {
            continue;
        };
        // The oracle: G over all rows, the QP of eq. (23) over all m_i of levels i..n_T.
        assert_the_least_correction(&levels, &dims, &settings, &bx, &q, &rep, from, case);
        checked[from] += 1;
    }
    assert!(
        checked[2] + checked[3] > 30,
        "rank-deficient levels corrected: {checked:?}"
    );
}

/// Lexicographic comparison with a tolerance: GF's level errors are never worse than IKTC's at
/// the first level where they differ (errata 3.2: IKTC's single QP is not lexicographic).
#[test]
fn gf_is_never_worse_than_iktc_lexicographically_and_the_gap_is_measured() {
    let mut r = rng(33);
    let dims = [6, 6, 6];
    let n = 20;
    let tol = 1e-6;
    let (mut climbed, mut iktc_worse, mut worst_gap) = (0, 0, 0.0f64);
    for case in 0..300 {
        let levels = random_levels(&mut r, n, &dims);
        let mut s = Solver::new(n, &dims, SolverSettings::default()).unwrap();
        let mut q0 = DVector::zeros(n);
        s.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        let bx = box_violated_by(&mut r, &q0, 1.0, 3 + case % 5, 1.0);
        let mut qi = DVector::zeros(n);
        let ri = s
            .solve(Method::Iktc, &levels, &bx, &mut qi)
            .unwrap()
            .clone();
        if ri.fallback.is_some() || ri.corrected_from == Some(dims.len() - 1) {
            continue;
        }
        climbed += 1;
        let mut qg = DVector::zeros(n);
        let rg = s
            .solve(Method::Cascade, &levels, &bx, &mut qg)
            .unwrap()
            .clone();
        assert_eq!(rg.qp_solves, 3);
        assert!(rg.violation <= 1e-7);
        for i in 0..dims.len() {
            let (eg, ei) = (rg.task_error_norms[i], ri.task_error_norms[i]);
            assert!(
                eg <= ei + tol,
                "case {case}: level {i}: GF {eg} > IKTC {ei}"
            );
            if eg < ei - tol {
                iktc_worse += 1;
                worst_gap = worst_gap.max(ei - eg);
                break;
            }
        }
    }
    println!("{climbed} problems needed a climb; IKTC sacrificed a higher level more than GF in {iktc_worse}, by up to {worst_gap:.3}");
    assert!(climbed > 30, "the test must exercise climbs ({climbed})");
    assert!(
        iktc_worse > 0,
        "errata 3.2 predicts IKTC is not lexicographic: expected some gap"
    );
}

#[test]
fn clamp_stays_in_the_box_and_loses_tasks() {
    let mut r = rng(34);
    let levels = random_levels(&mut r, 20, &[4, 4]);
    let mut s = Solver::new(20, &[4, 4], SolverSettings::default()).unwrap();
    let mut q0 = DVector::zeros(20);
    s.solve(Method::Prioritized, &levels, &wide_box(20), &mut q0)
        .unwrap();
    let bx = box_violated_by(&mut r, &q0, 1.0, 3, 1.0);
    let mut q = DVector::zeros(20);
    let rep = s.solve(Method::Clamp, &levels, &bx, &mut q).unwrap();
    assert_eq!(rep.violation, 0.0);
    assert!(
        rep.task_error_norms[0] > 1e-3,
        "clamping breaks even the first level"
    );
}

#[test]
fn empty_box_and_infeasible_problems_take_a_reported_fallback() {
    let mut r = rng(35);
    let n = 8;
    let levels = random_levels(&mut r, n, &[4, 4]);
    let mut s = Solver::new(n, &[4, 4], SolverSettings::default()).unwrap();
    // Σm = n: no freedom; a box excluding the unique solution on every dof cannot be met by
    // any correction that keeps G's columns independent... but G is square and invertible,
    // so level 1 can always be corrected. Make the box empty on two dofs instead.
    let mut q0 = DVector::zeros(n);
    s.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
        .unwrap();
    let mut bx = wide_box(n);
    bx.lower[2] = 1.0;
    bx.upper[2] = -1.0;
    bx.lower[5] = 3.0;
    bx.upper[5] = 2.0;
    let mut q = DVector::zeros(n);
    let rep = s.solve(Method::Iktc, &levels, &bx, &mut q).unwrap().clone();
    assert_eq!(rep.empty_box_dofs, 2);
    assert!(
        (q[2] - 0.0).abs() < 1e-8 && (q[5] - 2.5).abs() < 1e-8,
        "midpoints: {} {}",
        q[2],
        q[5]
    );
    // Rank loss: a zero Jacobian on the only level leaves G = 0: no level is feasible, and a
    // level of rank 0 is known to be without a QP (it moves nothing).
    let mut zero = random_levels(&mut r, 3, &[2]);
    zero[0].jacobian.fill(0.0);
    let mut s = Solver::new(3, &[2], SolverSettings::default()).unwrap();
    let mut bx = wide_box(3);
    bx.lower[0] = 1.0;
    bx.upper[0] = 2.0;
    let mut q = DVector::zeros(3);
    let rep = s.solve(Method::Iktc, &zero, &bx, &mut q).unwrap();
    assert_eq!(rep.fallback, Some(Fallback::ClampedToBox));
    assert_eq!(rep.ranks, vec![0]);
    assert_eq!((rep.qp_solves, rep.qp_infeasible), (0, 0));
    assert_eq!(q[0], 1.0);
}

#[test]
fn bad_input_is_an_error() {
    let mut r = rng(36);
    let mut levels = random_levels(&mut r, 5, &[2, 2]);
    let mut s = Solver::new(5, &[2, 2], SolverSettings::default()).unwrap();
    let mut q = DVector::zeros(5);
    assert!(matches!(
        s.solve(Method::Iktc, &levels, &wide_box(4), &mut q),
        Err(iktc_core::Error::DimensionMismatch { .. })
    ));
    assert!(s
        .solve(Method::Iktc, &levels[..1], &wide_box(5), &mut q)
        .is_err());
    levels[1].jacobian[(0, 0)] = f64::NAN;
    assert!(matches!(
        s.solve(Method::Iktc, &levels, &wide_box(5), &mut q),
        Err(iktc_core::Error::NonFinite { .. })
    ));
    let bad = SolverSettings {
        rank_threshold: -1.0,
        ..Default::default()
    };
    assert!(Solver::new(5, &[2], bad).is_err());
    let bad = SolverSettings {
        damping: Damping::Fixed(f64::NAN),
        ..Default::default()
    };
    assert!(Solver::new(5, &[2], bad).is_err());
}

#[test]
fn climbing_from_the_last_level_finds_the_same_correction_as_from_the_bottom() {
    // Feasibility is monotone in the level, so starting the climb where the last tick ended
    // must give the level and the q̈ of Algorithm 2 as printed. One solver of each kind runs
    // through the same sequence of problems (state carries over between them); each problem
    // is repeated with small box changes, as consecutive ticks are.
    let mut r = rng(35);
    let dims = [6, 6, 6];
    let n = 20;
    // The screen off in both, so that the QP counts measure the climb alone.
    let bottom = SolverSettings {
        climb: Climb::FromBottom,
        screen: false,
        ..Default::default()
    };
    let last = SolverSettings {
        climb: Climb::FromLast,
        screen: false,
        ..Default::default()
    };
    let mut sb = Solver::new(n, &dims, bottom).unwrap();
    let mut sl = Solver::new(n, &dims, last).unwrap();
    let (mut qps_bottom, mut qps_last, mut started_above, mut levels_seen) = (0, 0, 0, [0usize; 3]);
    let mut prev_from = None;
    for case in 0..120 {
        let levels = random_levels(&mut r, n, &dims);
        let mut q0 = DVector::zeros(n);
        sb.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        let bx0 = box_violated_by(&mut r, &q0, 1.0, 1 + case % 6, 1.0);
        for tick in 0..4 {
            let mut bx = bx0.clone();
            for d in 0..n {
                let shift = 0.01 * tick as f64;
                bx.lower[d] -= shift;
                bx.upper[d] += shift;
            }
            let (mut qb, mut ql) = (DVector::zeros(n), DVector::zeros(n));
            let rb = sb
                .solve(Method::Iktc, &levels, &bx, &mut qb)
                .unwrap()
                .clone();
            let rl = sl
                .solve(Method::Iktc, &levels, &bx, &mut ql)
                .unwrap()
                .clone();
            assert_eq!(
                rb.corrected_from, rl.corrected_from,
                "case {case} tick {tick}"
            );
            assert_eq!(rb.fallback, rl.fallback, "case {case} tick {tick}");
            assert!(
                (&qb - &ql).norm() <= 1e-9 * (1.0 + qb.norm()),
                "case {case} tick {tick}: {}",
                (&qb - &ql).norm()
            );
            if let (Some(p), Some(f)) = (prev_from, rl.corrected_from) {
                if p < dims.len() - 1 && p != f {
                    started_above += 1;
                }
            }
            if let Some(f) = rl.corrected_from {
                levels_seen[f] += 1;
                prev_from = Some(f);
            }
            qps_bottom += rb.qp_solves;
            qps_last += rl.qp_solves;
        }
    }
    println!("QPs: from the bottom {qps_bottom}, from the last level {qps_last}; corrected levels {levels_seen:?}");
    assert!(
        levels_seen.iter().all(|&c| c > 10),
        "every level must be exercised: {levels_seen:?}"
    );
    assert!(
        started_above > 5,
        "the test must exercise climbs that start above the bottom and move ({started_above})"
    );
    assert!(qps_last < qps_bottom);
}

#[test]
fn the_infeasibility_screen_never_changes_the_answer() {
    // The screen may only skip QPs that would have been infeasible: with and without it, the
    // same sequence of problems gives the same level, fallback and q̈. Consecutive ticks repeat
    // a problem with small box changes, so that a level stays infeasible and the certificate
    // of its last QP gets reused.
    let mut r = rng(36);
    let dims = [6, 6, 6];
    let n = 20;
    let on = SolverSettings::default();
    assert!(on.screen);
    let off = SolverSettings {
        screen: false,
        ..Default::default()
    };
    let mut s_on = Solver::new(n, &dims, on).unwrap();
    let mut s_off = Solver::new(n, &dims, off).unwrap();
    let (mut screened, mut qps_on, mut qps_off, mut iters_on, mut iters_off) = (0, 0, 0, 0, 0);
    for case in 0..150 {
        let levels = random_levels(&mut r, n, &dims);
        let mut q0 = DVector::zeros(n);
        s_off
            .solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        let bx0 = box_violated_by(&mut r, &q0, 1.0, 2 + case % 6, 1.0);
        for tick in 0..5 {
            let mut bx = bx0.clone();
            for d in 0..n {
                let shift = 0.02 * tick as f64 * if d % 2 == 0 { 1.0 } else { -0.5 };
                bx.lower[d] += shift;
                bx.upper[d] += shift;
            }
            let (mut a, mut b) = (DVector::zeros(n), DVector::zeros(n));
            let ra = s_on
                .solve(Method::Iktc, &levels, &bx, &mut a)
                .unwrap()
                .clone();
            let rb = s_off
                .solve(Method::Iktc, &levels, &bx, &mut b)
                .unwrap()
                .clone();
            assert_eq!(
                ra.corrected_from, rb.corrected_from,
                "case {case} tick {tick}"
            );
            assert_eq!(ra.fallback, rb.fallback, "case {case} tick {tick}");
            assert!(
                (&a - &b).norm() <= 1e-9 * (1.0 + b.norm()),
                "case {case} tick {tick}"
            );
            assert_eq!(rb.screened_infeasible, 0);
            // Every level checked is counted once: by a QP or by the screen.
            assert_eq!(
                ra.qp_solves + ra.screened_infeasible,
                rb.qp_solves,
                "case {case} tick {tick}"
            );
            screened += ra.screened_infeasible;
            qps_on += ra.qp_solves;
            qps_off += rb.qp_solves;
            iters_on += ra.qp_iterations;
            iters_off += rb.qp_iterations;
        }
    }
    println!(
        "screened {screened} levels; QPs {qps_on} vs {qps_off}, iterations {iters_on} vs {iters_off}"
    );
    assert!(screened > 50, "the screen must fire ({screened})");
    assert!(iters_on < iters_off);
}

#[test]
fn level_hold_keeps_the_box_and_the_levels_above_exact() {
    // Sequences of ticks whose box swings between two states, as a joint limit does when a
    // correction of a higher level makes room: with the hold, the corrected level is never below
    // Algorithm 2's, never alternates tick by tick, the box is met and every level above the
    // corrected one is solved exactly; with a hold of 1 it is Algorithm 2 exactly.
    let mut r = rng(1313);
    let dims = [4, 4, 4, 4];
    let n = 14;
    let hold = 6;
    let held = SolverSettings {
        level_hold: hold,
        ..Default::default()
    };
    let mut sh = Solver::new(n, &dims, held).unwrap();
    let mut sa = Solver::new(n, &dims, SolverSettings::default()).unwrap();
    let (mut held_ticks, mut a2_switches, mut held_flips) = (0, 0, 0);
    for case in 0..60 {
        let levels = random_levels(&mut r, n, &dims);
        let mut q0 = DVector::zeros(n);
        sa.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        let tight = box_violated_by(&mut r, &q0, 1.0, 3 + case % 4, 1.0);
        let loose = box_violated_by(&mut r, &q0, 1.0, 1, 0.2);
        let mut chosen = Vec::new();
        let mut prev_a2 = None;
        for tick in 0..24 {
            let bx = if tick % 2 == 0 { &tight } else { &loose };
            let (mut qh, mut qa) = (DVector::zeros(n), DVector::zeros(n));
            let ra = sa
                .solve(Method::Iktc, &levels, bx, &mut qa)
                .unwrap()
                .clone();
            let rh = sh
                .solve(Method::Iktc, &levels, bx, &mut qh)
                .unwrap()
                .clone();
            assert_eq!(ra.corrected_from, ra.feasible_from);
            assert_eq!(
                rh.feasible_from, ra.corrected_from,
                "case {case} tick {tick}"
            );
            if let (Some(c), Some(f)) = (rh.corrected_from, rh.feasible_from) {
                assert!(c <= f);
                if c < f {
                    held_ticks += 1;
                }
                assert!(bx.max_violation(qh.as_slice()).unwrap() <= 1e-8);
                for (i, e) in rh.task_error_norms.iter().enumerate().take(c) {
                    assert!(*e <= 1e-8 * (1.0 + levels[i].rhs.norm()), "level {i}: {e}");
                }
            }
            if prev_a2.is_some() && ra.corrected_from.is_some() && prev_a2 != ra.corrected_from {
                a2_switches += 1;
            }
            prev_a2 = ra.corrected_from;
            chosen.push(rh.corrected_from);
        }
        held_flips += chosen
            .windows(3)
            .filter(|w| w[0].is_some() && w[1].is_some() && w[0] == w[2] && w[0] != w[1])
            .count();
    }
    println!("Algorithm 2 switched level {a2_switches} times; held ticks {held_ticks}, flips with the hold {held_flips}");
    assert!(
        a2_switches > 100,
        "the test must make Algorithm 2 alternate"
    );
    assert!(held_ticks > 100);
    assert_eq!(held_flips, 0);
}

#[test]
fn rebase_converges_on_the_achievable_demand_and_leaves_uncorrected_levels_alone() {
    // The same problem tick after tick, the box cutting the lowest levels: with the re-base the
    // q̈ stays in the box, and the levels above every corrected one are exact
    // with respect to their own (unchanged) demands. Once the box lets the level go, it recovers
    // its demand geometrically.
    let mut r = rng(3303);
    let dims = [3, 3, 3];
    let n = 8;
    let release = 0.2;
    let settings = SolverSettings {
        rebase_release: release,
        ..Default::default()
    };
    let mut checked = 0;
    let mut ratios = Vec::new();
    for _ in 0..40 {
        let levels = random_levels(&mut r, n, &dims);
        let mut s = Solver::new(n, &dims, settings).unwrap();
        let mut q0 = DVector::zeros(n);
        s.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        let bx = box_violated_by(&mut r, &q0, 1.0, 2, 0.5);
        let mut q = DVector::zeros(n);
        let mut first = None;
        let mut last = DVector::zeros(n);
        let mut highest = dims.len();
        for _ in 0..200 {
            let rep = s.solve(Method::Iktc, &levels, &bx, &mut q).unwrap().clone();
            assert!(bx.max_violation(q.as_slice()).unwrap() <= 1e-8);
            if let Some(c) = rep.corrected_from {
                // Levels never corrected carry no offset.
                highest = highest.min(c);
                for (e, l) in rep.task_error_norms.iter().zip(&levels).take(highest) {
                    assert!(*e <= 1e-8 * (1.0 + l.rhs.norm()));
                }
                let dh: f64 = rep
                    .corrections
                    .iter()
                    .map(|c| c.norm_squared())
                    .sum::<f64>();
                first.get_or_insert(dh.sqrt());
            }
            last.copy_from(&q);
        }
        let Some(first) = first else { continue };
        // The last correction against the first (printed: with a QP whose active set changes as
        // the demand moves, the scalar steady state r/(1 − r) w is not a bound).
        let rep = s.report().clone();
        let dh: f64 = rep
            .corrections
            .iter()
            .map(|c| c.norm_squared())
            .sum::<f64>()
            .sqrt();
        ratios.push(dh / first);
        // Released: a wide box, the re-based demand decays back to the CLIK demand.
        let mut free = DVector::zeros(n);
        for _ in 0..120 {
            s.solve(Method::Iktc, &levels, &wide_box(n), &mut free)
                .unwrap();
        }
        assert!(
            (&free - &q0).norm() <= 1e-6 * (1.0 + q0.norm()),
            "{}",
            (&free - &q0).norm()
        );
        checked += 1;
    }
    ratios.sort_by(f64::total_cmp);
    println!("last/first correction: {ratios:.3?}");
    assert!(checked > 20, "{checked}");
    // Where the active set settles, the refused part shrinks to r of the first one (scalar
    // steady state: Δh = r/(1 − r) w = r Δh₀); most cases are such.
    let settled = ratios.iter().filter(|&&x| x <= release + 1e-6).count();
    assert!(4 * settled >= 3 * ratios.len(), "{ratios:?}");
}

/// A bottom level of general rows and weighted joint rows that takes every coordinate left is
/// stepped by its Gram matrix, and its columns of the correction map (and its response to the
/// levels above) come from the same factors, in a basis of its own: the correction and q̈ must
/// be the QP's of eq. (23) over all rows with G built by the QR, level by level, with each
/// damping rule.
#[test]
fn a_level_stepped_by_its_gram_matrix_is_corrected_as_the_qr_would() {
    use rand::seq::SliceRandom;
    use rand::Rng;
    let mut r = rng(48);
    let n = 16;
    let mut checked = [0usize; 3];
    for case in 0..240 {
        // 4 + 3 rows above, then 2 general rows and 13 joint rows (3 coordinates left out).
        let dims = [4, 3, 15];
        let mut levels = random_levels(&mut r, n, &dims);
        let bottom = &mut levels[2];
        bottom.jacobian.rows_mut(2, 13).fill(0.0);
        let mut coords: Vec<usize> = (0..n).collect();
        coords.shuffle(&mut r);
        for (row, &c) in coords[3..].iter().enumerate() {
            bottom.jacobian[(2 + row, c)] = if r.random_bool(0.5) { 0.4 } else { -0.4 };
        }
        let settings = SolverSettings {
            damping: match case % 3 {
                0 => Damping::None,
                1 => Damping::Fixed(0.05),
                _ => Damping::Adaptive {
                    max: 0.05,
                    threshold: 10.0,
                },
            },
            ..Default::default()
        };
        let mut s = Solver::new(n, &dims, settings).unwrap();
        let mut q0 = DVector::zeros(n);
        s.solve(Method::Prioritized, &levels, &wide_box(n), &mut q0)
            .unwrap();
        assert_eq!(s.report().ranks, vec![4, 3, 9], "case {case}");
        // Up to 14 dofs cut: more than the bottom level's 9 coordinates can fix, so that the
        // levels above are corrected too (the bottom level's response to them).
        let bx = box_violated_by(&mut r, &q0, 2.0, [2, 8, 11, 14][case % 4], 0.5);
        let mut q = DVector::zeros(n);
        let rep = s.solve(Method::Iktc, &levels, &bx, &mut q).unwrap().clone();
        let Some(from) = rep.corrected_from else {
            continue;
        };
        // The Gram step was taken, and the oracle: G over all rows by the QR, the QP of
        // eq. (23) over all m_i.
        let mut h = Hierarchy::new(n, &dims);
        let mut p = DVector::zeros(n);
        h.solve(&levels, &settings, &mut p).unwrap();
        assert_eq!(h.stepped_by_gram(), Some(2), "case {case}");
        assert!((&p - &q0).amax() < 1e-12 * (1.0 + q0.amax()), "case {case}");
        assert_the_least_correction(&levels, &dims, &settings, &bx, &q, &rep, from, case);
        checked[from] += 1;
    }
    assert!(
        checked[0] + checked[1] >= 15 && checked[2] >= 10,
        "corrections from each level: {checked:?}"
    );
}
