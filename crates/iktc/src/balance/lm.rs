//! A small Levenberg–Marquardt solver for nonlinear least squares, `min_x ½‖r(x)‖²`.
//!
//! Marquardt's scaled form (Marquardt 1963; Nocedal & Wright, *Numerical Optimization*, §10.3):
//! each step solves `(JᵀJ + λ diag(JᵀJ)) δ = −Jᵀ r` by Cholesky, with the Jacobian `J` from
//! central finite differences. A step that lowers the cost is taken and `λ` shrinks; otherwise
//! `λ` grows and the step is retried. Used for the identification of Section 4.2 and for the
//! damping-ratio fit of the push responses.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::model::invalid;
use crate::error::Result;

/// Settings of the Levenberg–Marquardt solver.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LmSettings {
    /// Most iterations (accepted or rejected steps) \[–\]. More costs time, fewer may stop early.
    pub max_iterations: usize,
    /// Initial damping `λ` \[–\]; large values start like gradient descent, small like Gauss–Newton.
    pub initial_lambda: f64,
    /// Factor `λ` is multiplied by after a rejected step and divided by after an accepted
    /// one \[–\] (> 1).
    pub lambda_factor: f64,
    /// Stop when the relative decrease of the cost in an accepted step is below this \[–\].
    /// Smaller is more precise but takes more iterations.
    pub relative_cost_tolerance: f64,
    /// Stop when the step's largest component is below this \[parameter units\].
    pub step_tolerance: f64,
    /// Give up (status [`LmStatus::NoImprovement`]) when `λ` exceeds this \[–\]: the step is then
    /// a tiny gradient step that still fails, i.e. a minimum to working precision.
    pub max_lambda: f64,
    /// Central finite-difference step for the Jacobian \[parameter units\]. Too small loses
    /// digits to round-off, too large to truncation; √ε·scale ≈ 1e-6 suits O(1) parameters.
    pub jacobian_step: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            initial_lambda: 1e-3,
            lambda_factor: 10.0,
            relative_cost_tolerance: 1e-12,
            step_tolerance: 1e-10,
            jacobian_step: 1e-6,
            max_lambda: 1e12,
        }
    }
}

impl LmSettings {
    /// Checks the settings' ranges.
    pub fn validate(&self) -> Result<()> {
        let pos = [
            ("LmSettings::initial_lambda", self.initial_lambda),
            (
                "LmSettings::relative_cost_tolerance",
                self.relative_cost_tolerance,
            ),
            ("LmSettings::step_tolerance", self.step_tolerance),
            ("LmSettings::jacobian_step", self.jacobian_step),
            ("LmSettings::max_lambda", self.max_lambda),
        ];
        for (name, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "finite and > 0"));
            }
        }
        if !(self.lambda_factor.is_finite() && self.lambda_factor > 1.0) {
            return Err(invalid(
                "LmSettings::lambda_factor",
                self.lambda_factor,
                "finite and > 1",
            ));
        }
        if self.max_iterations == 0 {
            return Err(invalid("LmSettings::max_iterations", 0.0, ">= 1"));
        }
        if self.max_iterations > crate::resources::MAX_LM_ITERATIONS {
            return Err(invalid(
                "LmSettings::max_iterations",
                self.max_iterations as f64,
                &format!(
                    "at most {} (resources::MAX_LM_ITERATIONS)",
                    crate::resources::MAX_LM_ITERATIONS
                ),
            ));
        }
        Ok(())
    }
}

/// Why the solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum LmStatus {
    /// The cost stopped decreasing (relative decrease below tolerance).
    CostConverged,
    /// The step became smaller than the tolerance.
    StepConverged,
    /// `λ` grew without finding a better point: a (local) minimum to working precision.
    NoImprovement,
    /// The iteration limit was reached first.
    MaxIterations,
}

/// The result of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct LmResult {
    /// The parameters at the end.
    pub x: DVector<f64>,
    /// Final cost `½‖r‖²`.
    pub cost: f64,
    /// Final residual vector.
    pub residual: DVector<f64>,
    /// Final Jacobian `∂r/∂x` (for parameter uncertainties).
    pub jacobian: DMatrix<f64>,
    /// Iterations used.
    pub iterations: usize,
    /// Why it stopped.
    pub status: LmStatus,
}

