//! The prioritized solution (paper eqs. 5–9) and the correction map G (eqs. 19–21, Algorithm 1).
//!
//! ## Method
//!
//! For level i with Jacobian J_i (m_i × n) and right-hand side h_i:
//!
//! q̈_i = q̈_{i−1} + J̄_i^{λ+} (h_i − J_i q̈_{i−1}),  J̄_i = J_i N_{i−1}  (eqs. 5–7),
//!
//! where N_{i−1} projects onto the null space of the levels above. No n × n projector is
//! formed. The levels are reduced one after the other by Householder reflectors, as in a
//! complete orthogonal decomposition of the stacked Jacobian: with Q = H_0 H_1 ⋯ (all
//! reflectors so far) and u = Qᵀ q̈, the levels above level i occupy the first p_i reduced
//! coordinates, and the null space of the levels above is spanned by the remaining columns
//! Z = Q\[:, p_i..n\], so N_{i−1} = Z Zᵀ. The rows of every lower level are kept multiplied by
//! the reflectors found so far, W_j = J_j Q, so the reduced Jacobian of level i is simply
//! A_iᵀ = W_i\[:, p_i..n\] = J_i Z (m_i × k, k = n − p_i) — no product with a basis.
//!
//! The column-pivoted Householder QR A_i Π = H_{p_i} ⋯ H_{p_i+r−1} R keeps the r pivots with
//! |R_jj| above the rank threshold. Then J_i Z = Π R_rᵀ Q_rᵀ and
//!
//! J̄_i^{λ+} = Z Q_r (R_r R_rᵀ + λ² I)⁻¹ R_r Πᵀ,
//!
//! the Moore–Penrose inverse for λ = 0 (eq. 4) and the damped least-squares inverse (eqs. 8–9)
//! otherwise. Z Q_r are the reduced coordinates p_i..p_i + r, so level i sets
//!
//! u\[p_i..p_i+r\] = S_i⁻¹ R_r Πᵀ (h_i − W_i\[:, 0..p_i\] u\[0..p_i\]),  S_i = R_r R_rᵀ + λ² I,
//!
//! the new reflectors are applied to the rows of the lower levels, and p_{i+1} = p_i + r. At
//! the end q̈ = Q u. Cost: one Householder reduction of the stacked Jacobian, O(n² Σm_i),
//! instead of the O(n² Σm_i) products with an explicit basis on top of it; no SVD.
//!
//! Algorithm 1 builds G = \[g_1 … g_{n_T}\] with g_i = (Π_{k>i} (I − J̄_k^{λ+} J_k)) J̄_i^{λ+},
//! which is ∂q̈/∂h_i: adding corrections Δh to the right-hand sides changes the solution by
//! G Δh (eq. 20). In reduced coordinates it is the same forward substitution as the solution,
//! driven by a unit right-hand side of level i and no h elsewhere, followed by Q.

use nalgebra::{DMatrix, DVector};

use super::settings::{Damping, SolverSettings};
use crate::error::{check_dim, Error, Result};
use crate::task::TaskEquation;

