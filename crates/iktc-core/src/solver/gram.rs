//! The step of a level of weighted joint rows that completes the rank, from its Gram matrix
//! instead of its pivoted QR.
//!
//! ## When it applies
//!
//! Level i, reached with k = n − p_i reduced coordinates left (the null space of the levels
//! above is spanned by Z = Q\[:, p_i..n\], ZᵀZ = I), holds m_g general rows J_g and m_s rows
//! that each select one coordinate C\[c\] with the same weight |s_c| = w (a posture task's
//! joints, weighted into a level with the hands), no coordinate selected twice; O are the
//! n − m_s coordinates not selected (the floating base and the joints outside the posture).
//! When the reduced level J_i Z (m_i × k) has full column rank k, level i takes every
//! coordinate left and its step is the unique least-squares solution
//!
//! ```text
//! y = argmin ‖J_i Z y − ρ‖²,   ρ = h_i − J_i q̈_{i−1},   q̈_i = q̈_{i−1} + Z y,
//! ```
//!
//! the same as the QR's J̄_i⁺ ρ (eq. 4) when the QR keeps k pivots with λ = 0. It solves the
//! normal equations M y = Zᵀ J_iᵀ ρ with
//!
//! ```text
//! M = Zᵀ J_iᵀ J_i Z = (J_g Z)ᵀ (J_g Z) + w² Σ_c z_cᵀ z_c = (J_g Z)ᵀ (J_g Z) + w² (I − Z_Oᵀ Z_O),
//! ```
//!
//! z_c the row C\[c\] of Z: the rows of an orthonormal basis sum to the identity, so the
//! selected rows' sum is I minus the rows O. Only J_g and the |O| unit rows e_o are carried
//! through the reflectors of the levels above (on G1's keypoint stack 6 + 6 rows instead of
//! the level's 35), and M (k × k) is factored by Cholesky instead of a pivoted QR of the
//! k × m_i reduced level. Zᵀ J_iᵀ ρ is one vector through the same reflectors.
//!
//! ## Rank without the QR
//!
//! The QR of A = (J_i Z)ᵀ (k × m_i, rank k) keeps every pivot when all exceed the rank
//! threshold. With greedy column pivoting, pivot j (0-based) is the largest norm of a
//! remaining column projected onto the complement P of the j columns chosen (dimension
//! k − j); the columns chosen vanish under P, so (m_i − j) · |R_jj|² ≥ ‖P A‖_F² ≥ ‖P A‖₂² ≥
//! σ_k(A)² and
//!
//! ```text
//! |R_jj| ≥ σ_min(J_i Z) / √m_i   for every j,
//! ```
//!
//! σ_min(J_i Z)² = λ_min(M). With M = L Lᵀ, λ_min(M) = 1 / ‖L⁻¹‖₂², ‖L⁻¹‖₂ ≤ √k ‖L⁻¹‖_∞, and
//! ‖L⁻¹‖_∞ ≤ max(M(L)⁻¹ 𝟙) for the comparison matrix M(L) (|L_jj| on the diagonal, −|L_rj|
//! off it; Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., Thm. 8.12).
//! Also M ⪰ w² (I − Z_Oᵀ Z_O), so λ_min(M) ≥ w² (1 − ‖Z_O Z_Oᵀ‖₂), the norm bounded by the
//! largest absolute row sum of the |O| × |O| matrix Z_O Z_Oᵀ (Gershgorin). The larger of the
//! two bounds, divided by √m_i, must clear 2 × the rank threshold, as the `selection`
//! module's bounds do; otherwise, or when the Cholesky factorisation meets a pivot that is
//! not positive, the caller reduces the level by its QR. The QR is run later only if
//! something needs the level's factors (the blocks of G, the correction map), with the λ²
//! of the step.
//!
//! ## Damping
//!
//! The damped least-squares inverse in reduced coordinates is J̄ᵀ(J̄J̄ᵀ + λ²I)⁻¹ =
//! (J̄ᵀJ̄ + λ²I)⁻¹J̄ᵀ (eqs. 8–9), so the damped step solves (M + λ² I) y = Zᵀ J_iᵀ ρ. A fixed λ
//! gives the other levels' answer to rounding. The adaptive rule
//! λ² = (1 − (σ/ε)²) λ_max² for σ < ε needs σ_min(J̄): the QR levels estimate it by their
//! last pivot |R_kk|, this step by inverse iteration on M ([`smallest_singular_value`]).
//! Both estimates lie above σ_min, neither is exact, and they differ: on a level of the
//! adaptive rule's region the two paths damp by different λ² and their answers differ by
//! that (the keypoint stack on G1: figures in the CHANGELOG).
//!
//! The normal equations square the level's condition number: with the bound above clearing
//! the floor the two solutions agree to rounding × κ(J_i Z)², which the tests compare.

