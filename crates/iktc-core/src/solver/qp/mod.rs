//! A dense dual active-set QP solver for the small problems of the control tick.
//!
//! Solves
//!
//! ```text
//! minimise ½ xᵀ H x + cᵀ x   subject to   A_eq x = b_eq,   l ≤ A_in x ≤ u,
//! ```
//!
//! with `H` symmetric positive definite (or `H = I`, [`Hessian::Identity`]) and ends of the
//! two-sided rows possibly infinite, by the dual method of Goldfarb & Idnani, *A numerically
//! stable dual method for solving strictly convex quadratic programs*, Mathematical Programming
//! 27 (1983) 1–33. The sizes in mind are tens of variables and rows: IKTC's correction QP
//! (paper eq. 23, `min ½‖Δh_i^a‖²  s.t.  b_l − q̈_{n_T} ≤ g_i^a Δh_i^a ≤ b_u − q̈_{n_T}`, with
//! [`Hessian::Identity`]) and one level of the GF cascade. Because the method detects an empty
//! constraint set by itself ([`QpStatus::Infeasible`]), it also replaces the simplex feasibility
//! test of the paper's Algorithm 2 (errata §3.3).
//!
//! # Method
//!
//! Each side of a row is written as `n⁺ᵀ x ≥ b⁺` (lower end: `n⁺ = a`, `b⁺ = l`; upper end:
//! `n⁺ = −a`, `b⁺ = −u`); a two-sided row is *one* constraint of which at most one side is
//! active. The method keeps a set `A` of active constraints with normals `N` (`n × q`) and
//! multipliers `u_A`, and the iterate `x` that minimises the objective subject to
//! `Nᵀ x = b_A`: it is dual feasible throughout (`u ≥ 0` on active inequalities) and works
//! towards primal feasibility, so it needs no feasible starting point.
//!
//! **Factorisation.** `H = L Lᵀ` (Cholesky, once per solve; skipped for `H = I`). With the QR
//! factorisation `L⁻¹ N = Q [R; 0]` the solver keeps
//!
//! ```text
//! J = L⁻ᵀ Q = [J₁ J₂],   Jᵀ N = [R; 0],   R upper triangular q × q.
//! ```
//!
//! For a normal `n⁺`, let `d = Jᵀ n⁺ = [d₁; d₂]`. Then
//!
//! ```text
//! z = J₂ d₂          primal step direction   (z = H⁻¹ n⁺ projected so that Nᵀ z = 0)
//! r = R⁻¹ d₁         dual step direction     (N r = n⁺ − H z)
//! ```
//!
//! **Steps.** `ε_feas` is [`QpSettings::feasibility_tolerance`], `ε_dep`
//! [`QpSettings::linear_dependence_tolerance`].
//!
//! 0. `x ← −H⁻¹ c = −J Jᵀ c` (unconstrained minimum, `J = L⁻ᵀ`), `A ← ∅`.
//! 1. Equalities (rows of `A_eq`, and rows of `A_in` with `l = u`), in order: orient the normal
//!    so that `s = n⁺ᵀx − b⁺ ≤ 0`; if `‖d₂‖ ≤ ε_dep ‖d‖` the row depends on the active ones: it is
//!    redundant if `|s| ≤ ε_feas`, else the problem is infeasible; otherwise step
//!    `t = −s / ‖d₂‖²`: `x ← x + t z`, `u_A ← u_A − t r`, add the row with `u⁺ = t`.
//!    Equalities are never dropped.
//! 2. Pick the inactive inequality side `p` with the largest violation `−s_p = b⁺ − n⁺ᵀx`
//!    above `ε_feas`. If none: **optimal**. Set `u⁺ = 0`.
//! 3. Compute `z`, `r` for `n⁺ = n_p`.
//!    * Partial (dual) step: `t₁ = min { u_k / r_k : k active inequality, r_k > 0 }` (an `r_k`
//!      counts as positive when `r_k ‖L⁻¹ n_k‖ > ε_dep ‖L⁻¹ n⁺‖`), `t₁ = ∞` if there is none.
//!    * Full (primal) step: `t₂ = −s_p / (zᵀ n⁺) = −s_p / ‖d₂‖²`, or `t₂ = ∞` if
//!      `‖d₂‖ ≤ ε_dep ‖d‖` (`n⁺` depends linearly on the active normals).
//! 4. If `t₁ = t₂ = ∞`: **infeasible** — `p` is violated, no primal step can reduce its
//!    violation and no active inequality can be released; by Farkas' lemma the constraints
//!    `A ∪ {p}` have no common point. The status names `p`.
//! 5. `t = min(t₁, t₂)`; `x ← x + t z` (only if `t₂ < ∞`), `u_A ← u_A − t r`, `u⁺ ← u⁺ + t`.
//!    If `t = t₂`, add `p` to `A` with multiplier `u⁺` and go to 2; otherwise drop the
//!    blocking constraint `k` (its multiplier reached zero) and go to 3.
//!
//! The dual objective grows strictly at every non-degenerate step, so no active set repeats and
//! the method ends after finitely many steps; [`QpSettings::max_iterations`] bounds degenerate
//! cases.
//!
//! **Updates.** Adding `n⁺`: one Householder reflection of columns `q, …, n−1` of `J` maps
//! `d₂` to `(‖d₂‖, 0, …, 0)` (plane rotations of adjacent columns when the data are near
//! under- or overflow); `R` gains the column `(d₀, …, d_q)`. Dropping
//! the `k`-th active normal: delete column `k` of `R`, then rotations of rows `(i, i+1)` of `R`
//! and columns `(i, i+1)` of `J`, `i = k, …, q−2`, restore the triangle. Each update is
//! `O(n²)`; nothing is refactorised during the iteration.
//!
//! **Multipliers.** On return `H x + c = A_eqᵀ y_eq + A_inᵀ y_in` with `y_in,i ≥ 0` at an
//! active lower end, `≤ 0` at an active upper end and `0` at an inactive row.
//!
//! # Allocation
//!
//! [`QpWorkspace::new`] sizes every buffer; [`QpWorkspace::solve`] allocates nothing (except
//! when it returns an error).
//!
//! # Example
//!
//! ```
//! use iktc_core::solver::{Hessian, QpProblem, QpSettings, QpStatus, QpWorkspace};
//! use nalgebra::{DMatrix, DVector};
//!
//! // min ½‖x‖² − x₀ − x₁  s.t.  x₀ + x₁ ≤ 1  →  x = (½, ½)
//! let a_in = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
//! let a_eq = DMatrix::<f64>::zeros(0, 2);
//! let problem = QpProblem {
//!     hessian: Hessian::Identity,
//!     c: &[-1.0, -1.0],
//!     a_eq: a_eq.as_view(),
//!     b_eq: &[],
//!     a_in: a_in.as_view(),
//!     lower: &[f64::NEG_INFINITY],
//!     upper: &[1.0],
//! };
//! let mut workspace = QpWorkspace::new(2, 0, 1);
//! let mut x = DVector::zeros(2);
//! let report = workspace.solve(&problem, &QpSettings::default(), &mut x)?;
//! assert_eq!(report.status, QpStatus::Optimal);
//! assert!((x[0] - 0.5).abs() < 1e-12 && (x[1] - 0.5).abs() < 1e-12);
//! assert!((workspace.multipliers_in()[0] + 0.5).abs() < 1e-12); // upper end: y ≤ 0
//! # Ok::<(), iktc_core::Error>(())
//! ```

mod basis;
mod factor;
mod problem;
mod report;
mod settings;
mod workspace;

pub use problem::{Hessian, QpProblem};
pub use report::{ActiveConstraint, QpConstraint, QpReport, QpStatus};
pub use settings::QpSettings;
pub use workspace::QpWorkspace;
pub(crate) use workspace::INACCURATE_FACTOR;
