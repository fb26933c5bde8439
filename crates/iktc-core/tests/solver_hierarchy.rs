//! The prioritized recursion and the correction map G against independent computations.

mod common;
use common::rng;
use common::solver as solver_common;
use solver_common::*;

use iktc_core::solver::*;
use iktc_core::task::TaskEquation;
use nalgebra::{DMatrix, DVector};

/// N_{i−1} = I − A⁺A for every level i, with A the stacked Jacobian of the levels above it
/// (the meaning of eq. 7), by SVD with a relative rank threshold; N_0 = I.
fn projectors_above(levels: &[TaskEquation]) -> Vec<DMatrix<f64>> {
    let n = levels[0].nv();
    let mut stacked = DMatrix::<f64>::zeros(0, n);
    let mut out = Vec::with_capacity(levels.len());
    for l in levels {
        out.push(if stacked.nrows() == 0 {
            DMatrix::<f64>::identity(n, n)
        } else {
            DMatrix::<f64>::identity(n, n)
                - stacked.clone().pseudo_inverse(1e-9).unwrap() * &stacked
        });
        let mut b = DMatrix::zeros(stacked.nrows() + l.dim(), n);
        b.rows_mut(0, stacked.nrows()).copy_from(&stacked);
        b.rows_mut(stacked.nrows(), l.dim()).copy_from(&l.jacobian);
        stacked = b;
    }
    out
}

/// Eqs. 5–7 with explicit n × n projectors and SVD pseudo-inverses (λ = 0) or the DLS formula
/// J̄ᵀ(J̄J̄ᵀ + λ²I)⁻¹ — a second, straightforward implementation. N_{i−1} is computed from
/// the stacked Jacobian of the levels above, N = I − A⁺A (the meaning of eq. 7), by SVD with a
/// relative rank threshold.
fn reference_solution(levels: &[TaskEquation], lambda: f64) -> DVector<f64> {
    reference_solution_damped(levels, |_| lambda * lambda)
}

/// As [`reference_solution`], with level i's λ² given by `lambda2(J̄_i)`.
fn reference_solution_damped(
    levels: &[TaskEquation],
    lambda2: impl Fn(&DMatrix<f64>) -> f64,
) -> DVector<f64> {
    let n = levels[0].nv();
    let mut q = DVector::zeros(n);
    for (l, na) in levels.iter().zip(projectors_above(levels)) {
        let jb = &l.jacobian * &na;
        let l2 = lambda2(&jb);
        let pinv = if l2 == 0.0 {
            jb.clone().pseudo_inverse(1e-9).unwrap()
        } else {
            let m = l.dim();
            let s = &jb * jb.transpose() + DMatrix::identity(m, m) * l2;
            jb.transpose() * s.try_inverse().unwrap()
        };
        q += &pinv * (&l.rhs - &l.jacobian * &q);
    }
    q
}

/// The last kept pivot |R_rr| of the column-pivoted QR of J̄ᵀ (n × m), by Gram–Schmidt: each
/// step takes the row of J̄ whose part orthogonal to the rows already taken is longest; that
/// length is |R_jj|. Pivots at or below `rank_threshold` are dropped. 0 when nothing is kept.
fn last_kept_pivot(jb: &DMatrix<f64>, rank_threshold: f64) -> f64 {
    let mut rest: Vec<DVector<f64>> = jb.row_iter().map(|r| r.transpose()).collect();
    let mut last = 0.0;
    while !rest.is_empty() {
        let (best, norm) = rest
            .iter()
            .enumerate()
            .map(|(i, v)| (i, v.norm()))
            .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
        if norm <= rank_threshold {
            break;
        }
        last = norm;
        let u = rest.swap_remove(best) / norm;
        for v in rest.iter_mut() {
            let d = u.dot(v);
            *v -= &u * d;
        }
    }
    last
}

/// λ² of [`Damping::Adaptive`] as its documentation states it: with σ the smallest kept
/// singular value, estimated by the last kept pivot of the pivoted QR,
/// λ² = (1 − (σ/ε)²) λ_max² when σ < ε, else 0.
fn adaptive_lambda2(jb: &DMatrix<f64>, max: f64, threshold: f64, rank_threshold: f64) -> f64 {
    let sigma = last_kept_pivot(jb, rank_threshold);
    if sigma < threshold {
        (1.0 - (sigma / threshold).powi(2)) * max * max
    } else {
        0.0
    }
}