use super::kernels::{axpy, dot};
use super::reflectors::Reflectors;
use super::settings::Damping;
use crate::task::TaskEquation;

/// The workspace of the Gram step, sized once for n coordinates and levels of at most `mmax`
/// rows. Allocates nothing per solve.
#[derive(Debug, Clone)]
pub(crate) struct GramLevel {
    n: usize,
    /// The general rows of the level (indices into its rows), and the joint rows with the
    /// coordinate each selects.
    general: Vec<usize>,
    selections: Vec<(usize, usize, f64)>,
    /// Per row: its number of non-zero entries and the coordinate of the last.
    count: Vec<usize>,
    last: Vec<usize>,
    /// The coordinates not selected (O).
    others: Vec<usize>,
    /// Per coordinate: selected by a row of the level.
    selected: Vec<bool>,
    /// Rows carried through the reflectors, by coordinate: entry (row r, coordinate t) at
    /// `rows[t * ld + r]`; the general rows first, then the unit rows e_o.
    rows: Vec<f64>,
    ld: usize,
    /// The carried rows' reduced parts (J_g Z, then Z_O), row r at r · n.
    reduced: Vec<f64>,
    /// M (lower triangle), and the Cholesky factor L (lower) of M + λ² I when λ > 0; k × k,
    /// row r at r · n, in n × n buffers.
    gram: Vec<f64>,
    m: Vec<f64>,
    /// n-vectors: q̈_{i−1}, then J_iᵀ ρ and Qᵀ J_iᵀ ρ; the comparison matrix' solve.
    v: Vec<f64>,
    x: Vec<f64>,
    /// ρ (m_i).
    res: Vec<f64>,
    scratch: Vec<f64>,
    /// The undamped Cholesky factor L₀ of M (row r at r · n): the step's factor when λ = 0, and
    /// the basis of the correction map; and scratch blocks of the correction map.
    l0: Vec<f64>,
    block_t: Vec<f64>,
    block_b: Vec<f64>,
    /// The last step taken: p, k, the general rows' count m_g, the carried rows' count, w²
    /// and whether λ² > 0 (then `m` holds the factor of M + λ² I, else `l0` serves).
    geometry: Geometry,
}

/// Where the last step was taken (see [`GramLevel::step`]).
#[derive(Debug, Clone, Copy, Default)]
struct Geometry {
    p: usize,
    k: usize,
    mg: usize,
    nr: usize,
    w2: f64,
    damped: bool,
}

impl GramLevel {
    /// A workspace for `n` coordinates and levels of at most `mmax` rows.
    pub(crate) fn new(n: usize, mmax: usize) -> Self {
        let ld = (mmax + n).max(1);
        Self {
            n,
            general: Vec::with_capacity(mmax),
            selections: Vec::with_capacity(mmax),
            count: vec![0; mmax],
            last: vec![0; mmax],
            others: Vec::with_capacity(n),
            selected: vec![false; n],
            rows: vec![0.0; n * ld],
            ld,
            reduced: vec![0.0; ld * n],
            gram: vec![0.0; n * n],
            m: vec![0.0; n * n],
            v: vec![0.0; n],
            x: vec![0.0; n],
            res: vec![0.0; mmax],
            scratch: vec![0.0; 4 * ld],
            l0: vec![0.0; n * n],
            block_t: vec![0.0; ld * n.max(mmax)],
            block_b: vec![0.0; n * n.max(mmax)],
            geometry: Geometry::default(),
        }
    }

