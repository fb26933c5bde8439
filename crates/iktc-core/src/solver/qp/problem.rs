//! The QP as plain data (borrowed views), and its input checks.

use nalgebra::DMatrixView;

use super::QpSettings;
use crate::error::{check_all_finite, check_dim};
use crate::{Error, Result};

/// The Hessian `H` of the objective `½ xᵀ H x + cᵀ x`.
#[derive(Debug, Clone, Copy)]
pub enum Hessian<'a> {
    /// `H = I`: no factorisation is needed (the IKTC correction QP, `min ½‖Δh‖²`).
    Identity,
    /// A dense symmetric positive definite `n × n` matrix. Only its lower triangle enters the
    /// factorisation; the upper one is checked for symmetry.
    Dense(DMatrixView<'a, f64>),
}

/// A convex QP with two-sided inequality rows:
///
/// ```text
/// minimise ½ xᵀ H x + cᵀ x   subject to   A_eq x = b_eq,   l ≤ A_in x ≤ u
/// ```
///
/// `n` is the length of `c`. A matrix with zero rows may have any number of columns; otherwise
/// it has `n`. An end of an inequality row may be infinite (`l_i = −∞` or `u_i = +∞`: that side
/// is absent); a row with `l_i = u_i` is handled as an equality.
#[derive(Debug, Clone, Copy)]
pub struct QpProblem<'a> {
    /// `H`, symmetric positive definite [objective units per (variable unit)²].
    pub hessian: Hessian<'a>,
    /// `c`, length `n` [objective units per variable unit].
    pub c: &'a [f64],
    /// `A_eq`, `m_eq × n`.
    pub a_eq: DMatrixView<'a, f64>,
    /// `b_eq`, length `m_eq` [row units].
    pub b_eq: &'a [f64],
    /// `A_in`, `m_in × n`.
    pub a_in: DMatrixView<'a, f64>,
    /// `l`, length `m_in`, entries in `[−∞, +∞)` [row units].
    pub lower: &'a [f64],
    /// `u`, length `m_in`, entries in `(−∞, +∞]`, `u_i ≥ l_i` [row units].
    pub upper: &'a [f64],
}

/// Sizes of a checked problem.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Dims {
    pub n: usize,
    pub m_eq: usize,
    pub m_in: usize,
}

impl QpProblem<'_> {
    /// Checks sizes against the workspace capacity, finiteness, limit order and the symmetry of
    /// H (positive definiteness is checked by the factorisation).
    pub(crate) fn check(&self, capacity: Dims, settings: &QpSettings) -> Result<Dims> {
        let n = self.c.len();
        let m_eq = self.a_eq.nrows();
        let m_in = self.a_in.nrows();
        check_capacity("number of variables (length of c)", capacity.n, n)?;
        check_capacity(
            "number of equality rows (rows of A_eq)",
            capacity.m_eq,
            m_eq,
        )?;
        check_capacity(
            "number of inequality rows (rows of A_in)",
            capacity.m_in,
            m_in,
        )?;
        if m_eq > 0 {
            check_dim("columns of A_eq", n, self.a_eq.ncols())?;
        }
        if m_in > 0 {
            check_dim("columns of A_in", n, self.a_in.ncols())?;
        }
        check_dim("length of b_eq", m_eq, self.b_eq.len())?;
        check_dim(
            "length of l (lower ends of A_in rows)",
            m_in,
            self.lower.len(),
        )?;
        check_dim(
            "length of u (upper ends of A_in rows)",
            m_in,
            self.upper.len(),
        )?;
        check_all_finite("c", self.c)?;
        check_all_finite("b_eq", self.b_eq)?;
        check_matrix_finite("A_eq", &self.a_eq)?;
        check_matrix_finite("A_in", &self.a_in)?;
        for (i, (&l, &u)) in self.lower.iter().zip(self.upper).enumerate() {
            if l.is_nan() || u.is_nan() {
                return Err(Error::NonFinite {
                    what: format!("limits of A_in row {i} (l = {l}, u = {u})"),
                    value: f64::NAN,
                });
            }
            if l > u || l == f64::INFINITY || u == f64::NEG_INFINITY {
                return Err(Error::InvalidLimit {
                    what: format!("row {i} of A_in (expected l ≤ u, l < +∞, u > −∞)"),
                    lower: l,
                    upper: u,
                });
            }
        }
        if let Hessian::Dense(h) = &self.hessian {
            check_dim("rows of H", n, h.nrows())?;
            check_dim("columns of H", n, h.ncols())?;
            check_matrix_finite("H", h)?;
            check_symmetric(h, settings.hessian_symmetry_tolerance)?;
        }
        Ok(Dims { n, m_eq, m_in })
    }
}

fn check_capacity(what: &str, capacity: usize, got: usize) -> Result<()> {
    if got <= capacity {
        Ok(())
    } else {
        Err(Error::DimensionMismatch {
            what: format!("{what}: more than the workspace was sized for"),
            expected: capacity,
            got,
        })
    }
}

fn check_matrix_finite(what: &str, m: &DMatrixView<'_, f64>) -> Result<()> {
    for j in 0..m.ncols() {
        let column = m.column(j);
        let column = column.as_slice();
        if crate::error::all_finite(column) {
            continue;
        }
        if let Some((i, &v)) = column.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: format!("{what}[({i}, {j})]"),
                value: v,
            });
        }
    }
    Ok(())
}

fn check_symmetric(h: &DMatrixView<'_, f64>, tolerance: f64) -> Result<()> {
    let scale = h.iter().fold(0.0_f64, |acc, v| acc.max(v.abs()));
    let n = h.nrows();
    for j in 0..n {
        for i in (j + 1)..n {
            let gap = (h[(i, j)] - h[(j, i)]).abs();
            if gap > tolerance * scale {
                return Err(Error::InvalidSetting {
                    name: format!("H[({i}, {j})] vs H[({j}, {i})]"),
                    value: format!("{} vs {}", h[(i, j)], h[(j, i)]),
                    expected: format!(
                        "a symmetric H (|H_ij − H_ji| ≤ {tolerance:e} × max|H| = {:e})",
                        tolerance * scale
                    ),
                });
            }
        }
    }
    Ok(())
}
