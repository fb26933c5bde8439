//! Vector kernels shared by the solvers: dot product and axpy on slices.

/// `xᵀ y` over the common length, with four partial sums (so that the compiler can use SIMD
/// lanes; strict left-to-right summation cannot be vectorised).
#[inline]
pub(crate) fn dot(x: &[f64], y: &[f64]) -> f64 {
    let len = x.len().min(y.len());
    let (x, y) = (&x[..len], &y[..len]);
    let mut acc = [0.0_f64; 4];
    let (xc, yc) = (x.chunks_exact(4), y.chunks_exact(4));
    let tail: f64 = xc
        .remainder()
        .iter()
        .zip(yc.remainder())
        .map(|(a, b)| a * b)
        .sum();
    for (a, b) in xc.zip(yc) {
        for k in 0..4 {
            acc[k] += a[k] * b[k];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// `y ← y + a x` over the common length.
#[inline]
pub(crate) fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    for (yi, &xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

/// `y ← (y + a x) + b z` over the common length: two axpys in one pass over y (the same sums
/// in the same order as two [`axpy`] calls).
#[inline]
pub(crate) fn axpy2(a: f64, x: &[f64], b: f64, z: &[f64], y: &mut [f64]) {
    for ((yi, &xi), &zi) in y.iter_mut().zip(x).zip(z) {
        *yi = (*yi + a * xi) + b * zi;
    }
}

/// Applies `H = I − τ v vᵀ` to the `K` columns `cols` (each of `v`'s length):
/// `x_j ← x_j − τ (v·x_j) v`. The K dot products share one pass over `v` and the K updates
/// another (instead of a dot and an axpy per column), each dot with two partial sums (even
/// and odd coordinates) so that both SIMD lanes are used.
#[inline]
pub(crate) fn reflect_columns<const K: usize>(v: &[f64], tau: f64, cols: [&mut [f64]; K]) {
    let len = v.len();
    let cols: [&mut [f64]; K] = cols.map(|c| &mut c[..len]);
    let pairs = len / 2 * 2;
    let mut acc = [[0.0_f64; 2]; K];
    for t in (0..pairs).step_by(2) {
        let (v0, v1) = (v[t], v[t + 1]);
        for j in 0..K {
            acc[j][0] += v0 * cols[j][t];
            acc[j][1] += v1 * cols[j][t + 1];
        }
    }
    let mut f = [0.0_f64; K];
    for j in 0..K {
        let mut d = acc[j][0] + acc[j][1];
        if pairs < len {
            d += v[pairs] * cols[j][pairs];
        }
        f[j] = tau * d;
    }
    for t in 0..len {
        let vt = v[t];
        for j in 0..K {
            cols[j][t] -= f[j] * vt;
        }
    }
}
