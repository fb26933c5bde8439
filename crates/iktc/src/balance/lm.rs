//! Levenberg–Marquardt for nonlinear least squares, `min_x ½‖r(x)‖²`, on the
//! [`levenberg-marquardt`](::levenberg_marquardt) crate: a port of MINPACK's `lmder` (Moré,
//! "The Levenberg–Marquardt algorithm: implementation and theory", 1978).
//!
//! Each iteration solves the trust-region subproblem
//! `min_p ‖J p + r‖²` subject to `‖D p‖ ≤ Δ`, i.e.
//! `(JᵀJ + λ DᵀD) p = −Jᵀ r`, with `λ = 0` when the Gauss–Newton step lies inside the region
//! and otherwise `λ > 0` chosen so that `‖D p‖ ≈ Δ`. The system is solved through a
//! column-pivoted QR factorisation of `J`, not the normal equations. `D` is Marquardt's
//! scaling, the largest column norms of `J` seen so far; the radius `Δ` starts at
//! [`LmSettings::initial_step_bound`]`·‖D x₀‖` and follows the ratio `ρ` of the actual to the
//! predicted decrease of `‖r‖²` (halved or more when `ρ ≤ ¼`, set to `2‖D p‖` when `ρ ≥ ¾`); the
//! step is taken when `ρ ≥ 10⁻⁴`. The Jacobian `J` comes from central finite differences
//! with [`LmSettings::jacobian_step`].
//!
//! A trial point where the residual function errors or gives a value that is not finite counts
//! as a rejected step: the radius shrinks and the step is retried from the same point. Used
//! for the identification of Section 4.2 and for the damping-ratio fit of the push responses.

use std::cell::{Cell, RefCell};

use ::levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::storage::Owned;
use nalgebra::{DMatrix, DVector, Dyn};
use serde::Serialize;

use super::model::invalid;
use crate::error::{Error, Result};

/// Settings of the Levenberg–Marquardt solver.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LmSettings {
    /// Most trial steps (accepted or rejected; one residual evaluation each, the Jacobian's
    /// not counted) \[steps\]; at most [`crate::resources::MAX_LM_ITERATIONS`]. More costs
    /// time, fewer may stop early with [`LmStatus::MaxIterations`].
    pub max_iterations: usize,
    /// Stop ([`LmStatus::CostConverged`]) when both the actual and the predicted relative
    /// decrease of `‖r‖²` in a step are at most this \[–\] (MINPACK's `ftol`). Smaller is more
    /// precise but takes more steps.
    pub relative_cost_tolerance: f64,
    /// Stop ([`LmStatus::StepConverged`]) when the trust-region radius is at most this
    /// fraction of the scaled parameters' norm, `Δ ≤ xtol·‖D x‖` \[–\] (MINPACK's `xtol`): the
    /// relative change of the parameters is below it.
    pub relative_step_tolerance: f64,
    /// Stop ([`LmStatus::GradientConverged`]) when the cosine of the angle between the
    /// residual and every column of `J` is at most this \[–\] (MINPACK's `gtol`): the gradient
    /// `Jᵀr` vanishes relative to `‖r‖` and the columns' norms. 0 turns the test off.
    pub gradient_tolerance: f64,
    /// Initial trust-region radius as a multiple of the scaled start's norm, `Δ₀ =
    /// initial_step_bound·‖D x₀‖` (or `initial_step_bound` itself when `x₀ = 0`) \[–\]
    /// (MINPACK's `factor`). Larger lets the first steps go further; 0.1–100 is usual.
    pub initial_step_bound: f64,
    /// Central finite-difference step for the Jacobian \[parameter units\]. Too small loses
    /// digits to round-off, too large to truncation; √ε·scale ≈ 1e-6 suits O(1) parameters.
    pub jacobian_step: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            relative_cost_tolerance: 1e-12,
            relative_step_tolerance: 1e-10,
            gradient_tolerance: 1e-12,
            initial_step_bound: 100.0,
            jacobian_step: 1e-6,
        }
    }
}

