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
//! triangular in the order O, C). One LU factorization of M_O (partial pivoting) and m_i
//! triangular solves cost about (2/3)(n − m_i)³ + 2(n − m_i)² m_i flops, against applying the
//! n reflectors of the whole hierarchy to m_i columns in the general construction.
//!
//! The result equals the general construction's up to rounding; when any condition fails (a
//! row with two entries, a coordinate selected twice, a singular or non-finite pivot) the
//! caller builds the block the general way.

use nalgebra::DMatrix;

use super::kernels::axpy;
use crate::error::all_finite;
use crate::task::TaskEquation;

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
    /// M_O (column-major, `no` × `no`, overwritten by its LU factors) and the right-hand
    /// sides, then solutions (column-major, `no` × m).
    lu: Vec<f64>,
    piv: Vec<usize>,
    rhs: Vec<f64>,
}

impl SelectionBlock {
    /// Room for `n` coordinates and levels of at most `mmax` rows.
    pub(crate) fn new(n: usize, mmax: usize) -> Self {
        Self {
            coord: vec![0; mmax],
            scale: vec![0.0; mmax],
            other_index: vec![0; n],
            row_of: vec![0; n],
            others: vec![0; n],
            lu: vec![0.0; n * n],
            piv: vec![0; n],
            rhs: vec![0.0; n * mmax.max(1)],
        }
    }

    /// Writes g_i (n × m_i, column-major) into `out` for the level `level` under the levels
    /// `above`, assuming the rank conditions of the module docs hold; false (and `out`
    /// unspecified) when the level is not a selection, the rows do not add up to n, or M_O has
    /// a zero or non-finite pivot. Allocates nothing.
    pub(crate) fn build(
        &mut self,
        above: &[TaskEquation],
        level: &TaskEquation,
        n: usize,
        out: &mut [f64],
    ) -> bool {
        let m = level.dim();
        let no = n.wrapping_sub(m);
        if m == 0 || m > n || above.iter().map(TaskEquation::dim).sum::<usize>() != no {
            return false;
        }
        if !self.detect(&level.jacobian, n) {
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
        lu_solve_rows(lu, no, &self.piv[..no], x, m);
        // g[O, c] = −X[:, c] / s_c; g[C[c], c] = 1 / s_c.
        for c in 0..m {
            let inv = 1.0 / self.scale[c];
            let col = &mut out[c * n..(c + 1) * n];
            col.fill(0.0);
            for (o, &t) in self.others[..no].iter().enumerate() {
                col[t] = -x[o * m + c] * inv;
            }
            col[self.coord[c]] = inv;
        }
        all_finite(&out[..n * m])
    }

    /// Finds the coordinate and entry of each row of `j` (m × n, column-major); false unless
    /// every row has exactly one non-zero entry and no two rows share a coordinate.
    fn detect(&mut self, j: &DMatrix<f64>, n: usize) -> bool {
        let m = j.nrows();
        let js = j.as_slice();
        self.coord[..m].fill(usize::MAX);
        let mut others = 0;
        for t in 0..n {
            let col = &js[t * m..(t + 1) * m];
            let mut hit = None;
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
            self.other_index[t] = if hit.is_some() {
                usize::MAX
            } else {
                self.others[others] = t;
                others += 1;
                others - 1
            };
        }
        self.coord[..m].iter().all(|&c| c != usize::MAX)
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

/// Solves (L U) X = P B in place for the factors of [`lu_factor`] and the m right-hand sides
/// of the row-major k × m `x`: row operations on rows of length m (one axpy each), so that all
/// right-hand sides go through each step together.
fn lu_solve_rows(lu: &[f64], k: usize, piv: &[usize], x: &mut [f64], m: usize) {
    for (j, &p) in piv.iter().enumerate().take(k) {
        if p != j {
            for c in 0..m {
                x.swap(j * m + c, p * m + c);
            }
        }
    }
    // L Y = P B (unit lower): row r −= L[r, j] row j, for j < r.
    for j in 0..k {
        let (head, tail) = x.split_at_mut((j + 1) * m);
        let xj = &head[j * m..];
        for (q, row) in tail.chunks_exact_mut(m).enumerate() {
            let l = lu[j * k + j + 1 + q];
            if l != 0.0 {
                axpy(-l, xj, row);
            }
        }
    }
    // U X = Y: row j /= U[j, j], then row r −= U[r, j] row j, for r < j.
    for j in (0..k).rev() {
        let (head, tail) = x.split_at_mut(j * m);
        let xj = &mut tail[..m];
        let d = 1.0 / lu[j * k + j];
        xj.iter_mut().for_each(|v| *v *= d);
        for (r, row) in head.chunks_exact_mut(m).enumerate() {
            let u = lu[j * k + r];
            if u != 0.0 {
                axpy(-u, xj, row);
            }
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
            lu_solve_rows(&lu, k, &piv, &mut x, 1);
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
        let mut x = vec![3.0, 5.0];
        lu_solve_rows(&a, 2, &piv, &mut x, 1);
        assert_eq!(x, vec![5.0, 3.0]);
        // A tiny pivot left in place would lose every digit of the first unknown:
        // [[1e-20, 1], [1, 1]] x = [1, 2] has x ≈ [1, 1].
        let mut a = vec![1e-20, 1.0, 1.0, 1.0];
        assert!(lu_factor(&mut a, 2, &mut piv));
        let mut x = vec![1.0, 2.0];
        lu_solve_rows(&a, 2, &piv, &mut x, 1);
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
        assert!(b.build(&above, &bottom, 3, &mut g));
        let g = DMatrix::from_column_slice(3, 2, &g);
        // By hand: column 0 moves x2 by 1/2 and x1 by −(1/2)/2; column 1 moves x0 by 1 and
        // x1 by −1/2.
        let want = DMatrix::from_row_slice(3, 2, &[0.0, 1.0, -0.25, -0.5, 0.5, 0.0]);
        assert!((&g - &want).amax() < 1e-15, "{g}");
        // Two rows on one coordinate, a row with two entries, rows that do not add up to n.
        let twice = level(2, 3, &[(0, 2, 2.0), (1, 2, 1.0)]);
        assert!(!b.build(&above, &twice, 3, &mut [0.0; 6]));
        let wide = level(2, 3, &[(0, 2, 2.0), (1, 0, 1.0), (1, 1, 1.0)]);
        assert!(!b.build(&above, &wide, 3, &mut [0.0; 6]));
        let short = level(1, 3, &[(0, 2, 2.0)]);
        assert!(!b.build(&above, &short, 3, &mut [0.0; 3]));
    }

    #[test]
    fn a_singular_matrix_is_refused() {
        let mut a = vec![1.0, 2.0, 2.0, 4.0];
        let mut piv = vec![0; 2];
        assert!(!lu_factor(&mut a, 2, &mut piv));
    }
}
