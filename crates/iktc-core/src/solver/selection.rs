//! The block g_i of G in closed form for a bottom level that selects coordinates, such as a
//! posture or joint task under a floating-base humanoid's feet, COM and pelvis tasks.
//!
//! ## When it applies
//!
//! Level i is the last level that moves q̈ (the levels below it have rank 0), it is solved
//! exactly (full rank, no damping: J_i Δq̈ = Δh_i for every change Δh_i), the levels above it
//! have full rank (so Δq̈, which lies in the null space of the rows they keep, satisfies
//! J_k Δq̈ = 0 for every k < i), the stacked rows are as many as the coordinates
//! (Σ_{k≤i} m_k = n), and every row of J_i has a single non-zero entry s_c, in a coordinate
//! C\[c\] no other row uses. Then g_i = ∂q̈/∂h_i is the unique solution of
//!
//! ```text
//! [ J_{<i} ]          [ 0 ]
//! [  J_i   ] g_i  =   [ I ],
//! ```
//!
//! and with the coordinates split into the selected ones C and the others O (n − m_i of them,
//! as many as the rows above), J_i g_i = I gives the rows C directly and the rows above give
//! the rows O:
//!
//! ```text
//! g_i[C[c], c'] = δ_{cc'} / s_c,     M_O g_i[O, :] = −J_{<i}[:, C] diag(1/s),
//! ```
//!
//! with M_O = J_{<i}\[:, O\] square and invertible (the stacked matrix is, and it is block
//! triangular in the order O, C). One LU factorization of M_O (partial pivoting) costs about
//! (2/3)(n − m_i)³ flops, against applying the n reflectors of the whole hierarchy to m_i
//! columns in the general construction. The right-hand side B = J_{<i}\[:, C\] has non-zero
//! rows only where a row above reaches a selected coordinate (on a humanoid: the COM rows,
//! not the feet or the pelvis, whose Jacobians have exact zeros in the upper body's columns),
//! so X = M_O⁻¹ B is taken as X = Y B_nz with Y = M_O⁻¹ E_nz: one triangular solve per
//! non-zero row of B (k of them) instead of one per column (m_i), and a product of
//! (n − m_i) k m_i.
//!
//! The result equals the general construction's up to rounding; when any condition fails (a
//! row with two entries, a coordinate selected twice, a singular or non-finite pivot) the
//! caller builds the block the general way.
//!
//! ## The level's step and its rank without its QR
//!
//! The same block gives level i's step of the prioritized solution: level i is solved exactly
//! in the null space of the levels above, so q̈ = q̈_{i−1} + g_i (h_i − J_i q̈_{i−1})
//! ([`SelectionBlock::step`]; J_i q̈ is s_c q̈\[C\[c\]\] row by row). Whether the hierarchy's
//! pivoted QR would keep all m_i rows of level i follows from X = M_O⁻¹ J_{<i}\[:, C\]: the
//! null space of the rows above is spanned by N = \[−X; I\] (coordinates O, then C), so with
//! Z = N (NᵀN)^{−1/2} orthonormal the reduced level J_i Z = diag(s) (I + XᵀX)^{−1/2} has
//!
//! ```text
//! σ_min(J_i Z) ≥ min_c |s_c| / √(1 + ‖X‖₂²) ≥ min_c |s_c| / √(1 + ‖X‖_F²) =: σ_low,
//! ```
//!
//! and every pivot |R_jj| of its column-pivoted QR is at least σ_min(J_i Z) (the distance of
//! a column from the span of the columns before it): above the rank threshold when σ_low is
//! ([`SelectionBlock::sigma_lower_bound`]). The last pivot, which sets the adaptive damping,
//! is at least σ_low too.
//!
//! ## The whole stack without QR
//!
//! The same holds for every level above when the whole square stack J (levels 0..=i, n × n)
//! is far from singular: level k reduced to the null space of the rows above it has, for any
//! y, ‖Zᵀ J_kᵀ y‖ = min_a ‖J_{≤k}ᵀ \[−a; y\]‖ ≥ σ_min(J) ‖y‖ (J_{≤k} is a subset of J's
//! rows), so all its pivots exceed σ_min(J). In the order (O, C),
//!
//! ```text
//! J = [ M_O  B ]      J⁻¹ = [ M_O⁻¹  −X S⁻¹ ]      ‖J⁻¹‖₂ ≤ ‖M_O⁻¹‖₂ + (‖X‖₂ + 1) ‖S⁻¹‖₂,
//!     [ 0    S ],           [ 0       S⁻¹   ],
//! ```
//!
//! S = diag(s), and with M_O = Pᵀ L U, ‖M_O⁻¹‖₂ ≤ √(n − m_i) ‖U⁻¹‖_∞ ‖L⁻¹‖_∞, each triangular
//! factor bounded through its comparison matrix M(T) (|T_jj| on the diagonal, −|T_rj| off it):
//! |T⁻¹| ≤ M(T)⁻¹ entrywise, so ‖T⁻¹‖_∞ ≤ max(M(T)⁻¹ 𝟙), one triangular solve each (Higham,
//! *Accuracy and Stability of Numerical Algorithms*, 2nd ed., Thm. 8.12). When 1 / that bound
//! clears the rank threshold every level keeps all its rows, and the prioritized solution of a
//! square stack solved exactly at every level is J⁻¹ h: q̈\[O\] = M_O⁻¹ h_{<i} − X S⁻¹ h_i,
//! q̈\[C\] = S⁻¹ h_i ([`SelectionBlock::solve_above`], then [`SelectionBlock::step`]).
//!
//! ## Stacks short of square
//!
//! When the rows of every level up to the last, a selection, add up to n − d (a posture task
//! that leaves d ≤ [`MAX_SPARE`] joints out), d unit rows selecting d coordinates the level
//! leaves out (those the levels above move least: [`SelectionBlock::choose_spare`]) make the
//! stack square, J_a = \[J; E\]. With every level solved exactly (the bound above, for J_a:
//! the levels' rows are among its rows), the prioritized solution satisfies J q̈ = h and lies
//! in the row space of J (each level's step J̄_i⁺ ρ_i lies in that of J̄_i = J_i N_{i−1}), so it
//! is the least-norm solution of J q̈ = h. The solutions of J q̈ = h are q̈_a + V t, with
//! q̈_a = J_a⁻¹ \[h; 0\] and V = J_a⁻¹ \[0; I\] (the appended rows' columns of the closed block,
//! a basis of the null space of J), so
//!
//! ```text
//! q̈ = (I − V (VᵀV)⁻¹ Vᵀ) q̈_a,    g_i = (I − V (VᵀV)⁻¹ Vᵀ) g_{a,i}
//! ```
//!
//! ([`SelectionBlock::project_spare`]; g_i is linear in h_i the same way).

