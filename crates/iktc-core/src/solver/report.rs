//! What a solve reports: how q̈ was obtained, and which task paid for the limits.

use nalgebra::DVector;

/// Which solver.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// The plain prioritized solution (eqs. 5–9), ignoring the box.
    Prioritized,
    /// IKTC: the prioritized solution, corrected by one QP when it leaves the box (Section 3.2).
    Iktc,
    /// GF: the cascade of QPs with the box on top (Kanoun et al.), one QP per level.
    Cascade,
    /// The prioritized solution clamped to the box.
    Clamp,
}

impl Method {
    /// Lower-case name: "prioritized", "iktc", "gf", "clamp".
    pub fn name(&self) -> &'static str {
        match self {
            Method::Prioritized => "prioritized",
            Method::Iktc => "iktc",
            Method::Cascade => "gf",
            Method::Clamp => "clamp",
        }
    }
}

/// A fallback taken because the problem as posed had no solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Fallback {
    /// No level of IKTC could bring q̈ into the box (rank loss, or Σm_i < n left no freedom):
    /// the prioritized solution was clamped to the box. Also: an IKTC or GF answer that still
    /// left the box by more than 10³ × the box
    /// tolerance (a QP that lost its accuracy) was clamped into it.
    ClampedToBox,
    /// A level of the cascade had no feasible solution; the solution of the level above was
    /// kept, clamped to the box.
    CascadeStoppedAtLevel(usize),
    /// The box of at least one dof was empty (`b_l > b_u`: the state was outside the limits'
    /// viable set); those dofs were held to the midpoint of their bounds
    /// ([`SolveReport::empty_box_dofs`]). A fallback of the method itself replaces this one.
    EmptyBox,
}

/// The record of one solve. Sized once, refreshed each tick without allocation.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveReport {
    /// The method used.
    pub method: Method,
    /// IKTC: the highest-priority level (0-based) whose correction was needed; `None` when the
    /// prioritized solution was inside the box (or another method ran).
    pub corrected_from: Option<usize>,
    /// IKTC: Algorithm 2's level, the lowest-priority one whose correction alone brings q̈ into
    /// the box (0-based). `corrected_from` is a higher level only while
    /// [`SolverSettings::level_hold`](super::SolverSettings::level_hold) holds an earlier choice.
    pub feasible_from: Option<usize>,
    /// IKTC's correction Δh_i of each level \[task unit/s²\] (zero where uncorrected).
    pub corrections: Vec<DVector<f64>>,
    /// J_i q̈ − h_i of each level at the returned q̈ \[task unit/s²\]: what the level lost.
    pub task_errors: Vec<DVector<f64>>,
    /// ‖J_i q̈ − h_i‖ per level.
    pub task_error_norms: Vec<f64>,
    /// Rank kept at each level by the prioritized recursion.
    pub ranks: Vec<usize>,
    /// QPs solved, infeasible ones included (for IKTC each one is also its level's feasibility
    /// check: the dual active-set QP detects an empty constraint set by itself).
    pub qp_solves: usize,
    /// QPs that reported an infeasible constraint set.
    pub qp_infeasible: usize,
    /// IKTC feasibility checks settled without a QP: levels proved infeasible by the
    /// certificate of the rows their last infeasible QP ended with active (see
    /// [`SolverSettings::screen`](super::SolverSettings::screen)). Each such level also counts
    /// as a feasibility check, not as a QP.
    pub screened_infeasible: usize,
    /// IKTC QPs settled by the warm start, without active-set iterations: the rows active at
    /// the level's last optimum gave the optimum (see
    /// [`SolverSettings::warm_start`](super::SolverSettings::warm_start)). Counted in
    /// `qp_solves` too.
    pub qp_warm_started: usize,
    /// Active-set iterations over all QPs.
    pub qp_iterations: usize,
    /// Dofs whose box was empty (b_l > b_u); they were given the midpoint, the least possible
    /// violation.
    pub empty_box_dofs: usize,
    /// Largest violation of the box by the prioritized solution \[rad/s²\].
    pub violation_before: f64,
    /// Largest violation of the (midpoint-relaxed) box by the returned q̈ \[rad/s²\].
    pub violation: f64,
    /// The fallback taken, if any.
    pub fallback: Option<Fallback>,
}

impl SolveReport {
    /// A zeroed report for levels of the given sizes.
    pub fn new(dims: &[usize]) -> Self {
        Self {
            method: Method::Iktc,
            corrected_from: None,
            feasible_from: None,
            corrections: dims.iter().map(|&m| DVector::zeros(m)).collect(),
            task_errors: dims.iter().map(|&m| DVector::zeros(m)).collect(),
            task_error_norms: vec![0.0; dims.len()],
            ranks: vec![0; dims.len()],
            qp_solves: 0,
            qp_infeasible: 0,
            screened_infeasible: 0,
            qp_warm_started: 0,
            qp_iterations: 0,
            empty_box_dofs: 0,
            violation_before: 0.0,
            violation: 0.0,
            fallback: None,
        }
    }

    pub(crate) fn reset(&mut self, method: Method) {
        self.method = method;
        self.corrected_from = None;
        self.feasible_from = None;
        for c in &mut self.corrections {
            c.fill(0.0);
        }
        self.qp_solves = 0;
        self.qp_infeasible = 0;
        self.screened_infeasible = 0;
        self.qp_warm_started = 0;
        self.qp_iterations = 0;
        self.empty_box_dofs = 0;
        self.violation_before = 0.0;
        self.violation = 0.0;
        self.fallback = None;
    }
}
