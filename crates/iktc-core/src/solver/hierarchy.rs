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
//! Z = Q\[:, p_i..n\], so N_{i−1} = Z Zᵀ. When level i is reached its rows are multiplied by
//! the reflectors of the levels above, W_i = J_i H_0 ⋯ H_{p_i−1} (left-looking: one blocked
//! pass over all of them instead of one pass per level above), so the reduced Jacobian of
//! level i is simply A_iᵀ = W_i\[:, p_i..n\] = J_i Z (m_i × k, k = n − p_i) — no product with
//! a basis.
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
//! and p_{i+1} = p_i + r (the lower levels' rows receive the new reflectors when they are
//! reached). At the end q̈ = Q u. Cost: one Householder reduction of the stacked Jacobian, O(n² Σm_i),
//! instead of the O(n² Σm_i) products with an explicit basis on top of it; no SVD.
//!
//! A level reached with no coordinate left (p_i = n: the levels above use every degree of
//! freedom, as the posture level of the keypoint stack on G1 does on every tick) has rank 0 and
//! moves nothing: its rows are not reduced, its columns of G are zero and are not computed, and
//! it has no column in IKTC's correction QP (its correction is zero at the optimum).
//!
//! A level that selects coordinates and completes the rank under levels of full rank (the
//! posture level of the peer problem: the upper-body joints under feet, COM and pelvis) is
//! solved in closed form instead: q̈ = q̈_{i−1} + g_i (h_i − J_i q̈_{i−1}) with g_i from one LU
//! of the other coordinates' block (the `selection` module, which also bounds the reduced
//! level's singular values from below to decide that the QR would keep all its rows). Its
//! Householder reduction is run only if something later needs its factors
//! ([`Hierarchy::complete`]).
//!
//! IKTC's correction QP (eq. 23) needs G only through the changes of h that move q̈. Level i
//! moves q̈ through J̄_i^{λ+} = Z Q_r S_i⁻¹ R_r Πᵀ, whose row space is that of R_r Πᵀ (S_i is
//! invertible): r_i dimensions. With R_rᵀ = V T (Householder QR, V m_i × r_i orthonormal) and
//! U_i = Π V, a correction Δh_i = U_i z_i + w with w ⊥ U_i moves q̈ by g_i U_i z_i and costs
//! ‖z_i‖² + ‖w‖²: the least correction has w = 0. The correction map holds g_i U_i (r_i
//! columns) for a level with r_i < m_i, g_i for a full-rank one and nothing at rank 0
//! ([`Hierarchy::build_correction_map`]); it is built as G is, with U_i as the level's
//! right-hand sides in place of the identity.
//!
//! Algorithm 1 builds G = \[g_1 … g_{n_T}\] with g_i = (Π_{k>i} (I − J̄_k^{λ+} J_k)) J̄_i^{λ+},
//! which is ∂q̈/∂h_i: adding corrections Δh to the right-hand sides changes the solution by
//! G Δh (eq. 20). In reduced coordinates it is the same forward substitution as the solution,
//! driven by a unit right-hand side of level i and no h elsewhere, followed by Q.

use nalgebra::{DMatrix, DVector};

use super::gram::GramLevel;
use super::kernels::{axpy, axpy2, dot, reflect_columns};
use super::reflectors::Reflectors;
use super::selection::SelectionBlock;
use super::settings::{Damping, SolverSettings};
use crate::error::{check_dim, Error, Result};
use crate::task::TaskEquation;

