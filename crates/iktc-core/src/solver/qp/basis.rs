//! The factorised active-set basis `J = L⁻ᵀ Q`, `R`, and its Givens updates.
//!
//! With `N` the `n × q` matrix of active constraint normals and `L⁻¹ N = Q [R; 0]` a QR
//! factorisation (`Q` orthogonal, `R` upper triangular `q × q`), the basis keeps
//!
//! ```text
//! J = L⁻ᵀ Q = [J₁ J₂]   (J₁: first q columns),   so that   Jᵀ N = [R; 0].
//! ```
//!
//! Adding a normal appends a column to `R` after rotating `Jᵀ n` so that its entries below row
//! `q` vanish; dropping one deletes a column of `R` and restores its triangular shape by
//! rotations of adjacent rows. The same rotations act on the columns of `J`. Each update costs
//! `O(n²)`; nothing is refactorised.

use nalgebra::DMatrix;

pub(crate) use crate::solver::kernels::{axpy, dot};

/// `J` and `R` on column-major storage of the workspace's capacity.
#[derive(Debug, Clone)]
pub(crate) struct ActiveBasis {
    /// Leading dimension (capacity in variables).
    ld: usize,
    /// Number of variables of the current problem.
    n: usize,
    /// Number of active normals.
    q: usize,
    /// `J = L⁻ᵀ Q`, leading `n × n` block used.
    j: DMatrix<f64>,
    /// `R`, leading `q × q` upper triangle used.
    r: DMatrix<f64>,
    /// Scratch of [`ActiveBasis::add`]: the Householder vector and `J v`.
    hv: Vec<f64>,
    hw: Vec<f64>,
}

/// A plane rotation `[c s; −s c]` that maps `(a, b)` to `(h, 0)`, `h = √(a² + b²)`.
#[derive(Debug, Clone, Copy)]
struct Givens {
    c: f64,
    s: f64,
    h: f64,
}

impl Givens {
    fn new(a: f64, b: f64) -> Self {
        // √(a² + b²) directly when the squares neither overflow nor underflow (libm's hypot is
        // several times slower), `hypot` otherwise.
        let squares = a * a + b * b;
        let h = if squares.is_finite() && squares >= f64::MIN_POSITIVE {
            squares.sqrt()
        } else {
            a.hypot(b)
        };
        let inv = 1.0 / h;
        Self {
            c: a * inv,
            s: b * inv,
            h,
        }
    }

    /// `(x, y) ← (c x + s y, −s x + c y)` element-wise (in blocks of four, which the compiler
    /// turns into SIMD lanes).
    fn apply(self, x: &mut [f64], y: &mut [f64]) {
        let (c, s) = (self.c, self.s);
        let len = x.len().min(y.len());
        let (x, y) = (&mut x[..len], &mut y[..len]);
        let mut xc = x.chunks_exact_mut(4);
        let mut yc = y.chunks_exact_mut(4);
        for (xb, yb) in (&mut xc).zip(&mut yc) {
            let a = [xb[0], xb[1], xb[2], xb[3]];
            let b = [yb[0], yb[1], yb[2], yb[3]];
            for k in 0..4 {
                xb[k] = c * a[k] + s * b[k];
                yb[k] = c * b[k] - s * a[k];
            }
        }
        for (xi, yi) in xc.into_remainder().iter_mut().zip(yc.into_remainder()) {
            let (a, b) = (*xi, *yi);
            *xi = c * a + s * b;
            *yi = c * b - s * a;
        }
    }
}

impl ActiveBasis {
    /// Storage for up to `capacity` variables.
    pub(crate) fn new(capacity: usize) -> Self {
        Self {
            ld: capacity,
            n: 0,
            q: 0,
            j: DMatrix::zeros(capacity, capacity),
            r: DMatrix::zeros(capacity, capacity),
            hv: vec![0.0; capacity],
            hw: vec![0.0; capacity],
        }
    }

    /// Number of active normals `q`.
    pub(crate) fn active(&self) -> usize {
        self.q
    }

    /// Starts an empty active set with `J = I` (the case `H = I`).
    pub(crate) fn reset_identity(&mut self, n: usize) {
        self.n = n;
        self.q = 0;
        let ld = self.ld;
        let j = self.j.as_mut_slice();
        for k in 0..n {
            let col = &mut j[k * ld..k * ld + n];
            col.fill(0.0);
            col[k] = 1.0;
        }
    }