    /// The Cholesky factor of M + λ² I of the last step.
    fn factor(&self) -> &[f64] {
        if self.geometry.damped {
            &self.m
        } else {
            &self.l0
        }
    }

    /// Sorts the rows of `level` into selections and general rows (`general`, `others`); the
    /// common weight w of the selections, or None when the level is not one this step covers
    /// (no selection, two weights, a coordinate selected twice) or would not gain by it (as
    /// many rows to carry as the level has).
    fn classify(&mut self, level: &TaskEquation) -> Option<f64> {
        let (n, m) = (self.n, level.dim());
        let j = level.jacobian.as_slice();
        self.general.clear();
        self.others.clear();
        self.selections.clear();
        self.selected.fill(false);
        // One pass over J by columns: per row, its count of non-zero entries and the last one.
        let count = &mut self.count[..m];
        count.fill(0);
        for (t, col) in j.chunks_exact(m).enumerate() {
            for (r, &x) in col.iter().enumerate() {
                if x != 0.0 {
                    count[r] += 1;
                    self.last[r] = t;
                }
            }
        }
        let mut weight: Option<f64> = None;
        for r in 0..m {
            let t = self.last[r];
            let s = j[t * m + r].abs();
            if count[r] == 1 && weight.is_none_or(|w| w == s) && !self.selected[t] {
                weight = Some(s);
                self.selected[t] = true;
                self.selections.push((r, t, j[t * m + r]));
            } else {
                self.general.push(r);
            }
        }
        self.others.extend((0..n).filter(|&t| !self.selected[t]));
        let w = weight?;
        (self.general.len() + self.others.len() < m && w.is_finite()).then_some(w)
    }