/// Workspace of the prioritized recursion, sized once for given level dimensions.
#[derive(Debug, Clone)]
pub struct Hierarchy {
    n: usize,
    dims: Vec<usize>,
    /// Offset of level i among the stacked task rows (and the columns of G).
    offsets: Vec<usize>,
    /// Rank r_i kept per level.
    ranks: Vec<usize>,
    /// First reduced coordinate p_i of level i.
    starts: Vec<usize>,
    /// Wᵀ (n × Σm_i): column j is stacked task row j multiplied by the reflectors of the
    /// levels above its own.
    w: DMatrix<f64>,
    /// Householder vectors: column s acts on the coordinates s..vend\[s\]
    /// (H_s = I − τ_s v_s v_sᵀ); there is one reflector per kept pivot, Σ r_i ≤ n in all.
    v: DMatrix<f64>,
    tau: Vec<f64>,
    vend: Vec<usize>,
    /// Number of reflectors, Σ r_i.
    nref: usize,
    /// Per level: R_r (upper trapezoidal, r_i × m_i, in an m_i × m_i buffer), the Cholesky
    /// factor L of S_i (lower, r_i × r_i) and the pivot order Π.
    rfac: Vec<DMatrix<f64>>,
    chol: Vec<DMatrix<f64>>,
    perm: Vec<Vec<usize>>,
    /// Scratch: A_i (k × m_i) during the QR, its column norms, the reduced solution u, a
    /// reduced G column, a level residual and a small vector.
    a: DMatrix<f64>,
    colnorm: Vec<f64>,
    u: DVector<f64>,
    y: Vec<f64>,
    res: Vec<f64>,
    x: Vec<f64>,
    /// G, n × Σm_i, blocks in level order; columns of level i valid once built.
    g: DMatrix<f64>,
    /// J̄_i^{λ+} formed on request ([`Hierarchy::pinv`]); never in the tick.
    pinv: Vec<DMatrix<f64>>,
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
            ranks: vec![0; dims.len()],
            starts: vec![0; dims.len()],
            w: DMatrix::zeros(n, total.max(1)),
            v: DMatrix::zeros(n, n),
            tau: vec![0.0; n],
            vend: vec![0; n],
            nref: 0,
            rfac: dims.iter().map(|&m| DMatrix::zeros(m, m)).collect(),
            chol: dims.iter().map(|&m| DMatrix::zeros(m, m)).collect(),
            perm: dims.iter().map(|&m| vec![0; m]).collect(),
            a: DMatrix::zeros(n.max(1), mmax),
            colnorm: vec![0.0; mmax],
            u: DVector::zeros(n),
            y: vec![0.0; n],
            res: vec![0.0; mmax],
            x: vec![0.0; mmax],
            g: DMatrix::zeros(n, total.max(1)),
            pinv: dims.iter().map(|&m| DMatrix::zeros(n, m)).collect(),
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

    /// J̄_i^{λ+} of level i (n × m_i), from the last solve. Formed on request from the
    /// factorization (column c is Q applied to S_i⁻¹ R_r Πᵀ e_c placed at p_i); not needed by
    /// the solvers, which use the factors directly.
    pub fn pinv(&mut self, i: usize) -> &DMatrix<f64> {
        for c in 0..self.dims[i] {
            self.y.fill(0.0);
            self.level_unit(i, c, false);
            self.apply_q_to_y();
            self.pinv[i].column_mut(c).copy_from_slice(&self.y);
        }
        &self.pinv[i]
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
        // Wᵀ ← Jᵀ of every level.
        let wr = self.w.nrows();
        for (i, lvl) in levels.iter().enumerate() {
            let off = self.offsets[i];
            let ws = self.w.as_mut_slice();
            for r in 0..lvl.dim() {
                let col = &mut ws[(off + r) * wr..(off + r + 1) * wr];
                for (d, x) in col.iter_mut().enumerate() {
                    *x = lvl.jacobian[(r, d)];
                }
            }
        }
        self.u.fill(0.0);
        self.nref = 0;
        for (i, lvl) in levels.iter().enumerate() {
            let p = self.nref;
            self.starts[i] = p;
            self.reduce_level(i, settings);
            let (m, r) = (self.dims[i], self.ranks[i]);
            if r == 0 {
                continue;
            }
            // residual = h_i − W_i[:, 0..p] u[0..p] (u is zero from p on).
            let off = self.offsets[i];
            let ws = self.w.as_slice();
            let us = &self.u.as_slice()[..p];
            for c in 0..m {
                let wc = &ws[(off + c) * wr..(off + c) * wr + p];
                self.res[c] = lvl.rhs[c] - dot(wc, us);
            }
            // u[p..p+r] = S⁻¹ R_r Πᵀ residual.
            for c in 0..m {
                self.x[c] = self.res[self.perm[i][c]];
            }
            let (rf, ch) = (&self.rfac[i], &self.chol[i]);
            let out = &mut self.u.as_mut_slice()[p..p + r];
            apply_t(rf, ch, r, m, &self.x[..m], out);
        }
        // q̈ = Q u.
        qdd.copy_from(&self.u);
        apply_q(
            &self.v,
            &self.tau,
            &self.vend,
            self.nref,
            qdd.as_mut_slice(),
        );
        Ok(())
    }

