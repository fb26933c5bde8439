//! The prioritized solution (paper eqs. 5–9) and the correction map G (eqs. 19–21, Algorithm 1).
//!
//! ## Method
//!
//! For level i with Jacobian J_i (m_i × n) and right-hand side h_i:
//!
//! q̈_i = q̈_{i−1} + J̄_i^{λ+} (h_i − J_i q̈_{i−1}),  J̄_i = J_i N_{i−1}  (eqs. 5–7),
//!
//! where N_{i−1} projects onto the null space of the levels above. Instead of n × n projectors
//! we keep an orthonormal basis Z (n × k) of that null space, N_{i−1} = Z Zᵀ. Then
//! J̄_i = (J_i Z) Zᵀ and, with the column-pivoted QR (J_i Z)ᵀ Π = Q R of rank r (pivots
//! |R_jj| above the rank threshold), J_i Z = Π R_rᵀ Q_rᵀ, so
//!
//! J̄_i^{λ+} = Z Q_r (R_r R_rᵀ + λ² I)⁻¹ R_r Πᵀ,
//!
//! which is the Moore–Penrose inverse for λ = 0 (eq. 4) and the damped least-squares inverse
//! (eqs. 8–9) otherwise. The next basis is Z Q_{r+1..k}. Cost O(n k m) per level: no n × n
//! product, no SVD.
//!
//! Algorithm 1 builds G = \[g_1 … g_{n_T}\] with g_i = (Π_{k>i} (I − J̄_k^{λ+} J_k)) J̄_i^{λ+},
//! so that adding corrections Δh to the right-hand sides changes the solution by G Δh (eq. 20).

use nalgebra::{DMatrix, DVector};

use super::settings::{Damping, SolverSettings};
use crate::error::{check_dim, Error, Result};
use crate::task::TaskEquation;

/// Workspace of the prioritized recursion, sized once for given level dimensions.
#[derive(Debug, Clone)]
pub struct Hierarchy {
    n: usize,
    dims: Vec<usize>,
    offsets: Vec<usize>,
    /// J̄_i^{λ+}, n × m_i per level.
    pinv: Vec<DMatrix<f64>>,
    /// Rank kept per level.
    ranks: Vec<usize>,
    /// G, n × Σm_i, blocks in level order; columns of level i valid once built.
    g: DMatrix<f64>,
    /// Null-space basis Z (first k columns valid) and its product with Q.
    z: DMatrix<f64>,
    zq: DMatrix<f64>,
    k: usize,
    /// (J Z)ᵀ in place → R (upper part), Householder vectors.
    a: DMatrix<f64>,
    v: DMatrix<f64>,
    tau: Vec<f64>,
    perm: Vec<usize>,
    colnorm: Vec<f64>,
    /// Small r × r system and r × m result.
    s: DMatrix<f64>,
    t: DMatrix<f64>,
    tmp_n: DVector<f64>,
    tmp_m: DVector<f64>,
    residual: DVector<f64>,
    /// Jᵀ of the current level (n × m_max) and T with permuted columns (m_max × m_max).
    jt: DMatrix<f64>,
    tp: DMatrix<f64>,
    /// Indices of the non-zero entries of one task row.
    nz: Vec<usize>,
    /// The last level keeps J̄⁺ factored as Z · Y with Y = Q_r T Πᵀ (k × m): its solution
    /// needs only J̄⁺ times the residual, and J̄⁺ itself only when G is built.
    y_last: DMatrix<f64>,
    tmp_k: DVector<f64>,
    k_last: usize,
    last_ready: bool,
}