use nalgebra::DMatrix;

use super::kernels::{axpy, dot};
use crate::task::TaskEquation;

/// The most coordinates a stack may leave free and still be solved in closed form ("Stacks
/// short of square" in the module docs): each costs one more column of the block and one
/// projection.
pub(crate) const MAX_SPARE: usize = 3;

/// Scratch of the closed form, sized once.
#[derive(Debug, Clone)]
pub(crate) struct SelectionBlock {
    /// The coordinate selected by each row of the level, and the row's entry there.
    coord: Vec<usize>,
    scale: Vec<f64>,
    /// Per coordinate: its index among the others O, or `usize::MAX` when it is selected; and
    /// for a selected one, the row that selects it.
    other_index: Vec<usize>,
    row_of: Vec<usize>,
    /// The coordinates O, in order.
    others: Vec<usize>,
    /// M_O (column-major, `no` × `no`, overwritten by its LU factors), B = J_{<i}\[:, C\]
    /// (row-major, `no` × m), its non-zero rows nz, a unit right-hand side e and
    /// Y = M_O⁻¹ E_nz scattered to n-long columns (column-major, n × k).
    lu: Vec<f64>,
    piv: Vec<usize>,
    rhs: Vec<f64>,
    nz: Vec<usize>,
    e: Vec<f64>,
    y: Vec<f64>,
    /// The coordinates selected by the rows appended to a stack short of square
    /// ([`SelectionBlock::choose_spare`]).
    spare: Vec<usize>,
    /// Rows m_i and ‖X‖_F² of the last successful [`SelectionBlock::build`].
    m: usize,
    no: usize,
    xx: f64,
}