/// Round-off of O(n) sums of O(1) products, amplified by the conditioning of random
/// Jacobians (condition numbers up to ~1e3 here): 1e-8 relative.
const REL_TOL: f64 = 1e-8;

/// The lexicographic optimality of each level (independent of how the recursion is coded):
/// the residual h_i − J_i q̈ of level i is orthogonal to every direction still free below the
/// levels above, N_{i−1} J_iᵀ (h_i − J_i q̈) = 0, with N_{i−1} = I − A⁺A from the stacked
/// Jacobian A of the levels above.
fn check_lexicographic(levels: &[TaskEquation], q: &DVector<f64>, tol: f64) {
    for (i, (l, na)) in levels.iter().zip(projectors_above(levels)).enumerate() {
        let res = &l.rhs - &l.jacobian * q;
        let g = &na * l.jacobian.transpose() * &res;
        assert!(
            g.norm() < tol * (1.0 + res.norm()),
            "level {i}: gradient {}",
            g.norm()
        );
    }
}

#[test]
fn recursion_matches_explicit_projectors() {
    let mut r = rng(21);
    let mut compared = 0;
    for case in 0..300 {
        let n = 3 + case % 20;
        let nt = 1 + case % 4;
        let dims: Vec<usize> = (0..nt).map(|i| 1 + (case + i) % 4).collect();
        let levels = random_levels(&mut r, n, &dims);
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &SolverSettings::default(), &mut q)
            .unwrap();
        check_lexicographic(&levels, &q, 1e-7);
        // Where every level fits (Σm ≤ n) the solution is also the minimum-norm one, which
        // the explicit formula gives.
        if dims.iter().sum::<usize>() <= n {
            let want = reference_solution(&levels, 0.0);
            let err = (&q - &want).norm() / (1.0 + want.norm());
            assert!(err < REL_TOL, "case {case}: n {n}, dims {dims:?}: {err}");
            compared += 1;
        }
    }
    assert!(compared > 100);
}

#[test]
fn damped_recursion_matches_the_dls_formula() {
    let mut r = rng(22);
    let settings = SolverSettings {
        damping: Damping::Fixed(0.3),
        ..Default::default()
    };
    for case in 0..100 {
        let n = 4 + case % 12;
        let dims = [2, 1 + case % 3, 2];
        let levels = random_levels(&mut r, n, &dims);
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &settings, &mut q).unwrap();
        let want = reference_solution(&levels, 0.3);
        assert!(
            (&q - &want).norm() < REL_TOL * (1.0 + want.norm()),
            "case {case}"
        );
    }
}

#[test]
fn adaptive_damping_matches_its_formula() {
    // Level 2's second row is its first plus δ times a random row: the smaller δ, the closer
    // the level is to a singularity (σ ≈ δ). With ε = 0.5 some levels are damped, others not.
    let (max, threshold) = (0.3, 0.5);
    let settings = SolverSettings {
        damping: Damping::Adaptive { max, threshold },
        ..Default::default()
    };
    let mut r = rng(26);
    let (mut damped, mut undamped) = (0, 0);
    for case in 0..120 {
        let n = 8 + case % 8;
        let dims = [2, 2, 2];
        let mut levels = random_levels(&mut r, n, &dims);
        let delta = [1e-3, 1e-2, 0.1, 0.3, 1.0][case % 5];
        let row = levels[1].jacobian.row(0) + levels[1].jacobian.row(1) * delta;
        levels[1].jacobian.set_row(1, &row);
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &settings, &mut q).unwrap();
        let rank = settings.rank_threshold;
        let want =
            reference_solution_damped(&levels, |jb| adaptive_lambda2(jb, max, threshold, rank));
        let err = (&q - &want).norm() / (1.0 + want.norm());
        assert!(err < REL_TOL, "case {case} (δ = {delta}): {err}");
        // The damping must matter where it applies: the undamped solution is elsewhere.
        let plain = reference_solution(&levels, 0.0);
        let moved = (&plain - &want).norm() / (1.0 + want.norm());
        let any_damped = projectors_above(&levels)
            .iter()
            .zip(&levels)
            .any(|(na, l)| adaptive_lambda2(&(&l.jacobian * na), max, threshold, rank) > 0.0);
        if any_damped {
            damped += 1;
            assert!(
                moved > 1e3 * REL_TOL,
                "case {case}: damping changed nothing"
            );
        } else {
            undamped += 1;
        }
    }
    assert!(
        damped > 30 && undamped > 10,
        "{damped} damped, {undamped} undamped cases"
    );
}