impl Hierarchy {
    /// A workspace for `n` velocity coordinates and levels of the given sizes.
    pub fn new(n: usize, dims: &[usize]) -> Self {
        let mmax = dims.iter().copied().max().unwrap_or(0).max(1);
        let total: usize = dims.iter().sum();
        let mut offsets = Vec::with_capacity(dims.len());
        let mut o = 0;
        for d in dims {
            offsets.push(o);
            o += d;
        }
        Self {
            n,
            dims: dims.to_vec(),
            offsets,
            pinv: dims.iter().map(|&m| DMatrix::zeros(n, m)).collect(),
            ranks: vec![0; dims.len()],
            g: DMatrix::zeros(n, total.max(1)),
            z: DMatrix::zeros(n, n),
            zq: DMatrix::zeros(n, n),
            k: n,
            a: DMatrix::zeros(n.max(1), mmax),
            v: DMatrix::zeros(n.max(1), mmax),
            tau: vec![0.0; mmax],
            perm: vec![0; mmax],
            colnorm: vec![0.0; mmax],
            s: DMatrix::zeros(mmax, mmax),
            t: DMatrix::zeros(mmax, mmax),
            tmp_n: DVector::zeros(n),
            tmp_m: DVector::zeros(mmax),
            residual: DVector::zeros(mmax),
            jt: DMatrix::zeros(n, mmax),
            tp: DMatrix::zeros(mmax, mmax),
            nz: vec![0; n],
            y_last: DMatrix::zeros(n.max(1), mmax),
            tmp_k: DVector::zeros(n),
            k_last: 0,
            last_ready: true,
        }
    }

    /// Number of velocity coordinates n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Level sizes m_i.
    pub fn dims(&self) -> &[usize] {
        &self.dims
    }

    /// Column offset of level i in G.
    pub fn offset(&self, i: usize) -> usize {
        self.offsets[i]
    }

    /// Rank kept at each level by the last [`Hierarchy::solve`].
    pub fn ranks(&self) -> &[usize] {
        &self.ranks
    }

    /// J̄_i^{λ+} of level i (n × m_i), from the last solve.
    pub fn pinv(&mut self, i: usize) -> &DMatrix<f64> {
        self.ensure_last_pinv();
        &self.pinv[i]
    }

    /// Forms J̄⁺ = Z · Y of the last level if it is still factored.
    fn ensure_last_pinv(&mut self) {
        if self.last_ready || self.dims.is_empty() {
            return;
        }
        let last = self.dims.len() - 1;
        let (n, m, k) = (self.n, self.dims[last], self.k_last);
        let zs = self.z.as_slice();
        let yr = self.y_last.nrows();
        let ys = self.y_last.as_slice();
        let pi = self.pinv[last].as_mut_slice();
        for c in 0..m {
            let out = &mut pi[c * n..(c + 1) * n];
            out.fill(0.0);
            for a in 0..k {
                let f = ys[a + c * yr];
                if f != 0.0 {
                    axpy(f, &zs[a * n..(a + 1) * n], out);
                }
            }
        }
        self.last_ready = true;
    }

    /// G (n × Σm_i); the blocks of levels ≥ `from` are valid after
    /// [`Hierarchy::build_g_level`].
    pub fn g(&self) -> &DMatrix<f64> {
        &self.g
    }

    /// Checks that `levels` match the sizes this workspace was made for.
    pub fn check(&self, levels: &[TaskEquation]) -> Result<()> {
        check_dim("number of levels", self.dims.len(), levels.len())?;
        for (l, &m) in levels.iter().zip(&self.dims) {
            if l.dim() != m || l.nv() != self.n {
                return Err(Error::DimensionMismatch {
                    what: format!("rows of level `{}` (columns must be {})", l.name, self.n),
                    expected: m,
                    got: l.dim(),
                });
            }
        }
        Ok(())
    }

    /// Runs the recursion (eq. 5) and writes the prioritized solution q̈_{n_T} into `qdd`.
    /// Allocates nothing.
    pub fn solve(
        &mut self,
        levels: &[TaskEquation],
        settings: &SolverSettings,
        qdd: &mut DVector<f64>,
    ) -> Result<()> {
        self.check(levels)?;
        check_dim("q̈", self.n, qdd.len())?;
        let n = self.n;
        qdd.fill(0.0);
        self.z.fill(0.0);
        for d in 0..n {
            self.z[(d, d)] = 1.0;
        }
        self.k = n;
        for (i, lvl) in levels.iter().enumerate() {
            let m = self.dims[i];
            self.level_inverse(i, &lvl.jacobian, settings);
            // residual = h_i − J_i q̈_{i−1};  q̈ += J̄⁺ residual.
            let mut res = self.residual.rows_mut(0, m);
            res.copy_from(&lvl.rhs);
            res.gemv(-1.0, &lvl.jacobian, qdd, 1.0);
            if i + 1 == levels.len() {
                // q̈ += Z (Y residual).
                let k = self.k_last;
                let mut y = self.tmp_k.rows_mut(0, k);
                y.gemv(
                    1.0,
                    &self.y_last.view((0, 0), (k, m)),
                    &self.residual.rows(0, m),
                    0.0,
                );
                qdd.gemv(
                    1.0,
                    &self.z.view((0, 0), (n, k)),
                    &self.tmp_k.rows(0, k),
                    1.0,
                );
            } else {
                qdd.gemv(1.0, &self.pinv[i], &self.residual.rows(0, m), 1.0);
            }
        }
        Ok(())
    }