    /// Starts an empty active set with `J = L⁻ᵀ`, `L` the lower Cholesky factor in `l`
    /// (same storage layout).
    pub(crate) fn reset_from_factor(&mut self, l: &[f64], n: usize) {
        self.n = n;
        self.q = 0;
        super::factor::inverse_transpose(l, self.j.as_mut_slice(), self.ld, n);
    }

    fn j_col(&self, k: usize) -> &[f64] {
        &self.j.as_slice()[k * self.ld..k * self.ld + self.n]
    }

    /// `d = Jᵀ v` (all `n` entries): `n` dot products with the columns of `J`, or, when `v` has
    /// few non-zeros (a box row, `v = ±e_i`), `d = Σ_{i: v_i ≠ 0} v_i J[i, :]`.
    pub(crate) fn project(&self, v: &[f64], d: &mut [f64]) {
        let (n, ld) = (self.n, self.ld);
        let v = &v[..n];
        let d = &mut d[..n];
        let nonzeros = v.iter().filter(|vi| **vi != 0.0).count();
        if 4 * nonzeros < n {
            d.fill(0.0);
            let j = self.j.as_slice();
            for (i, &vi) in v.iter().enumerate().filter(|(_, vi)| **vi != 0.0) {
                for (k, dk) in d.iter_mut().enumerate() {
                    *dk += vi * j[k * ld + i];
                }
            }
        } else {
            for (k, dk) in d.iter_mut().enumerate() {
                *dk = dot(self.j_col(k), v);
            }
        }
    }

    /// `z = J₂ d₂ = Σ_{k ≥ q} d_k J_k`: the primal step direction (the projection of `H⁻¹ n`
    /// onto the null space of the active normals, in the metric of H).
    pub(crate) fn primal_direction(&self, d: &[f64], z: &mut [f64]) {
        let z = &mut z[..self.n];
        z.fill(0.0);
        for (k, &dk) in d.iter().enumerate().take(self.n).skip(self.q) {
            if dk != 0.0 {
                axpy(dk, self.j_col(k), z);
            }
        }
    }

    /// `‖d₂‖ = ‖(d_q, …, d_{n−1})‖`: the size of the new normal orthogonal to the active ones.
    pub(crate) fn orthogonal_norm(&self, d: &[f64]) -> f64 {
        norm(&d[self.q..self.n])
    }

    /// `r = R⁻¹ d₁`: the dual step direction (minus the rate of change of the active
    /// multipliers per unit of the new one).
    pub(crate) fn dual_direction(&self, d: &[f64], r: &mut [f64]) {
        let q = self.q;
        let ld = self.ld;
        let rm = self.r.as_slice();
        let r = &mut r[..q];
        r.copy_from_slice(&d[..q]);
        for k in (0..q).rev() {
            let col = &rm[k * ld..k * ld + k + 1];
            r[k] /= col[k];
            let rk = r[k];
            if rk != 0.0 {
                for (ri, &rik) in r[..k].iter_mut().zip(&col[..k]) {
                    *ri -= rk * rik;
                }
            }
        }
    }