#[test]
fn rank_deficient_levels_are_handled() {
    // Level 2 repeats a row of level 1 (algorithmic singularity) and adds a new one.
    let mut r = rng(23);
    let n = 6;
    let mut levels = random_levels(&mut r, n, &[2, 2]);
    let row = levels[0].jacobian.row(0).into_owned();
    levels[1].jacobian.set_row(0, &row);
    let mut h = Hierarchy::new(n, &[2, 2]);
    let mut q = DVector::zeros(n);
    h.solve(&levels, &SolverSettings::default(), &mut q)
        .unwrap();
    assert_eq!(h.ranks(), &[2, 1]);
    let want = reference_solution(&levels, 0.0);
    assert!((&q - &want).norm() < 1e-8 * (1.0 + want.norm()));
    // Level 1 is met exactly.
    assert!((&levels[0].jacobian * &q - &levels[0].rhs).norm() < 1e-9);
}

/// Column j of g_i is the change of q̈ when h_i moves by e_j (eq. 20), measured by re-running
/// the recursion from `q0`, the solution at `levels` (restored on return).
fn assert_g_is_the_derivative(
    levels: &mut [TaskEquation],
    dims: &[usize],
    settings: &SolverSettings,
    q0: &DVector<f64>,
    g: &DMatrix<f64>,
    case: usize,
) {
    let n = q0.len();
    let mut col = 0;
    for i in 0..dims.len() {
        for j in 0..dims[i] {
            levels[i].rhs[j] += 1.0;
            let mut q1 = DVector::zeros(n);
            Hierarchy::new(n, dims)
                .solve(levels, settings, &mut q1)
                .unwrap();
            levels[i].rhs[j] -= 1.0;
            let d = &q1 - q0;
            assert!(
                (&d - g.column(col)).norm() < 1e-9 * (1.0 + d.norm()),
                "case {case} level {i} row {j}"
            );
            col += 1;
        }
    }
}

#[test]
fn g_is_the_derivative_of_the_solution_with_respect_to_h() {
    // Algorithm 1: the solution is affine in the right-hand sides; column j of g_i is the
    // change of q̈ when h_i moves by e_j (eq. 20), measured by re-running the recursion.
    // Damping depends on the Jacobians only, so the solution stays affine in h with any
    // damping rule: cases cycle through none, fixed and adaptive (with a region ε wide enough
    // that random levels fall in it).
    let mut r = rng(24);
    for case in 0..30 {
        let n = 10 + case % 10;
        let dims = [3, 2, 1 + case % 4];
        let mut levels = random_levels(&mut r, n, &dims);
        let settings = SolverSettings {
            damping: match case % 3 {
                0 => Damping::None,
                1 => Damping::Fixed(0.2),
                _ => Damping::Adaptive {
                    max: 0.2,
                    threshold: 2.0,
                },
            },
            ..Default::default()
        };
        let mut h = Hierarchy::new(n, &dims);
        let mut q0 = DVector::zeros(n);
        h.solve(&levels, &settings, &mut q0).unwrap();
        // Level by level (as Algorithm 1 climbs) or all levels in one pass.
        if case % 2 == 0 {
            for i in 0..dims.len() {
                h.build_g_level(i);
            }
        } else {
            h.build_g_levels(0, dims.len());
        }
        assert_g_is_the_derivative(&mut levels, &dims, &settings, &q0, h.g(), case);
    }
}

#[test]
fn levels_with_no_coordinate_left_have_rank_zero_and_zero_columns_of_g() {
    // n = 9 and the levels ask for 4 + 3 + 4 + 2 rows: the third keeps 2 of its 4 rows, the
    // fourth gets none. The solution is the projector recursion's, and G is still the
    // derivative of the solution with respect to every h (the fourth level's columns zero),
    // built level by level, all at once, or over a range that starts at the empty level.
    let mut r = rng(43);
    let (n, dims) = (9, [4, 3, 4, 2]);
    for case in 0..20 {
        let mut levels = random_levels(&mut r, n, &dims);
        let settings = SolverSettings::default();
        let mut h = Hierarchy::new(n, &dims);
        let mut q0 = DVector::zeros(n);
        h.solve(&levels, &settings, &mut q0).unwrap();
        assert_eq!(h.ranks(), &[4, 3, 2, 0], "case {case}");
        let want = reference_solution(&levels, 0.0);
        assert!(
            (&q0 - &want).norm() < 1e-8 * (1.0 + want.norm()),
            "case {case}"
        );
        // Poison G first: every column must be written.
        h.build_g_levels(0, dims.len());
        match case % 3 {
            0 => (0..dims.len()).for_each(|i| h.build_g_level(i)),
            1 => h.build_g_levels(0, dims.len()),
            _ => {
                h.build_g_levels(3, 4);
                h.build_g_levels(0, 3);
            }
        }
        assert!(
            h.g().columns(11, 2).iter().all(|x| *x == 0.0),
            "case {case}"
        );
        assert_g_is_the_derivative(&mut levels, &dims, &settings, &q0, h.g(), case);
    }
}