/// Relative size below which a downdated squared column norm of the pivoted QR is recomputed
/// from its entries \[–\]: √ε, LAPACK's choice in xGEQP3 (the downdate has then lost about half
/// the significant digits).
const NORM_DOWNDATE_TOL: f64 = 1.4901161193847656e-8;

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
    /// W, stored by coordinate: entry (j, t) of the stacked task rows j (Σm_i of them) in the
    /// coordinates t (n) at `w[t * wld + j]`, so that the rows of one level are a block of
    /// adjacent columns. Row j is multiplied by the reflectors of the levels above its own
    /// once its level has been reached.
    w: Vec<f64>,
    /// Leading dimension of `w` (Σm_i).
    wld: usize,
    /// The Householder reflectors of all levels so far, one per kept pivot (Σ r_i ≤ n); their
    /// number is the next free reduced coordinate.
    refl: Reflectors,
    /// Per level: the factors of J̄_i^{λ+} in reduced coordinates.
    fac: Vec<LevelFactor>,
    /// Scratch: A_i (k × m_i) during the QR, its column norms, the reduced solution u, a
    /// reduced G column, a level residual and a small vector.
    a: DMatrix<f64>,
    colnorm: Vec<f64>,
    colnorm_ref: Vec<f64>,
    u: DVector<f64>,
    /// Row-major n × m_i block of reduced G columns, a row-major right-hand side block and
    /// the four-row scratch of the reflectors.
    yb: Vec<f64>,
    /// Row-major n × Σm_i: the reduced blocks of several levels side by side.
    yall: Vec<f64>,
    bb: Vec<f64>,
    qscratch: Vec<f64>,
    res: Vec<f64>,
    x: Vec<f64>,
    /// G, n × Σm_i, blocks in level order; columns of level i valid once built.
    g: DMatrix<f64>,
    /// The correction map ([`Hierarchy::build_correction_map`]), n × Σ widths.
    gc: DMatrix<f64>,
    /// J̄_i^{λ+} formed on request ([`Hierarchy::pinv`]); never in the tick.
    pinv: Vec<DMatrix<f64>>,
    /// The closed form of a bottom selection level's block ([`super::selection`]).
    selection: SelectionBlock,
    /// The block g_i (n × m_i, column-major) of the selection level `built` by the last
    /// [`Hierarchy::solve`] ([`Hierarchy::build_closed`]), and the level whose step it took
    /// in closed form ([`Hierarchy::solve_closed`], [`Hierarchy::solve_stack_closed`]).
    closed: Vec<f64>,
    built: Option<usize>,
    closed_level: Option<usize>,
    /// The levels whose reduction (QR, factors) has not been run (first, last): those above
    /// and at the closed level, or the level stepped by its Gram matrix. Only what needs
    /// their factors runs it ([`Hierarchy::complete`]), with the settings of the solve.
    deferred: Option<(usize, usize)>,
    /// The Gram step of a bottom level of weighted joint rows ([`super::gram`]), and whether
    /// the last solve took it (the levels below it then have rank 0).
    gram: GramLevel,
    gram_level: Option<usize>,
    /// The same level, kept after its reduction has run ([`Hierarchy::stepped_by_gram`]).
    gram_stepped: Option<usize>,
    /// The λ² of that level's step, which its reduction then uses.
    gram_lambda2: f64,
    settings: SolverSettings,
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
            w: vec![0.0; n * total],
            wld: total,
            refl: Reflectors::new(n),
            fac: dims.iter().map(|&m| LevelFactor::new(m)).collect(),
            a: DMatrix::zeros(n.max(1), mmax),
            colnorm: vec![0.0; mmax],
            colnorm_ref: vec![0.0; mmax],
            u: DVector::zeros(n),
            yb: vec![0.0; n * mmax],
            bb: vec![0.0; mmax * mmax],
            yall: vec![0.0; n * total],
            qscratch: vec![0.0; 4 * total.max(1)],
            res: vec![0.0; mmax.max(n)],
            x: vec![0.0; mmax.max(n)],
            g: DMatrix::zeros(n, total.max(1)),
            gc: DMatrix::zeros(n, total.max(1)),
            pinv: dims.iter().map(|&m| DMatrix::zeros(n, m)).collect(),
            selection: SelectionBlock::new(n, mmax),
            closed: vec![0.0; n * mmax.max(n)],
            built: None,
            closed_level: None,
            deferred: None,
            gram: GramLevel::new(n, mmax),
            gram_level: None,
            gram_stepped: None,
            gram_lambda2: 0.0,
            settings: SolverSettings::default(),
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

    /// The level the last [`Hierarchy::solve`] stepped by its Gram matrix (the `gram` module:
    /// a bottom level of weighted joint rows that completes the rank), if any. Its answer is
    /// the QR's to rounding; its reduction runs only when its factors are asked for.
    pub fn stepped_by_gram(&self) -> Option<usize> {
        self.gram_stepped
    }

    /// J̄_i^{λ+} of level i (n × m_i), from the last solve. Formed on request from the
    /// factorization (column c is Q applied to S_i⁻¹ R_r Πᵀ e_c placed at p_i); not needed by
    /// the solvers, which use the factors directly.
    pub fn pinv(&mut self, i: usize) -> &DMatrix<f64> {
        let (m, n) = (self.dims[i], self.n);
        self.reduced_block(i, false);
        self.refl
            .apply_q_rows(&mut self.yb[..n * m], m, &mut self.qscratch);
        for c in 0..m {
            for d in 0..n {
                self.pinv[i][(d, c)] = self.yb[d * m + c];
            }
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
        // W ← J of every level: column t of the column-major J_i is coordinate t of its rows.
        let wld = self.wld;
        for (i, lvl) in levels.iter().enumerate() {
            let (off, m) = (self.offsets[i], lvl.dim());
            if m == 0 {
                continue;
            }
            for (t, jc) in lvl.jacobian.as_slice().chunks_exact(m).enumerate() {
                self.w[t * wld + off..t * wld + off + m].copy_from_slice(jc);
            }
        }
        self.u.fill(0.0);
        self.refl.truncate(0);
        (self.built, self.closed_level, self.deferred) = (None, None, None);
        (self.gram_level, self.gram_stepped) = (None, None);
        self.settings = *settings;
        if self.solve_stack_closed(levels, settings, qdd) {
            return Ok(());
        }
        for (i, lvl) in levels.iter().enumerate() {
            if self.closed_level.is_some() || self.gram_level.is_some() {
                // The level solved in closed form completed the rank: no coordinate left.
                (self.starts[i], self.ranks[i]) = (self.n, 0);
                continue;
            }
            let p = self.refl.len();
            self.starts[i] = p;
            if self.solve_closed(i, levels, settings) || self.solve_gram(i, lvl, settings) {
                continue;
            }
            self.reduce_level(i, settings);
            let (m, r) = (self.dims[i], self.ranks[i]);
            if r == 0 {
                continue;
            }
            // residual = h_i − W_i[:, 0..p] u[0..p] (u is zero from p on), coordinate by
            // coordinate over the level's rows.
            let off = self.offsets[i];
            let res = &mut self.res[..m];
            res.copy_from_slice(lvl.rhs.as_slice());
            for (t, &ut) in self.u.as_slice()[..p].iter().enumerate() {
                if ut != 0.0 {
                    axpy(-ut, &self.w[t * wld + off..t * wld + off + m], res);
                }
            }
            // u[p..p+r] = S⁻¹ R_r Πᵀ residual.
            let f = &self.fac[i];
            for c in 0..m {
                self.x[c] = self.res[f.perm[c]];
            }
            f.apply(r, m, &self.x[..m], &mut self.u.as_mut_slice()[p..p + r]);
        }
        // q̈ = Q u, then the step of the level solved in closed form.
        qdd.copy_from(&self.u);
        self.refl.apply_q(qdd.as_mut_slice());
        if let Some(i) = self.closed_level {
            let (n, m) = (self.n, self.dims[i]);
            self.selection.step(
                levels[i].rhs.as_slice(),
                &self.closed[..n * m],
                n,
                &mut self.res[..m],
                qdd.as_mut_slice(),
            );
        }
        Ok(())
    }

    /// The whole stack in closed form ([`super::selection`], "The whole stack without QR"):
    /// when the first level that makes the rows add up to n is a selection, M_O is regular and
    /// the lower bound on σ_min of the stacked Jacobian exceeds 2 × the rank threshold (and
    /// the adaptive damping's threshold), every level keeps all its rows undamped, and
    /// q̈ = J⁻¹ h: no level is reduced ([`Hierarchy::complete`] does it on demand). Also when
    /// the rows of all levels add up to n − d, d ≤ [`MAX_SPARE`](super::selection::MAX_SPARE), the last a selection ("Stacks
    /// short of square": d unit rows appended, the solution and block projected). False
    /// (nothing decided) otherwise.
    fn solve_stack_closed(
        &mut self,
        levels: &[TaskEquation],
        settings: &SolverSettings,
        qdd: &mut DVector<f64>,
    ) -> bool {
        let n = self.n;
        let nt = self.dims.len();
        let square = (0..nt).find(|&i| self.dims[i] > 0 && self.offsets[i] + self.dims[i] == n);
        let (i, spare) = match square {
            Some(i) => (i, 0),
            None => match nt.checked_sub(1) {
                Some(i) if self.dims[i] > 0 && self.offsets[i] + self.dims[i] < n => {
                    let spare = n - self.offsets[i] - self.dims[i];
                    if levels.len() != nt
                        || !self
                            .selection
                            .choose_spare(&levels[..i], &levels[i], spare, n)
                    {
                        return false;
                    }
                    (i, spare)
                }
                _ => return false,
            },
        };
        let Some(floor) = undamped_floor(settings) else {
            return false;
        };
        if !self.build_closed(i, levels, spare)
            || !clears(self.selection.stack_sigma_lower_bound(), floor)
        {
            self.built = None;
            return false;
        }
        let (m, q) = (self.dims[i], qdd.as_mut_slice());
        self.selection.solve_above(&levels[..i], q);
        // h_i, then zero for the appended rows.
        let h = &mut self.x[..m + spare];
        h[..m].copy_from_slice(levels[i].rhs.as_slice());
        h[m..].fill(0.0);
        self.selection.step(
            h,
            &self.closed[..n * (m + spare)],
            n,
            &mut self.res[..m + spare],
            q,
        );
        if spare > 0
            && !self
                .selection
                .project_spare(&mut self.closed, n, m, spare, q)
        {
            self.built = None;
            return false;
        }
        for k in 0..nt {
            let full = k <= i;
            self.starts[k] = if full { self.offsets[k] } else { n };
            self.ranks[k] = if full { self.dims[k] } else { 0 };
            self.fac[k].direct = full;
        }
        self.closed_level = Some(i);
        self.deferred = Some((0, i));
        true
    }

    /// The closed-form block of level i into `closed` (once per solve), with `spare` unit rows
    /// appended ([`SelectionBlock::build`]); false when the `selection` module does not cover
    /// it.
    fn build_closed(&mut self, i: usize, levels: &[TaskEquation], spare: usize) -> bool {
        if self.built == Some(i) && spare == 0 {
            return true;
        }
        let (n, m) = (self.n, self.dims[i] + spare);
        if levels.len() != self.dims.len()
            || !self.selection.build(
                &levels[..i],
                &levels[i],
                spare,
                n,
                &mut self.closed[..n * m],
            )
        {
            return false;
        }
        self.built = Some(i);
        true
    }

    /// Level i in closed form, when it is a selection that completes the rank under levels of
    /// full rank ([`super::selection`]): its block g_i from one LU instead of its reduction, and
    /// its rank m_i (all its rows kept, no damping) decided by the lower bound σ_low on the
    /// reduced level's singular values: taken only when σ_low > 2 × the rank threshold (and
    /// × the adaptive damping's threshold), so that the QR, which is not run, would keep every
    /// row with λ = 0 up to rounding. Its reduction is deferred ([`Hierarchy::complete`]);
    /// [`Hierarchy::solve`] adds its step. False (nothing decided) otherwise.
    fn solve_closed(
        &mut self,
        i: usize,
        levels: &[TaskEquation],
        settings: &SolverSettings,
    ) -> bool {
        let (n, m, p) = (self.n, self.dims[i], self.refl.len());
        // p = Σ_{k<i} r_k equals Σ_{k<i} m_k only when every level above has full rank.
        if m == 0 || p != self.offsets[i] || p + m != n {
            return false;
        }
        let Some(floor) = undamped_floor(settings) else {
            return false;
        };
        if !self.build_closed(i, levels, 0) || !clears(self.selection.sigma_lower_bound(), floor) {
            return false;
        }
        self.ranks[i] = m;
        self.fac[i].direct = true;
        self.closed_level = Some(i);
        self.deferred = Some((i, i));
        true
    }

    /// Level i by its Gram matrix, when it holds weighted joint rows and completes the rank
    /// ([`super::gram`]): its step into `u`, its rank k = n − p_i, its reduction deferred
    /// ([`Hierarchy::complete`]). False (nothing decided) otherwise.
    fn solve_gram(&mut self, i: usize, level: &TaskEquation, settings: &SolverSettings) -> bool {
        let p = self.refl.len();
        let Some(lambda2) = self.gram.step(
            level,
            &self.refl,
            self.u.as_mut_slice(),
            settings.damping,
            settings.rank_threshold,
        ) else {
            return false;
        };
        self.gram_lambda2 = lambda2;
        self.gram_stepped = Some(i);
        self.ranks[i] = self.n - p;
        self.fac[i].direct = false;
        self.gram_level = Some(i);
        self.deferred = Some((i, i));
        true
    }

    /// Runs the reductions that the last [`Hierarchy::solve`] deferred (the levels from
    /// `deferred.0` to the one it took in closed form or by its Gram matrix), for what needs
    /// their factors (the reflectors, R, Π: the blocks of the general construction, J̄^{λ+}).
    /// The ranks they find are the ones decided (by the bounds of the `selection` and `gram`
    /// modules).
    fn complete(&mut self) {
        let Some((from, to)) = self.deferred.take() else {
            return;
        };
        let settings = self.settings;
        for k in from..=to {
            self.starts[k] = self.refl.len();
            let decided = self.ranks[k];
            self.reduce_level(k, &settings);
            debug_assert_eq!(self.ranks[k], decided, "level {k}: the rank decided");
        }
        // From here on the level's QR factors serve it (its reflectors are in `refl`).
        self.gram_level = None;
    }

    /// Reduces level i: its rows multiplied by the reflectors of the levels above, pivoted QR
    /// of A_i = (W_i\[:, p..n\])ᵀ, the factors R_r, L and Π, and the damping.
    fn reduce_level(&mut self, i: usize, settings: &SolverSettings) {
        let (n, m, p) = (self.n, self.dims[i], self.refl.len());
        let k = n - p;
        self.ranks[i] = 0;
        if m == 0 || k == 0 {
            // No coordinate left (the levels above took all n) or no row: rank 0, and W_i is
            // never read (the residual, the reduced blocks and the propagation into lower
            // levels all skip a level of rank 0), so its rows are not reduced.
            return;
        }
        let (off, wld) = (self.offsets[i], self.wld);
        // The rows of this level under the reflectors of the levels above:
        // W_i = J_i H_0 ⋯ H_{p−1}, applied when the level is reached (left-looking), in the
        // blocks of four of all levels above at once, to all the level's rows together.
        self.refl
            .apply_forward_rows(p, &mut self.w, wld, off, m, &mut self.qscratch);
        let ar = self.a.nrows();
        {
            let asl = self.a.as_mut_slice();
            for t in 0..k {
                let wrow = &self.w[(p + t) * wld + off..(p + t) * wld + off + m];
                for (c, &x) in wrow.iter().enumerate() {
                    asl[c * ar + t] = x;
                }
            }
        }
        let perm = &mut self.fac[i].perm;
        for (c, pc) in perm.iter_mut().enumerate() {
            *pc = c;
        }
        // Householder QR with column pivoting of A (k × m).
        let steps = k.min(m);
        let mut rank = 0;
        // Squared column norms over the rows not yet reduced, downdated after each step
        // (‖x[st+1..]‖² = ‖x[st..]‖² − x_st²) and recomputed when the downdate has cancelled
        // to below NORM_DOWNDATE_TOL of the last exact value, as LAPACK's xGEQP3 does.
        {
            let asl = self.a.as_slice();
            for c in 0..m {
                let col = &asl[c * ar..c * ar + k];
                self.colnorm[c] = dot(col, col);
                self.colnorm_ref[c] = self.colnorm[c];
            }
        }
        for st in 0..steps {
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
                self.colnorm_ref.swap(st, best);
            }
            // The pivot's norm exactly: it decides the rank and forms the reflector.
            let norm = {
                let col = &self.a.as_slice()[st * ar + st..st * ar + k];
                dot(col, col).sqrt()
            };
            if norm <= settings.rank_threshold {
                break;
            }
            // v = x − α e1 with α = −sign(x0)‖x‖; H = I − τ v vᵀ, τ = 2 / vᵀv.
            let asl = self.a.as_mut_slice();
            let x0 = asl[st * ar + st];
            let alpha = if x0 >= 0.0 { -norm } else { norm };
            let vcol = self.refl.next_slot();
            vcol.copy_from_slice(&asl[st * ar + st..st * ar + k]);
            vcol[0] = x0 - alpha;
            let (tau, _) = self.refl.commit();
            let v = self.refl.vector(p + st);
            // Apply H to the remaining columns of A: column st becomes α e1.
            asl[st * ar + st] = alpha;
            asl[st * ar + st + 1..st * ar + k].fill(0.0);
            reflect_trailing(v, tau, asl, ar, st, m);
            for c in st + 1..m {
                let top = asl[c * ar + st];
                self.colnorm[c] -= top * top;
                if self.colnorm[c] <= NORM_DOWNDATE_TOL * self.colnorm_ref[c] {
                    let rest = &asl[c * ar + st + 1..c * ar + k];
                    self.colnorm[c] = dot(rest, rest);
                    self.colnorm_ref[c] = self.colnorm[c];
                }
            }
            rank = st + 1;
        }
        self.ranks[i] = rank;
        if rank == 0 {
            return;
        }
        // λ² from the damping rule; σ_min estimated by the last kept pivot |R_rr|.
        let sigma = self.a[(rank - 1, rank - 1)].abs();
        let lambda2 = match settings.damping {
            // The level stepped by its Gram matrix keeps the damping it was stepped with.
            _ if self.gram_level == Some(i) => self.gram_lambda2,
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
        let f = &mut self.fac[i];
        let (fr, asl) = (f.r.nrows(), self.a.as_slice());
        for (c, col) in f.r.as_mut_slice().chunks_exact_mut(fr).take(m).enumerate() {
            let top = rank.min(c + 1);
            col[..top].copy_from_slice(&asl[c * ar..c * ar + top]);
            col[top..rank].fill(0.0);
        }
        f.factor(rank, m, lambda2);
    }

    /// Writes into `yb` (row-major n × m_i, rows p_i.. written, the rows above zero) the
    /// reduced-coordinate change of q̈ caused by unit changes of the rows of h_i: level i's own
    /// step (J̄_i⁺ in reduced coordinates), then, if `propagate`, every lower level's response
    /// (g_i). All m_i columns at once: each step is a row operation on m_i-long rows.
    ///
    /// With `in_basis` and 0 < r_i < m_i the right-hand sides are instead the r_i columns of
    /// U_i = Π V_i ([`LevelFactor::row_space`]): the changes of h_i that move q̈ at all, in an
    /// orthonormal basis, so `yb` is n × r_i. Returns the number of columns written.
    fn reduced_block(&mut self, i: usize, propagate: bool) -> usize {
        self.reduced_block_in(i, propagate, false)
    }

    fn reduced_block_in(&mut self, i: usize, propagate: bool, in_basis: bool) -> usize {
        // The correction map of a level stepped by its Gram matrix, and the responses of that
        // level to the levels above, come from its Gram factors ([`super::gram`]); anything
        // else needs its QR.
        let gram = self
            .gram_level
            .filter(|&g| in_basis && self.rank_deficient(g) && i <= g);
        if gram.is_none() {
            self.complete();
        }
        let (n, m, r, p) = (self.n, self.dims[i], self.ranks[i], self.starts[i]);
        if gram == Some(i) {
            // U_i = J̄ L₀⁻ᵀ: r = k columns, rows p..n.
            let yb = &mut self.yb[..n * r];
            yb[..p * r].fill(0.0);
            self.gram.basis_block(yb);
            return r;
        }
        let basis = in_basis && self.rank_deficient(i);
        if basis {
            // U_i is needed only here, when a correction map is built.
            self.fac[i].row_space(r, m);
        }
        let nc = if basis { r } else { m };
        let yb = &mut self.yb[..n * nc];
        if r == 0 || nc == 0 {
            // Level i moves nothing, so nothing below it moves either.
            yb.fill(0.0);
            return nc;
        }
        // Rows p..p + r are written below (and the lower levels' rows, when propagating).
        yb[..p * nc].fill(0.0);
        yb[(p + r) * nc..].fill(0.0);
        let f = &self.fac[i];
        let bb = &mut self.bb[..m * nc];
        if basis {
            // B = Πᵀ U = V (pivoted order): row j is row j of V.
            for j in 0..m {
                for q in 0..nc {
                    bb[j * nc + q] = f.basis[(j, q)];
                }
            }
            f.apply_rows(r, m, nc, bb, &mut yb[p * nc..(p + r) * nc]);
        } else if f.direct {
            f.inverse_rows(nc, bb, &mut yb[p * nc..(p + r) * nc]);
        } else {
            // B = Πᵀ I: row j is e_{perm[j]}.
            bb.fill(0.0);
            for (j, &pj) in f.perm.iter().enumerate() {
                bb[j * nc + pj] = 1.0;
            }
            f.apply_rows(r, nc, nc, bb, &mut yb[p * nc..(p + r) * nc]);
        }
        if !propagate {
            return nc;
        }
        let (ws, wld) = (&self.w, self.wld);
        for k in i + 1..self.dims.len() {
            let (mk, rk, pk) = (self.dims[k], self.ranks[k], self.starts[k]);
            if rk == 0 {
                continue;
            }
            if gram == Some(k) {
                // Its rows p_k..n from the rows p..p_k above; the levels below it have rank 0.
                self.gram.propagate(&mut self.yb[..n * nc], nc, p);
                break;
            }
            let off = self.offsets[k];
            let f = &self.fac[k];
            // B row j = −Σ_{s ∈ [p, p_k)} W[s, row perm[j] of level k] · Y[s, :].
            let bb = &mut self.bb[..mk * nc];
            bb.fill(0.0);
            for (j, &pj) in f.perm.iter().enumerate() {
                let brow = &mut bb[j * nc..(j + 1) * nc];
                for sidx in p..pk {
                    let c = ws[sidx * wld + off + pj];
                    if c != 0.0 {
                        axpy(-c, &yb[sidx * nc..(sidx + 1) * nc], brow);
                    }
                }
            }
            f.apply_rows(rk, mk, nc, bb, &mut yb[pk * nc..(pk + rk) * nc]);
        }
        nc
    }

    /// Builds the block g_i of G (Algorithm 1), using the factors of the last
    /// [`Hierarchy::solve`]. Allocates nothing.
    pub fn build_g_level(&mut self, i: usize) {
        self.build_g_levels(i, i + 1);
    }

    /// Builds the blocks g_i of the levels `from..to` together: each level's reduced block,
    /// then Q applied once to all their columns (one pass over the reflectors instead of one
    /// per level). A level of rank 0 moves nothing (g_i = 0, nor does any level below it
    /// respond): its columns are zeroed, not computed. Allocates nothing.
    pub fn build_g_levels(&mut self, from: usize, to: usize) {
        let _ = self.build_blocks(None, from, to, false);
    }

    /// The columns of levels `from..to` of G (`in_basis` false) or of the correction map
    /// (`in_basis` true; [`Hierarchy::build_correction_map`]): the reduced blocks of the
    /// levels with columns, side by side in `yall`, Q applied once to all of them, then each
    /// level's columns into place.
    ///
    /// With `levels` (those of the last solve), a block that the closed form of the
    /// `selection` module covers is built that way instead.
    /// Returns whether the closed form built them.
    fn build_blocks(
        &mut self,
        levels: Option<&[TaskEquation]>,
        from: usize,
        to: usize,
        in_basis: bool,
    ) -> bool {
        let n = self.n;
        let to = to.min(self.dims.len());
        if from >= to {
            return false;
        }
        let width = |h: &Self, i: usize| {
            if in_basis {
                h.correction_width(i)
            } else if h.ranks[i] > 0 {
                h.dims[i]
            } else {
                0
            }
        };
        if !in_basis {
            for i in (from..to).filter(|&i| self.ranks[i] == 0) {
                let (c, m) = (self.offsets[i], self.dims[i]);
                self.g.as_mut_slice()[c * n..(c + m) * n].fill(0.0);
            }
        }
        let w: usize = (from..to).map(|i| width(self, i)).sum();
        if w == 0 {
            return false;
        }
        if let Some(levels) = levels {
            if self.selection_block(levels, from, to, in_basis) {
                return true;
            }
        }
        let mut co = 0;
        for i in from..to {
            if width(self, i) == 0 {
                continue;
            }
            let m = self.reduced_block_in(i, true, in_basis);
            for d in 0..n {
                self.yall[d * w + co..d * w + co + m].copy_from_slice(&self.yb[d * m..(d + 1) * m]);
            }
            co += m;
        }
        // Q Y on the rows of Y, then into the columns of each level.
        self.refl
            .apply_q_rows(&mut self.yall[..n * w], w, &mut self.qscratch);
        let mut co = 0;
        for i in from..to {
            let m = width(self, i);
            if m == 0 {
                continue;
            }
            let c0 = self.block_offset(i, in_basis);
            let target = if in_basis { &mut self.gc } else { &mut self.g };
            let gs = &mut target.as_mut_slice()[c0 * n..(c0 + m) * n];
            for (c, col) in gs.chunks_exact_mut(n).enumerate() {
                for (d, x) in col.iter_mut().enumerate() {
                    *x = self.yall[d * w + co + c];
                }
            }
            co += m;
        }
        false
    }

    /// First column of level i's block: in the correction map with `in_basis`, in G otherwise.
    fn block_offset(&self, i: usize, in_basis: bool) -> usize {
        if in_basis {
            self.correction_offset(i)
        } else {
            self.offsets[i]
        }
    }

    /// The block of the one level with columns among `from..to` by the closed form of the
    /// `selection` module, when its conditions hold: that level is the last of rank > 0,
    /// solved exactly (full rank, no damping), under levels of full rank. False (nothing
    /// written that the general construction does not overwrite) otherwise.
    fn selection_block(
        &mut self,
        levels: &[TaskEquation],
        from: usize,
        to: usize,
        in_basis: bool,
    ) -> bool {
        let nt = self.dims.len();
        let Some(i) = (from..to).find(|&k| self.ranks[k] > 0) else {
            return false;
        };
        if levels.len() != nt
            || !self.fac[i].direct
            || (i + 1..nt).any(|k| self.ranks[k] > 0)
            || (0..i).any(|k| self.ranks[k] != self.dims[k])
        {
            return false;
        }
        let (n, m) = (self.n, self.dims[i]);
        let c0 = self.block_offset(i, in_basis);
        let target = if in_basis { &mut self.gc } else { &mut self.g };
        let out = &mut target.as_mut_slice()[c0 * n..(c0 + m) * n];
        if self.built == Some(i) {
            // Built by the solve already.
            out.copy_from_slice(&self.closed[..n * m]);
            return true;
        }
        self.selection.build(&levels[..i], &levels[i], 0, n, out)
    }

    /// Columns of level i in the correction map ([`Hierarchy::build_correction_map`]): 0 when
    /// its rank is 0, r_i when 0 < r_i < m_i, m_i when it has full rank.
    pub fn correction_width(&self, i: usize) -> usize {
        if self.rank_deficient(i) {
            self.ranks[i]
        } else if self.ranks[i] == 0 {
            0
        } else {
            self.dims[i]
        }
    }

    /// Whether level i kept fewer rows than it has, but some (0 < r_i < m_i): its corrections
    /// enter the correction map in the basis U_i.
    fn rank_deficient(&self, i: usize) -> bool {
        let r = self.ranks[i];
        r > 0 && r < self.dims[i]
    }

    /// First column of level i in the correction map: the widths of the levels above.
    pub fn correction_offset(&self, i: usize) -> usize {
        (0..i).map(|k| self.correction_width(k)).sum()
    }

    /// The correction map of levels `from..to`, the columns of IKTC's correction QP: for a
    /// level of full rank its block g_i of G (Algorithm 1); for a level of rank r_i < m_i the
    /// r_i columns g_i U_i, U_i (m_i × r_i, orthonormal) spanning the changes of h_i that move
    /// q̈ (the row space of J̄_i^{λ+}; [`Hierarchy::correction_demand`] maps back); nothing for
    /// a level of rank 0. A correction Δh_i outside that row space changes ‖Δh_i‖ without
    /// changing q̈, so the least correction lies in it, and with Δh_i = U_i z_i, ‖Δh_i‖ =
    /// ‖z_i‖: the QP over z has the same optimum, with r_i instead of m_i variables. Allocates
    /// nothing.
    ///
    /// `levels` are those of the last [`Hierarchy::solve`] (only their Jacobians are read): a
    /// bottom level that selects coordinates and completes the rank gets its block in closed
    /// form from them (the `selection` module), the same map up to rounding. Returns whether
    /// it was.
    pub fn build_correction_map(
        &mut self,
        levels: &[TaskEquation],
        from: usize,
        to: usize,
    ) -> bool {
        self.build_blocks(Some(levels), from, to, true)
    }

    /// The correction map (n × Σ widths), columns of level i from
    /// [`Hierarchy::correction_offset`]`(i)`, valid once built.
    pub fn correction_map(&self) -> &DMatrix<f64> {
        &self.gc
    }

    /// Δh_i \[task units\] (length m_i) for the correction `z` of level i in the correction
    /// map's coordinates (length [`Hierarchy::correction_width`]`(i)`): U_i z, z itself at full
    /// rank, zero at rank 0.
    pub fn correction_demand(&mut self, i: usize, z: &[f64], out: &mut [f64]) {
        let (m, w) = (self.dims[i], self.correction_width(i));
        if w == m {
            out[..m].copy_from_slice(&z[..m]);
            return;
        }
        if self.gram_level == Some(i) {
            self.gram.demand(&self.refl, z, out);
            return;
        }
        out[..m].fill(0.0);
        let f = &self.fac[i];
        for (c, &pc) in f.perm.iter().enumerate() {
            out[pc] = (0..w).map(|q| f.basis[(c, q)] * z[q]).sum();
        }
    }
}