    /// J̄_i^{λ+} for level i from the current basis Z, then Z ← basis of null(J_i Z) within Z.
    fn level_inverse(&mut self, i: usize, j: &DMatrix<f64>, settings: &SolverSettings) {
        let (n, m, k) = (self.n, self.dims[i], self.k);
        let last = i + 1 == self.dims.len();
        self.pinv[i].fill(0.0);
        if last {
            self.k_last = 0;
            self.last_ready = true;
        }
        if m == 0 || k == 0 {
            self.ranks[i] = 0;
            return;
        }
        // A = (J Z)ᵀ = Zᵀ Jᵀ, k × m.
        self.jt.view_mut((0, 0), (n, m)).tr_copy_from(j);
        // Entry (a, c) is the dot product of column a of Z and column c of Jᵀ (both contiguous).
        // Written out: nalgebra's gemm may allocate packing buffers, and the tick must not.
        if k == n && i == 0 {
            // First level: Z = I, so A = Jᵀ.
            self.a
                .view_mut((0, 0), (n, m))
                .copy_from(&self.jt.view((0, 0), (n, m)));
        } else {
            let zs = self.z.as_slice();
            let js = self.jt.as_slice();
            let arows = self.a.nrows();
            let asl = self.a.as_mut_slice();
            for c in 0..m {
                let jc = &js[c * n..(c + 1) * n];
                // Task rows are often sparse (a joint task selects one dof, the pelvis moves
                // with the base only): when fewer than half the entries are non-zero, sum over
                // those alone.
                let mut nnz = 0;
                for (d, v) in jc.iter().enumerate() {
                    if *v != 0.0 {
                        self.nz[nnz] = d;
                        nnz += 1;
                    }
                }
                if 2 * nnz < n {
                    let idx = &self.nz[..nnz];
                    for a in 0..k {
                        let za = &zs[a * n..(a + 1) * n];
                        asl[a + c * arows] = idx.iter().map(|&d| za[d] * jc[d]).sum();
                    }
                } else {
                    for a in 0..k {
                        let za = &zs[a * n..(a + 1) * n];
                        asl[a + c * arows] = dot(za, jc);
                    }
                }
            }
        }
        // Householder QR with column pivoting of A (k × m).
        let steps = k.min(m);
        for c in 0..m {
            self.perm[c] = c;
        }
        let mut rank = 0;
        let ar = self.a.nrows();
        let vr = self.v.nrows();
        for st in 0..steps {
            // Pivot: the remaining column of largest norm (rows st..k).
            {
                let asl = self.a.as_slice();
                for c in st..m {
                    let col = &asl[c * ar + st..c * ar + k];
                    self.colnorm[c] = dot(col, col);
                }
            }
            let mut best = st;
            for c in st + 1..m {
                if self.colnorm[c] > self.colnorm[best] {
                    best = c;
                }
            }
            if best != st {
                self.a.swap_columns(st, best);
                self.perm.swap(st, best);
                self.colnorm.swap(st, best);
            }
            let norm = self.colnorm[st].sqrt();
            if norm <= settings.rank_threshold {
                break;
            }
            // v = x − α e1 with α = −sign(x0)‖x‖; H = I − τ v vᵀ, τ = 2 / vᵀv.
            let asl = self.a.as_mut_slice();
            let vsl = self.v.as_mut_slice();
            let x0 = asl[st * ar + st];
            let alpha = if x0 >= 0.0 { -norm } else { norm };
            let vcol = &mut vsl[st * vr..st * vr + k];
            vcol[..st].fill(0.0);
            vcol[st..k].copy_from_slice(&asl[st * ar + st..st * ar + k]);
            vcol[st] = x0 - alpha;
            let v = &vcol[st..k];
            let vv = dot(v, v);
            let tau = if vv > 0.0 { 2.0 / vv } else { 0.0 };
            self.tau[st] = tau;
            // Apply H to the remaining columns of A.
            for c in st..m {
                let col = &mut asl[c * ar + st..c * ar + k];
                let f = tau * dot(v, col);
                for (x, vi) in col.iter_mut().zip(v) {
                    *x -= f * vi;
                }
            }
            rank = st + 1;
        }
        self.ranks[i] = rank;
        // ZQ = Z H_1 … H_rank (n × k): each reflector is a rank-one update
        // ZQ ← ZQ − τ (ZQ v) vᵀ on the columns st..k.
        if !last {
            self.zq
                .view_mut((0, 0), (n, k))
                .copy_from(&self.z.view((0, 0), (n, k)));
            let vr = self.v.nrows();
            let vsl = self.v.as_slice();
            let zq = self.zq.as_mut_slice();
            let w = &mut self.tmp_n.as_mut_slice()[..n];
            for st in 0..rank {
                let tau = self.tau[st];
                let v = &vsl[st * vr + st..st * vr + k];
                // w = ZQ[:, st..k] v, then ZQ[:, st + a] −= τ v_a w. Zero entries of v (dofs a
                // level does not move, e.g. the arms for the feet) are skipped.
                w.fill(0.0);
                for (a, &va) in v.iter().enumerate() {
                    if va != 0.0 {
                        axpy(va, &zq[(st + a) * n..(st + a + 1) * n], w);
                    }
                }
                for (a, &va) in v.iter().enumerate() {
                    if va != 0.0 {
                        axpy(-tau * va, w, &mut zq[(st + a) * n..(st + a + 1) * n]);
                    }
                }
            }
        }
        if rank > 0 {
            // λ² from the damping rule; σ_min estimated by the last kept pivot |R_rr|.
            let sigma = self.a[(rank - 1, rank - 1)].abs();
            let lambda2 = match settings.damping {
                Damping::None => 0.0,
                Damping::Fixed(l) => l * l,
                Damping::Adaptive { max, threshold } => {
                    if sigma < threshold {
                        (1.0 - (sigma / threshold).powi(2)) * max * max
                    } else {
                        0.0
                    }
                }
            };
            // S = R_r R_rᵀ + λ² I (r × r), R_r = rows 0..r of R (upper trapezoidal, r × m).
            for p in 0..rank {
                for q in 0..=p {
                    let mut s = 0.0;
                    for c in p.max(q)..m {
                        s += self.a[(p, c)] * self.a[(q, c)];
                    }
                    if p == q {
                        s += lambda2;
                    }
                    self.s[(p, q)] = s;
                    self.s[(q, p)] = s;
                }
            }
            // Cholesky S = L Lᵀ in place (lower). S is SPD: R_r has full row rank r.
            for p in 0..rank {
                let mut d = self.s[(p, p)];
                for q in 0..p {
                    d -= self.s[(p, q)] * self.s[(p, q)];
                }
                let l = d.max(f64::MIN_POSITIVE).sqrt();
                self.s[(p, p)] = l;
                for r in p + 1..rank {
                    let mut x = self.s[(r, p)];
                    for q in 0..p {
                        x -= self.s[(r, q)] * self.s[(p, q)];
                    }
                    self.s[(r, p)] = x / l;
                }
            }
            // T = S⁻¹ R_r (r × m), column by column (R entries below the diagonal are zero):
            // L y = b by columns of L, then Lᵀ x = y by dot products with columns of L (L is
            // stored column-major in the lower triangle of `s`).
            {
                let sr = self.s.nrows();
                let ls = self.s.as_slice();
                let ar = self.a.nrows();
                let asl = self.a.as_slice();
                let x = &mut self.tmp_m.as_mut_slice()[..rank];
                for c in 0..m {
                    for (p, xp) in x.iter_mut().enumerate() {
                        *xp = if p <= c { asl[p + c * ar] } else { 0.0 };
                    }
                    for q in 0..rank {
                        let xq = x[q] / ls[q + q * sr];
                        x[q] = xq;
                        if xq != 0.0 {
                            axpy(-xq, &ls[q * sr + q + 1..q * sr + rank], &mut x[q + 1..rank]);
                        }
                    }
                    for p in (0..rank).rev() {
                        let tail = dot(&ls[p * sr + p + 1..p * sr + rank], &x[p + 1..rank]);
                        x[p] = (x[p] - tail) / ls[p + p * sr];
                    }
                    for (p, xp) in x.iter().enumerate() {
                        self.t[(p, c)] = *xp;
                    }
                }
            }
            // J̄⁺ = ZQ_r · T · Πᵀ: column perm[c] of J̄⁺ is ZQ_r · T[:, c].
            for c in 0..m {
                let col = self.perm[c];
                for p in 0..rank {
                    self.tp[(p, col)] = self.t[(p, c)];
                }
            }
            if last {
                // Y = Q_r Tp = H_1 … H_r [Tp; 0] (k × m): reflectors applied last to first.
                let yr = self.y_last.nrows();
                let vr = self.v.nrows();
                let tprows = self.tp.nrows();
                let ys = self.y_last.as_mut_slice();
                let tp = self.tp.as_slice();
                let vsl = self.v.as_slice();
                for c in 0..m {
                    let col = &mut ys[c * yr..c * yr + k];
                    col.fill(0.0);
                    for p in 0..rank {
                        col[p] = tp[p + c * tprows];
                    }
                }
                for st in (0..rank).rev() {
                    let tau = self.tau[st];
                    let v = &vsl[st * vr + st..st * vr + k];
                    for c in 0..m {
                        let col = &mut ys[c * yr + st..c * yr + k];
                        let f = tau * dot(v, col);
                        axpy(-f, v, col);
                    }
                }
                self.k_last = k;
                self.last_ready = false;
                return;
            }
            // Column c of J̄⁺ = Σ_p ZQ[:, p] · Tp[p, c] (contiguous column updates).
            let zq = self.zq.as_slice();
            let tprows = self.tp.nrows();
            let tp = self.tp.as_slice();
            let pi = self.pinv[i].as_mut_slice();
            for c in 0..m {
                let out = &mut pi[c * n..(c + 1) * n];
                out.fill(0.0);
                for p in 0..rank {
                    let f = tp[p + c * tprows];
                    if f != 0.0 {
                        for (o, z) in out.iter_mut().zip(&zq[p * n..(p + 1) * n]) {
                            *o += f * z;
                        }
                    }
                }
            }
        }
        if last {
            // Rank 0: J̄⁺ = 0 (k_last = 0), and no level follows.
            return;
        }
        // Z ← ZQ[:, rank..k].
        let newk = k - rank;
        self.z
            .view_mut((0, 0), (n, newk))
            .copy_from(&self.zq.view((0, rank), (n, newk)));
        self.k = newk;
    }