    /// Appends the normal whose projection is `d = Jᵀ n` (overwritten): one Householder
    /// reflection H of columns `q..n` of `J` maps `(d_q, …, d_{n−1})` to `(−σ sign d_q, 0, …)`,
    /// σ = ‖d₂‖, and the sign of column `q` is chosen so that `R`'s new diagonal entry is +σ;
    /// then `R`'s new column is `(d_0, …, d_q)`. `J H Hᵀ Jᵀ = J Jᵀ`, so `J Jᵀ = H⁻¹` still
    /// holds. When σ(σ + |d_q|) is not a normal number (data near under- or overflow) the
    /// reflection's scale is unsafe and rotations of adjacent columns are used instead. The
    /// caller has checked that `d₂ ≠ 0` (the normal is independent).
    pub(crate) fn add(&mut self, d: &mut [f64]) {
        let (n, q, ld) = (self.n, self.q, self.ld);
        if n > q + 1 && d[q + 1..n].iter().any(|x| *x != 0.0) {
            let sigma = norm(&d[q..n]);
            let dq = d[q];
            let scale = sigma * (sigma + dq.abs());
            if scale.is_normal() {
                // v = d₂ − α e₁, α = −sign(d_q) σ;  τ = 2 / vᵀv = 1 / (σ (σ + |d_q|)).
                let alpha = if dq >= 0.0 { -sigma } else { sigma };
                let len = n - q;
                let v = &mut self.hv[..len];
                v.copy_from_slice(&d[q..n]);
                v[0] = dq - alpha;
                let tau = 1.0 / scale;
                let j = self.j.as_mut_slice();
                let w = &mut self.hw[..n];
                w.fill(0.0);
                for (a, &va) in v.iter().enumerate() {
                    if va != 0.0 {
                        axpy(va, &j[(q + a) * ld..(q + a) * ld + n], w);
                    }
                }
                for (a, &va) in v.iter().enumerate() {
                    if va != 0.0 {
                        axpy(-tau * va, w, &mut j[(q + a) * ld..(q + a) * ld + n]);
                    }
                }
                // Column q now gives α; flip it when α < 0 so that R_qq = σ > 0.
                if alpha < 0.0 {
                    for x in &mut j[q * ld..q * ld + n] {
                        *x = -*x;
                    }
                }
                d[q] = sigma;
                d[q + 1..n].fill(0.0);
            } else {
                self.rotate_in(d);
            }
        }
        self.r.as_mut_slice()[q * ld..q * ld + q + 1].copy_from_slice(&d[..=q]);
        self.q += 1;
    }

    /// The rotation form of [`ActiveBasis::add`]'s reduction: rotations of columns `(k−1, k)`
    /// of `J`, `k = n−1 … q+1`, zero `d_k` into `d_{k−1}` (safe for any finite scale).
    fn rotate_in(&mut self, d: &mut [f64]) {
        let (n, q, ld) = (self.n, self.q, self.ld);
        let j = self.j.as_mut_slice();
        for k in ((q + 1)..n).rev() {
            if d[k] == 0.0 {
                continue;
            }
            let g = Givens::new(d[k - 1], d[k]);
            d[k - 1] = g.h;
            d[k] = 0.0;
            let (left, right) = j.split_at_mut(k * ld);
            g.apply(&mut left[(k - 1) * ld..(k - 1) * ld + n], &mut right[..n]);
        }
    }

    /// Removes the active normal at position `k < q`: deletes column `k` of `R`, then rotations
    /// of rows `(i, i+1)` of `R` and columns `(i, i+1)` of `J`, `i = k … q−2`, zero the
    /// sub-diagonal the deletion left.
    pub(crate) fn remove(&mut self, k: usize) {
        let (n, q, ld) = (self.n, self.q, self.ld);
        let rm = self.r.as_mut_slice();
        for col in k..q.saturating_sub(1) {
            rm.copy_within((col + 1) * ld..(col + 1) * ld + col + 2, col * ld);
        }
        let j = self.j.as_mut_slice();
        for i in k..q.saturating_sub(1) {
            let (a, b) = (rm[i * ld + i], rm[i * ld + i + 1]);
            if b == 0.0 {
                continue;
            }
            let g = Givens::new(a, b);
            rm[i * ld + i] = g.h;
            rm[i * ld + i + 1] = 0.0;
            for col in (i + 1)..(q - 1) {
                let (x, y) = (rm[col * ld + i], rm[col * ld + i + 1]);
                rm[col * ld + i] = g.c * x + g.s * y;
                rm[col * ld + i + 1] = -g.s * x + g.c * y;
            }
            let (left, right) = j.split_at_mut((i + 1) * ld);
            g.apply(&mut left[i * ld..i * ld + n], &mut right[..n]);
        }
        self.q = q.saturating_sub(1);
    }
}

/// `‖x‖₂`, without overflow or underflow of the squares: entries are scaled by the largest
/// magnitude when it lies outside `[1e-150, 1e150]`.
pub(crate) fn norm(x: &[f64]) -> f64 {
    /// Magnitudes whose squares (summed over up to 1e6 entries) stay normal and finite.
    const SAFE: std::ops::RangeInclusive<f64> = 1e-150..=1e150;
    let largest = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if largest == 0.0 || !largest.is_finite() || SAFE.contains(&largest) {
        dot(x, x).sqrt()
    } else {
        let scaled: f64 = x.iter().map(|v| (v / largest) * (v / largest)).sum();
        largest * scaled.sqrt()
    }
}