    /// Level `level`'s step when it completes the rank (module docs): `u[p..n]` ← y, the step
    /// in the coordinates Z = Q\[:, p..n\] of the reflectors `refl` (p of them) of the levels
    /// above, `u[..p]` the solution so far, damped by `damping` with σ from
    /// [`smallest_singular_value`]. Returns the λ² used; None (u unchanged) when the level is
    /// not covered, M is not positive definite, or the bound on its pivots does not clear
    /// 2 × `rank_threshold`.
    pub(crate) fn step(
        &mut self,
        level: &TaskEquation,
        refl: &Reflectors,
        u: &mut [f64],
        damping: Damping,
        rank_threshold: f64,
    ) -> Option<f64> {
        let (n, m, p) = (self.n, level.dim(), refl.len());
        let k = n - p;
        if k == 0 || m < k {
            return None;
        }
        let w = self.classify(level)?;
        let (mg, ld) = (self.general.len(), self.ld);
        let nr = mg + self.others.len();
        // The carried rows: J_g, then e_o; by coordinate.
        let j = level.jacobian.as_slice();
        for t in 0..n {
            let row = &mut self.rows[t * ld..t * ld + nr];
            for (a, &r) in self.general.iter().enumerate() {
                row[a] = j[t * m + r];
            }
            for (b, &o) in self.others.iter().enumerate() {
                row[mg + b] = if o == t { 1.0 } else { 0.0 };
            }
        }
        refl.apply_forward_rows(p, &mut self.rows, ld, 0, nr, &mut self.scratch);
        // The carried rows' reduced parts, row by row (row r at r · n, k entries).
        let tr = &mut self.reduced[..nr * n];
        for (t, row) in self.rows[p * ld..].chunks(ld).take(k).enumerate() {
            for (r, &x) in row[..nr].iter().enumerate() {
                tr[r * n + t] = x;
            }
        }
        // M = (J_g Z)ᵀ (J_g Z) + w² (I − Z_Oᵀ Z_O), lower triangle, kept in `gram`: one
        // rank-one update per carried row, row a of M by a contiguous axpy.
        let w2 = w * w;
        for a in 0..k {
            let row = &mut self.gram[a * n..a * n + a + 1];
            row.fill(0.0);
            row[a] = w2;
        }
        for r in 0..nr {
            let sign = if r < mg { 1.0 } else { -w2 };
            let x = &tr[r * n..r * n + k];
            for a in 0..k {
                let f = sign * x[a];
                if f != 0.0 {
                    axpy(f, &x[..=a], &mut self.gram[a * n..a * n + a + 1]);
                }
            }
        }
        // The Gershgorin bound on ‖Z_O Z_Oᵀ‖₂: its largest absolute row sum.
        let no = self.others.len();
        let zo = &tr[mg * n..];
        let gersh = (0..no)
            .map(|o1| {
                (0..no)
                    .map(|o2| dot(&zo[o1 * n..o1 * n + k], &zo[o2 * n..o2 * n + k]).abs())
                    .sum::<f64>()
            })
            .fold(0.0_f64, f64::max);
        self.l0[..n * k].copy_from_slice(&self.gram[..n * k]);
        if !cholesky(&mut self.l0, n, k) {
            return None;
        }
        // λ_min(M) from below: the comparison matrix of L, and the structure.
        let x = &mut self.x[..k];
        for r in 0..k {
            let row = &self.l0[r * n..r * n + r];
            let s = 1.0
                + row
                    .iter()
                    .zip(&x[..r])
                    .map(|(l, x)| l.abs() * x)
                    .sum::<f64>();
            x[r] = s / self.l0[r * n + r].abs();
        }
        let inv_inf = x.iter().fold(0.0_f64, |a, &b| a.max(b));
        let by_factor = 1.0 / (k as f64 * inv_inf * inv_inf);
        let by_structure = w2 * (1.0 - gersh);
        let lambda_min = by_factor.max(by_structure);
        if lambda_min.is_nan()
            || lambda_min <= 0.0
            || !super::hierarchy::clears((lambda_min / m as f64).sqrt(), rank_threshold)
        {
            return None;
        }
        let lambda2 = match damping {
            Damping::None => 0.0,
            Damping::Fixed(l) => l * l,
            Damping::Adaptive { max, threshold } => {
                let sigma =
                    smallest_singular_value(&self.gram, &self.l0, n, k, &mut self.x, &mut self.v);
                if sigma < threshold {
                    (1.0 - (sigma / threshold).powi(2)) * max * max
                } else {
                    0.0
                }
            }
        };
        let damped = lambda2 > 0.0;
        self.geometry = Geometry {
            p,
            k,
            mg,
            nr,
            w2,
            damped,
        };
        if damped {
            // M + λ² I (eqs. 8–9 in reduced coordinates: (J̄ᵀJ̄ + λ²I)⁻¹ J̄ᵀ = J̄ᵀ(J̄J̄ᵀ + λ²I)⁻¹).
            self.m[..n * k].copy_from_slice(&self.gram[..n * k]);
            for a in 0..k {
                self.m[a * n + a] += lambda2;
            }
            if !cholesky(&mut self.m, n, k) {
                return None;
            }
        }
        // q̈_{i−1} = Q u (u zero from p on), ρ = h − J_i q̈_{i−1}, v = J_iᵀ ρ.
        let q = &mut self.v;
        q.copy_from_slice(&u[..n]);
        q[p..].fill(0.0);
        refl.apply_q(q);
        // ρ and J_iᵀ ρ: the general rows through J, each joint row through its one entry.
        let (res, h) = (&mut self.res[..m], level.rhs.as_slice());
        for &r in &self.general {
            res[r] = h[r] - (0..n).map(|t| j[t * m + r] * q[t]).sum::<f64>();
        }
        for &(r, t, s) in &self.selections {
            res[r] = h[r] - s * q[t];
        }
        q.fill(0.0);
        for &r in &self.general {
            for (t, qt) in q.iter_mut().enumerate() {
                *qt += j[t * m + r] * res[r];
            }
        }
        for &(r, t, s) in &self.selections {
            q[t] += s * res[r];
        }
        // Zᵀ J_iᵀ ρ = (Qᵀ v)[p..n], then y = (M + λ² I)⁻¹ of it.
        refl.apply_forward_rows(p, q, 1, 0, 1, &mut self.scratch);
        let y = &mut u[p..n];
        y.copy_from_slice(&q[p..n]);
        cholesky_solve(self.factor(), n, k, y);
        Some(lambda2)
    }