#[test]
fn pinv_is_the_pseudo_inverse_of_the_projected_jacobian() {
    // J̄_i⁺ = (J_i N_{i−1})⁺ with N_{i−1} = I − A⁺A from the stacked Jacobian A of the levels
    // above, by SVD (λ = 0), against the matrix the factorization forms on request.
    let mut r = rng(25);
    let settings = SolverSettings {
        damping: Damping::None,
        ..Default::default()
    };
    for case in 0..40 {
        let n = 6 + case % 10;
        let dims = [2, 1 + case % 3, 3];
        let levels = random_levels(&mut r, n, &dims);
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &settings, &mut q).unwrap();
        for (i, (l, na)) in levels.iter().zip(projectors_above(&levels)).enumerate() {
            let want = (&l.jacobian * na).pseudo_inverse(1e-9).unwrap();
            let got = h.pinv(i).clone();
            assert!(
                (&got - &want).norm() < REL_TOL * (1.0 + want.norm()),
                "case {case} level {i}: {}",
                (&got - &want).norm()
            );
        }
    }
}

/// Random levels above a bottom level that selects `m` distinct coordinates (a joint or
/// posture task, each row scaled by a weight in ±[0.5, 2]), the upper rows `n − m` in two
/// levels, so that the stacked rows are as many as the coordinates.
fn levels_over_a_selection(
    r: &mut rand_chacha::ChaCha8Rng,
    n: usize,
    m: usize,
) -> Vec<TaskEquation> {
    use rand::seq::SliceRandom;
    use rand::Rng;
    let upper = n - m;
    let a = 1 + r.random_range(0..upper);
    let dims: Vec<usize> = [a, upper - a, m].into_iter().filter(|&d| d > 0).collect();
    let mut levels = random_levels(r, n, &dims);
    let bottom = levels.last_mut().unwrap();
    bottom.jacobian.fill(0.0);
    let mut coords: Vec<usize> = (0..n).collect();
    coords.shuffle(r);
    for (row, &c) in coords[..m].iter().enumerate() {
        let s = r.random_range(0.5..2.0) * if r.random_bool(0.5) { 1.0 } else { -1.0 };
        bottom.jacobian[(row, c)] = s;
    }
    levels
}

/// What the bottom level of `levels` gets: its correction-map block (built from `levels`), the
/// G block of the general construction, whether the closed form built the first, and the ranks
/// every level kept (the two blocks are comparable when the bottom level kept all its rows).
struct BottomBlocks {
    map: DMatrix<f64>,
    g: DMatrix<f64>,
    closed: bool,
    ranks: Vec<usize>,
}

fn bottom_blocks(levels: &[TaskEquation], damping: Damping) -> BottomBlocks {
    let n = levels[0].nv();
    let dims: Vec<usize> = levels.iter().map(|l| l.dim()).collect();
    let i = dims.len() - 1;
    let settings = SolverSettings {
        damping,
        ..Default::default()
    };
    let mut h = Hierarchy::new(n, &dims);
    let mut q0 = DVector::zeros(n);
    h.solve(levels, &settings, &mut q0).unwrap();
    let closed = h.build_correction_map(levels, i, i + 1);
    let map = h
        .correction_map()
        .columns(h.correction_offset(i), dims[i])
        .clone_owned();
    h.build_g_levels(i, i + 1);
    let g = h.g().columns(h.offset(i), dims[i]).clone_owned();
    BottomBlocks {
        map,
        g,
        closed,
        ranks: h.ranks().to_vec(),
    }
}