    /// Builds the block g_i of G (Algorithm 1), using the inverses of the last
    /// [`Hierarchy::solve`]. Allocates nothing.
    pub fn build_g_level(&mut self, levels: &[TaskEquation], i: usize) {
        self.ensure_last_pinv();
        let n = self.n;
        {
            let off = self.offsets[i];
            for c in 0..self.dims[i] {
                for d in 0..n {
                    self.tmp_n[d] = self.pinv[i][(d, c)];
                }
                // ψ ← (I − J̄_k⁺ J_k) ψ for k = i+1..n_T.
                for (k, lvl) in levels.iter().enumerate().skip(i + 1) {
                    let mk = self.dims[k];
                    for r in 0..mk {
                        let mut s = 0.0;
                        for d in 0..n {
                            s += lvl.jacobian[(r, d)] * self.tmp_n[d];
                        }
                        self.tmp_m[r] = s;
                    }
                    for r in 0..mk {
                        let s = self.tmp_m[r];
                        if s != 0.0 {
                            for d in 0..n {
                                self.tmp_n[d] -= self.pinv[k][(d, r)] * s;
                            }
                        }
                    }
                }
                for d in 0..n {
                    self.g[(d, off + c)] = self.tmp_n[d];
                }
            }
        }
    }
}

/// Dot product of two equally long slices with four independent accumulators, so that the
/// compiler can vectorise it (a single running sum fixes the order of the additions).
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let mut ca = a.chunks_exact(4);
    let mut cb = b.chunks_exact(4);
    for (x, y) in (&mut ca).zip(&mut cb) {
        acc[0] += x[0] * y[0];
        acc[1] += x[1] * y[1];
        acc[2] += x[2] * y[2];
        acc[3] += x[3] * y[3];
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (x, y) in ca.remainder().iter().zip(cb.remainder()) {
        s += x * y;
    }
    s
}

/// y += α x.
#[inline]
fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}