    /// The level's columns of the correction map in reduced coordinates, for the last step
    /// (the `hierarchy` module: a level of rank k < m_i enters the map in an orthonormal basis
    /// U of the column space of J̄ = J_i Z): with M = L₀ L₀ᵀ, U = J̄ L₀⁻ᵀ (UᵀU = L₀⁻¹ M L₀⁻ᵀ =
    /// I), and the change of the step for Δh_i = U z is (M + λ² I)⁻¹ J̄ᵀ U z =
    /// (M + λ² I)⁻¹ L₀ z. Writes X = (M + λ² I)⁻¹ L₀ into rows p..n of the row-major
    /// n × k block `y` (k columns).
    pub(crate) fn basis_block(&mut self, y: &mut [f64]) {
        let (n, Geometry { p, k, .. }) = (self.n, self.geometry);
        let x = &mut self.x[..k];
        let factor = if self.geometry.damped {
            &self.m
        } else {
            &self.l0
        };
        for j in 0..k {
            x.fill(0.0);
            for (a, xa) in x.iter_mut().enumerate().skip(j) {
                *xa = self.l0[a * n + j];
            }
            cholesky_solve(factor, n, k, x);
            for (a, xa) in x.iter().enumerate() {
                y[(p + a) * k + j] = *xa;
            }
        }
    }

    /// The level's response, in rows p..n of the row-major n × nc block `y`, to the changes
    /// of the levels above in its rows `from..p` (reduced coordinates u_a): with q̈_{i−1}
    /// moved by Q_a u_a, ρ moves by −J_i Q_a u_a and the step by
    /// −(M + λ² I)⁻¹ Zᵀ J_iᵀ J_i Q_a u_a, where Zᵀ J_iᵀ J_i Q_a = (J_g Z)ᵀ (J_g Q_a) −
    /// w² Z_Oᵀ (E_Oᵀ Q_a) (the joint rows contribute w² (I − E_O E_Oᵀ), and Zᵀ Q_a = 0): both
    /// parts of the carried rows, Q_a's from the reflectors as well.
    pub(crate) fn propagate(&mut self, y: &mut [f64], nc: usize, from: usize) {
        let (
            n,
            Geometry {
                p, k, mg, nr, w2, ..
            },
        ) = (self.n, self.geometry);
        let ld = self.ld;
        // T = (carried rows' Q_a part) · Y[from..p], nr × nc.
        let t = &mut self.block_t[..nr * nc];
        t.fill(0.0);
        for s in from..p {
            let ys = &y[s * nc..(s + 1) * nc];
            for (r, &c) in self.rows[s * ld..s * ld + nr].iter().enumerate() {
                if c != 0.0 {
                    axpy(c, ys, &mut t[r * nc..(r + 1) * nc]);
                }
            }
        }
        // B = −Σ_r sign_r (row r's Z part) ⊗ T_r, k × nc (row-major).
        let b = &mut self.block_b[..k * nc];
        b.fill(0.0);
        for r in 0..nr {
            let sign = if r < mg { -1.0 } else { w2 };
            let tr = &t[r * nc..(r + 1) * nc];
            for (a, &z) in self.reduced[r * n..r * n + k].iter().enumerate() {
                if z != 0.0 {
                    axpy(sign * z, tr, &mut b[a * nc..(a + 1) * nc]);
                }
            }
        }
        // Each column through (M + λ² I)⁻¹.
        let x = &mut self.x[..k];
        let factor = if self.geometry.damped {
            &self.m
        } else {
            &self.l0
        };
        for c in 0..nc {
            for (a, xa) in x.iter_mut().enumerate() {
                *xa = b[a * nc + c];
            }
            cholesky_solve(factor, n, k, x);
            for (a, xa) in x.iter().enumerate() {
                y[(p + a) * nc + c] = *xa;
            }
        }
    }