#[test]
fn a_bottom_selection_level_completing_the_rank_gets_the_general_block_in_closed_form() {
    let mut r = rng(77);
    for case in 0..60 {
        let n = 6 + case % 13;
        let m = 1 + case % (n - 1);
        let levels = levels_over_a_selection(&mut r, n, m);
        let dims: Vec<usize> = levels.iter().map(|l| l.dim()).collect();
        let BottomBlocks {
            map,
            g,
            closed,
            ranks,
        } = bottom_blocks(&levels, Damping::None);
        assert_eq!(ranks, dims, "case {case}: the random levels have full rank");
        assert!(closed, "case {case}: the closed form applies");
        let scale = g.amax().max(1.0);
        assert!(
            (&map - &g).amax() <= REL_TOL * scale,
            "case {case}: {}",
            (&map - &g).amax()
        );
        // Independently: J_i g = I and J_k g = 0 above.
        let (bottom, above) = levels.split_last().unwrap();
        let eye = DMatrix::<f64>::identity(m, m);
        assert!(
            (&bottom.jacobian * &map - eye).amax() <= REL_TOL * scale,
            "case {case}"
        );
        for l in above {
            assert!(
                (&l.jacobian * &map).amax() <= REL_TOL * scale,
                "case {case}"
            );
        }
    }
}

#[test]
fn the_closed_form_declines_what_it_does_not_cover_and_the_block_stays_the_same() {
    let mut r = rng(78);
    for case in 0..30 {
        let n = 6 + case % 7;
        let m = 2 + case % (n - 2);
        let mut levels = levels_over_a_selection(&mut r, n, m);
        let damping = match case % 3 {
            // A row with a second entry: not a selection.
            0 => {
                let bottom = levels.last_mut().unwrap();
                let c = (0..n).find(|&c| bottom.jacobian[(0, c)] == 0.0).unwrap();
                bottom.jacobian[(0, c)] = 0.3;
                Damping::None
            }
            // Two rows on one coordinate (the level is then rank deficient: not solved
            // exactly, and not a selection).
            1 => {
                let bottom = levels.last_mut().unwrap();
                let c = (0..n).find(|&c| bottom.jacobian[(0, c)] != 0.0).unwrap();
                bottom.jacobian[(1, c)] = 1.0;
                for c2 in 0..n {
                    if c2 != c {
                        bottom.jacobian[(1, c2)] = 0.0;
                    }
                }
                Damping::None
            }
            // Damped: not solved exactly.
            _ => Damping::Fixed(0.2),
        };
        let i = levels.len() - 1;
        let m = levels[i].dim();
        let b = bottom_blocks(&levels, damping);
        assert!(!b.closed, "case {case}");
        if b.ranks[i] == m {
            assert!(
                (&b.map - &b.g).amax() <= REL_TOL * b.g.amax().max(1.0),
                "case {case}"
            );
        }
    }
}

#[test]
fn a_square_stack_over_a_selection_solved_in_closed_form_gives_the_recursion_s_answer() {
    // Levels over a bottom selection that completes the rank: the solve takes q̈ = J⁻¹ h
    // without reducing any level (the `selection` module's bound on σ_min(J)). The answer,
    // the ranks and, once the factors are asked for, every J̄_i⁺ are those of the recursion.
    // With a row of the top level repeated, that level loses rank, M_O is singular, and the
    // general recursion answers.
    let mut r = rng(79);
    for case in 0..60 {
        let n = 6 + case % 13;
        let m = 1 + case % (n - 1);
        let mut levels = levels_over_a_selection(&mut r, n, m);
        let deficient = case % 4 == 3 && levels[0].dim() >= 2;
        if deficient {
            let row = levels[0].jacobian.row(0).clone_owned();
            levels[0].jacobian.set_row(1, &row);
        }
        let dims: Vec<usize> = levels.iter().map(|l| l.dim()).collect();
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &SolverSettings::default(), &mut q)
            .unwrap();
        check_lexicographic(&levels, &q, 1e-7);
        if deficient {
            assert_eq!(h.ranks()[0], dims[0] - 1, "case {case}");
            continue;
        }
        assert_eq!(h.ranks(), &dims[..], "case {case}");
        let want = reference_solution(&levels, 0.0);
        let err = (&q - &want).norm() / (1.0 + want.norm());
        assert!(err < REL_TOL, "case {case}: n {n}, dims {dims:?}: {err}");
        for (i, (l, na)) in levels.iter().zip(projectors_above(&levels)).enumerate() {
            let want = (&l.jacobian * na).pseudo_inverse(1e-9).unwrap();
            let got = h.pinv(i).clone();
            assert!(
                (&got - &want).norm() < REL_TOL * (1.0 + want.norm()),
                "case {case} level {i}: {}",
                (&got - &want).norm()
            );
        }
        assert_eq!(h.ranks(), &dims[..], "case {case}: the deferred reductions");
    }
}

