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
//!
//! Blocks start at multiples of four (H_0..H_3, H_4..H_7, …; the last one may hold fewer), so
//! that every product — the rows of a level (H_0 ⋯ H_{p−1}, applied level by level as each
//! level's rows are reached), Q on a vector, Q on a block of columns — uses the same blocks,
//! and the coupling coefficients v_j·v_i of a full block are computed once, when its fourth
//! reflector is committed.

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
    /// The coefficients of the full blocks committed so far: block b is H_{4b}..H_{4b+3},
    /// valid for 4(b + 1) ≤ `len`.
    blocks: Vec<Block>,
}

/// The coupling coefficients τ and v_j·v_i of one block of up to four reflectors.
#[derive(Debug, Clone, Copy, Default)]
struct Block {
    s: usize,
    end: usize,
    /// Reflectors in the block, 1..=4; the coefficients of the others are zero.
    k: usize,
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
            blocks: vec![Block::default(); n / 4],
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
        if self.len % 4 == 0 {
            self.blocks[s / 4] = self.compute_block(s - 3, 4);
        }
        (tau, e)
    }

    /// v_s on its support s..end(s).
    pub(crate) fn vector(&self, s: usize) -> &[f64] {
        let n = self.n;
        &self.v.as_slice()[s * n + s..s * n + self.end[s]]
    }

    /// The block of reflectors from s (a multiple of four) to min(s + 4, `to`).
    fn block(&self, s: usize, to: usize) -> Block {
        let k = (to - s).min(4);
        if k == 4 {
            self.blocks[s / 4]
        } else {
            self.compute_block(s, k)
        }
    }

    fn compute_block(&self, s: usize, k: usize) -> Block {
        let n = self.n;
        let end = (s..s + k).map(|j| self.end[j]).max().unwrap_or(s);
        let vs = self.v.as_slice();
        let col = |j: usize| &vs[(s + j) * n + s..(s + j) * n + end];
        let mut b = Block {
            s,
            end,
            k,
            ..Default::default()
        };
        for j in 0..k {
            b.tau[j] = self.tau[s + j];
            for i in 0..j {
                let c = dot(col(j), col(i));
                b.c[j][i] = c;
                b.c[i][j] = c;
            }
        }
        b
    }

    /// The vectors of block `b` on its support, as K slices (K = b.k).
    fn block_vectors<const K: usize>(&self, b: &Block) -> [&[f64]; K] {
        let (n, len) = (self.n, b.end - b.s);
        let vs = self.v.as_slice();
        std::array::from_fn(|j| &vs[(b.s + j) * n + b.s..][..len])
    }

    /// H_s ⋯ H_{s+k−1} x (the last reflector of block `b` first).
    fn apply_block(&self, b: &Block, x: &mut [f64]) {
        match b.k {
            4 => self.apply_block_k::<4>(b, x),
            3 => self.apply_block_k::<3>(b, x),
            2 => self.apply_block_k::<2>(b, x),
            _ => self.apply_one(b.s, x),
        }
    }

    fn apply_block_k<const K: usize>(&self, b: &Block, x: &mut [f64]) {
        let x = &mut x[b.s..b.end];
        if x.iter().all(|v| *v == 0.0) {
            // x is zero on the block's support (a sparse task row, e.g. a joint task's unit
            // row under the reflectors of the legs): H x = x. The test stops at the first
            // non-zero, so it costs a dense x almost nothing.
            return;
        }
        let v = self.block_vectors::<K>(b);
        let d = dots(v, x);
        let mut f = [0.0; K];
        for j in (0..K).rev() {
            let t = d[j] - (j + 1..K).map(|i| f[i] * b.c[j][i]).sum::<f64>();
            f[j] = b.tau[j] * t;
        }
        if f == [0.0; K] {
            return;
        }
        for (i, xi) in x.iter_mut().enumerate() {
            let mut u = *xi;
            for j in 0..K {
                u -= f[j] * v[j][i];
            }
            *xi = u;
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

    /// Applies Q = H_0 H_1 ⋯ H_{len−1} (the last reflector first) to every column of `cols`
    /// (column-major, columns of length n); for one vector or a few (blocks of columns go
    /// through [`Reflectors::apply_q_rows`]).
    pub(crate) fn apply_q(&self, cols: &mut [f64]) {
        let len = self.len;
        for s in (0..len).step_by(4).rev() {
            let b = self.block(s, len);
            for x in cols.chunks_exact_mut(self.n.max(1)) {
                self.apply_block(&b, x);
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
        if nc == 0 {
            return;
        }
        let len = self.len;
        for s in (0..len).step_by(4).rev() {
            let b = self.block(s, len);
            match b.k {
                4 => self.apply_q_rows_block::<4>(&b, y, nc, scratch),
                3 => self.apply_q_rows_block::<3>(&b, y, nc, scratch),
                2 => self.apply_q_rows_block::<2>(&b, y, nc, scratch),
                _ => self.apply_q_rows_block::<1>(&b, y, nc, scratch),
            }
        }
    }

    /// The block `b` of K reflectors (last first) on the rows of `y`: see
    /// [`Reflectors::apply_q_rows`].
    fn apply_q_rows_block<const K: usize>(
        &self,
        b: &Block,
        y: &mut [f64],
        nc: usize,
        scratch: &mut [f64],
    ) {
        let w = &mut scratch[..K * nc];
        let v = self.block_vectors::<K>(b);
        let rows = &mut y[b.s * nc..b.end * nc];
        block_products(v, rows, nc, nc, w);
        for j in (0..K).rev() {
            let (head, tail) = w.split_at_mut((j + 1) * nc);
            let fj = &mut head[j * nc..];
            for i in j + 1..K {
                axpy(-b.c[j][i], &tail[(i - j - 1) * nc..(i - j) * nc], fj);
            }
            let tau = b.tau[j];
            fj.iter_mut().for_each(|x| *x *= tau);
        }
        block_update(v, w, nc, nc, rows);
    }

    /// Applies H_{to−1} ⋯ H_0 (H_0 first) to the columns c0..c0 + nc of the row-major n × ld
    /// block `y`, block by block as in [`Reflectors::apply_q_rows`] with the coefficients in
    /// the forward order, F_j = τ_j (w_j − Σ_{i<j} (v_j·v_i) F_i). The leading rows that are
    /// zero in all nc columns are skipped: a block whose support ends above the first
    /// non-zero row leaves the columns as they are. `scratch` holds at least 4 nc entries.
    pub(crate) fn apply_forward_rows(
        &self,
        to: usize,
        y: &mut [f64],
        ld: usize,
        c0: usize,
        nc: usize,
        scratch: &mut [f64],
    ) {
        if nc == 0 || to == 0 {
            return;
        }
        let mut lead = (0..self.n)
            .find(|&t| y[t * ld + c0..t * ld + c0 + nc].iter().any(|x| *x != 0.0))
            .unwrap_or(self.n);
        for s in (0..to).step_by(4) {
            let b = self.block(s, to);
            if b.end <= lead {
                continue;
            }
            lead = lead.min(b.s);
            let rows = &mut y[b.s * ld + c0..(b.end - 1) * ld + c0 + nc];
            match b.k {
                4 => self.forward_rows_block::<4>(&b, rows, ld, nc, scratch),
                3 => self.forward_rows_block::<3>(&b, rows, ld, nc, scratch),
                2 => self.forward_rows_block::<2>(&b, rows, ld, nc, scratch),
                _ => self.forward_rows_block::<1>(&b, rows, ld, nc, scratch),
            }
        }
    }

    /// The block `b` of K reflectors (first first) on `rows` (row t of the support at
    /// t · ld, nc columns each).
    fn forward_rows_block<const K: usize>(
        &self,
        b: &Block,
        rows: &mut [f64],
        ld: usize,
        nc: usize,
        scratch: &mut [f64],
    ) {
        let w = &mut scratch[..K * nc];
        let v = self.block_vectors::<K>(b);
        block_products(v, rows, ld, nc, w);
        for j in 0..K {
            let (head, tail) = w.split_at_mut(j * nc);
            let fj = &mut tail[..nc];
            for i in 0..j {
                axpy(-b.c[j][i], &head[i * nc..(i + 1) * nc], fj);
            }
            let tau = b.tau[j];
            fj.iter_mut().for_each(|x| *x *= tau);
        }
        block_update(v, w, ld, nc, rows);
    }
}

/// Columns per register block of [`block_products`] and [`block_update`]: four accumulators of
/// four columns each fit the sixteen vector registers of x86-64 (two lanes each) with room to
/// spare.
const CHUNK: usize = 4;

/// W_j = Σ_t v_j\[t\] Y\[t, :\] for the K reflectors of a block (`rows`: row-major, row t at
/// t · ld, `nc` columns, one row per coordinate of the block's support; `w`: K rows of `nc`). Each W_j
/// entry sums over t in order from 0, as one axpy per row would; the columns are taken
/// [`CHUNK`] at a time so that the sums stay in registers.
fn block_products<const K: usize>(
    v: [&[f64]; K],
    rows: &[f64],
    ld: usize,
    nc: usize,
    w: &mut [f64],
) {
    // Slices of known length and rows taken by chunks, so that the loops check no bounds.
    let len = v[0].len();
    let v: [&[f64]; K] = std::array::from_fn(|j| &v[j][..len]);
    let full = nc / CHUNK * CHUNK;
    for c0 in (0..full).step_by(CHUNK) {
        let mut acc = [[0.0_f64; CHUNK]; K];
        for (t, yrow) in rows.chunks(ld).take(len).enumerate() {
            let yc = &yrow[c0..c0 + CHUNK];
            let yr: [f64; CHUNK] = std::array::from_fn(|l| yc[l]);
            for j in 0..K {
                let a = v[j][t];
                for l in 0..CHUNK {
                    acc[j][l] += a * yr[l];
                }
            }
        }
        for j in 0..K {
            w[j * nc + c0..j * nc + c0 + CHUNK].copy_from_slice(&acc[j]);
        }
    }
    for c in full..nc {
        let mut acc = [0.0_f64; K];
        for (t, yrow) in rows.chunks(ld).take(len).enumerate() {
            let yv = yrow[c];
            for j in 0..K {
                acc[j] += v[j][t] * yv;
            }
        }
        for j in 0..K {
            w[j * nc + c] = acc[j];
        }
    }
}

/// Y\[t, :\] ← Y\[t, :\] − v_0\[t\] F_0 − … − v_{K−1}\[t\] F_{K−1}, subtracted in that order
/// (`f`: K rows of `nc`; `rows` as in [`block_products`]), [`CHUNK`] columns at a time.
fn block_update<const K: usize>(v: [&[f64]; K], f: &[f64], ld: usize, nc: usize, rows: &mut [f64]) {
    let len = v[0].len();
    let v: [&[f64]; K] = std::array::from_fn(|j| &v[j][..len]);
    let full = nc / CHUNK * CHUNK;
    for c0 in (0..full).step_by(CHUNK) {
        let fr: [[f64; CHUNK]; K] =
            std::array::from_fn(|j| std::array::from_fn(|l| f[j * nc + c0 + l]));
        for (t, yrow) in rows.chunks_mut(ld).take(len).enumerate() {
            let yr = &mut yrow[c0..c0 + CHUNK];
            let a: [f64; K] = std::array::from_fn(|j| v[j][t]);
            for l in 0..CHUNK {
                let mut x = yr[l];
                for j in 0..K {
                    x -= a[j] * fr[j][l];
                }
                yr[l] = x;
            }
        }
    }
    for c in full..nc {
        let fc: [f64; K] = std::array::from_fn(|j| f[j * nc + c]);
        for (t, yrow) in rows.chunks_mut(ld).take(len).enumerate() {
            let mut x = yrow[c];
            for j in 0..K {
                x -= v[j][t] * fc[j];
            }
            yrow[c] = x;
        }
    }
}

/// The K dot products v_j·x in one pass, each with four partial sums.
#[inline]
fn dots<const K: usize>(v: [&[f64]; K], x: &[f64]) -> [f64; K] {
    let len = x.len();
    let v: [&[f64]; K] = std::array::from_fn(|j| &v[j][..len]);
    let mut acc = [[0.0f64; 4]; K];
    let full = len / 4 * 4;
    let mut i = 0;
    while i < full {
        for l in 0..4 {
            let xi = x[i + l];
            for j in 0..K {
                acc[j][l] += v[j][i + l] * xi;
            }
        }
        i += 4;
    }
    let mut d = [0.0; K];
    for j in 0..K {
        d[j] = (acc[j][0] + acc[j][1]) + (acc[j][2] + acc[j][3]);
    }
    for i in full..len {
        let xi = x[i];
        for j in 0..K {
            d[j] += v[j][i] * xi;
        }
    }
    d
}
