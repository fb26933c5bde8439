//! Cholesky factorisation of the Hessian and the inverse of its transposed factor.
//!
//! Both work in place on column-major storage with leading dimension `ld` (the workspace's
//! capacity), on the leading `n × n` block; they allocate nothing.

use nalgebra::DMatrixView;

use crate::{Error, Result};

/// Writes the lower Cholesky factor `L` of `H = L Lᵀ` into the lower triangle of `l`
/// (column-major, leading dimension `ld`); the strict upper triangle is not touched.
///
/// Column-wise (left-looking) Cholesky: `L_jj = √(H_jj − Σ_{k<j} L_jk²)`,
/// `L_ij = (H_ij − Σ_{k<j} L_ik L_jk) / L_jj` for `i > j`. A pivot `L_jj² < tol · max_i H_ii`
/// (or a non-positive one) is an error: H is not (numerically) positive definite.
pub(crate) fn cholesky(
    h: &DMatrixView<'_, f64>,
    l: &mut [f64],
    ld: usize,
    pivot_tolerance: f64,
) -> Result<()> {
    let n = h.nrows();
    let max_diag = (0..n).fold(0.0_f64, |acc, i| acc.max(h[(i, i)]));
    let min_pivot = pivot_tolerance * max_diag;
    for j in 0..n {
        for i in j..n {
            l[j * ld + i] = h[(i, j)];
        }
        for k in 0..j {
            let ljk = l[k * ld + j];
            if ljk != 0.0 {
                let (left, right) = l.split_at_mut(j * ld);
                let col_k = &left[k * ld + j..k * ld + n];
                let col_j = &mut right[j..n];
                for (dst, &src) in col_j.iter_mut().zip(col_k) {
                    *dst -= ljk * src;
                }
            }
        }
        let pivot = l[j * ld + j];
        if !(pivot > 0.0 && pivot >= min_pivot) {
            return Err(Error::InvalidSetting {
                name: "H (Hessian)".to_string(),
                value: format!("Cholesky pivot {j} = {pivot:e} (largest diagonal entry {max_diag:e})"),
                expected: format!(
                    "a positive definite matrix (every pivot ≥ {pivot_tolerance:e} × largest diagonal entry)"
                ),
            });
        }
        let ljj = pivot.sqrt();
        l[j * ld + j] = ljj;
        for v in &mut l[j * ld + j + 1..j * ld + n] {
            *v /= ljj;
        }
    }
    Ok(())
}

/// Writes `J = L⁻ᵀ` (upper triangular) into the leading `n × n` block of `j`, zeroing its strict
/// lower triangle, from the lower factor in `l`.
///
/// Column `k` of `J` solves `Lᵀ j_k = e_k` by back substitution:
/// `J_kk = 1 / L_kk`, `J_ik = −(Σ_{p=i+1}^{k} L_pi J_pk) / L_ii` for `i < k`.
pub(crate) fn inverse_transpose(l: &[f64], j: &mut [f64], ld: usize, n: usize) {
    for k in 0..n {
        let col = &mut j[k * ld..k * ld + n];
        for v in &mut col[k + 1..] {
            *v = 0.0;
        }
        col[k] = 1.0 / l[k * ld + k];
        for i in (0..k).rev() {
            let l_col_i = &l[i * ld + i + 1..i * ld + k + 1];
            col[i] = -super::basis::dot(l_col_i, &col[i + 1..=k]) / l[i * ld + i];
        }
    }
}