#[test]
fn a_badly_scaled_stack_over_a_selection_gets_the_same_answer() {
    // The rows above scaled by 1e-6 under a rank threshold of 1e-8: the bound on σ_min of the
    // whole stack no longer clears the threshold, the levels above are reduced, and the bottom
    // selection (whose reduced rows do not depend on the scale) is still taken in closed form.
    let mut r = rng(80);
    let settings = SolverSettings {
        rank_threshold: 1e-8,
        ..Default::default()
    };
    for case in 0..40 {
        let n = 6 + case % 13;
        let m = 1 + case % (n - 1);
        let mut levels = levels_over_a_selection(&mut r, n, m);
        let nt = levels.len();
        for l in &mut levels[..nt - 1] {
            l.jacobian *= 1e-6;
            l.rhs *= 1e-6;
        }
        let dims: Vec<usize> = levels.iter().map(|l| l.dim()).collect();
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &settings, &mut q).unwrap();
        if h.ranks() != &dims[..] {
            // A random level above with a pivot under the threshold: not this test's case.
            continue;
        }
        let want = reference_solution(&levels, 0.0);
        let err = (&q - &want).norm() / (1.0 + want.norm());
        assert!(err < REL_TOL, "case {case}: n {n}, dims {dims:?}: {err}");
        let i = nt - 1;
        let want = (&levels[i].jacobian * &projectors_above(&levels)[i])
            .pseudo_inverse(1e-12)
            .unwrap();
        let got = h.pinv(i).clone();
        assert!(
            (&got - &want).norm() < REL_TOL * (1.0 + want.norm()),
            "case {case}: {}",
            (&got - &want).norm()
        );
    }
}

/// Random levels above a bottom level of `g` general rows and weighted joint rows: every
/// coordinate but `o` of them (chosen at random) selected once, each with weight ±`w`. The
/// levels above hold `upper` random rows in two levels.
fn levels_over_weighted_joints(
    r: &mut rand_chacha::ChaCha8Rng,
    n: usize,
    upper: usize,
    g: usize,
    o: usize,
    w: f64,
) -> Vec<TaskEquation> {
    use rand::seq::SliceRandom;
    use rand::Rng;
    let a = 1 + r.random_range(0..upper);
    let dims: Vec<usize> = [a, upper - a, g + n - o]
        .into_iter()
        .filter(|&d| d > 0)
        .collect();
    let mut levels = random_levels(r, n, &dims);
    let bottom = levels.last_mut().unwrap();
    bottom.jacobian.rows_mut(g, n - o).fill(0.0);
    let mut coords: Vec<usize> = (0..n).collect();
    coords.shuffle(r);
    for (row, &c) in coords[o..].iter().enumerate() {
        bottom.jacobian[(g + row, c)] = if r.random_bool(0.5) { w } else { -w };
    }
    levels
}

/// The prioritized solution of levels whose upper levels are consistent and of full rank (so
/// together they are solved exactly, by the least-norm q̈₀ = A⁺ h_A of their stacked rows A)
/// and whose bottom level J has full column rank in the null space of A: with Z an
/// orthonormal basis of that null space (the right singular vectors of A past its rank),
/// q̈ = q̈₀ + Z y, y the least-squares solution of (J Z) y = h − J q̈₀ (a tall matrix of full
/// column rank, solved by its SVD); and J̄⁺ = (J Z Zᵀ)⁺ = Z (J Z)⁺.
fn completing_bottom_reference(levels: &[TaskEquation]) -> (DVector<f64>, DMatrix<f64>) {
    let n = levels[0].nv();
    let (bottom, upper) = levels.split_last().unwrap();
    let rows: usize = upper.iter().map(|l| l.dim()).sum();
    let mut a = DMatrix::zeros(rows, n);
    let mut h = DVector::zeros(rows);
    let mut r0 = 0;
    for l in upper {
        a.rows_mut(r0, l.dim()).copy_from(&l.jacobian);
        h.rows_mut(r0, l.dim()).copy_from(&l.rhs);
        r0 += l.dim();
    }
    let q0 = a.clone().pseudo_inverse(1e-12).unwrap() * h;
    // Right singular vectors of A: the SVD of the square AᵀA-free padded matrix [A; 0].
    let mut padded = DMatrix::zeros(n, n);
    padded.rows_mut(0, rows).copy_from(&a);
    let svd = padded.svd(false, true);
    let vt = svd.v_t.unwrap();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&x, &y| svd.singular_values[y].total_cmp(&svd.singular_values[x]));
    let z = DMatrix::from_fn(n, n - rows, |t, c| vt[(order[rows + c], t)]);
    let jz_pinv = (&bottom.jacobian * &z).pseudo_inverse(1e-12).unwrap();
    let rho = &bottom.rhs - &bottom.jacobian * &q0;
    (q0 + &z * (&jz_pinv * rho), z * jz_pinv)
}