impl SelectionBlock {
    /// Room for `n` coordinates and levels of at most `mmax` rows.
    pub(crate) fn new(n: usize, mmax: usize) -> Self {
        let mmax = mmax.max(n);
        Self {
            coord: vec![0; mmax],
            scale: vec![0.0; mmax],
            other_index: vec![0; n],
            row_of: vec![0; n],
            others: vec![0; n],
            lu: vec![0.0; n * n],
            piv: vec![0; n],
            rhs: vec![0.0; n * mmax.max(1)],
            nz: vec![0; n],
            e: vec![0.0; n],
            y: vec![0.0; n * n],
            spare: vec![0; MAX_SPARE],
            m: 0,
            no: 0,
            xx: 0.0,
        }
    }

    /// Writes g_i (n × m_i, column-major) into `out` for the level `level` under the levels
    /// `above`, assuming the rank conditions of the module docs hold; false (and `out`
    /// unspecified) when the level is not a selection, the rows do not add up to n, or M_O has
    /// a zero or non-finite pivot. Allocates nothing.
    ///
    /// With `spare` > 0 the first `spare` coordinates of [`SelectionBlock::choose_spare`] are
    /// selected by unit rows appended to the level ("Stacks short of square" in the module
    /// docs): `out` is then n × (m_i + spare), the appended rows' columns last.
    pub(crate) fn build(
        &mut self,
        above: &[TaskEquation],
        level: &TaskEquation,
        spare: usize,
        n: usize,
        out: &mut [f64],
    ) -> bool {
        let m = level.dim() + spare;
        let no = n.wrapping_sub(m);
        if level.dim() == 0 || m > n || above.iter().map(TaskEquation::dim).sum::<usize>() != no {
            return false;
        }
        if !self.detect(&level.jacobian, spare, n) {
            return false;
        }
        // M_O (column-major) and B = J_{<i}[:, C] (row-major, `no` × m), level by level.
        let (lu, x) = (&mut self.lu[..no * no], &mut self.rhs[..no * m]);
        for c in 0..m {
            self.row_of[self.coord[c]] = c;
        }
        let mut r0 = 0;
        for l in above {
            let mk = l.dim();
            let js = l.jacobian.as_slice();
            for t in 0..n {
                let col = &js[t * mk..(t + 1) * mk];
                let o = self.other_index[t];
                if o == usize::MAX {
                    let c = self.row_of[t];
                    for (q, &v) in col.iter().enumerate() {
                        x[(r0 + q) * m + c] = v;
                    }
                } else {
                    lu[o * no + r0..o * no + r0 + mk].copy_from_slice(col);
                }
            }
            r0 += mk;
        }
        if !lu_factor(lu, no, &mut self.piv[..no]) {
            return false;
        }
        // Y = M_O⁻¹ E_nz, one unit right-hand side per non-zero row of B, each column scattered
        // to the coordinates O of an n-long column (zero on C): Y_j[others[o]] = (M_O⁻¹ e_r)[o].
        let mut k = 0;
        for r in 0..no {
            if x[r * m..(r + 1) * m].iter().any(|v| *v != 0.0) {
                self.nz[k] = r;
                k += 1;
            }
        }
        for (j, &r) in self.nz[..k].iter().enumerate() {
            let e = &mut self.e[..no];
            e.fill(0.0);
            e[r] = 1.0;
            lu_solve(lu, no, &self.piv[..no], e);
            let yj = &mut self.y[j * n..(j + 1) * n];
            yj.fill(0.0);
            for (&t, &v) in self.others[..no].iter().zip(e.iter()) {
                yj[t] = v;
            }
        }
        // Column c of g: −(Σ_j B[nz_j, c] Y_j) / s_c, and 1 / s_c at C[c]. Its squared norm
        // less 1 / s_c², times s_c², is ‖X[:, c]‖² (X = Y B_nz); their sum, finite only when
        // every entry is, gives σ_low.
        let mut xx = 0.0;
        for c in 0..m {
            let inv = 1.0 / self.scale[c];
            let col = &mut out[c * n..(c + 1) * n];
            col.fill(0.0);
            for (j, &r) in self.nz[..k].iter().enumerate() {
                let f = x[r * m + c];
                if f != 0.0 {
                    axpy(-f * inv, &self.y[j * n..(j + 1) * n], col);
                }
            }
            xx += (dot(col, col) * (self.scale[c] * self.scale[c]) - 1.0).max(0.0);
            col[self.coord[c]] = inv;
        }
        (self.m, self.no, self.xx) = (m, no, xx);
        xx.is_finite() && self.scale[..m].iter().all(|s| (1.0 / s).is_finite())
    }