/// Minimises `½‖r(x)‖²` from `x0`. `residual(x, r)` fills `r` (length `m`) and returns an error
/// for parameters where the model is undefined; such trial steps are treated as rejected.
/// An error if the residual is undefined at `x0` or the settings are invalid.
pub fn levenberg_marquardt<F>(
    mut residual: F,
    x0: DVector<f64>,
    m: usize,
    settings: &LmSettings,
) -> Result<LmResult>
where
    F: FnMut(&DVector<f64>, &mut DVector<f64>) -> Result<()>,
{
    settings.validate()?;
    let n = x0.len();
    let mut x = x0;
    let mut r = DVector::zeros(m);
    residual(&x, &mut r)?;
    let mut cost = 0.5 * r.norm_squared();
    let mut jac = DMatrix::zeros(m, n);
    let mut lambda = settings.initial_lambda;
    let mut trial_r = DVector::zeros(m);
    let mut status = LmStatus::MaxIterations;
    let mut iterations = 0;
    let mut need_jacobian = true;
    while iterations < settings.max_iterations {
        iterations += 1;
        if need_jacobian {
            jacobian(&mut residual, &x, &mut jac, settings.jacobian_step)?;
            need_jacobian = false;
        }
        let jtj = jac.transpose() * &jac;
        let g = jac.transpose() * &r;
        let mut lhs = jtj.clone();
        for i in 0..n {
            lhs[(i, i)] += lambda * jtj[(i, i)].max(f64::MIN_POSITIVE);
        }
        let step = match lhs.cholesky() {
            Some(ch) => -ch.solve(&g),
            None => {
                lambda *= settings.lambda_factor;
                continue;
            }
        };
        let trial = &x + &step;
        let accepted = residual(&trial, &mut trial_r).is_ok()
            && trial_r.iter().all(|v| v.is_finite())
            && 0.5 * trial_r.norm_squared() < cost;
        if accepted {
            let new_cost = 0.5 * trial_r.norm_squared();
            let rel = (cost - new_cost) / cost.max(f64::MIN_POSITIVE);
            x = trial;
            std::mem::swap(&mut r, &mut trial_r);
            cost = new_cost;
            lambda = (lambda / settings.lambda_factor).max(f64::EPSILON);
            need_jacobian = true;
            if rel < settings.relative_cost_tolerance {
                status = LmStatus::CostConverged;
                break;
            }
            if step.amax() < settings.step_tolerance {
                status = LmStatus::StepConverged;
                break;
            }
        } else {
            lambda *= settings.lambda_factor;
            if lambda > settings.max_lambda {
                status = LmStatus::NoImprovement;
                break;
            }
        }
    }
    jacobian(&mut residual, &x, &mut jac, settings.jacobian_step)?;
    Ok(LmResult {
        x,
        cost,
        residual: r,
        jacobian: jac,
        iterations,
        status,
    })
}

fn jacobian<F>(residual: &mut F, x: &DVector<f64>, jac: &mut DMatrix<f64>, h: f64) -> Result<()>
where
    F: FnMut(&DVector<f64>, &mut DVector<f64>) -> Result<()>,
{
    let m = jac.nrows();
    let mut rp = DVector::zeros(m);
    let mut rm = DVector::zeros(m);
    let mut xp = x.clone();
    for j in 0..x.len() {
        let xj = x[j];
        xp[j] = xj + h;
        residual(&xp, &mut rp)?;
        xp[j] = xj - h;
        residual(&xp, &mut rm)?;
        xp[j] = xj;
        let col = (&rp - &rm) / (2.0 * h);
        jac.set_column(j, &col);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iterations_are_bounded() {
        let at = |max_iterations: usize| LmSettings {
            max_iterations,
            ..LmSettings::default()
        };
        assert!(at(crate::resources::MAX_LM_ITERATIONS).validate().is_ok());
        for bad in [0, crate::resources::MAX_LM_ITERATIONS + 1, usize::MAX] {
            assert!(at(bad).validate().is_err(), "{bad}");
        }
    }
}