    /// Reduces level i: pivoted QR of A_i = (W_i\[:, p..n\])ᵀ, the factors R_r, L and Π, the
    /// damping, and the new reflectors applied to the rows of the lower levels.
    fn reduce_level(&mut self, i: usize, settings: &SolverSettings) {
        let (n, m, p) = (self.n, self.dims[i], self.nref);
        let k = n - p;
        self.ranks[i] = 0;
        if m == 0 || k == 0 {
            return;
        }
        let off = self.offsets[i];
        let wr = self.w.nrows();
        let ar = self.a.nrows();
        {
            let ws = self.w.as_slice();
            let asl = self.a.as_mut_slice();
            for c in 0..m {
                asl[c * ar..c * ar + k]
                    .copy_from_slice(&ws[(off + c) * wr + p..(off + c + 1) * wr]);
            }
        }
        let perm = &mut self.perm[i];
        for (c, pc) in perm.iter_mut().enumerate() {
            *pc = c;
        }
        // Householder QR with column pivoting of A (k × m).
        let steps = k.min(m);
        let mut rank = 0;
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
                perm.swap(st, best);
                self.colnorm.swap(st, best);
            }
            let norm = self.colnorm[st].sqrt();
            if norm <= settings.rank_threshold {
                break;
            }
            // v = x − α e1 with α = −sign(x0)‖x‖; H = I − τ v vᵀ, τ = 2 / vᵀv.
            let s = p + st;
            let asl = self.a.as_mut_slice();
            let vsl = self.v.as_mut_slice();
            let x0 = asl[st * ar + st];
            let alpha = if x0 >= 0.0 { -norm } else { norm };
            let vcol = &mut vsl[s * vr + s..s * vr + n];
            vcol.copy_from_slice(&asl[st * ar + st..st * ar + k]);
            vcol[0] = x0 - alpha;
            let mut end = vcol.len();
            while end > 1 && vcol[end - 1] == 0.0 {
                end -= 1;
            }
            self.vend[s] = s + end;
            let v = &vcol[..end];
            let vv = dot(v, v);
            let tau = if vv > 0.0 { 2.0 / vv } else { 0.0 };
            self.tau[s] = tau;
            // Apply H to the remaining columns of A: column st becomes α e1.
            asl[st * ar + st] = alpha;
            asl[st * ar + st + 1..st * ar + k].fill(0.0);
            for c in st + 1..m {
                let col = &mut asl[c * ar + st..c * ar + st + end];
                let f = tau * dot(v, col);
                if f != 0.0 {
                    axpy(-f, v, col);
                }
            }
            rank = st + 1;
        }
        self.ranks[i] = rank;
        if rank == 0 {
            return;
        }
        self.nref = p + rank;
        // The rows of the lower levels: w ← H_{p+r−1} ⋯ H_p w on the coordinates p..n.
        {
            let total = self.w.ncols();
            let vsl = self.v.as_slice();
            let ws = self.w.as_mut_slice();
            for col in off + m..total {
                let wc = &mut ws[col * wr..(col + 1) * wr];
                for s in p..p + rank {
                    let (b, e) = (s, self.vend[s]);
                    let v = &vsl[s * vr + b..s * vr + e];
                    let f = self.tau[s] * dot(v, &wc[b..e]);
                    if f != 0.0 {
                        axpy(-f, v, &mut wc[b..e]);
                    }
                }
            }
        }
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
        // R_r = rows 0..r of R (upper trapezoidal, r × m).
        let rf = &mut self.rfac[i];
        for c in 0..m {
            for q in 0..rank {
                rf[(q, c)] = if q <= c { self.a[(q, c)] } else { 0.0 };
            }
        }
        // S = R_r R_rᵀ + λ² I (r × r), then Cholesky S = L Lᵀ (lower). S is SPD: R_r has full
        // row rank r.
        let l = &mut self.chol[i];
        for q in 0..rank {
            for t in 0..=q {
                let mut s = 0.0;
                for c in q..m {
                    s += rf[(q, c)] * rf[(t, c)];
                }
                if q == t {
                    s += lambda2;
                }
                l[(q, t)] = s;
            }
        }
        for q in 0..rank {
            let mut d = l[(q, q)];
            for t in 0..q {
                d -= l[(q, t)] * l[(q, t)];
            }
            let lq = d.max(f64::MIN_POSITIVE).sqrt();
            l[(q, q)] = lq;
            for r in q + 1..rank {
                let mut x = l[(r, q)];
                for t in 0..q {
                    x -= l[(r, t)] * l[(q, t)];
                }
                l[(r, q)] = x / lq;
            }
        }
    }

    /// Writes into `y` (zero outside p_i..) the reduced-coordinate change of q̈ caused by a unit
    /// change of row c of h_i: level i's own step (J̄_i⁺ e_c), then, if `propagate`, every lower
    /// level's response (g_i e_c).
    fn level_unit(&mut self, i: usize, c: usize, propagate: bool) {
        let (m, r, p) = (self.dims[i], self.ranks[i], self.starts[i]);
        if r == 0 {
            // Level i moves nothing, so nothing below it moves either.
            return;
        }
        for (j, x) in self.x[..m].iter_mut().enumerate() {
            *x = if self.perm[i][j] == c { 1.0 } else { 0.0 };
        }
        apply_t(
            &self.rfac[i],
            &self.chol[i],
            r,
            m,
            &self.x[..m],
            &mut self.y[p..p + r],
        );
        if !propagate {
            return;
        }
        let wr = self.w.nrows();
        for k in i + 1..self.dims.len() {
            let (mk, rk, pk) = (self.dims[k], self.ranks[k], self.starts[k]);
            if rk == 0 {
                continue;
            }
            let off = self.offsets[k];
            let ws = self.w.as_slice();
            for t in 0..mk {
                let wc = &ws[(off + t) * wr + p..(off + t) * wr + pk];
                self.res[t] = -dot(wc, &self.y[p..pk]);
            }
            for t in 0..mk {
                self.x[t] = self.res[self.perm[k][t]];
            }
            apply_t(
                &self.rfac[k],
                &self.chol[k],
                rk,
                mk,
                &self.x[..mk],
                &mut self.y[pk..pk + rk],
            );
        }
    }

    /// y ← Q y.
    fn apply_q_to_y(&mut self) {
        apply_q(&self.v, &self.tau, &self.vend, self.nref, &mut self.y);
    }

    /// Builds the block g_i of G (Algorithm 1), using the factors of the last
    /// [`Hierarchy::solve`]. Allocates nothing.
    pub fn build_g_level(&mut self, i: usize) {
        let off = self.offsets[i];
        for c in 0..self.dims[i] {
            self.y.fill(0.0);
            self.level_unit(i, c, true);
            self.apply_q_to_y();
            self.g.column_mut(off + c).copy_from_slice(&self.y);
        }
    }
}