/// The floor that the closed forms' lower bounds on the reduced levels' singular values must
/// clear (× 2, for rounding) for the QR to keep every row with λ = 0: the rank threshold, and
/// the adaptive damping's threshold ε (λ = 0 for a last pivot ≥ ε); None for a fixed λ > 0.
fn undamped_floor(settings: &SolverSettings) -> Option<f64> {
    match settings.damping {
        Damping::None => Some(settings.rank_threshold),
        Damping::Fixed(0.0) => Some(settings.rank_threshold),
        Damping::Fixed(_) => None,
        Damping::Adaptive { max, threshold } if max != 0.0 => {
            Some(settings.rank_threshold.max(threshold))
        }
        Damping::Adaptive { .. } => Some(settings.rank_threshold),
    }
}

/// Whether a lower bound on singular values clears 2 × `floor` (false for NaN).
pub(super) fn clears(bound: f64, floor: f64) -> bool {
    bound > 2.0 * floor
}

/// The factors of one level's J̄^{λ+} in reduced coordinates: out = S⁻¹ R_r Πᵀ b with
/// S = R_r R_rᵀ + λ² I.
#[derive(Debug, Clone)]
struct LevelFactor {
    /// R_r, upper trapezoidal r × m (in an m × m buffer).
    r: DMatrix<f64>,
    /// The Cholesky factor L of S (lower, r × r); unused when `direct`.
    l: DMatrix<f64>,
    /// The pivot order Π: position c of the pivoted rows holds task row perm\[c\].
    perm: Vec<usize>,
    /// λ = 0 and r = m: R_r is square and invertible, S⁻¹ R_r = R_r⁻ᵀ, one triangular solve.
    direct: bool,
    /// 0 < r < m: the m × r orthonormal basis V of the column space of R_rᵀ (pivoted order)
    /// in the first r columns, from a Householder QR of R_rᵀ ([`LevelFactor::row_space`]).
    basis: DMatrix<f64>,
    /// Scratch of the QR of R_rᵀ.
    qr: DMatrix<f64>,
}

