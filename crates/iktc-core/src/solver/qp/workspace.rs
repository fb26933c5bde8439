//! The preallocated workspace and the dual active-set iteration.

use nalgebra::{DMatrix, DVector};

use super::basis::{axpy, dot, norm, ActiveBasis};
use super::factor::cholesky;
use super::problem::Dims;
use super::{ActiveConstraint, Hessian, QpConstraint, QpProblem, QpReport, QpSettings, QpStatus};
use crate::buffer::Buffer;
use crate::error::check_dim;
use crate::{Error, Result};

/// A solve that ends with nothing left to add is [`QpStatus::Optimal`] only if no row is
/// violated by more than this many times the feasibility tolerance \[–\]; beyond it the
/// status is [`QpStatus::Inaccurate`]. Active rows carry the rounding of `aᵀx` (≈ 1e-16 ‖a‖‖x‖):
/// far below the tolerance for a sane iterate, and hundreds of units for the blown-up iterates
/// (‖x‖ ≈ 1e18) of near-dependent normals. Large enough never to reject a sane solve, small
/// enough to catch every blow-up seen.
pub(crate) const INACCURATE_FACTOR: f64 = 1e3;

/// A constraint row as the solver sees it (before choosing a side).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Row {
    /// Row of `A_eq`.
    Eq(usize),
    /// Row of `A_in`.
    In(usize),
}

/// What the solver knows about a row of `A_in`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RowState {
    /// Not in the active set.
    Inactive,
    /// In the active set with one of its sides.
    Active,
    /// `l = u`: handled as an equality (active, or skipped as redundant).
    Fixed,
}

/// An active constraint: the row, the side (`sign = +1`: normal `+a`, bound `l` or `b`;
/// `sign = −1`: normal `−a`, bound `−u` or `−b`), and `‖L⁻¹ n‖` at the time it was added.
#[derive(Debug, Clone, Copy)]
struct Entry {
    row: Row,
    sign: f64,
    metric_norm: f64,
}

impl Entry {
    fn droppable(&self, states: &[RowState]) -> bool {
        match self.row {
            Row::Eq(_) => false,
            Row::In(i) => states.get(i) == Some(&RowState::Active),
        }
    }

    /// The public name of the side: for a row of `A_in` with `l < u` the side follows `sign`;
    /// for a fixed row (`l = u`) it follows the sign of the multiplier `y`.
    fn constraint(&self, y: f64, fixed: bool) -> QpConstraint {
        let lower = if fixed {
            y > 0.0 || (y == 0.0 && self.sign > 0.0)
        } else {
            self.sign > 0.0
        };
        match self.row {
            Row::Eq(row) => QpConstraint::Equality { row },
            Row::In(row) if lower => QpConstraint::Lower { row },
            Row::In(row) => QpConstraint::Upper { row },
        }
    }
}

/// How the iteration ended (before the report is filled in).
enum Outcome {
    Optimal,
    Infeasible(QpConstraint),
    MaxIterations,
}

/// Preallocated storage of the dense dual active-set QP solver (see the [module
/// documentation](super) for the method).
///
/// Sized once with [`QpWorkspace::new`]; [`QpWorkspace::solve`] then allocates nothing for any
/// problem within those sizes.
#[derive(Debug, Clone)]
pub struct QpWorkspace {
    capacity: Dims,
    last: Dims,
    /// Lower Cholesky factor of H.
    chol: DMatrix<f64>,
    basis: ActiveBasis,
    /// Signed normal `n⁺` of the constraint being added.
    normal: DVector<f64>,
    /// `d = Jᵀ n⁺`.
    d: DVector<f64>,
    /// Primal step direction `z`.
    z: DVector<f64>,
    /// Dual step direction `r`.
    r: DVector<f64>,
    /// Multipliers of the active set, in its order (sign convention of the signed normals).
    u: DVector<f64>,
    /// Active constraints, in the order of the columns of `R`.
    active: Buffer<Entry>,
    /// `A_in x`.
    ax: DVector<f64>,
    /// `ax` holds `A_in x` at the current `x` (no primal step since it was computed).
    ax_current: bool,
    /// `H x` (objective evaluation).
    hx: DVector<f64>,
    states: Vec<RowState>,
    y_eq: DVector<f64>,
    y_in: DVector<f64>,
    active_out: Buffer<ActiveConstraint>,
}

