//! A sequence of Householder reflectors H_s = I − τ_s v_s v_sᵀ and their products, applied
//! one at a time or four at a time.
//!
//! ## Four at a time
//!
//! Applying H_{s+3} H_{s+2} H_{s+1} H_s to x (H_s first) is x − Σ_j f_j v_j with
//!
//! f_j = τ_j (v_j·x − Σ_{i<j} f_i (v_j·v_i)),
//!
//! which follows by expanding x_{j+1} = x_j − τ_j (v_j·x_j) v_j; the reverse order
//! (H_{s+3} first) sums over i > j instead. This is the compact WY form (Schreiber & Van Loan
//! 1989) for a block of four: the four dot products v_j·x share one pass over x and the update
//! another, instead of four passes each. The arithmetic is the same.

use nalgebra::DMatrix;

use super::kernels::{axpy, dot};

/// Householder vectors stored by column: column s acts on the coordinates s..end(s) and is
/// zero elsewhere (H_s = I − τ_s v_s v_sᵀ). Sized once; pushing allocates nothing.
#[derive(Debug, Clone)]
pub(crate) struct Reflectors {
    n: usize,
    v: DMatrix<f64>,
    tau: Vec<f64>,
    end: Vec<usize>,
    len: usize,
}

/// The coupling coefficients τ and v_j·v_i of one block of four reflectors.
#[derive(Debug, Clone, Copy, Default)]
struct Block {
    s: usize,
    end: usize,
    tau: [f64; 4],
    /// c\[j\]\[i\] = v_j·v_i for i ≠ j.
    c: [[f64; 4]; 4],
}

impl Reflectors {
    /// Room for `n` reflectors on vectors of length `n`.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            n,
            v: DMatrix::zeros(n, n),
            tau: vec![0.0; n],
            end: vec![0; n],
            len: 0,
        }
    }

    /// Number of reflectors.
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Forgets all reflectors from `len` on.
    pub(crate) fn truncate(&mut self, len: usize) {
        self.len = self.len.min(len);
    }

    /// Slot of reflector s = `len()`: the caller writes v_s into coordinates s..n (zero before
    /// s is kept) and then calls [`Reflectors::commit`].
    pub(crate) fn next_slot(&mut self) -> &mut [f64] {
        let (s, n) = (self.len, self.n);
        &mut self.v.as_mut_slice()[s * n + s..(s + 1) * n]
    }

    /// Commits the reflector written by [`Reflectors::next_slot`]; returns τ = 2 / vᵀv (0 for a
    /// zero vector) and the support length from s.
    pub(crate) fn commit(&mut self) -> (f64, usize) {
        let (s, n) = (self.len, self.n);
        let vcol = &self.v.as_slice()[s * n + s..(s + 1) * n];
        let mut e = vcol.len();
        while e > 1 && vcol[e - 1] == 0.0 {
            e -= 1;
        }
        let vv = dot(&vcol[..e], &vcol[..e]);
        let tau = if vv > 0.0 { 2.0 / vv } else { 0.0 };
        self.tau[s] = tau;
        self.end[s] = s + e;
        self.len = s + 1;
        (tau, e)
    }

    /// v_s on its support s..end(s).
    pub(crate) fn vector(&self, s: usize) -> &[f64] {
        let n = self.n;
        &self.v.as_slice()[s * n + s..s * n + self.end[s]]
    }

    fn block(&self, s: usize) -> Block {
        let n = self.n;
        let end = (s..s + 4).map(|j| self.end[j]).max().unwrap_or(s);
        let vs = self.v.as_slice();
        let col = |j: usize| &vs[(s + j) * n + s..(s + j) * n + end];
        let mut b = Block {
            s,
            end,
            ..Default::default()
        };
        for j in 0..4 {
            b.tau[j] = self.tau[s + j];
            for i in 0..j {
                let c = dot(col(j), col(i));
                b.c[j][i] = c;
                b.c[i][j] = c;
            }
        }
        b
    }

    fn apply_block(&self, b: &Block, forward: bool, x: &mut [f64]) {
        let n = self.n;
        let vs = self.v.as_slice();
        let len = b.end - b.s;
        let x = &mut x[b.s..b.end];
        if x.iter().all(|v| *v == 0.0) {
            // x is zero on the block's support (a sparse task row, e.g. a joint task's unit
            // row under the reflectors of the legs): H x = x. The test stops at the first
            // non-zero, so it costs a dense x almost nothing.
            return;
        }
        let v0 = &vs[b.s * n + b.s..][..len];
        let v1 = &vs[(b.s + 1) * n + b.s..][..len];
        let v2 = &vs[(b.s + 2) * n + b.s..][..len];
        let v3 = &vs[(b.s + 3) * n + b.s..][..len];
        let d = dot4([v0, v1, v2, v3], x);
        let mut f = [0.0; 4];
        if forward {
            for j in 0..4 {
                let t = d[j] - (0..j).map(|i| f[i] * b.c[j][i]).sum::<f64>();
                f[j] = b.tau[j] * t;
            }
        } else {
            for j in (0..4).rev() {
                let t = d[j] - (j + 1..4).map(|i| f[i] * b.c[j][i]).sum::<f64>();
                f[j] = b.tau[j] * t;
            }
        }
        if f == [0.0; 4] {
            return;
        }
        for (i, xi) in x.iter_mut().enumerate() {
            *xi -= f[0] * v0[i] + f[1] * v1[i] + f[2] * v2[i] + f[3] * v3[i];
        }
    }

    fn apply_one(&self, s: usize, x: &mut [f64]) {
        let e = self.end[s];
        let v = self.vector(s);
        let x = &mut x[s..e];
        if x.iter().all(|v| *v == 0.0) {
            return;
        }
        let f = self.tau[s] * dot(v, x);
        if f != 0.0 {
            axpy(-f, v, x);
        }
    }

    /// Applies H_{to−1} ⋯ H_{from} (H_from first) to every column of `cols` (column-major,
    /// columns of length n).
    pub(crate) fn apply_forward(&self, from: usize, to: usize, cols: &mut [f64]) {
        let n = self.n;
        let mut s = from;
        while s + 4 <= to {
            let b = self.block(s);
            for x in cols.chunks_exact_mut(n) {
                self.apply_block(&b, true, x);
            }
            s += 4;
        }
        for s in s..to {
            for x in cols.chunks_exact_mut(n) {
                self.apply_one(s, x);
            }
        }
    }

    /// Applies Q = H_0 H_1 ⋯ H_{len−1} (the last reflector first) to every column of `cols`
    /// (column-major, columns of length n); for one vector or a few (blocks of columns go
    /// through [`Reflectors::apply_q_rows`]).
    pub(crate) fn apply_q(&self, cols: &mut [f64]) {
        for x in cols.chunks_exact_mut(self.n.max(1)) {
            for s in (0..self.len).rev() {
                self.apply_one(s, x);
            }
        }
    }
}

