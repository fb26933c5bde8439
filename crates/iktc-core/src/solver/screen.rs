//! A certificate of infeasibility for IKTC's correction QPs, tried before the QP.
//!
//! The correction QP of levels i..n_T asks for Δh with l ≤ G Δh ≤ u (G: n × m_c, l and u the
//! box shifted by the prioritized q̈). The dual active-set method proves an empty set only after
//! fixing every one of the m_c variables, i.e. m_c iterations of O(m_c²) each, and in a
//! humanoid run the same level stays infeasible for many ticks in a row.
//!
//! The test: take m_c rows S of G — those the last infeasible QP of this level ended with
//! active — with G_S invertible. Every feasible Δh has w = G_S Δh in the box \[l_S, u_S\], and
//! any other row j satisfies g_jᵀ Δh = cᵀ w with G_Sᵀ c = g_j. Over the box, cᵀ w ranges over
//!
//! \[Σ_k min(c_k l_k, c_k u_k), Σ_k max(c_k l_k, c_k u_k)\];
//!
//! if that interval misses \[l_j, u_j\] the set is empty. This is a relaxation (only the rows
//! S ∪ {j} are used), so it never calls a feasible set infeasible; with every bound widened by
//! the QP's feasibility tolerance, and a rounding margin on top, it also never contradicts the
//! QP, which accepts violations up to that tolerance. When it proves nothing the QP runs as
//! before. It costs one LU factorization of an m_c × m_c matrix (m_c³/3) and two triangular
//! solves per violated row.

use nalgebra::{DMatrix, DMatrixView};

use super::qp::{ActiveConstraint, QpConstraint};
use crate::buffer::Buffer;

/// Relative rounding allowance of the interval test \[–\]: the interval must miss the row's
/// bounds by this fraction of the magnitudes summed into it, on top of the feasibility
/// tolerance. Far above the round-off of an m_c-term sum (≈ m_c · 1e-16).
const ROUNDING_MARGIN: f64 = 1e-9;

/// A pivot of the LU factorization of G_Sᵀ smaller than this fraction of the largest entry
/// makes G_S count as singular, and the test is skipped \[–\].
const PIVOT_TOLERANCE: f64 = 1e-10;

/// Workspace of the test: the rows remembered per level, the LU factors, a solution vector.
#[derive(Debug, Clone)]
pub(crate) struct Screen {
    rows: Vec<Buffer<usize>>,
    /// Per level: the row the last infeasible QP could not add (its certificate's own row).
    failed: Vec<Option<usize>>,
    lu: DMatrix<f64>,
    piv: Vec<usize>,
    c: Vec<f64>,
}

impl Screen {
    /// Room for `levels` levels and QPs of up to `cap` variables.
    pub(crate) fn new(levels: usize, cap: usize) -> Self {
        Self {
            rows: (0..levels).map(|_| Buffer::with_capacity(cap)).collect(),
            failed: vec![None; levels],
            lu: DMatrix::zeros(cap.max(1), cap.max(1)),
            piv: vec![0; cap],
            c: vec![0.0; cap],
        }
    }

    /// Remembers the inequality rows an infeasible QP of `level` ended with active, and the
    /// row it failed on. Allocates nothing (the row lists were sized for the largest QP).
    pub(crate) fn remember(
        &mut self,
        level: usize,
        active: &[ActiveConstraint],
        failed: Option<QpConstraint>,
    ) {
        self.failed[level] = match failed {
            Some(QpConstraint::Lower { row } | QpConstraint::Upper { row }) => Some(row),
            _ => None,
        };
        let rows = &mut self.rows[level];
        rows.clear();
        for a in active {
            let row = match a.constraint {
                QpConstraint::Lower { row } | QpConstraint::Upper { row } => row,
                QpConstraint::Equality { .. } => continue,
            };
            if rows.len() == rows.capacity() {
                rows.clear();
                return;
            }
            rows.push(row);
        }
    }

