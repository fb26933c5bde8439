//! A warm start of IKTC's correction QP: the active set of the level's last optimum, checked
//! before the QP runs.
//!
//! The correction QP of levels i..n_T is min ½‖x‖² s.t. l ≤ G x ≤ u (x = Δh^a_i, G: n × m_c).
//! When the limits bind for many ticks in a row, its optimal active set changes little from one
//! tick to the next, while the dual active-set method rebuilds it from nothing, one constraint
//! per iteration at O(m_c²) each.
//!
//! The guess: the rows A with sides s_k (+1 lower end l, −1 upper end u) active at the level's
//! last optimum. With N the m_c-long rows g_kᵀ of G on A and b_k their active ends, the
//! least-norm point on them is
//!
//! x = Nᵀ y,   (N Nᵀ) y = b,
//!
//! (one Cholesky factorization of the |A| × |A| Gram matrix). It is the QP's optimum exactly
//! when the KKT conditions hold: every multiplier has its side's sign (s_k y_k ≥ 0, since
//! ∇½‖x‖² = x = Σ_k y_k g_k) and every row holds, l_j − ε ≤ g_jᵀ x ≤ u_j + ε with ε the QP's
//! feasibility tolerance (the cold QP accepts the same violations). The optimum of this
//! strictly convex QP is unique, so an accepted guess is the QP's answer up to rounding and the
//! tolerance; a rejected one costs O(|A|² m_c + n m_c) and the QP runs as before.

use nalgebra::DMatrixView;

use super::kernels::{axpy, dot};
use super::qp::{ActiveConstraint, QpConstraint};
use crate::buffer::Buffer;

/// A Cholesky pivot of the Gram matrix N Nᵀ below this fraction of its largest diagonal entry
/// rejects the guess \[–\]: its active rows are (nearly) dependent, and the QP, which keeps only
/// independent ones, decides instead. Smaller values accept worse-conditioned guesses (x
/// loses about log10(1/pivot) digits); larger ones fall back to the QP more often.
const PIVOT_TOLERANCE: f64 = 1e-12;

/// The remembered active sets and the scratch of the check. Sized once; allocates nothing.
#[derive(Debug, Clone)]
pub(crate) struct WarmStart {
    /// Per level: (row, side) of the last optimum, side +1 for the lower end, −1 for the upper.
    sets: Vec<Buffer<(usize, f64)>>,
    /// N, row-major |A| × m_c (leading dimension `cap`).
    rows: Vec<f64>,
    /// The Gram matrix and its Cholesky factor, |A| × |A| (leading dimension `cap`).
    gram: Vec<f64>,
    /// y, then b.
    y: Vec<f64>,
    /// G x.
    gx: Vec<f64>,
    cap: usize,
}

impl WarmStart {
    /// Room for `levels` levels, QPs of up to `cap` variables and `n` rows.
    pub(crate) fn new(levels: usize, cap: usize, n: usize) -> Self {
        Self {
            sets: (0..levels).map(|_| Buffer::with_capacity(cap)).collect(),
            rows: vec![0.0; cap * cap],
            gram: vec![0.0; cap * cap],
            y: vec![0.0; cap],
            gx: vec![0.0; n],
            cap,
        }
    }

    /// Remembers the inequality rows active at the optimum of `level`'s QP (an empty set when
    /// there are more than the QP has variables, which an optimum never has).
    pub(crate) fn remember(&mut self, level: usize, active: &[ActiveConstraint]) {
        let set = &mut self.sets[level];
        set.clear();
        for a in active {
            let entry = match a.constraint {
                QpConstraint::Lower { row } => (row, 1.0),
                QpConstraint::Upper { row } => (row, -1.0),
                QpConstraint::Equality { .. } => continue,
            };
            if set.len() == set.capacity() {
                set.clear();
                return;
            }
            set.push(entry);
        }
    }

    /// Forgets the set of `level` (its QP was infeasible).
    pub(crate) fn forget(&mut self, level: usize) {
        self.sets[level].clear();
    }