    /// σ_low = min_c |s_c| / √(1 + ‖X‖_F²) of the last successful [`SelectionBlock::build`]:
    /// a lower bound on the smallest singular value of the level's rows reduced to the null
    /// space of the levels above \[task units per coordinate unit\] (module docs).
    pub(crate) fn sigma_lower_bound(&self) -> f64 {
        let smin = self.scale[..self.m]
            .iter()
            .fold(f64::INFINITY, |a, s| a.min(s.abs()));
        smin / (1.0 + self.xx).sqrt()
    }

    /// A lower bound on the smallest singular value of the whole stacked Jacobian J of the
    /// level and the levels above (n × n) for the last successful [`SelectionBlock::build`]
    /// \[task units per coordinate unit\] (module docs): 1 / (√(n − m_i) β_L β_U +
    /// (‖X‖_F + 1) / min_c |s_c|), β_T = max(M(T)⁻¹ 𝟙) for the triangular factors of M_O and
    /// their comparison matrices. Allocates nothing.
    pub(crate) fn stack_sigma_lower_bound(&mut self) -> f64 {
        let no = self.no;
        let (lu, z) = (&self.lu[..no * no], &mut self.e[..no]);
        let max = |z: &[f64]| z.iter().fold(0.0_f64, |a, &v| a.max(v));
        // M(L) z = 𝟙 (L unit lower, entries −|l_rj| off the diagonal), by columns.
        z.fill(1.0);
        for j in 0..no {
            let zj = z[j];
            for (zr, l) in z[j + 1..].iter_mut().zip(&lu[j * no + j + 1..(j + 1) * no]) {
                *zr += l.abs() * zj;
            }
        }
        let beta_l = max(z);
        // M(U) z = 𝟙 (U upper), by columns from the last.
        z.fill(1.0);
        for j in (0..no).rev() {
            let zj = z[j] / lu[j * no + j].abs();
            z[j] = zj;
            for (zr, u) in z[..j].iter_mut().zip(&lu[j * no..j * no + j]) {
                *zr += u.abs() * zj;
            }
        }
        let beta_u = max(z);
        let smin = self.scale[..self.m]
            .iter()
            .fold(f64::INFINITY, |a, s| a.min(s.abs()));
        1.0 / ((no as f64).sqrt() * beta_l * beta_u + (self.xx.sqrt() + 1.0) / smin)
    }

    /// q ← (M_O⁻¹ h_{<i} on the coordinates O, zero on C): with [`SelectionBlock::step`]
    /// after it, J⁻¹ h for the square stack of the levels `above` (their right-hand sides
    /// h_{<i}) and the level of the last successful [`SelectionBlock::build`]. Allocates
    /// nothing.
    pub(crate) fn solve_above(&mut self, above: &[TaskEquation], q: &mut [f64]) {
        let no = self.no;
        let e = &mut self.e[..no];
        let mut r0 = 0;
        for l in above {
            e[r0..r0 + l.dim()].copy_from_slice(l.rhs.as_slice());
            r0 += l.dim();
        }
        lu_solve(&self.lu[..no * no], no, &self.piv[..no], e);
        q.fill(0.0);
        for (&t, &v) in self.others[..no].iter().zip(e.iter()) {
            q[t] = v;
        }
    }