    /// True when the rows remembered for `level` prove that l ≤ G x ≤ u has no solution with
    /// every row within `tol`. False means "not proven", never "feasible".
    pub(crate) fn proves_infeasible(
        &mut self,
        level: usize,
        g: &DMatrixView<'_, f64>,
        lower: &[f64],
        upper: &[f64],
        tol: f64,
    ) -> bool {
        let mc = g.ncols();
        let rows = &self.rows[level];
        if mc == 0 || rows.len() != mc || mc > self.piv.len() {
            return false;
        }
        // A = G_Sᵀ (column a of A is row rows[a] of G), mc × mc stored compactly (leading
        // dimension mc), factored P A = L U in place.
        let a = &mut self.lu.as_mut_slice()[..mc * mc];
        for k in 0..mc {
            let gk = g.column(k);
            let gk = gk.as_slice();
            for (col, &row) in rows.iter().enumerate() {
                a[col * mc + k] = gk[row];
            }
        }
        // max |a|, four independent lanes (f64::max is a serial chain with NaN handling).
        let mut lanes = [0.0_f64; 4];
        for chunk in a.chunks(4) {
            for (m, v) in lanes.iter_mut().zip(chunk) {
                let v = v.abs();
                *m = if v > *m { v } else { *m };
            }
        }
        let scale = lanes
            .iter()
            .fold(0.0_f64, |m, &v| if v > m { v } else { m });
        if scale == 0.0 || !scale.is_finite() {
            return false;
        }
        for k in 0..mc {
            let (head, tail) = a.split_at_mut((k + 1) * mc);
            let colk = &mut head[k * mc..];
            let mut p = k;
            let mut big = colk[k].abs();
            for (r, v) in colk.iter().enumerate().skip(k + 1) {
                if v.abs() > big {
                    big = v.abs();
                    p = r;
                }
            }
            if big <= PIVOT_TOLERANCE * scale {
                return false;
            }
            self.piv[k] = p;
            if p != k {
                colk.swap(k, p);
                for col in head[..k * mc].chunks_exact_mut(mc) {
                    col.swap(k, p);
                }
                for col in tail.chunks_exact_mut(mc) {
                    col.swap(k, p);
                }
            }
            let colk = &mut head[k * mc..];
            let inv = 1.0 / colk[k];
            for v in &mut colk[k + 1..] {
                *v *= inv;
            }
            let lk = &colk[k + 1..];
            for col in tail.chunks_exact_mut(mc) {
                let f = col[k];
                if f != 0.0 {
                    for (x, l) in col[k + 1..].iter_mut().zip(lk) {
                        *x -= f * l;
                    }
                }
            }
        }
        let ld = mc;
        // Candidates: the row the last QP failed on (the row of its own certificate), then
        // the rows violated at Δh = 0.
        let n = g.nrows();
        let first = self.failed[level].filter(|&j| j < n);
        let rest = (0..n).filter(|&j| Some(j) != first);
        for j in first.into_iter().chain(rest) {
            let (lj, uj) = (lower[j], upper[j]);
            let violated = lj > tol || uj < -tol;
            if (!violated && Some(j) != first) || rows.contains(&j) {
                continue;
            }
            // A c = g_j: permute, L y = P g_j, U c = y.
            let c = &mut self.c[..mc];
            for (k, ck) in c.iter_mut().enumerate() {
                *ck = g.column(k)[j];
            }
            for k in 0..mc {
                c.swap(k, self.piv[k]);
            }
            for k in 0..mc {
                let ck = c[k];
                if ck != 0.0 {
                    let lk = &a[k * ld + k + 1..(k + 1) * ld];
                    for (x, l) in c[k + 1..].iter_mut().zip(lk) {
                        *x -= ck * l;
                    }
                }
            }
            for k in (0..mc).rev() {
                c[k] /= a[k * ld + k];
                let ck = c[k];
                if ck != 0.0 {
                    let uk = &a[k * ld..k * ld + k];
                    for (x, u) in c[..k].iter_mut().zip(uk) {
                        *x -= ck * u;
                    }
                }
            }
            // The range of g_jᵀ Δh = cᵀ w over w in the widened box of the rows S.
            let (mut lo, mut hi, mut mag) = (0.0, 0.0, 0.0);
            let mut bounded = true;
            for (k, &ck) in c.iter().enumerate() {
                if ck == 0.0 {
                    continue;
                }
                let (l, u) = (lower[rows[k]] - tol, upper[rows[k]] + tol);
                if !(l.is_finite() && u.is_finite()) {
                    bounded = false;
                    break;
                }
                let (a1, a2) = (ck * l, ck * u);
                lo += a1.min(a2);
                hi += a1.max(a2);
                mag += a1.abs() + a2.abs();
            }
            if !(bounded && lo.is_finite() && hi.is_finite()) {
                continue;
            }
            let finite = |x: f64| if x.is_finite() { x.abs() } else { 0.0 };
            let slack = ROUNDING_MARGIN * (mag + finite(lj) + finite(uj));
            if hi < lj - tol - slack || lo > uj + tol + slack {
                return true;
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    //! The screen against an independent evaluation of the same certificate (nalgebra's LU
    //! instead of the in-place one, the interval summed directly), on seeded random problems,
    //! plus the cases where the screen must decline.
    use super::{Screen, PIVOT_TOLERANCE, ROUNDING_MARGIN};
    use crate::solver::qp::{ActiveConstraint, QpConstraint};
    use nalgebra::DMatrix;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Cases within this relative distance of the decision threshold, or with G_S this close
    /// to singular (ratio of smallest to largest singular value), are left out of the
    /// comparison: there the two evaluations may round differently [–].
    const AMBIGUOUS: f64 = 1e-6;

    fn active(rows: &[usize], upper: bool) -> Vec<ActiveConstraint> {
        rows.iter()
            .map(|&row| ActiveConstraint {
                constraint: if upper {
                    QpConstraint::Upper { row }
                } else {
                    QpConstraint::Lower { row }
                },
                multiplier: 1.0,
            })
            .collect()
    }

    /// The certificate evaluated independently: `Some(verdict)`, or `None` when ambiguous.
    fn oracle(
        g: &DMatrix<f64>,
        rows: &[usize],
        failed: Option<usize>,
        lower: &[f64],
        upper: &[f64],
        tol: f64,
    ) -> Option<bool> {
        let mc = g.ncols();
        let gs = DMatrix::from_fn(mc, mc, |r, c| g[(rows[r], c)]);
        let sv = gs.clone().singular_values();
        if sv.min() <= AMBIGUOUS * sv.max() {
            return Some(false).filter(|_| sv.min() <= PIVOT_TOLERANCE * 1e-3 * sv.max());
        }
        let lu = gs.transpose().lu();
        let mut proven = false;
        for j in 0..g.nrows() {
            let violated = lower[j] > tol || upper[j] < -tol;
            if !(violated || Some(j) == failed) || rows.contains(&j) {
                continue;
            }
            let c = lu.solve(&g.row(j).transpose())?;
            let (mut lo, mut hi, mut mag) = (0.0, 0.0, 0.0);
            let mut bounded = true;
            for (k, &ck) in c.iter().enumerate() {
                let (l, u) = (lower[rows[k]] - tol, upper[rows[k]] + tol);
                if ck == 0.0 {
                    continue;
                }
                if !(l.is_finite() && u.is_finite()) {
                    bounded = false;
                }
                lo += (ck * l).min(ck * u);
                hi += (ck * l).max(ck * u);
                mag += (ck * l).abs() + (ck * u).abs();
            }
            if !bounded {
                continue;
            }
            let fin = |x: f64| if x.is_finite() { x.abs() } else { 0.0 };
            let slack = ROUNDING_MARGIN * (mag + fin(lower[j]) + fin(upper[j]));
            let miss = (lower[j] - tol - slack - hi).max(lo - upper[j] - tol - slack);
            let scale = mag + fin(lower[j]) + fin(upper[j]) + 1.0;
            if miss.abs() <= AMBIGUOUS * scale {
                return None;
            }
            proven |= miss > 0.0;
        }
        Some(proven)
    }

    /// Random problems: G with entries of a random scale, the rows S tight around G_S x0, the
    /// other rows random intervals (some one-sided), a random failed row.
    #[test]
    fn the_screen_agrees_with_an_independent_evaluation() {
        let mut rng = ChaCha8Rng::seed_from_u64(2024);
        let (mut proven, mut declined, mut compared) = (0, 0, 0);
        let mut screen = Screen::new(2, 8);
        for case in 0..4000 {
            let mc = rng.random_range(1..=6);
            let n = mc + rng.random_range(1..=8);
            let scale = [1.0, 1e3, 1e-3][case % 3];
            let g = DMatrix::from_fn(n, mc, |_, _| scale * rng.random_range(-1.0..1.0));
            let x0: Vec<f64> = (0..mc).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut rows: Vec<usize> = (0..n).collect();
            for i in 0..mc {
                let k = rng.random_range(i..n);
                rows.swap(i, k);
            }
            rows.truncate(mc);
            let tol = [0.0, 1e-9, 1e-3][case % 3];
            let (mut lower, mut upper) = (vec![0.0; n], vec![0.0; n]);
            for j in 0..n {
                let gx: f64 = (0..mc).map(|k| g[(j, k)] * x0[k]).sum();
                if rows.contains(&j) {
                    let w = scale * rng.random_range(0.0..0.05);
                    (lower[j], upper[j]) = (gx - w, gx + w);
                } else {
                    let a = scale * rng.random_range(-2.0..2.0);
                    let b = scale * rng.random_range(0.0..1.0);
                    (lower[j], upper[j]) = match rng.random_range(0..4) {
                        0 => (f64::NEG_INFINITY, a),
                        1 => (a, f64::INFINITY),
                        _ => (a, a + b),
                    };
                }
            }
            let failed = rng.random_bool(0.5).then(|| rng.random_range(0..n));
            let level = case % 2;
            let fail_row = failed.map(|row| QpConstraint::Upper { row });
            screen.remember(level, &active(&rows, case % 4 == 0), fail_row);
            let got = screen.proves_infeasible(level, &g.as_view(), &lower, &upper, tol);
            let Some(want) = oracle(&g, &rows, failed, &lower, &upper, tol) else {
                continue;
            };
            assert_eq!(got, want, "case {case}: mc {mc}, n {n}, rows {rows:?}");
            compared += 1;
            if got {
                proven += 1;
            } else {
                declined += 1;
            }
        }
        // Both verdicts must be exercised for the comparison to mean anything.
        assert!(
            compared > 3000 && proven > 500 && declined > 500,
            "{proven} / {declined}"
        );
    }

    /// Two rows fix x to 0 within `tol` and a third asks for x ≥ 1: proven; the same third row
    /// asking for x ≥ 0 (feasible) is not.
    #[test]
    fn a_plain_contradiction_is_proven_and_a_feasible_set_is_not() {
        let g = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
        let mut screen = Screen::new(1, 2);
        screen.remember(0, &active(&[0, 1], false), None);
        let tol = 1e-9;
        let lo = [0.0, 0.0, 1.0];
        let hi = [0.0, 0.0, 2.0];
        assert!(screen.proves_infeasible(0, &g.as_view(), &lo, &hi, tol));
        // x1 + x2 = 0 is reachable: not violated at 0, so never a candidate.
        assert!(!screen.proves_infeasible(0, &g.as_view(), &[0.0, 0.0, 0.0], &hi, tol));
        // The contradiction is smaller than the tolerance: the QP would accept it.
        // (Upper end 1e-6: the rounding margin, 1e-9 of the magnitudes, stays far below tol.)
        let small = [0.0, 0.0, 1e-6];
        let near = [0.0, 0.0, 1.5 * tol];
        assert!(!screen.proves_infeasible(0, &g.as_view(), &near, &small, tol));
        // ... and larger than twice the tolerance (each S row may move by tol): proven.
        let beyond = [0.0, 0.0, 3.5 * tol];
        assert!(screen.proves_infeasible(0, &g.as_view(), &beyond, &small, tol));
        // Row j violated from above.
        let below = [-2.0, -2.0, -2.0];
        let cap = [0.0, 0.0, -1.0];
        let mut tight = [0.0, 0.0, 0.0];
        tight[..2].copy_from_slice(&[0.0, 0.0]);
        assert!(screen.proves_infeasible(0, &g.as_view(), &tight, &cap, tol));
        assert!(!screen.proves_infeasible(0, &g.as_view(), &below, &cap, tol));
    }

    /// The margin of the test: a miss smaller than `ROUNDING_MARGIN` times the magnitudes summed
    /// is not a proof.
    #[test]
    fn a_miss_within_the_rounding_margin_is_not_a_proof() {
        let g = DMatrix::from_row_slice(2, 1, &[1.0, 1.0]);
        let mut screen = Screen::new(1, 1);
        screen.remember(0, &active(&[0], true), None);
        // Row 0 pins x to 1e3; row 1 asks x ≥ 1e3 + δ (mirrored below), δ a multiple d of
        // the margin: the magnitudes summed are 2x (the interval) + x + 1e4 (row 1's ends).
        let x = 1e3;
        let margin = ROUNDING_MARGIN * (2.0 * x + x + 1e4);
        for (d, want) in [(0.9, false), (1.1, true)] {
            let lo = [x, x + d * margin];
            let hi = [x, 1e4];
            let got = screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0);
            assert_eq!(got, want, "above: miss {d} × margin");
            // Mirrored (x pinned to −1e3, so that row 1 is violated at Δh = 0).
            let lo = [-x, -1e4];
            let hi = [-x, -x - d * margin];
            let got = screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0);
            assert_eq!(got, want, "below: miss {d} × margin");
        }
    }

    /// A certificate whose LU needs a row exchange (G_S a permutation) is proven.
    #[test]
    fn a_certificate_needing_a_pivot_exchange_is_proven() {
        let g = DMatrix::from_row_slice(3, 2, &[0.0, 1.0, 1.0, 0.0, 1.0, 1.0]);
        let mut screen = Screen::new(1, 2);
        screen.remember(0, &active(&[0, 1], false), None);
        let (lo, hi) = ([0.0, 0.0, 1.0], [0.0, 0.0, 2.0]);
        assert!(screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
    }

    /// G_S singular or nearly so (a pivot below `PIVOT_TOLERANCE` of the largest entry): the
    /// screen declines even where the set is in fact empty.
    #[test]
    fn a_near_singular_certificate_is_declined() {
        let s = 1e3;
        let eps = 0.1 * PIVOT_TOLERANCE * s;
        let g = DMatrix::from_row_slice(3, 2, &[s, 0.0, s, eps, 0.0, 1.0]);
        let mut screen = Screen::new(1, 2);
        screen.remember(0, &active(&[0, 1], false), None);
        let (lo, hi) = ([0.0, 0.0, 1.0], [0.0, 0.0, 2.0]);
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 1e-9));
        // Well conditioned (eps 100× above the threshold): the same contradiction is proven.
        let eps = 100.0 * PIVOT_TOLERANCE * s;
        let g = DMatrix::from_row_slice(3, 2, &[s, 0.0, s, eps, 0.0, 1.0]);
        assert!(screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 1e-12));
    }

    /// Nothing remembered, a different count of rows than variables, more active rows than
    /// room, equality rows only, an unbounded S row: no proof.
    #[test]
    fn the_screen_declines_without_a_usable_certificate() {
        let g = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
        let (lo, hi) = ([0.0, 0.0, 1.0], [0.0, 0.0, 2.0]);
        let mut screen = Screen::new(1, 2);
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        // A full certificate first (it fills the factors), then one row for two variables:
        // the stale factors must not be used.
        screen.remember(0, &active(&[0, 1], false), None);
        assert!(screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        screen.remember(0, &active(&[0], false), None);
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        // Three active rows into room for two: the list is dropped.
        screen.remember(0, &active(&[0, 1, 2], false), None);
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        let eq: Vec<ActiveConstraint> = (0..2)
            .map(|row| ActiveConstraint {
                constraint: QpConstraint::Equality { row },
                multiplier: 1.0,
            })
            .collect();
        screen.remember(0, &eq, None);
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        // Row 1 of S unbounded above: x2 may grow, x1 + x2 ≥ 1 is reachable.
        screen.remember(0, &active(&[0, 1], false), None);
        let hi_open = [0.0, f64::INFINITY, 2.0];
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi_open, 0.0));
        assert!(screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        // A zero G: no scale, no proof; a non-finite entry: no proof.
        let zero = DMatrix::zeros(3, 2);
        assert!(!screen.proves_infeasible(0, &zero.as_view(), &lo, &hi, 0.0));
        let mut bad = g.clone();
        bad[(0, 0)] = f64::NAN;
        assert!(!screen.proves_infeasible(0, &bad.as_view(), &lo, &hi, 0.0));
    }

    /// The failed row is tried even when it is not violated at Δh = 0 (a row the QP failed on
    /// can be satisfiable alone), and a failed row out of range is ignored.
    #[test]
    fn the_failed_row_is_a_candidate_even_when_not_violated_at_zero() {
        // S: x1 = 1, x2 = −1; row 2: x1 − x2 ∈ [−1, 1] — satisfied at 0, not on S (x1 − x2 = 2).
        let g = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, -1.0]);
        let (lo, hi) = ([1.0, -1.0, -1.0], [1.0, -1.0, 1.0]);
        let mut screen = Screen::new(1, 2);
        screen.remember(0, &active(&[0, 1], false), None);
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        screen.remember(
            0,
            &active(&[0, 1], false),
            Some(QpConstraint::Lower { row: 2 }),
        );
        assert!(screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        screen.remember(
            0,
            &active(&[0, 1], false),
            Some(QpConstraint::Lower { row: 9 }),
        );
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        // One past the last row (n = 3): ignored.
        let past = Some(QpConstraint::Lower { row: 3 });
        screen.remember(0, &active(&[0, 1], false), past);
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
        screen.remember(
            0,
            &active(&[0, 1], false),
            Some(QpConstraint::Equality { row: 2 }),
        );
        assert!(!screen.proves_infeasible(0, &g.as_view(), &lo, &hi, 0.0));
    }
}