impl QpWorkspace {
    /// A workspace for problems with at most `max_vars` variables, `max_eq` rows of `A_eq` and
    /// `max_ineq` rows of `A_in`.
    pub fn new(max_vars: usize, max_eq: usize, max_ineq: usize) -> Self {
        Self {
            capacity: Dims {
                n: max_vars,
                m_eq: max_eq,
                m_in: max_ineq,
            },
            last: Dims {
                n: 0,
                m_eq: 0,
                m_in: 0,
            },
            chol: DMatrix::zeros(max_vars, max_vars),
            basis: ActiveBasis::new(max_vars),
            normal: DVector::zeros(max_vars),
            d: DVector::zeros(max_vars),
            z: DVector::zeros(max_vars),
            r: DVector::zeros(max_vars),
            u: DVector::zeros(max_vars),
            active: Buffer::with_capacity(max_vars),
            ax: DVector::zeros(max_ineq),
            ax_current: false,
            hx: DVector::zeros(max_vars),
            states: vec![RowState::Inactive; max_ineq],
            y_eq: DVector::zeros(max_eq),
            y_in: DVector::zeros(max_ineq),
            active_out: Buffer::with_capacity(max_vars),
        }
    }

    /// The capacity `(max_vars, max_eq, max_ineq)` the workspace was sized for.
    pub fn capacity(&self) -> (usize, usize, usize) {
        (self.capacity.n, self.capacity.m_eq, self.capacity.m_in)
    }

    /// The active set of the last solve with the multipliers (see [`ActiveConstraint`] for the
    /// sign convention), in the order the constraints entered.
    pub fn active_set(&self) -> &[ActiveConstraint] {
        &self.active_out
    }

    /// Multipliers `y_eq` of the rows of `A_eq` after the last solve (length `m_eq`; zero for a
    /// redundant row) [objective units per row unit].
    pub fn multipliers_eq(&self) -> &[f64] {
        &self.y_eq.as_slice()[..self.last.m_eq]
    }

    /// Multipliers `y_in` of the rows of `A_in` after the last solve (length `m_in`): `≥ 0` at
    /// an active lower end, `≤ 0` at an active upper end, zero if inactive, so that
    /// `H x + c = A_eqᵀ y_eq + A_inᵀ y_in` at the optimum [objective units per row unit].
    pub fn multipliers_in(&self) -> &[f64] {
        &self.y_in.as_slice()[..self.last.m_in]
    }

    /// Solves `min ½ xᵀ H x + cᵀ x  s.t.  A_eq x = b_eq,  l ≤ A_in x ≤ u` by the dual
    /// active-set method of Goldfarb & Idnani (1983) described in the [module
    /// documentation](super).
    ///
    /// `x` must have length `n`; its content on entry is ignored (the method starts from the
    /// unconstrained minimum) and on return it holds the solution, or the last iterate if the
    /// status is not [`QpStatus::Optimal`].
    ///
    /// # Errors
    ///
    /// Invalid settings; sizes that do not match each other or exceed the workspace; a NaN or
    /// infinite entry in `H`, `c`, `A_eq`, `b_eq`, `A_in`; a NaN limit, `l_i > u_i`, `l_i = +∞`
    /// or `u_i = −∞`; an `H` that is not symmetric or not positive definite (see
    /// [`QpSettings`]); finite data so large that the iteration overflows. An infeasible
    /// problem is not an error: it is [`QpStatus::Infeasible`].
    pub fn solve(
        &mut self,
        problem: &QpProblem<'_>,
        settings: &QpSettings,
        x: &mut DVector<f64>,
    ) -> Result<QpReport> {
        self.solve_into(problem, settings, x.as_mut_slice())
    }