#[test]
fn a_bottom_level_of_weighted_joints_completing_the_rank_is_stepped_by_its_gram_matrix() {
    // The step, the ranks, G and J̄⁺ of the bottom level against the projector recursion, the
    // derivative of the solution and SVD; the factors that G and J̄⁺ need come from the QR run
    // afterwards, which must find the rank the Gram step decided. A joint row with another
    // weight, or selecting a coordinate already selected, is one of the general rows.
    let (mut twice, mut stepped) = (0, 0);
    let mut r = rng(78);
    for case in 0..60 {
        let n = 8 + case % 11;
        let upper = 2 + case % (n / 2);
        let g = 1 + case % 3;
        // Fewer coordinates left out than selected, and rows enough to complete the rank.
        let o = 1 + case % (n / 2 - 1).min(g + upper);
        let w = [0.1, 0.5, 2.0][case % 3];
        let mut levels = levels_over_weighted_joints(&mut r, n, upper, g, o, w);
        let i = levels.len() - 1;
        let m = levels[i].dim();
        // The rows carried through the reflectors: the general ones and a unit row per
        // coordinate left out; the Gram step is taken when they are fewer than the level's.
        let mut carried = g + o;
        if case % 5 == 0 {
            levels[i].jacobian.row_mut(m - 1).scale_mut(3.0);
            carried += 2;
        } else if case % 7 == 0 && m > n - upper {
            // (With a row to spare: the two rows are parallel.)
            let prev = levels[i].jacobian.row(m - 2).clone_owned();
            levels[i].jacobian.row_mut(m - 1).copy_from(&prev);
            twice += 1;
            carried += 1;
        }
        let dims: Vec<usize> = levels.iter().map(|l| l.dim()).collect();
        let settings = SolverSettings::default();
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &settings, &mut q).unwrap();
        if carried >= m {
            assert_eq!(h.stepped_by_gram(), None, "case {case}: nothing to gain");
        } else {
            assert_eq!(
                h.stepped_by_gram(),
                Some(i),
                "case {case}: n {n}, dims {dims:?}, o {o}"
            );
            stepped += 1;
        }
        assert_eq!(
            h.ranks()[i],
            n - upper,
            "case {case}: the bottom level takes what is left"
        );
        let (want, pinv) = completing_bottom_reference(&levels);
        let err = (&q - &want).norm() / (1.0 + want.norm());
        assert!(err < REL_TOL, "case {case}: {err}");
        check_lexicographic(&levels, &q, 1e-7);
        let got = h.pinv(i).clone();
        assert!(
            (&got - &pinv).norm() < REL_TOL * (1.0 + pinv.norm()),
            "case {case}: J̄⁺ {}",
            (&got - &pinv).norm()
        );
        h.build_g_levels(0, dims.len());
        assert_eq!(h.ranks()[i], n - upper, "case {case}: the QR's rank");
        let g_all = h.g().clone();
        assert_g_is_the_derivative(&mut levels, &dims, &settings, &q, &g_all, case);
    }
    assert!(twice >= 3, "{twice} cases with a coordinate selected twice");
    assert!(
        stepped >= 40,
        "{stepped} of 60 cases stepped by the Gram matrix"
    );
}

#[test]
fn the_gram_step_declines_what_it_does_not_cover_and_the_answer_stays_the_recursion_s() {
    // A level that does not complete the rank, and joint rows that miss a direction the
    // levels above leave free (their Gram matrix singular): each solved by the QR, the
    // projectors' answer.
    let mut r = rng(79);
    let n = 12;
    for case in 0..2 {
        let (g, o) = if case == 0 { (0, 7) } else { (2, 3) };
        let mut levels = levels_over_weighted_joints(&mut r, n, 4, g, o, 0.5);
        let i = levels.len() - 1;
        if case == 1 {
            levels[i].jacobian.rows_mut(0, g).fill(0.0);
            for l in &mut levels[..i] {
                l.jacobian.fill(0.0);
                l.rhs.fill(0.0);
            }
        }
        let dims: Vec<usize> = levels.iter().map(|l| l.dim()).collect();
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &SolverSettings::default(), &mut q)
            .unwrap();
        assert_eq!(h.stepped_by_gram(), None, "case {case}");
        let want = reference_solution(&levels, 0.0);
        let err = (&q - &want).norm() / (1.0 + want.norm());
        assert!(err < REL_TOL, "case {case}: {err}");
    }
}

