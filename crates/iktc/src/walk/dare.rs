//! The discrete algebraic Riccati equation (DARE), solved by the structure-preserving
//! doubling algorithm.
//!
//! For `x⁺ = A x + B u` and the cost `Σ xᵀQx + uᵀRu` (`Q = Qᵀ ⪰ 0`, `R = Rᵀ ≻ 0`), the
//! stabilizing solution `X = Xᵀ ⪰ 0` of
//!
//! `X = Aᵀ X A − Aᵀ X B (R + Bᵀ X B)⁻¹ Bᵀ X A + Q`
//!
//! gives the infinite-horizon optimal feedback `u = −(R + BᵀXB)⁻¹ BᵀXA x`.
//!
//! The structure-preserving doubling algorithm (SDA; Chu, Fan, Lin & Wang, "Structure-preserving
//! algorithms for periodic discrete-time algebraic Riccati equations", Int. J. Control 77(8),
//! 2004; Lin & Xu, SIAM J. Matrix Anal. Appl. 28(1), 2006) iterates, from `A₀ = A`,
//! `G₀ = B R⁻¹ Bᵀ`, `H₀ = Q`, with `W_k = I + G_k H_k`:
//!
//! ```text
//! A_{k+1} = A_k W_k⁻¹ A_k
//! G_{k+1} = G_k + A_k W_k⁻¹ G_k A_kᵀ
//! H_{k+1} = H_k + A_kᵀ H_k W_k⁻¹ A_k
//! ```
//!
//! `H_k` is the cost-to-go matrix of the finite-horizon problem over `2^k` steps, so it converges
//! to `X` quadratically once the horizon exceeds the closed loop's settling time, when
//! `(A, B)` is stabilizable and `(Q^{1/2}, A)` detectable. Stop when
//! `‖H_{k+1} − H_k‖_F ≤ tolerance · max(1, ‖H_{k+1}‖_F)`.

use nalgebra::DMatrix;
use serde::Serialize;

use super::settings::invalid;
use crate::error::{check_all_finite, check_dim, Error, Result};

/// Stopping rule of [`solve_dare`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DareSettings {
    /// Relative change of the iterate `‖H_{k+1} − H_k‖_F / max(1, ‖H_{k+1}‖_F)` below which the
    /// iteration stops \[–\], in `(0, 1)`. Smaller is more accurate; below ≈ 1e-14 round-off
    /// may prevent convergence. Also the largest relative asymmetry `‖Q − Qᵀ‖_F / max(1, ‖Q‖_F)`
    /// accepted in `Q`.
    pub tolerance: f64,
    /// Most doubling steps, `≥ 1`. Step `k` covers a horizon of `2^k` samples, so 60 steps
    /// are far more than any stabilizable problem needs; hitting it means a (nearly)
    /// non-stabilizable problem.
    pub max_iterations: usize,
}

impl Default for DareSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-13,
            max_iterations: 60,
        }
    }
}

impl DareSettings {
    /// Checks `0 < tolerance < 1` and `max_iterations ≥ 1`.
    pub fn validate(&self) -> Result<()> {
        let t = self.tolerance;
        if !(t.is_finite() && t > 0.0 && t < 1.0) {
            return Err(invalid("DareSettings::tolerance", t, "in (0, 1)"));
        }
        if self.max_iterations == 0 {
            return Err(invalid("DareSettings::max_iterations", 0.0, ">= 1"));
        }
        Ok(())
    }
}

/// How [`solve_dare`] ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum DareStatus {
    /// The stopping rule was met.
    Converged,
    /// `max_iterations` ran out first; the last iterate is returned.
    MaxIterations,
    /// `I + G_k H_k` became singular or an iterate non-finite (a problem without a
    /// stabilizing solution); the last finite iterate is returned.
    Breakdown,
}

/// Result of [`solve_dare`].
#[derive(Debug, Clone, PartialEq)]
pub struct DareSolution {
    /// The solution `X` (symmetrized), `n × n`.
    pub x: DMatrix<f64>,
    /// Doubling steps taken.
    pub iterations: usize,
    /// Relative residual of the DARE at `X`, see [`dare_residual`] \[–\].
    pub residual: f64,
    /// How the iteration ended.
    pub status: DareStatus,
}

fn symmetrize(m: &mut DMatrix<f64>) {
    let t = m.transpose();
    *m += t;
    *m *= 0.5;
}