    /// Level i's step of the prioritized solution, q ← q + g_i (h − J_i q) with J_i q =
    /// s_c q\[C\[c\]\] row by row, for the block `g` (n × m_i, column-major) of the last
    /// successful [`SelectionBlock::build`] and the level's right-hand side `h` \[task units\].
    /// `res`: scratch of m_i entries.
    pub(crate) fn step(&self, h: &[f64], g: &[f64], n: usize, res: &mut [f64], q: &mut [f64]) {
        let m = self.m;
        for c in 0..m {
            res[c] = h[c] - self.scale[c] * q[self.coord[c]];
        }
        for (c, col) in g.chunks_exact(n).take(m).enumerate() {
            if res[c] != 0.0 {
                axpy(res[c], col, q);
            }
        }
    }

    /// Finds the coordinate and entry of each row of `j` (m × n, column-major), then of the unit
    /// rows selecting `extra` (rows m.., entry 1); false unless every row has exactly one
    /// non-zero entry and no two rows share a coordinate.
    fn detect(&mut self, j: &DMatrix<f64>, spare: usize, n: usize) -> bool {
        let m = j.nrows();
        let js = j.as_slice();
        self.coord[..m + spare].fill(usize::MAX);
        let mut others = 0;
        for t in 0..n {
            let col = &js[t * m..(t + 1) * m];
            let mut hit = None;
            if let Some(e) = self.spare[..spare].iter().position(|&c| c == t) {
                hit = Some(m + e);
                self.coord[m + e] = t;
                self.scale[m + e] = 1.0;
            }
            // Most columns are all zero: one branch-free pass decides (the scan below finds the
            // row of a non-zero column).
            if col.iter().fold(false, |a, &v| a | (v != 0.0)) {
                for (r, &v) in col.iter().enumerate() {
                    if v != 0.0 {
                        if hit.is_some() || self.coord[r] != usize::MAX {
                            return false;
                        }
                        hit = Some(r);
                        self.coord[r] = t;
                        self.scale[r] = v;
                    }
                }
            }
            self.other_index[t] = if hit.is_some() {
                usize::MAX
            } else {
                self.others[others] = t;
                others += 1;
                others - 1
            };
        }
        self.coord[..m + spare].iter().all(|&c| c != usize::MAX)
    }

    /// Chooses `spare` coordinates that no row of `level` selects, those with the smallest
    /// column norms in the rows `above` (the ones the levels above move least; ties to the
    /// lower index), for [`SelectionBlock::build`]. False when fewer than `spare` are left or
    /// `spare` exceeds [`MAX_SPARE`].
    pub(crate) fn choose_spare(
        &mut self,
        above: &[TaskEquation],
        level: &TaskEquation,
        spare: usize,
        n: usize,
    ) -> bool {
        if spare > MAX_SPARE {
            return false;
        }
        let m = level.dim();
        let js = level.jacobian.as_slice();
        let norms = &mut self.e[..n];
        for (t, x) in norms.iter_mut().enumerate() {
            *x = if js[t * m..(t + 1) * m].iter().any(|v| *v != 0.0) {
                f64::INFINITY
            } else {
                above
                    .iter()
                    .map(|l| {
                        let c = &l.jacobian.as_slice()[t * l.dim()..(t + 1) * l.dim()];
                        dot(c, c)
                    })
                    .sum()
            };
        }
        for k in 0..spare {
            let Some(best) = (0..n)
                .filter(|&t| norms[t].is_finite())
                .min_by(|&a, &b| norms[a].total_cmp(&norms[b]).then(a.cmp(&b)))
            else {
                return false;
            };
            self.spare[k] = best;
            norms[best] = f64::INFINITY;
        }
        true
    }