impl Reflectors {
    /// Applies Q = H_0 ⋯ H_{len−1} to the nc columns of a row-major n × nc block `y`: per
    /// block of four reflectors, w_j = v_jᵀ Y (four rows of length nc, one pass over Y), the
    /// coefficients F_j = τ_j (w_j − Σ_{i>j} (v_j·v_i) F_i), and Y −= Σ_j v_j F_jᵀ (another
    /// pass). `scratch` holds at least 4 nc entries.
    pub(crate) fn apply_q_rows(&self, y: &mut [f64], nc: usize, scratch: &mut [f64]) {
        let n = self.n;
        if nc == 0 {
            return;
        }
        let vs = self.v.as_slice();
        let mut s = self.len;
        while s >= 4 {
            s -= 4;
            let b = self.block(s);
            let w = &mut scratch[..4 * nc];
            let len = b.end - b.s;
            let v: [&[f64]; 4] = std::array::from_fn(|j| &vs[(b.s + j) * n + b.s..][..len]);
            let rows = &mut y[b.s * nc..b.end * nc];
            block_products(v, rows, nc, w);
            for j in (0..4).rev() {
                let (head, tail) = w.split_at_mut((j + 1) * nc);
                let fj = &mut head[j * nc..];
                for i in j + 1..4 {
                    axpy(-b.c[j][i], &tail[(i - j - 1) * nc..(i - j) * nc], fj);
                }
                let tau = b.tau[j];
                fj.iter_mut().for_each(|x| *x *= tau);
            }
            block_update(v, w, nc, rows);
        }
        for s in (0..s).rev() {
            let w = &mut scratch[..nc];
            w.fill(0.0);
            let v = self.vector(s);
            for (a, &va) in v.iter().enumerate() {
                if va != 0.0 {
                    axpy(va, &y[(s + a) * nc..(s + a + 1) * nc], w);
                }
            }
            let tau = self.tau[s];
            for (a, &va) in v.iter().enumerate() {
                if va != 0.0 {
                    axpy(-tau * va, w, &mut y[(s + a) * nc..(s + a + 1) * nc]);
                }
            }
        }
    }
}

