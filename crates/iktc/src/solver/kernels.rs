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