    /// After [`SelectionBlock::build`] with `spare` appended rows (`g`, n × (m + spare)) and the
    /// solution `q` of the square stack: both projected off the span V of the appended rows'
    /// columns (the null space of the stack without them), q ← q − V (VᵀV)⁻¹ Vᵀ q and each of
    /// the first m columns likewise (module docs). V is orthonormalised in place (modified
    /// Gram–Schmidt). False when V is not of full rank (the build could not have succeeded).
    pub(crate) fn project_spare(
        &self,
        g: &mut [f64],
        n: usize,
        m: usize,
        spare: usize,
        q: &mut [f64],
    ) -> bool {
        let (cols, v) = g[..n * (m + spare)].split_at_mut(n * m);
        for j in 0..spare {
            let (done, rest) = v.split_at_mut(j * n);
            let vj = &mut rest[..n];
            for u in done.chunks_exact(n) {
                let c = dot(u, vj);
                axpy(-c, u, vj);
            }
            let norm = dot(vj, vj).sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                return false;
            }
            vj.iter_mut().for_each(|x| *x /= norm);
        }
        for x in std::iter::once(q).chain(cols.chunks_exact_mut(n)) {
            for u in v.chunks_exact(n) {
                let c = dot(u, x);
                axpy(-c, u, x);
            }
        }
        true
    }
}

/// LU factorization with partial pivoting of the column-major k × k `a` in place (L unit lower,
/// U upper; `piv[j]` the row swapped with row j at step j); false on a zero or non-finite pivot.
fn lu_factor(a: &mut [f64], k: usize, piv: &mut [usize]) -> bool {
    for j in 0..k {
        let (mut p, mut best) = (j, a[j * k + j].abs());
        for r in j + 1..k {
            let v = a[j * k + r].abs();
            if v > best {
                p = r;
                best = v;
            }
        }
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        piv[j] = p;
        if p != j {
            for c in 0..k {
                a.swap(c * k + j, c * k + p);
            }
        }
        let d = 1.0 / a[j * k + j];
        for r in j + 1..k {
            a[j * k + r] *= d;
        }
        // Trailing update, column by column: a[r, c] −= l[r] u[c].
        let (left, right) = a.split_at_mut((j + 1) * k);
        let l = &left[j * k + j + 1..j * k + k];
        for col in right.chunks_exact_mut(k) {
            let u = col[j];
            if u != 0.0 {
                for (x, &lr) in col[j + 1..].iter_mut().zip(l) {
                    *x -= lr * u;
                }
            }
        }
    }
    true
}