/// Columns per register block of [`block_products`] and [`block_update`]: four accumulators of
/// four columns each fit the sixteen vector registers of x86-64 (two lanes each) with room to
/// spare.
const CHUNK: usize = 4;

/// W_j = Σ_t v_j\[t\] Y\[t, :\] for the four reflectors of a block (`rows`: row-major, `nc`
/// columns, one row per coordinate of the block's support; `w`: four rows of `nc`). Each W_j
/// entry sums over t in order from 0, as one axpy per row would; the columns are taken
/// [`CHUNK`] at a time so that the sums stay in registers.
fn block_products(v: [&[f64]; 4], rows: &[f64], nc: usize, w: &mut [f64]) {
    let len = v[0].len();
    let full = nc / CHUNK * CHUNK;
    for c0 in (0..full).step_by(CHUNK) {
        let mut acc = [[0.0_f64; CHUNK]; 4];
        for t in 0..len {
            let yr: [f64; CHUNK] = std::array::from_fn(|l| rows[t * nc + c0 + l]);
            for j in 0..4 {
                let a = v[j][t];
                for l in 0..CHUNK {
                    acc[j][l] += a * yr[l];
                }
            }
        }
        for j in 0..4 {
            w[j * nc + c0..j * nc + c0 + CHUNK].copy_from_slice(&acc[j]);
        }
    }
    for c in full..nc {
        let mut acc = [0.0_f64; 4];
        for t in 0..len {
            let yv = rows[t * nc + c];
            for j in 0..4 {
                acc[j] += v[j][t] * yv;
            }
        }
        for j in 0..4 {
            w[j * nc + c] = acc[j];
        }
    }
}

/// Y\[t, :\] ← Y\[t, :\] − v_0\[t\] F_0 − v_1\[t\] F_1 − v_2\[t\] F_2 − v_3\[t\] F_3, subtracted in
/// that order (`f`: four rows of `nc`), [`CHUNK`] columns at a time.
fn block_update(v: [&[f64]; 4], f: &[f64], nc: usize, rows: &mut [f64]) {
    let len = v[0].len();
    let full = nc / CHUNK * CHUNK;
    for c0 in (0..full).step_by(CHUNK) {
        let fr: [[f64; CHUNK]; 4] =
            std::array::from_fn(|j| std::array::from_fn(|l| f[j * nc + c0 + l]));
        for t in 0..len {
            let yr = &mut rows[t * nc + c0..t * nc + c0 + CHUNK];
            let a: [f64; 4] = std::array::from_fn(|j| v[j][t]);
            for l in 0..CHUNK {
                let mut x = yr[l];
                for j in 0..4 {
                    x -= a[j] * fr[j][l];
                }
                yr[l] = x;
            }
        }
    }
    for c in full..nc {
        for t in 0..len {
            let mut x = rows[t * nc + c];
            for j in 0..4 {
                x -= v[j][t] * f[j * nc + c];
            }
            rows[t * nc + c] = x;
        }
    }
}

/// The four dot products v_j·x in one pass, each with four partial sums.
#[inline]
fn dot4(v: [&[f64]; 4], x: &[f64]) -> [f64; 4] {
    let len = x.len();
    let (v0, v1, v2, v3) = (&v[0][..len], &v[1][..len], &v[2][..len], &v[3][..len]);
    let mut acc = [[0.0f64; 4]; 4];
    let full = len / 4 * 4;
    let mut i = 0;
    while i < full {
        for l in 0..4 {
            let xi = x[i + l];
            acc[0][l] += v0[i + l] * xi;
            acc[1][l] += v1[i + l] * xi;
            acc[2][l] += v2[i + l] * xi;
            acc[3][l] += v3[i + l] * xi;
        }
        i += 4;
    }
    let mut d = [0.0; 4];
    for j in 0..4 {
        d[j] = (acc[j][0] + acc[j][1]) + (acc[j][2] + acc[j][3]);
    }
    for i in full..len {
        let xi = x[i];
        d[0] += v0[i] * xi;
        d[1] += v1[i] * xi;
        d[2] += v2[i] * xi;
        d[3] += v3[i] * xi;
    }
    d
}