    /// [`QpWorkspace::solve`] into a slice of length `n`.
    pub fn solve_into(
        &mut self,
        problem: &QpProblem<'_>,
        settings: &QpSettings,
        x: &mut [f64],
    ) -> Result<QpReport> {
        settings.validate()?;
        let dims = problem.check(self.capacity, settings)?;
        check_dim("length of x", dims.n, x.len())?;
        let n = dims.n;
        self.ax_current = false;
        // forget the previous solve first, so that a failed factorisation leaves an empty
        // active set and zero multipliers behind
        self.last = dims;
        self.active.clear();
        self.fill_multipliers();
        match problem.hessian {
            Hessian::Identity => self.basis.reset_identity(n),
            Hessian::Dense(h) => {
                cholesky(
                    &h,
                    self.chol.as_mut_slice(),
                    self.capacity.n,
                    settings.hessian_pivot_tolerance,
                )?;
                self.basis.reset_from_factor(self.chol.as_slice(), n);
            }
        }
        // Unconstrained minimum x₀ = −H⁻¹ c = −J Jᵀ c (J = L⁻ᵀ while nothing is active).
        self.basis.project(problem.c, self.d.as_mut_slice());
        self.basis.primal_direction(self.d.as_slice(), x);
        for v in x.iter_mut() {
            *v = -*v;
        }
        for (state, (&l, &u)) in self.states[..dims.m_in]
            .iter_mut()
            .zip(problem.lower.iter().zip(problem.upper))
        {
            *state = if l == u {
                RowState::Fixed
            } else {
                RowState::Inactive
            };
        }

        let mut iterations = 0;
        let mut redundant = 0;
        let mut outcome =
            self.add_equalities(problem, settings, x, &mut iterations, &mut redundant);
        if outcome.is_none() {
            outcome = Some(self.add_inequalities(problem, settings, x, &mut iterations));
        }
        let mut status = match outcome.unwrap_or(Outcome::Optimal) {
            Outcome::Optimal => QpStatus::Optimal,
            Outcome::Infeasible(constraint) => QpStatus::Infeasible { constraint },
            Outcome::MaxIterations => QpStatus::MaxIterations,
        };
        self.fill_multipliers();
        let objective = self.objective(problem, x);
        if !objective.is_finite() {
            // finite data whose products overflow (entries near 1e154 and beyond)
            return Err(Error::NonFinite {
                what: "QP objective at the last iterate (the iteration overflowed: rescale H, c \
                       and the constraint rows)"
                    .to_string(),
                value: objective,
            });
        }
        let max_violation = self.max_violation(problem, x);
        if status == QpStatus::Optimal
            && max_violation > INACCURATE_FACTOR * settings.feasibility_tolerance
        {
            status = QpStatus::Inaccurate { max_violation };
        }
        Ok(QpReport {
            status,
            iterations,
            objective,
            active_count: self.active.len(),
            redundant_equalities: redundant,
            max_violation,
        })
    }

    /// Loads the signed normal `n⁺ = sign · a_row` into `self.normal` and returns its bound
    /// `b⁺` (the constraint is `n⁺ᵀ x ≥ b⁺`, or `= b⁺` for an equality).
    fn load_normal(&mut self, problem: &QpProblem<'_>, row: Row, sign: f64) -> f64 {
        let (a, bound) = match row {
            Row::Eq(i) => (problem.a_eq.row(i), problem.b_eq[i]),
            Row::In(i) => (
                problem.a_in.row(i),
                if sign > 0.0 {
                    problem.lower[i]
                } else {
                    problem.upper[i]
                },
            ),
        };
        for (dst, &src) in self.normal.iter_mut().zip(a.iter()) {
            *dst = sign * src;
        }
        sign * bound
    }

    /// Computes `d = Jᵀ n⁺`, `z = J₂ d₂`, `r = R⁻¹ d₁`; returns `(‖d‖, ‖d₂‖)`.
    fn directions(&mut self) -> (f64, f64) {
        let n = self.last.n;
        self.basis
            .project(self.normal.as_slice(), self.d.as_mut_slice());
        self.basis
            .primal_direction(self.d.as_slice(), self.z.as_mut_slice());
        self.basis
            .dual_direction(self.d.as_slice(), self.r.as_mut_slice());
        let d = &self.d.as_slice()[..n];
        (norm(d), self.basis.orthogonal_norm(d))
    }

    /// Takes the step `x ← x + t z`, `u ← u − t r` (the active multipliers).
    fn step(&mut self, x: &mut [f64], t: f64, primal: bool) {
        let q = self.basis.active();
        if primal {
            axpy(t, &self.z.as_slice()[..x.len()], x);
            self.ax_current = false;
        }
        axpy(-t, &self.r.as_slice()[..q], &mut self.u.as_mut_slice()[..q]);
    }

    /// Appends the constraint whose `d` is current to the active set with multiplier `u⁺`.
    fn push_active(&mut self, entry: Entry, multiplier: f64) {
        let q = self.basis.active();
        self.basis.add(self.d.as_mut_slice());
        self.u[q] = multiplier;
        self.active.push(entry);
    }

    /// Removes the active constraint at position `k`.
    fn drop_active(&mut self, k: usize) {
        let q = self.basis.active();
        self.basis.remove(k);
        self.u.as_mut_slice().copy_within(k + 1..q, k);
        let entry = self.active.remove(k);
        if let Row::In(i) = entry.row {
            if let Some(state) = self.states.get_mut(i) {
                *state = RowState::Inactive;
            }
        }
    }