    /// Δh_i = U z \[task units\] for the correction `z` (k entries) of the last step's level in
    /// the basis of [`GramLevel::basis_block`]: U z = J̄ L₀⁻ᵀ z = J_i Z t with t = L₀⁻ᵀ z, the
    /// general rows through their reduced parts (J_g Z) t, each joint row s_c (Z t)\[C_c\]
    /// with Z t = Q \[0; t\] (the p reflectors of the levels above in `refl`).
    pub(crate) fn demand(&mut self, refl: &Reflectors, z: &[f64], out: &mut [f64]) {
        let (n, Geometry { p, k, .. }) = (self.n, self.geometry);
        let t = &mut self.x[..k];
        t.copy_from_slice(&z[..k]);
        for r in (0..k).rev() {
            t[r] /= self.l0[r * n + r];
            let tr = t[r];
            axpy(-tr, &self.l0[r * n..r * n + r], &mut t[..r]);
        }
        for (a, &r) in self.general.iter().enumerate() {
            out[r] = dot(&self.reduced[a * n..a * n + k], t);
        }
        let d = &mut self.v;
        d[..p].fill(0.0);
        d[p..].copy_from_slice(t);
        refl.apply_q(d);
        for &(r, c, s) in &self.selections {
            out[r] = s * d[c];
        }
    }
}

/// Steps of inverse iteration in [`smallest_singular_value`].
const INVERSE_ITERATIONS: usize = 4;

/// σ_min(J̄) estimated from M = J̄ᵀJ̄ (`gram`, lower triangle, row r at r · `ld`) and its
/// Cholesky factor `l` (likewise) \[unit of a singular value of J\]: the square root of the
/// Rayleigh quotient xᵀ M x of x after [`INVERSE_ITERATIONS`] steps x ← M⁻¹ x / ‖M⁻¹ x‖ from
/// x = 𝟙 / √k. Never below the true σ_min (a Rayleigh quotient is at least λ_min) and
/// converging on it at the rate (λ_min / λ_2)² per step; the QR's last pivot, which the other
/// levels use, is likewise an estimate from above. `x` and `y` are scratch of length ≥ k.
fn smallest_singular_value(
    gram: &[f64],
    l: &[f64],
    ld: usize,
    k: usize,
    x: &mut [f64],
    y: &mut [f64],
) -> f64 {
    let (x, y) = (&mut x[..k], &mut y[..k]);
    x.fill(1.0 / (k as f64).sqrt());
    for _ in 0..INVERSE_ITERATIONS {
        cholesky_solve(l, ld, k, x);
        let norm = dot(x, x).sqrt();
        x.iter_mut().for_each(|v| *v /= norm);
    }
    // y = M x from the lower triangle.
    for (r, yr) in y.iter_mut().enumerate() {
        *yr = x
            .iter()
            .enumerate()
            .map(|(c, xc)| {
                let (a, b) = if c <= r { (r, c) } else { (c, r) };
                gram[a * ld + b] * xc
            })
            .sum();
    }
    dot(x, y).max(0.0).sqrt()
}

/// In-place Cholesky factorisation of the k × k lower triangle of `a` (row r at r · `ld`,
/// entries 0..=r): L with M = L Lᵀ in the lower triangle, row by row (each entry one dot
/// product of two contiguous rows). False when a pivot is not positive (or not finite).
fn cholesky(a: &mut [f64], ld: usize, k: usize) -> bool {
    for r in 0..k {
        for c in 0..=r {
            let s = a[r * ld + c] - dot(&a[r * ld..r * ld + c], &a[c * ld..c * ld + c]);
            if c < r {
                a[r * ld + c] = s / a[c * ld + c];
            } else if s.is_nan() || s <= 0.0 || s.is_infinite() {
                return false;
            } else {
                a[r * ld + r] = s.sqrt();
            }
        }
    }
    true
}

