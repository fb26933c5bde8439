//! What a QP solve reports: status, iterations, objective, active set.

/// One side of one constraint row of a [`QpProblem`](super::QpProblem).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum QpConstraint {
    /// Row `row` of the equalities `A_eq x = b_eq`.
    Equality {
        /// Row index in `A_eq`.
        row: usize,
    },
    /// The lower end `l_row ≤ a_rowᵀ x` of row `row` of `A_in`.
    Lower {
        /// Row index in `A_in`.
        row: usize,
    },
    /// The upper end `a_rowᵀ x ≤ u_row` of row `row` of `A_in`.
    Upper {
        /// Row index in `A_in`.
        row: usize,
    },
}

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum QpStatus {
    /// `x` is the minimiser: every constraint holds within
    /// [`feasibility_tolerance`](super::QpSettings::feasibility_tolerance) and every active
    /// inequality has a multiplier of the right sign.
    Optimal,
    /// The constraint set is empty: `constraint` is violated at the current iterate and can be
    /// satisfied neither by a primal step (its normal depends linearly on the active normals) nor
    /// by a dual step (no active inequality can be released). `x` is the last iterate, the
    /// minimiser over the constraints that were active.
    Infeasible {
        /// The violated constraint that could not be added.
        constraint: QpConstraint,
    },
    /// [`max_iterations`](super::QpSettings::max_iterations) active-set changes were made
    /// without reaching the optimum. `x` is the last iterate: the minimiser over the active
    /// constraints, which may violate others.
    MaxIterations,
    /// Nothing was left to add, but the last iterate violates a row by `max_violation`, more
    /// than 10³ times the feasibility tolerance:
    /// near-dependent constraint normals made the iterate grow until rounding dominates the
    /// active rows (seen with rank-deficient task levels, ‖x‖ ≈ 1e18). Not a solution; callers
    /// treat it as a failed solve.
    Inaccurate {
        /// The largest row violation at the last iterate [units of the constraint row].
        max_violation: f64,
    },
}

/// An active constraint at the returned point with its Lagrange multiplier.
///
/// Multipliers follow `H x + c = A_eqᵀ y_eq + A_inᵀ y_in`: an active lower end has `y ≥ 0`, an
/// active upper end `y ≤ 0`, an equality any sign [units of the objective per unit of the row].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActiveConstraint {
    /// Which constraint.
    pub constraint: QpConstraint,
    /// Its multiplier `y`.
    pub multiplier: f64,
}

/// Summary of one solve (plain data, no allocation).
///
/// The active set and the multipliers of every row are read from the workspace after the solve:
/// [`QpWorkspace::active_set`](super::QpWorkspace::active_set),
/// [`QpWorkspace::multipliers_eq`](super::QpWorkspace::multipliers_eq),
/// [`QpWorkspace::multipliers_in`](super::QpWorkspace::multipliers_in).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QpReport {
    /// How the solve ended.
    pub status: QpStatus,
    /// Number of active-set changes made (constraints added plus constraints dropped) [–].
    pub iterations: usize,
    /// `½ xᵀ H x + cᵀ x` at the returned `x` [units of the objective].
    pub objective: f64,
    /// Number of constraints in the final active set [–].
    pub active_count: usize,
    /// Equality rows (of `A_eq`, or rows of `A_in` with `l = u`) skipped because they were
    /// linearly dependent on earlier ones and satisfied [–].
    pub redundant_equalities: usize,
    /// Largest violation of any constraint at the returned `x` [units of the row]; zero if all
    /// hold.
    pub max_violation: f64,
}