impl LevelFactor {
    fn new(m: usize) -> Self {
        Self {
            r: DMatrix::zeros(m, m),
            l: DMatrix::zeros(m, m),
            perm: vec![0; m],
            direct: false,
            basis: DMatrix::zeros(m, m),
            qr: DMatrix::zeros(m, m),
        }
    }

    /// When 0 < r < m: V (m × r, orthonormal columns) spanning the column space of R_rᵀ, by a
    /// Householder QR R_rᵀ = V T (T upper triangular r × r, invertible since R_r has full row
    /// rank): V = H_0 ⋯ H_{r−1} \[I_r; 0\]. The reflectors are kept in `qr` (vector j in
    /// column j from row j on, τ_j in column r, free since r < m). Allocates nothing.
    fn row_space(&mut self, r: usize, m: usize) {
        if r == 0 || r >= m {
            return;
        }
        let rr = self.r.nrows();
        let (rs, h, v) = (self.r.as_slice(), &mut self.qr, &mut self.basis);
        // M = R_rᵀ: M[c, q] = R[q, c] (zero for c < q).
        for q in 0..r {
            for c in 0..m {
                h[(c, q)] = if c >= q { rs[c * rr + q] } else { 0.0 };
            }
        }
        for j in 0..r {
            let norm = (j..m).map(|c| h[(c, j)] * h[(c, j)]).sum::<f64>().sqrt();
            let x0 = h[(j, j)];
            let alpha = if x0 >= 0.0 { -norm } else { norm };
            h[(j, j)] = x0 - alpha;
            let vv: f64 = (j..m).map(|c| h[(c, j)] * h[(c, j)]).sum();
            let t = if vv > 0.0 { 2.0 / vv } else { 0.0 };
            for q in j + 1..r {
                let f = t * (j..m).map(|c| h[(c, j)] * h[(c, q)]).sum::<f64>();
                for c in j..m {
                    h[(c, q)] -= f * h[(c, j)];
                }
            }
            h[(j, r)] = t;
        }
        for q in 0..r {
            for c in 0..m {
                v[(c, q)] = if c == q { 1.0 } else { 0.0 };
            }
        }
        for j in (0..r).rev() {
            let t = h[(j, r)];
            for q in 0..r {
                let f = t * (j..m).map(|c| h[(c, j)] * v[(c, q)]).sum::<f64>();
                if f != 0.0 {
                    for c in j..m {
                        v[(c, q)] -= f * h[(c, j)];
                    }
                }
            }
        }
    }