/// Solves L Lᵀ y = b in place (`y` holds b), L from [`cholesky`]: L z = b row by row, then
/// Lᵀ y = z by columns of Lᵀ (the rows of L), both over contiguous rows.
fn cholesky_solve(l: &[f64], ld: usize, k: usize, y: &mut [f64]) {
    for r in 0..k {
        y[r] = (y[r] - dot(&l[r * ld..r * ld + r], &y[..r])) / l[r * ld + r];
    }
    for r in (0..k).rev() {
        y[r] /= l[r * ld + r];
        let yr = y[r];
        axpy(-yr, &l[r * ld..r * ld + r], &mut y[..r]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;
    use rand::{Rng, SeedableRng};

    /// A random symmetric positive definite k × k matrix with eigenvalues `eig` (a random
    /// orthogonal basis from the QR of a random matrix), column-major with leading dimension k.
    fn spd(r: &mut rand_chacha::ChaCha8Rng, eig: &[f64]) -> DMatrix<f64> {
        let k = eig.len();
        let a = DMatrix::from_fn(k, k, |_, _| r.random_range(-1.0..1.0));
        let q = a.qr().q();
        &q * DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(eig)) * q.transpose()
    }

    #[test]
    fn cholesky_solves_as_nalgebra_and_refuses_what_is_not_positive_definite() {
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for k in 1..9 {
            let eig: Vec<f64> = (0..k).map(|j| 0.1 + j as f64).collect();
            let m = spd(&mut r, &eig);
            let b: Vec<f64> = (0..k).map(|_| r.random_range(-1.0..1.0)).collect();
            let mut l = m.as_slice().to_vec();
            assert!(cholesky(&mut l, k, k));
            let mut y = b.clone();
            cholesky_solve(&l, k, k, &mut y);
            let want = m
                .clone()
                .cholesky()
                .unwrap()
                .solve(&nalgebra::DVector::from_column_slice(&b));
            for (a, w) in y.iter().zip(want.iter()) {
                assert!((a - w).abs() <= 1e-12 * (1.0 + w.abs()), "k {k}");
            }
            let mut neg = spd(&mut r, &{
                let mut e = eig.clone();
                e[0] = -0.5;
                e
            })
            .as_slice()
            .to_vec();
            assert!(!cholesky(&mut neg, k, k), "k {k}: an eigenvalue −0.5");
        }
    }

    #[test]
    fn the_singular_value_estimate_is_never_below_the_true_one_and_close_when_separated() {
        // σ_min² = 0.01 under eigenvalues from 1 up: inverse iteration converges by a factor
        // (0.01 / 1)² per step, so the estimate is σ_min to well within 1 %.
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(6);
        for k in 2..12 {
            let mut eig: Vec<f64> = (0..k).map(|j| 1.0 + j as f64).collect();
            eig[k / 2] = 0.01;
            let m = spd(&mut r, &eig);
            let mut l = m.as_slice().to_vec();
            assert!(cholesky(&mut l, k, k));
            let (mut x, mut y) = (vec![0.0; k], vec![0.0; k]);
            let s = smallest_singular_value(m.as_slice(), &l, k, k, &mut x, &mut y);
            assert!(s >= 0.1 * (1.0 - 1e-12), "k {k}: {s}");
            assert!(s <= 0.1 * 1.01, "k {k}: {s}");
            // A nearly flat spectrum: still an estimate from above.
            let eig: Vec<f64> = (0..k).map(|j| 1.0 + 0.01 * j as f64).collect();
            let m = spd(&mut r, &eig);
            let mut l = m.as_slice().to_vec();
            assert!(cholesky(&mut l, k, k));
            let s = smallest_singular_value(m.as_slice(), &l, k, k, &mut x, &mut y);
            assert!(
                s >= 1.0 - 1e-12 && s <= (1.0 + 0.01 * k as f64).sqrt(),
                "k {k}: {s}"
            );
        }
    }
}