    /// Tries the remembered set of `level` on min ½‖x‖² s.t. `lower` ≤ G x ≤ `upper`; true
    /// (with the optimum in `x`) when it satisfies the KKT conditions within `tol`.
    pub(crate) fn solve(
        &mut self,
        level: usize,
        g: &DMatrixView<'_, f64>,
        lower: &[f64],
        upper: &[f64],
        tol: f64,
        x: &mut [f64],
    ) -> bool {
        let (n, mc) = (g.nrows(), g.ncols());
        let set = &self.sets[level];
        let q = set.len();
        let ld = self.cap;
        if q == 0 || q > mc || mc > ld || n > self.gx.len() || x.len() != mc {
            return false;
        }
        // N: row k is row `set[k].0` of G; b_k its active end.
        for c in 0..mc {
            let col = g.column(c);
            let col = col.as_slice();
            for (k, &(row, _)) in set.iter().enumerate() {
                self.rows[k * ld + c] = col[row];
            }
        }
        let b = &mut self.y[..q];
        for (bk, &(row, side)) in b.iter_mut().zip(set.iter()) {
            *bk = if side > 0.0 { lower[row] } else { upper[row] };
            if !bk.is_finite() {
                return false;
            }
        }
        // Gram matrix N Nᵀ (lower triangle, column k holds rows k.. of column k) and its
        // Cholesky factor in place.
        let rows = &self.rows;
        let gram = &mut self.gram;
        let mut biggest = 0.0_f64;
        for k in 0..q {
            let nk = &rows[k * ld..k * ld + mc];
            for l in k..q {
                gram[k * ld + l] = dot(nk, &rows[l * ld..l * ld + mc]);
            }
            biggest = biggest.max(gram[k * ld + k]);
        }
        for k in 0..q {
            let (head, tail) = gram.split_at_mut((k + 1) * ld);
            let colk = &mut head[k * ld..];
            let pivot = colk[k];
            if pivot.is_nan() || pivot <= PIVOT_TOLERANCE * biggest {
                return false;
            }
            let d = pivot.sqrt();
            for v in &mut colk[k..q] {
                *v /= d;
            }
            let lk = &colk[k + 1..q];
            for (j, col) in tail.chunks_exact_mut(ld).take(q - k - 1).enumerate() {
                // column k + 1 + j: entries k + 1 + j.. decrease by L[i, k] L[k + 1 + j, k].
                let f = lk[j];
                if f != 0.0 {
                    axpy(-f, &lk[j..], &mut col[k + 1 + j..q]);
                }
            }
        }
        // y = (L Lᵀ)⁻¹ b.
        let y = &mut self.y[..q];
        for k in 0..q {
            y[k] /= gram[k * ld + k];
            let yk = y[k];
            axpy(-yk, &gram[k * ld + k + 1..k * ld + q], &mut y[k + 1..q]);
        }
        for k in (0..q).rev() {
            let t = dot(&gram[k * ld + k + 1..k * ld + q], &y[k + 1..q]);
            y[k] = (y[k] - t) / gram[k * ld + k];
        }
        // Dual feasibility: every multiplier on its side.
        if set
            .iter()
            .zip(y.iter())
            .any(|(&(_, side), &yk)| side * yk < 0.0)
        {
            return false;
        }
        // x = Nᵀ y, then primal feasibility of every row.
        x.fill(0.0);
        for (k, &yk) in y.iter().enumerate() {
            axpy(yk, &rows[k * ld..k * ld + mc], x);
        }
        let gx = &mut self.gx[..n];
        gx.fill(0.0);
        for (c, &xc) in x.iter().enumerate() {
            if xc != 0.0 {
                axpy(xc, g.column(c).as_slice(), gx);
            }
        }
        gx.iter()
            .zip(lower.iter().zip(upper))
            .all(|(&v, (&l, &u))| v >= l - tol && v <= u + tol)
    }
}