    /// Factors S = R_r R_rᵀ + λ² I = L Lᵀ, unless λ² = 0 and R_r is square. S is SPD: R_r
    /// has full row rank r.
    fn factor(&mut self, r: usize, m: usize, lambda2: f64) {
        self.direct = lambda2 == 0.0 && r == m;
        if self.direct {
            return;
        }
        let (rf, l) = (&self.r, &mut self.l);
        for q in 0..r {
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
        for q in 0..r {
            let mut d = l[(q, q)];
            for t in 0..q {
                d -= l[(q, t)] * l[(q, t)];
            }
            let lq = d.max(f64::MIN_POSITIVE).sqrt();
            l[(q, q)] = lq;
            for i in q + 1..r {
                let mut x = l[(i, q)];
                for t in 0..q {
                    x -= l[(i, t)] * l[(q, t)];
                }
                l[(i, q)] = x / lq;
            }
        }
    }

    /// The same for nc right-hand sides at once: `b` row-major m × nc (overwritten), `out`
    /// row-major r × nc.
    fn apply_rows(&self, r: usize, m: usize, nc: usize, b: &mut [f64], out: &mut [f64]) {
        let rr = self.r.nrows();
        let rs = self.r.as_slice();
        if self.direct {
            // R_rᵀ X = B row by row: X[q] = (B[q] − Σ_{t<q} R[t, q] X[t]) / R[q, q].
            for q in 0..r {
                let (done, rest) = out.split_at_mut(q * nc);
                let row = &mut rest[..nc];
                row.copy_from_slice(&b[q * nc..(q + 1) * nc]);
                // Two rows of X per pass over the row (same order of the sums).
                let mut t = 0;
                while t + 1 < q {
                    let (c0, c1) = (rs[q * rr + t], rs[q * rr + t + 1]);
                    let x0 = &done[t * nc..(t + 1) * nc];
                    let x1 = &done[(t + 1) * nc..(t + 2) * nc];
                    axpy2(-c0, x0, -c1, x1, row);
                    t += 2;
                }
                if t < q {
                    let c = rs[q * rr + t];
                    if c != 0.0 {
                        axpy(-c, &done[t * nc..(t + 1) * nc], row);
                    }
                }
                let inv = 1.0 / rs[q * rr + q];
                row.iter_mut().for_each(|x| *x *= inv);
            }
            return;
        }
        // Z = R_r B (R_r upper trapezoidal: row q starts at column q).
        for q in 0..r {
            let row = &mut out[q * nc..(q + 1) * nc];
            row.fill(0.0);
            for c in q..m {
                let f = rs[c * rr + q];
                if f != 0.0 {
                    axpy(f, &b[c * nc..(c + 1) * nc], row);
                }
            }
        }
        // L W = Z, then Lᵀ X = W, row by row.
        let lr = self.l.nrows();
        let ls = self.l.as_slice();
        for q in 0..r {
            let (done, rest) = out.split_at_mut(q * nc);
            let row = &mut rest[..nc];
            for t in 0..q {
                axpy(-ls[t * lr + q], &done[t * nc..(t + 1) * nc], row);
            }
            let inv = 1.0 / ls[q * lr + q];
            row.iter_mut().for_each(|x| *x *= inv);
        }
        for q in (0..r).rev() {
            let (head, tail) = out.split_at_mut((q + 1) * nc);
            let row = &mut head[q * nc..];
            for t in q + 1..r {
                axpy(-ls[q * lr + t], &tail[(t - q - 1) * nc..(t - q) * nc], row);
            }
            let inv = 1.0 / ls[q * lr + q];
            row.iter_mut().for_each(|x| *x *= inv);
        }
    }

    /// `out` (row-major m × m) = R⁻ᵀ Πᵀ, what [`LevelFactor::apply_rows`] gives for B = Πᵀ I
    /// when `direct` (r = m). In the pivoted column order X' = R⁻ᵀ is lower triangular: row q
    /// is (e_q − Σ_{t<q} R\[t, q\] X'\[t\]) / R\[q, q\] with X'\[t\] zero from column t + 1
    /// on, so each row costs q + 1 instead of m; then column c of X' is column perm\[c\] of
    /// `out`. The same sums as the full forward substitution, without its additions of zeros.
    /// `tri`: m × m scratch.
    fn inverse_rows(&self, m: usize, tri: &mut [f64], out: &mut [f64]) {
        let rr = self.r.nrows();
        let rs = self.r.as_slice();
        for q in 0..m {
            let (done, rest) = tri.split_at_mut(q * m);
            let row = &mut rest[..q + 1];
            row.fill(0.0);
            row[q] = 1.0;
            for t in 0..q {
                let c = rs[q * rr + t];
                if c != 0.0 {
                    axpy(-c, &done[t * m..t * m + t + 1], &mut row[..t + 1]);
                }
            }
            let inv = 1.0 / rs[q * rr + q];
            row.iter_mut().for_each(|x| *x *= inv);
            let orow = &mut out[q * m..(q + 1) * m];
            orow.fill(0.0);
            for (c, &x) in row.iter().enumerate() {
                orow[self.perm[c]] = x;
            }
        }
    }

    /// out = S⁻¹ R_r b (r entries) for b = Πᵀ residual of length m.
    fn apply(&self, r: usize, m: usize, b: &[f64], out: &mut [f64]) {
        let rr = self.r.nrows();
        let rs = self.r.as_slice();
        if self.direct {
            // R_rᵀ out = b by forward substitution; column q of R holds R[0..q, q].
            for q in 0..r {
                let t = dot(&rs[q * rr..q * rr + q], &out[..q]);
                out[q] = (b[q] - t) / rs[q * rr + q];
            }
            return;
        }
        // z = R_r b (R_r upper trapezoidal: row q starts at column q).
        out.fill(0.0);
        for (c, &bc) in b.iter().enumerate().take(m) {
            if bc != 0.0 {
                let top = (c + 1).min(r);
                axpy(bc, &rs[c * rr..c * rr + top], &mut out[..top]);
            }
        }
        // Forward substitution with the columns of L, then back substitution with its rows.
        let lr = self.l.nrows();
        let ls = self.l.as_slice();
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
}

/// Applies the reflector `H = I − τ v vᵀ` of QR step `st` to the columns `st + 1..m` of the
/// column-major `a` (leading dimension `ar`), on the rows `st..st + v.len()`: four columns at
/// a time ([`reflect_columns`]), then the rest one by one.
fn reflect_trailing(v: &[f64], tau: f64, a: &mut [f64], ar: usize, st: usize, m: usize) {
    let len = v.len();
    let mut c = st + 1;
    while c + 4 <= m {
        let block = &mut a[c * ar + st..];
        let (c0, rest) = block.split_at_mut(ar);
        let (c1, rest) = rest.split_at_mut(ar);
        let (c2, c3) = rest.split_at_mut(ar);
        reflect_columns::<4>(
            v,
            tau,
            [
                &mut c0[..len],
                &mut c1[..len],
                &mut c2[..len],
                &mut c3[..len],
            ],
        );
        c += 4;
    }
    while c < m {
        let col = &mut a[c * ar + st..c * ar + st + len];
        reflect_columns::<1>(v, tau, [col]);
        c += 1;
    }
}