/// Solves (L U) x = P b in place for the factors of [`lu_factor`] and one right-hand side
/// `x` (length k), by columns of the factors: forward with L (unit lower), skipping the
/// steps whose entry is zero (the leading entries of a unit right-hand side), then back with U.
fn lu_solve(lu: &[f64], k: usize, piv: &[usize], x: &mut [f64]) {
    for (j, &p) in piv.iter().enumerate().take(k) {
        x.swap(j, p);
    }
    // L y = P b: x[j + 1..] −= x_j L[j + 1.., j].
    for j in 0..k {
        let xj = x[j];
        if xj != 0.0 {
            axpy(-xj, &lu[j * k + j + 1..(j + 1) * k], &mut x[j + 1..k]);
        }
    }
    // U x = y: x_j = y_j / U[j, j], then x[..j] −= x_j U[..j, j].
    for j in (0..k).rev() {
        let xj = x[j] / lu[j * k + j];
        x[j] = xj;
        if xj != 0.0 {
            axpy(-xj, &lu[j * k..j * k + j], &mut x[..j]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn lu_solves_against_nalgebra() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for k in [1usize, 2, 5, 18] {
            let a = DMatrix::from_fn(k, k, |_, _| rng.random_range(-1.0..1.0));
            let b = DVector::from_fn(k, |_, _| rng.random_range(-1.0..1.0));
            let mut lu = a.as_slice().to_vec();
            let mut piv = vec![0; k];
            assert!(lu_factor(&mut lu, k, &mut piv));
            let mut x = b.as_slice().to_vec();
            lu_solve(&lu, k, &piv, &mut x);
            let want = a.clone().lu().solve(&b).unwrap();
            for (got, w) in x.iter().zip(want.iter()) {
                // Relative to the solution's size; a well-conditioned random k ≤ 18 system
                // loses a few digits at most.
                assert!((got - w).abs() <= 1e-10 * want.amax().max(1.0), "k {k}");
            }
        }
    }

    #[test]
    fn pivoting_handles_a_zero_on_the_diagonal() {
        // [[0, 1], [1, 0]] (column-major the same): without row exchanges the first pivot is 0.
        let mut a = vec![0.0, 1.0, 1.0, 0.0];
        let mut piv = vec![0; 2];
        assert!(lu_factor(&mut a, 2, &mut piv));
        let mut x = vec![3.0_f64, 5.0];
        lu_solve(&a, 2, &piv, &mut x);
        assert_eq!(x, vec![5.0, 3.0]);
        // A tiny pivot left in place would lose every digit of the first unknown:
        // [[1e-20, 1], [1, 1]] x = [1, 2] has x ≈ [1, 1].
        let mut a = vec![1e-20, 1.0, 1.0, 1.0];
        assert!(lu_factor(&mut a, 2, &mut piv));
        let mut x = vec![1.0_f64, 2.0];
        lu_solve(&a, 2, &piv, &mut x);
        assert!(
            (x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12,
            "{x:?}"
        );
    }

    #[test]
    fn a_non_finite_pivot_is_refused() {
        let mut a = vec![f64::INFINITY, 0.0, 0.0, 1.0];
        let mut piv = vec![0; 2];
        assert!(!lu_factor(&mut a, 2, &mut piv));
    }

    /// One level of `rows` × `n` from (row, column, value) entries.
    fn level(rows: usize, n: usize, entries: &[(usize, usize, f64)]) -> TaskEquation {
        let mut e = TaskEquation::zeros("level", rows, n);
        for &(r, c, v) in entries {
            e.jacobian[(r, c)] = v;
        }
        e
    }

    #[test]
    fn the_block_of_a_selection_and_what_is_not_one() {
        // n = 3: one row above (x0 + 2 x1 + x2), a bottom level selecting x2 (scale 2) and x0.
        let above = [level(1, 3, &[(0, 0, 1.0), (0, 1, 2.0), (0, 2, 1.0)])];
        let bottom = level(2, 3, &[(0, 2, 2.0), (1, 0, 1.0)]);
        let mut b = SelectionBlock::new(3, 2);
        let mut g = vec![0.0; 6];
        assert!(b.build(&above, &bottom, 0, 3, &mut g));
        let g = DMatrix::from_column_slice(3, 2, &g);
        // By hand: column 0 moves x2 by 1/2 and x1 by −(1/2)/2; column 1 moves x0 by 1 and
        // x1 by −1/2.
        let want = DMatrix::from_row_slice(3, 2, &[0.0, 1.0, -0.25, -0.5, 0.5, 0.0]);
        assert!((&g - &want).amax() < 1e-15, "{g}");
        // Two rows on one coordinate, a row with two entries, rows that do not add up to n.
        let twice = level(2, 3, &[(0, 2, 2.0), (1, 2, 1.0)]);
        assert!(!b.build(&above, &twice, 0, 3, &mut [0.0; 6]));
        let wide = level(2, 3, &[(0, 2, 2.0), (1, 0, 1.0), (1, 1, 1.0)]);
        assert!(!b.build(&above, &wide, 0, 3, &mut [0.0; 6]));
        let short = level(1, 3, &[(0, 2, 2.0)]);
        assert!(!b.build(&above, &short, 0, 3, &mut [0.0; 3]));
    }

    #[test]
    fn a_singular_matrix_is_refused() {
        let mut a = vec![1.0, 2.0, 2.0, 4.0];
        let mut piv = vec![0; 2];
        assert!(!lu_factor(&mut a, 2, &mut piv));
    }
}