    /// The smallest ratio `u_k / r_k` over droppable active constraints with
    /// `r_k ‖L⁻¹ n_k‖ > tol ‖L⁻¹ n⁺‖`, and its position: the partial (dual) step `t₁`.
    fn blocking(&self, metric_norm: f64, settings: &QpSettings) -> Option<(usize, f64)> {
        let threshold = settings.linear_dependence_tolerance * metric_norm;
        let mut best: Option<(usize, f64)> = None;
        for (k, entry) in self.active.iter().enumerate() {
            let rk = self.r[k];
            if entry.droppable(&self.states) && rk * entry.metric_norm > threshold {
                let ratio = (self.u[k] / rk).max(0.0);
                if best.is_none_or(|(_, t)| ratio < t) {
                    best = Some((k, ratio));
                }
            }
        }
        best
    }

    /// Phase 1: adds every equality (rows of `A_eq`, then rows of `A_in` with `l = u`) with a
    /// full step `t = −s / ‖d₂‖²`, the normal's sign chosen so that `s = n⁺ᵀx − b⁺ ≤ 0`; skips
    /// a dependent row that holds (redundant) and stops at a dependent row that does not
    /// (infeasible). `None` when all are in.
    fn add_equalities(
        &mut self,
        problem: &QpProblem<'_>,
        settings: &QpSettings,
        x: &mut [f64],
        iterations: &mut usize,
        redundant: &mut usize,
    ) -> Option<Outcome> {
        let Dims { n, m_eq, m_in } = self.last;
        for idx in 0..m_eq + m_in {
            let row = if idx < m_eq {
                Row::Eq(idx)
            } else if self.states[idx - m_eq] == RowState::Fixed {
                Row::In(idx - m_eq)
            } else {
                continue;
            };
            if *iterations >= settings.max_iterations {
                return Some(Outcome::MaxIterations);
            }
            let mut sign = 1.0;
            let bound = self.load_normal(problem, row, sign);
            let mut s = dot(&self.normal.as_slice()[..n], x) - bound;
            if s > 0.0 {
                sign = -1.0;
                for v in &mut self.normal.as_mut_slice()[..n] {
                    *v = -*v;
                }
                s = -s;
            }
            let (metric_norm, orthogonal) = self.directions();
            let entry = Entry {
                row,
                sign,
                metric_norm,
            };
            if is_dependent(orthogonal, metric_norm, settings) {
                if -s <= settings.feasibility_tolerance {
                    *redundant += 1;
                    continue;
                }
                return Some(Outcome::Infeasible(entry.constraint(sign, true)));
            }
            *iterations += 1;
            let t = -s / orthogonal / orthogonal;
            self.step(x, t, true);
            self.push_active(entry, t);
        }
        None
    }

    /// Phase 2: repeatedly picks the most violated inequality side `p` and adds it, releasing
    /// active inequalities whose multiplier would turn negative (partial steps), until nothing
    /// is violated (optimal) or `p` can be added by no step (infeasible).
    fn add_inequalities(
        &mut self,
        problem: &QpProblem<'_>,
        settings: &QpSettings,
        x: &mut [f64],
        iterations: &mut usize,
    ) -> Outcome {
        let n = self.last.n;
        loop {
            let Some((p, sign)) = self.most_violated(problem, settings, x) else {
                return Outcome::Optimal;
            };
            let bound = self.load_normal(problem, Row::In(p), sign);
            let mut u_plus = 0.0;
            loop {
                if *iterations >= settings.max_iterations {
                    return Outcome::MaxIterations;
                }
                let (metric_norm, orthogonal) = self.directions();
                let entry = Entry {
                    row: Row::In(p),
                    sign,
                    metric_norm,
                };
                let blocking = self.blocking(metric_norm, settings);
                let dependent = is_dependent(orthogonal, metric_norm, settings);
                let full_step = if dependent {
                    f64::INFINITY
                } else {
                    let s = dot(&self.normal.as_slice()[..n], x) - bound;
                    (-s).max(0.0) / orthogonal / orthogonal
                };
                match blocking {
                    None if dependent => {
                        return Outcome::Infeasible(entry.constraint(sign, false));
                    }
                    // a dependent normal is never added: only the dual step is possible
                    Some((k, partial_step)) if dependent || partial_step < full_step => {
                        *iterations += 1;
                        self.step(x, partial_step, !dependent);
                        u_plus += partial_step;
                        self.drop_active(k);
                    }
                    _ => {
                        *iterations += 1;
                        self.step(x, full_step, true);
                        u_plus += full_step;
                        self.push_active(entry, u_plus);
                        self.states[p] = RowState::Active;
                        break;
                    }
                }
            }
        }
    }

