//! Settings of the dense dual active-set QP solver.

use crate::{Error, Result};

/// Tolerances and limits of [`QpWorkspace::solve`](super::QpWorkspace::solve).
///
/// Every field has a default suited to problems whose data are of order one (the IK control
/// tick: accelerations of 1–100 rad/s², Jacobian entries of order one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QpSettings {
    /// Largest number of active-set changes (one constraint added or dropped each) before the
    /// solver gives up with [`QpStatus::MaxIterations`](super::QpStatus::MaxIterations) [–].
    ///
    /// The dual method needs at least one iteration per constraint active at the optimum; a
    /// larger limit only matters on degenerate problems that cycle.
    pub max_iterations: usize,
    /// Constraint violation accepted at the solution [units of the constraint row].
    ///
    /// A row with `l - tol ≤ aᵀx ≤ u + tol` is not added to the active set. Larger values stop
    /// earlier (fewer iterations) at the price of a less feasible answer; values near the
    /// rounding level (≈ 1e-14 × the size of the data) make the solver chase rounding noise.
    pub feasibility_tolerance: f64,
    /// Relative size below which a new constraint normal counts as linearly dependent on the
    /// active ones [–].
    ///
    /// With `d = L⁻¹ n` the new normal in the metric of H and `d₂` its part orthogonal to the
    /// active normals, the normal is dependent when `‖d₂‖ ≤ tol · ‖d‖` (the sine of the angle to
    /// the active subspace). The same bound, with the active normals' sizes, separates a positive
    /// entry of the dual step direction from rounding noise. Larger values declare nearly
    /// dependent constraints dependent (robust steps, but a nearly infeasible set may be called
    /// infeasible); smaller values accept them with very large multipliers.
    pub linear_dependence_tolerance: f64,
    /// Smallest accepted Cholesky pivot of H, relative to the largest diagonal entry of H [–].
    ///
    /// A pivot `L_kk² < tol · max_i H_ii` makes H count as not positive definite (an error).
    /// Larger values reject ill-conditioned Hessians early; smaller values accept them and their
    /// inaccurate solutions.
    pub hessian_pivot_tolerance: f64,
    /// Largest accepted asymmetry of H, relative to its largest entry in magnitude [–].
    ///
    /// `|H_ij − H_ji| > tol · max|H|` is an error. The solver reads only the lower triangle, so a
    /// larger value silently ignores the upper one; a value near zero rejects matrices that are
    /// symmetric up to rounding.
    pub hessian_symmetry_tolerance: f64,
}

impl Default for QpSettings {
    fn default() -> Self {
        Self {
            max_iterations: 1000,
            feasibility_tolerance: 1e-9,
            linear_dependence_tolerance: 1e-10,
            hessian_pivot_tolerance: 1e-14,
            hessian_symmetry_tolerance: 1e-10,
        }
    }
}

impl QpSettings {
    /// Checks that every field is in its valid range.
    ///
    /// `max_iterations ≥ 1`; the tolerances finite and `≥ 0`, the relative ones `< 1`.
    pub fn validate(&self) -> Result<()> {
        if self.max_iterations == 0 {
            return Err(invalid("max_iterations", self.max_iterations, "≥ 1"));
        }
        if !(self.feasibility_tolerance.is_finite() && self.feasibility_tolerance >= 0.0) {
            return Err(invalid(
                "feasibility_tolerance",
                self.feasibility_tolerance,
                "a finite number ≥ 0",
            ));
        }
        for (name, value) in [
            (
                "linear_dependence_tolerance",
                self.linear_dependence_tolerance,
            ),
            ("hessian_pivot_tolerance", self.hessian_pivot_tolerance),
            (
                "hessian_symmetry_tolerance",
                self.hessian_symmetry_tolerance,
            ),
        ] {
            if !(value.is_finite() && (0.0..1.0).contains(&value)) {
                return Err(invalid(name, value, "a number in [0, 1)"));
            }
        }
        Ok(())
    }
}

fn invalid(name: &str, value: impl std::fmt::Display, expected: &str) -> Error {
    Error::InvalidSetting {
        name: name.to_string(),
        value: value.to_string(),
        expected: expected.to_string(),
    }
}