#[test]
fn the_gram_step_is_damped_as_the_levels_above() {
    // A fixed λ: the DLS formula at every level. An adaptive rule whose region no level
    // reaches: no damping. An adaptive rule whose region holds every level, with λ_max
    // reached within rounding (σ ≤ ‖J‖ ≈ 10 against ε = 1e9): the DLS formula with λ_max.
    // Also G, the derivative of the solution, from the factors the QR builds afterwards with
    // the step's λ².
    let mut r = rng(80);
    for case in 0..30 {
        let n = 10 + case % 7;
        let upper = 3 + case % 3;
        let mut levels = levels_over_weighted_joints(&mut r, n, upper, 2, 2, 0.3);
        let i = levels.len() - 1;
        let (damping, l2) = match case % 3 {
            0 => (Damping::Fixed(0.2), 0.04),
            1 => (
                Damping::Adaptive {
                    max: 0.2,
                    threshold: 1e-6,
                },
                0.0,
            ),
            _ => (
                Damping::Adaptive {
                    max: 0.2,
                    threshold: 1e9,
                },
                0.04,
            ),
        };
        let settings = SolverSettings {
            damping,
            ..Default::default()
        };
        let dims: Vec<usize> = levels.iter().map(|l| l.dim()).collect();
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &settings, &mut q).unwrap();
        assert_eq!(h.stepped_by_gram(), Some(i), "case {case}");
        let want = if l2 == 0.0 {
            completing_bottom_reference(&levels).0
        } else {
            reference_solution_damped(&levels, |_| l2)
        };
        let err = (&q - &want).norm() / (1.0 + want.norm());
        assert!(err < REL_TOL, "case {case}: {err}");
        h.build_g_levels(0, dims.len());
        let g_all = h.g().clone();
        assert_g_is_the_derivative(&mut levels, &dims, &settings, &q, &g_all, case);
    }
}

#[test]
fn a_stack_short_of_square_over_a_selection_gets_the_recursion_s_answer_in_closed_form() {
    // The rows add up to n − d (d = 1, 2, 3): the bottom selection leaves d coordinates free.
    // The solution, the bottom level's block of G and its correction-map block (built in
    // closed form) against the projector recursion and the derivative of the solution.
    let mut r = rng(81);
    for case in 0..45 {
        let n = 8 + case % 11;
        let d = 1 + case % 3;
        let m = 1 + case % (n - d - 2);
        let mut levels = levels_over_a_selection(&mut r, n - d, m);
        for l in &mut levels {
            // d more coordinates, none selected: the upper levels' columns random.
            let mut j = DMatrix::zeros(l.dim(), n);
            j.columns_mut(0, n - d).copy_from(&l.jacobian);
            l.jacobian = j;
        }
        let i = levels.len() - 1;
        {
            use rand::Rng;
            for l in &mut levels[..i] {
                for c in n - d..n {
                    for row in 0..l.dim() {
                        l.jacobian[(row, c)] = r.random_range(-1.0..1.0);
                    }
                }
            }
        }
        let dims: Vec<usize> = levels.iter().map(|l| l.dim()).collect();
        assert_eq!(dims.iter().sum::<usize>(), n - d);
        let settings = SolverSettings::default();
        let mut h = Hierarchy::new(n, &dims);
        let mut q = DVector::zeros(n);
        h.solve(&levels, &settings, &mut q).unwrap();
        let want = reference_solution(&levels, 0.0);
        let err = (&q - &want).norm() / (1.0 + want.norm());
        assert!(err < REL_TOL, "case {case}: n {n}, dims {dims:?}: {err}");
        assert_eq!(h.ranks(), &dims[..], "case {case}");
        let closed = h.build_correction_map(&levels, i, i + 1);
        assert!(closed, "case {case}: the closed form applies");
        let map = h
            .correction_map()
            .columns(h.correction_offset(i), dims[i])
            .clone_owned();
        h.build_g_levels(0, dims.len());
        let g_all = h.g().clone();
        let g = g_all.columns(h.offset(i), dims[i]);
        assert!(
            (&map - g).amax() <= REL_TOL * g.amax().max(1.0),
            "case {case}: {}",
            (&map - g).amax()
        );
        assert_g_is_the_derivative(&mut levels, &dims, &settings, &q, &g_all, case);
    }
}