impl LmSettings {
    /// Checks the settings' ranges.
    pub fn validate(&self) -> Result<()> {
        let pos = [
            (
                "LmSettings::relative_cost_tolerance",
                self.relative_cost_tolerance,
            ),
            (
                "LmSettings::relative_step_tolerance",
                self.relative_step_tolerance,
            ),
            ("LmSettings::initial_step_bound", self.initial_step_bound),
            ("LmSettings::jacobian_step", self.jacobian_step),
        ];
        for (name, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(invalid(name, v, "finite and > 0"));
            }
        }
        if !(self.gradient_tolerance.is_finite() && self.gradient_tolerance >= 0.0) {
            return Err(invalid(
                "LmSettings::gradient_tolerance",
                self.gradient_tolerance,
                "finite and >= 0",
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
    /// The residual is exactly zero.
    ResidualsZero,
    /// The relative decrease of the cost fell below
    /// [`LmSettings::relative_cost_tolerance`] (possibly together with the step test).
    CostConverged,
    /// The relative step fell below [`LmSettings::relative_step_tolerance`].
    StepConverged,
    /// The residual is orthogonal to the Jacobian's columns within
    /// [`LmSettings::gradient_tolerance`]: a stationary point.
    GradientConverged,
    /// A tolerance could not be met at machine precision: a (local) minimum to working
    /// precision, tighter than the settings asked for.
    NoImprovement,
    /// The step limit [`LmSettings::max_iterations`] was reached first.
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
    /// Trial steps used (accepted and rejected).
    pub iterations: usize,
    /// Why it stopped.
    pub status: LmStatus,
}

/// The crate's view of our problem: the residual closure, the current parameters, the step
/// budget, and the iterate at the last Jacobian (the point the solver stands on).
struct Problem<F> {
    residual: RefCell<F>,
    m: usize,
    x: DVector<f64>,
    h: f64,
    /// Residual evaluations after the start's \[evaluations\].
    trials: Cell<usize>,
    max_trials: usize,
    /// Set when a trial was refused for the budget: the solver then stopped there.
    out_of_steps: Cell<bool>,
    /// The parameters of the last Jacobian, i.e. the solver's current iterate.
    iterate: RefCell<DVector<f64>>,
    /// An error of the residual function during the Jacobian.
    error: RefCell<Option<Error>>,
}

impl<F> Problem<F>
where
    F: FnMut(&DVector<f64>, &mut DVector<f64>) -> Result<()>,
{
    /// The residual at `x`, or `None` where the function errors or gives a non-finite value.
    fn eval(&self, x: &DVector<f64>) -> Option<DVector<f64>> {
        let mut r = DVector::zeros(self.m);
        let ok = (self.residual.borrow_mut())(x, &mut r).is_ok();
        (ok && r.iter().all(|v| v.is_finite())).then_some(r)
    }
}

impl<F> LeastSquaresProblem<f64, Dyn, Dyn> for Problem<F>
where
    F: FnMut(&DVector<f64>, &mut DVector<f64>) -> Result<()>,
{
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.x.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.x.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        // The first call is the start; every later one is a trial step.
        let trials = self.trials.get();
        if trials > self.max_trials {
            // `None` stops the solver (`TerminationReason::User`).
            self.out_of_steps.set(true);
            return None;
        }
        self.trials.set(trials + 1);
        if trials == 0 {
            return self.eval(&self.x);
        }
        // A rejected step: a NaN residual norm makes the crate's actual reduction −1, so the
        // ratio ρ < 0 shrinks the radius and keeps the iterate (`None` would stop the solver).
        Some(
            self.eval(&self.x)
                .unwrap_or_else(|| DVector::from_element(self.m, f64::NAN)),
        )
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        self.iterate.borrow_mut().copy_from(&self.x);
        let mut jac = DMatrix::zeros(self.m, self.x.len());
        match jacobian(&mut *self.residual.borrow_mut(), &self.x, &mut jac, self.h) {
            Ok(()) => Some(jac),
            Err(e) => {
                *self.error.borrow_mut() = Some(e);
                None
            }
        }
    }
}

/// Checks the settings, that there are parameters and residuals, and that `x0` is finite.
fn check_problem(x0: &DVector<f64>, m: usize, settings: &LmSettings) -> Result<()> {
    settings.validate()?;
    if x0.is_empty() {
        return Err(invalid("levenberg_marquardt parameters", 0.0, ">= 1"));
    }
    if m == 0 {
        return Err(invalid("levenberg_marquardt residuals", 0.0, ">= 1"));
    }
    crate::error::check_all_finite("levenberg_marquardt x0", x0.as_slice())?;
    Ok(())
}

/// The crate's solver with the settings' tolerances. The crate stops after
/// `patience·(n + 1)` residual evaluations; this one is never reached before our own budget
/// of `max_iterations` trials (plus the start).
fn solver(settings: &LmSettings) -> LevenbergMarquardt<f64> {
    LevenbergMarquardt::new()
        .with_ftol(settings.relative_cost_tolerance)
        .with_xtol(settings.relative_step_tolerance)
        .with_gtol(settings.gradient_tolerance)
        .with_stepbound(settings.initial_step_bound)
        .with_patience(settings.max_iterations + 1)
        .with_scale_diag(true)
}

/// The status of the solver's `termination`, and whether the answer is the point of the last
/// Jacobian (a trial refused for the budget, `out_of_steps`) rather than the solver's `x`; an
/// error for a numerical failure or a malformed problem.
fn termination_status(
    termination: &TerminationReason,
    out_of_steps: bool,
) -> Result<(LmStatus, bool)> {
    Ok(match termination {
        TerminationReason::ResidualsZero => (LmStatus::ResidualsZero, false),
        TerminationReason::Converged { ftol: true, .. } => (LmStatus::CostConverged, false),
        TerminationReason::Converged { .. } => (LmStatus::StepConverged, false),
        TerminationReason::Orthogonal => (LmStatus::GradientConverged, false),
        TerminationReason::NoImprovementPossible(_) => (LmStatus::NoImprovement, false),
        TerminationReason::LostPatience => (LmStatus::MaxIterations, false),
        // Our refusal of a trial beyond the budget: the solver's iterate is the point of the
        // last Jacobian (the refused trial's parameters were not reset).
        TerminationReason::User(_) if out_of_steps => (LmStatus::MaxIterations, true),
        TerminationReason::Numerical(what) | TerminationReason::User(what) => {
            return Err(Error::NonFinite {
                what: format!("Levenberg–Marquardt {what}"),
                value: f64::NAN,
            });
        }
        TerminationReason::NoParameters
        | TerminationReason::NoResiduals
        | TerminationReason::WrongDimensions(_) => {
            return Err(invalid(
                "levenberg_marquardt problem",
                f64::NAN,
                &format!("well-formed ({:?})", termination),
            ));
        }
    })
}

/// Minimises `½‖r(x)‖²` from `x0`. `residual(x, r)` fills `r` (length `m`) and returns an error
/// for parameters where the model is undefined; such trial steps, and those whose residual is
/// not finite, are treated as rejected. An error if the residual is undefined or not finite at
/// `x0`, if it errors at a finite-difference point of the Jacobian, if the Jacobian is not
/// finite, if `x0` or `m` is empty, or if the settings are invalid.
pub fn levenberg_marquardt<F>(
    residual: F,
    x0: DVector<f64>,
    m: usize,
    settings: &LmSettings,
) -> Result<LmResult>
where
    F: FnMut(&DVector<f64>, &mut DVector<f64>) -> Result<()>,
{
    check_problem(&x0, m, settings)?;
    let n = x0.len();
    let mut residual = residual;
    // The start: its errors are the caller's to see.
    let mut r0 = DVector::zeros(m);
    residual(&x0, &mut r0)?;
    crate::error::check_all_finite("levenberg_marquardt residual at x0", r0.as_slice())?;
    let problem = Problem {
        residual: RefCell::new(residual),
        m,
        iterate: RefCell::new(x0.clone()),
        x: x0,
        h: settings.jacobian_step,
        trials: Cell::new(0),
        max_trials: settings.max_iterations,
        out_of_steps: Cell::new(false),
        error: RefCell::new(None),
    };
    let (problem, report) = solver(settings).minimize(problem);
    if let Some(e) = problem.error.take() {
        return Err(e);
    }
    let (status, at_iterate) = termination_status(&report.termination, problem.out_of_steps.get())?;
    let x = if at_iterate {
        problem.iterate.into_inner()
    } else {
        problem.x
    };
    let iterations = problem.trials.get().saturating_sub(1);
    let mut residual = problem.residual.into_inner();
    let mut r = DVector::zeros(m);
    residual(&x, &mut r)?;
    crate::error::check_all_finite("levenberg_marquardt final residual", r.as_slice())?;
    let mut jac = DMatrix::zeros(m, n);
    jacobian(&mut residual, &x, &mut jac, settings.jacobian_step)?;
    Ok(LmResult {
        cost: 0.5 * r.norm_squared(),
        x,
        residual: r,
        jacobian: jac,
        iterations,
        status,
    })
}

/// Central finite differences: column `j` is `(r(x + h eⱼ) − r(x − h eⱼ)) / 2h`. An error
/// where the residual function errors or a column is not finite.
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
        crate::error::check_all_finite(&format!("Jacobian column {j}"), col.as_slice())?;
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

    fn rosenbrock(x: &DVector<f64>, r: &mut DVector<f64>) -> Result<()> {
        r[0] = 10.0 * (x[1] - x[0] * x[0]);
        r[1] = 1.0 - x[0];
        Ok(())
    }

    /// Rosenbrock's residuals from the classic start (−1.2, 1) reach the minimum (1, 1),
    /// cost 0, through the curved valley.
    #[test]
    fn rosenbrock_reaches_its_minimum() {
        let x0 = DVector::from_vec(vec![-1.2, 1.0]);
        let fit = levenberg_marquardt(rosenbrock, x0, 2, &LmSettings::default()).unwrap();
        assert!((fit.x[0] - 1.0).abs() < 1e-8, "{}", fit.x);
        assert!((fit.x[1] - 1.0).abs() < 1e-8, "{}", fit.x);
        assert!(fit.cost < 1e-20, "{}", fit.cost);
        assert_ne!(fit.status, LmStatus::MaxIterations);
        assert!(fit.iterations < 100, "{}", fit.iterations);
        // The Jacobian at (1, 1): [[−20, 10], [−1, 0]].
        let want = DMatrix::from_row_slice(2, 2, &[-20.0, 10.0, -1.0, 0.0]);
        assert!((fit.jacobian - want).amax() < 1e-6);
    }

    /// `y = a e^(−b t) + c` sampled without noise at a = 2.5, b = 1.3, c = 0.4, fitted from
    /// (1, 0.5, 0): the samples' parameters come back.
    #[test]
    fn exponential_decay_is_fitted() {
        let truth = [2.5, 1.3, 0.4];
        let t: Vec<f64> = (0..30).map(|i| 0.1 * i as f64).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|t| truth[0] * (-truth[1] * t).exp() + truth[2])
            .collect();
        let residual = |x: &DVector<f64>, r: &mut DVector<f64>| -> Result<()> {
            for (i, (t, y)) in t.iter().zip(&y).enumerate() {
                r[i] = x[0] * (-x[1] * t).exp() + x[2] - y;
            }
            Ok(())
        };
        let x0 = DVector::from_vec(vec![1.0, 0.5, 0.0]);
        let fit = levenberg_marquardt(residual, x0, t.len(), &LmSettings::default()).unwrap();
        for (got, want) in fit.x.iter().zip(truth) {
            assert!((got - want).abs() < 1e-8, "{} against {truth:?}", fit.x);
        }
        assert!(fit.cost < 1e-20, "{}", fit.cost);
        assert_eq!(fit.residual.len(), t.len());
    }