#[cfg(test)]
mod tests {
    //! The invariant `Jᵀ N = [R; 0]`, `J Jᵀ = H⁻¹` through random add/remove sequences, checked
    //! against products computed directly with nalgebra.

    use super::*;
    use nalgebra::DVector;

    /// Residual bound for products of O(n) rotated columns of size O(1), n ≤ 12.
    const TOL: f64 = 1e-12;

    /// Small deterministic pseudo-random numbers in [−1, 1) (a linear congruential generator, so
    /// the unit test needs no dev-dependency).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    fn check(basis: &ActiveBasis, l: &DMatrix<f64>, normals: &[Vec<f64>]) {
        let n = basis.n;
        let q = basis.q;
        assert_eq!(q, normals.len());
        let j = basis.j.view((0, 0), (n, n)).into_owned();
        // J Jᵀ = H⁻¹ = L⁻ᵀ L⁻¹  ⇔  Lᵀ J Jᵀ L = I
        let m = l.transpose() * &j * j.transpose() * l;
        assert!((m - DMatrix::identity(n, n)).amax() < TOL);
        for (k, nk) in normals.iter().enumerate() {
            let col = j.transpose() * DVector::from_column_slice(nk);
            for i in 0..n {
                let expected = if i <= k { basis.r[(i, k)] } else { 0.0 };
                assert!((col[i] - expected).abs() < TOL, "entry ({i}, {k})");
            }
        }
    }

    #[test]
    fn tiny_normals_take_the_rotation_path_and_keep_the_factorisation() {
        // Normals of size 1e-160: σ(σ + |d_q|) underflows, so `add` rotates instead of
        // reflecting. Checked relative to that size, with H = I (J Jᵀ = I).
        let mut rng = Lcg(11);
        let n = 6;
        let scale = 1e-160;
        let mut basis = ActiveBasis::new(n);
        basis.reset_identity(n);
        let mut d = vec![0.0; n];
        let mut normals = Vec::new();
        for _ in 0..4 {
            let v: Vec<f64> = (0..n).map(|_| rng.next() * scale).collect();
            basis.project(&v, &mut d);
            let sigma = norm(&d[basis.q..n]);
            assert!(!(sigma * sigma).is_normal());
            basis.add(&mut d);
            normals.push(v);
        }
        let j = basis.j.view((0, 0), (n, n)).into_owned();
        assert!((&j * j.transpose() - DMatrix::identity(n, n)).amax() < TOL);
        for (k, nk) in normals.iter().enumerate() {
            let col = j.transpose() * DVector::from_column_slice(nk) / scale;
            for i in 0..n {
                let expected = if i <= k { basis.r[(i, k)] / scale } else { 0.0 };
                assert!((col[i] - expected).abs() < TOL, "entry ({i}, {k})");
            }
            assert!(basis.r[(k, k)] > 0.0);
        }
    }

    #[test]
    fn add_and_remove_keep_the_factorisation() {
        let mut rng = Lcg(7);
        for n in 1..=12 {
            let m = DMatrix::from_fn(n, n, |_, _| rng.next());
            let h = m.transpose() * &m + DMatrix::identity(n, n);
            let mut chol = DMatrix::zeros(n, n);
            super::super::factor::cholesky(&h.as_view(), chol.as_mut_slice(), n, 1e-14)
                .expect("positive definite");
            let l = chol.lower_triangle();
            let mut basis = ActiveBasis::new(n);
            basis.reset_from_factor(chol.as_slice(), n);
            let mut normals: Vec<Vec<f64>> = Vec::new();
            let mut d = vec![0.0; n];
            for step in 0..4 * n {
                let remove = !normals.is_empty() && (normals.len() == n || step % 3 == 2);
                if remove {
                    let k = (rng.next().abs() * normals.len() as f64) as usize % normals.len();
                    basis.remove(k);
                    normals.remove(k);
                } else {
                    let v: Vec<f64> = (0..n).map(|_| rng.next()).collect();
                    basis.project(&v, &mut d);
                    basis.add(&mut d);
                    normals.push(v);
                }
                check(&basis, &l, &normals);
            }
        }
    }
}