/// out = S⁻¹ R_r b (r entries) for b of length m: z = R_r b, then L w = z and Lᵀ out = w.
fn apply_t(rf: &DMatrix<f64>, l: &DMatrix<f64>, r: usize, m: usize, b: &[f64], out: &mut [f64]) {
    // z = R_r b (R_r upper trapezoidal: row q starts at column q).
    let rr = rf.nrows();
    let rs = rf.as_slice();
    out.fill(0.0);
    for (c, &bc) in b.iter().enumerate().take(m) {
        if bc != 0.0 {
            let top = (c + 1).min(r);
            axpy(bc, &rs[c * rr..c * rr + top], &mut out[..top]);
        }
    }
    // Forward substitution with the columns of L, then back substitution with its rows.
    let lr = l.nrows();
    let ls = l.as_slice();
    for q in 0..r {
        let xq = out[q] / ls[q + q * lr];
        out[q] = xq;
        if xq != 0.0 {
            axpy(-xq, &ls[q * lr + q + 1..q * lr + r], &mut out[q + 1..r]);
        }
    }
    for q in (0..r).rev() {
        let tail = dot(&ls[q * lr + q + 1..q * lr + r], &out[q + 1..r]);
        out[q] = (out[q] - tail) / ls[q + q * lr];
    }
}

/// x ← Q x = H_0 H_1 ⋯ H_{nref−1} x: the reflectors applied last to first.
fn apply_q(v: &DMatrix<f64>, tau: &[f64], vend: &[usize], nref: usize, x: &mut [f64]) {
    let vr = v.nrows();
    let vs = v.as_slice();
    for s in (0..nref).rev() {
        let e = vend[s];
        let vv = &vs[s * vr + s..s * vr + e];
        let f = tau[s] * dot(vv, &x[s..e]);
        if f != 0.0 {
            axpy(-f, vv, &mut x[s..e]);
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