    /// `r = √x − 1` is undefined for `x ≤ 0`. From `x = 4` the Gauss–Newton step
    /// `−r/r' = −4` lands on `x = 0`: that trial errors, counts as a rejected step, and the
    /// solver goes on with a smaller radius to `x = 1`.
    #[test]
    fn a_residual_error_is_a_rejected_step() {
        let refused = Cell::new(0);
        let residual = |x: &DVector<f64>, r: &mut DVector<f64>| -> Result<()> {
            if x[0] <= 0.0 {
                refused.set(refused.get() + 1);
                return Err(invalid("x", x[0], "> 0"));
            }
            r[0] = x[0].sqrt() - 1.0;
            Ok(())
        };
        let x0 = DVector::from_vec(vec![4.0]);
        let fit = levenberg_marquardt(residual, x0, 1, &LmSettings::default()).unwrap();
        assert!(refused.get() >= 1, "no trial fell outside the domain");
        assert!((fit.x[0] - 1.0).abs() < 1e-8, "{}", fit.x);
        assert_ne!(fit.status, LmStatus::MaxIterations);

        // The same with a NaN instead of an error: from `x = 9` the first trial is `x = −3`.
        let negative = Cell::new(0);
        let nan = |x: &DVector<f64>, r: &mut DVector<f64>| -> Result<()> {
            negative.set(negative.get() + usize::from(x[0] < 0.0));
            r[0] = x[0].sqrt() - 1.0;
            Ok(())
        };
        let fit = levenberg_marquardt(nan, DVector::from_vec(vec![9.0]), 1, &LmSettings::default())
            .unwrap();
        assert!(negative.get() >= 1, "no trial fell outside the domain");
        assert!((fit.x[0] - 1.0).abs() < 1e-8, "{}", fit.x);
    }

