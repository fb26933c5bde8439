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