    /// `ax ← A_in x`, unless it is current (the optimality check and the final violation
    /// share one product).
    fn compute_ax(&mut self, problem: &QpProblem<'_>, x: &[f64]) {
        if self.ax_current {
            return;
        }
        self.ax_current = true;
        let Dims { n, m_in, .. } = self.last;
        let ax = &mut self.ax.as_mut_slice()[..m_in];
        ax.fill(0.0);
        if m_in == 0 {
            return;
        }
        for (j, &xj) in x.iter().enumerate().take(n) {
            if xj != 0.0 {
                axpy(xj, problem.a_in.column(j).as_slice(), ax);
            }
        }
    }

    /// The inactive inequality side with the largest violation above the feasibility
    /// tolerance: `(row, +1)` for `l − aᵀx`, `(row, −1)` for `aᵀx − u`.
    fn most_violated(
        &mut self,
        problem: &QpProblem<'_>,
        settings: &QpSettings,
        x: &[f64],
    ) -> Option<(usize, f64)> {
        self.compute_ax(problem, x);
        let mut worst = settings.feasibility_tolerance;
        let mut pick = None;
        let rows = self.states.iter().zip(self.ax.iter());
        for (i, ((state, &ax), (&l, &u))) in rows
            .zip(problem.lower.iter().zip(problem.upper))
            .enumerate()
        {
            if *state != RowState::Inactive {
                continue;
            }
            if l - ax > worst {
                worst = l - ax;
                pick = Some((i, 1.0));
            }
            if ax - u > worst {
                worst = ax - u;
                pick = Some((i, -1.0));
            }
        }
        pick
    }

    /// Writes `y_eq`, `y_in` and the public active set from the internal one.
    fn fill_multipliers(&mut self) {
        let Dims { m_eq, m_in, .. } = self.last;
        self.y_eq.as_mut_slice()[..m_eq].fill(0.0);
        self.y_in.as_mut_slice()[..m_in].fill(0.0);
        self.active_out.clear();
        for (entry, &u) in self.active.iter().zip(self.u.iter()) {
            let y = entry.sign * u;
            let fixed = match entry.row {
                Row::Eq(i) => {
                    self.y_eq[i] = y;
                    true
                }
                Row::In(i) => {
                    self.y_in[i] = y;
                    self.states.get(i) == Some(&RowState::Fixed)
                }
            };
            self.active_out.push(ActiveConstraint {
                constraint: entry.constraint(y, fixed),
                multiplier: y,
            });
        }
    }

    /// `½ xᵀ H x + cᵀ x`.
    fn objective(&mut self, problem: &QpProblem<'_>, x: &[f64]) -> f64 {
        let linear = dot(problem.c, x);
        let quadratic = match &problem.hessian {
            Hessian::Identity => dot(x, x),
            Hessian::Dense(h) => {
                let hx = &mut self.hx.as_mut_slice()[..x.len()];
                hx.fill(0.0);
                for (j, &xj) in x.iter().enumerate() {
                    axpy(xj, h.column(j).as_slice(), hx);
                }
                dot(hx, x)
            }
        };
        0.5 * quadratic + linear
    }

    /// Largest violation of any row at `x` (zero if all hold).
    fn max_violation(&mut self, problem: &QpProblem<'_>, x: &[f64]) -> f64 {
        let mut worst = 0.0_f64;
        for (i, &b) in problem.b_eq.iter().enumerate() {
            let ax: f64 = problem.a_eq.row(i).iter().zip(x).map(|(a, v)| a * v).sum();
            worst = worst.max((ax - b).abs());
        }
        self.compute_ax(problem, x);
        for ((&ax, &l), &u) in self.ax.iter().zip(problem.lower).zip(problem.upper) {
            worst = worst.max(l - ax).max(ax - u);
        }
        worst
    }
}

/// `‖d₂‖ ≤ ε_dep ‖d‖`: the new normal depends linearly on the active ones. A NaN (overflow)
/// counts as dependent, so that nothing is added to a full basis.
fn is_dependent(orthogonal: f64, metric_norm: f64, settings: &QpSettings) -> bool {
    let bound = settings.linear_dependence_tolerance * metric_norm;
    !matches!(
        orthogonal.partial_cmp(&bound),
        Some(std::cmp::Ordering::Greater)
    )
}