    /// With a budget of three trial steps the solver stops after three, at its current
    /// iterate: a point no worse than the start, with the residual and cost of that point.
    #[test]
    fn the_step_budget_stops_at_the_iterate() {
        let settings = LmSettings {
            max_iterations: 3,
            ..LmSettings::default()
        };
        let x0 = DVector::from_vec(vec![-1.2, 1.0]);
        let mut r0 = DVector::zeros(2);
        rosenbrock(&x0, &mut r0).unwrap();
        let fit = levenberg_marquardt(rosenbrock, x0, 2, &settings).unwrap();
        assert_eq!(fit.status, LmStatus::MaxIterations);
        assert_eq!(fit.iterations, 3);
        let mut r = DVector::zeros(2);
        rosenbrock(&fit.x, &mut r).unwrap();
        assert_eq!(r, fit.residual);
        assert_eq!(fit.cost, 0.5 * r.norm_squared());
        assert!(fit.cost <= 0.5 * r0.norm_squared());
    }

    /// Bad input is an error, not a panic.
    #[test]
    fn bad_input_is_an_error() {
        let s = LmSettings::default();
        let one = || DVector::from_vec(vec![1.0]);
        let zero = |_: &DVector<f64>, r: &mut DVector<f64>| -> Result<()> {
            r.fill(1.0);
            Ok(())
        };
        assert!(levenberg_marquardt(zero, DVector::zeros(0), 1, &s).is_err());
        assert!(levenberg_marquardt(zero, one(), 0, &s).is_err());
        assert!(levenberg_marquardt(zero, DVector::from_vec(vec![f64::NAN]), 1, &s).is_err());
        let fails = |_: &DVector<f64>, _: &mut DVector<f64>| -> Result<()> {
            Err(invalid("x", 0.0, "never"))
        };
        assert!(levenberg_marquardt(fails, one(), 1, &s).is_err());
        let infinite = |_: &DVector<f64>, r: &mut DVector<f64>| -> Result<()> {
            r.fill(f64::INFINITY);
            Ok(())
        };
        assert!(levenberg_marquardt(infinite, one(), 1, &s).is_err());
        for bad in [
            LmSettings {
                relative_cost_tolerance: -1.0,
                ..s
            },
            LmSettings {
                relative_step_tolerance: 0.0,
                ..s
            },
            LmSettings {
                gradient_tolerance: -1e-3,
                ..s
            },
            LmSettings {
                initial_step_bound: f64::NAN,
                ..s
            },
            LmSettings {
                jacobian_step: 0.0,
                ..s
            },
        ] {
            assert!(
                levenberg_marquardt(zero, one(), 1, &bad).is_err(),
                "{bad:?}"
            );
        }
    }

    /// A residual that is zero at the start stops there.
    #[test]
    fn a_zero_residual_stops_at_once() {
        let zero = |_: &DVector<f64>, r: &mut DVector<f64>| -> Result<()> {
            r.fill(0.0);
            Ok(())
        };
        let fit = levenberg_marquardt(
            zero,
            DVector::from_vec(vec![1.0]),
            2,
            &LmSettings::default(),
        )
        .unwrap();
        assert_eq!(fit.status, LmStatus::ResidualsZero);
        assert_eq!(fit.iterations, 0);
        assert_eq!(fit.cost, 0.0);
    }
}