fn check_inputs(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> Result<()> {
    let n = a.nrows();
    check_dim("DARE A (columns)", n, a.ncols())?;
    check_dim("DARE B (rows)", n, b.nrows())?;
    let m = b.ncols();
    check_dim("DARE Q (rows)", n, q.nrows())?;
    check_dim("DARE Q (columns)", n, q.ncols())?;
    check_dim("DARE R (rows)", m, r.nrows())?;
    check_dim("DARE R (columns)", m, r.ncols())?;
    check_all_finite("DARE A", a.as_slice())?;
    check_all_finite("DARE B", b.as_slice())?;
    check_all_finite("DARE Q", q.as_slice())?;
    check_all_finite("DARE R", r.as_slice())?;
    Ok(())
}

/// Relative residual of the DARE at `x`:
/// `‖X − (AᵀXA − AᵀXB(R + BᵀXB)⁻¹BᵀXA + Q)‖_F / max(1, ‖X‖_F)` \[–\]; `+∞` if `R + BᵀXB` is
/// singular. Errors on dimension mismatch or non-finite input.
pub fn dare_residual(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
    x: &DMatrix<f64>,
) -> Result<f64> {
    check_inputs(a, b, q, r)?;
    check_dim("DARE X (rows)", a.nrows(), x.nrows())?;
    check_dim("DARE X (columns)", a.nrows(), x.ncols())?;
    check_all_finite("DARE X", x.as_slice())?;
    let xa = x * a;
    let xb = x * b;
    let s = r + b.transpose() * &xb;
    let Some(k) = s.lu().solve(&(b.transpose() * &xa)) else {
        return Ok(f64::INFINITY);
    };
    let rhs = a.transpose() * &xa - a.transpose() * &xb * k + q;
    Ok((x - rhs).norm() / x.norm().max(1.0))
}

/// Solves the DARE by the doubling algorithm of the module documentation.
///
/// Errors: dimension mismatch, non-finite entries, `R` not symmetric positive definite,
/// `Q` not symmetric, invalid settings. A problem without a stabilizing solution is not an
/// error: it shows in [`DareSolution::status`].
pub fn solve_dare(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
    settings: &DareSettings,
) -> Result<DareSolution> {
    settings.validate()?;
    check_inputs(a, b, q, r)?;
    let asym = (q - q.transpose()).norm();
    if asym > settings.tolerance * q.norm().max(1.0) {
        return Err(invalid(
            "DARE Q asymmetry ‖Q − Qᵀ‖_F",
            asym,
            "a symmetric Q",
        ));
    }
    let Some(r_chol) = r.clone().cholesky() else {
        return Err(Error::InvalidSetting {
            name: "DARE R".to_string(),
            value: format!("{r}"),
            expected: "a symmetric positive definite matrix".to_string(),
        });
    };
    let n = a.nrows();
    let mut ak = a.clone();
    let mut gk = b * r_chol.solve(&b.transpose());
    symmetrize(&mut gk);
    let mut hk = q.clone();
    symmetrize(&mut hk);
    let identity = DMatrix::<f64>::identity(n, n);
    let mut status = DareStatus::MaxIterations;
    let mut iterations = 0;
    for k in 1..=settings.max_iterations {
        iterations = k;
        let w = (&identity + &gk * &hk).lu();
        let (Some(w_a), Some(w_g)) = (w.solve(&ak), w.solve(&gk)) else {
            status = DareStatus::Breakdown;
            break;
        };
        let mut h_next = &hk + ak.transpose() * &hk * &w_a;
        symmetrize(&mut h_next);
        let mut g_next = &gk + &ak * w_g * ak.transpose();
        symmetrize(&mut g_next);
        let a_next = &ak * w_a;
        if !(h_next.iter().all(|v| v.is_finite())
            && g_next.iter().all(|v| v.is_finite())
            && a_next.iter().all(|v| v.is_finite()))
        {
            status = DareStatus::Breakdown;
            break;
        }
        let change = (&h_next - &hk).norm();
        let scale = h_next.norm().max(1.0);
        if !(change.is_finite() && scale.is_finite()) {
            // The norms overflow: the iterate grows without bound.
            status = DareStatus::Breakdown;
            break;
        }
        hk = h_next;
        gk = g_next;
        ak = a_next;
        if change <= settings.tolerance * scale {
            status = DareStatus::Converged;
            break;
        }
    }
    let residual = dare_residual(a, b, q, r, &hk)?;
    if status == DareStatus::Converged && !residual.is_finite() {
        status = DareStatus::Breakdown;
    }
    Ok(DareSolution {
        x: hk,
        iterations,
        residual,
        status,
    })
}
