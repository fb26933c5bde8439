//! The solvers: prioritized, IKTC (Section 3.2), cascade (GF) and clamp, behind one workspace.

use nalgebra::{DMatrix, DVector};

use super::continuity::LevelHold;
use super::hierarchy::Hierarchy;
use super::qp::INACCURATE_FACTOR;
use super::qp::{Hessian, QpProblem, QpStatus, QpWorkspace};
use super::rebase::Rebase;
use super::report::{Fallback, Method, SolveReport};
use super::screen::Screen;
use super::settings::{Climb, SolverSettings};
use super::warm::WarmStart;
use crate::error::{check_dim, Result};
use crate::limits::AccelerationBox;
use crate::task::TaskEquation;

/// Solves a task hierarchy under an acceleration box. Made once for given level sizes; each
/// [`Solver::solve`] allocates nothing.
///
/// The solver remembers, from one solve to the next, the level IKTC last corrected from, the
/// rows of each level's last infeasible QP and the rows active at each level's last optimum
/// ([`Climb`], [`SolverSettings::screen`], [`SolverSettings::warm_start`]). That history
/// changes how many QPs and QP iterations a solve runs, never its result (up to rounding and
/// the QP's feasibility tolerance).
#[derive(Debug, Clone)]
pub struct Solver {
    settings: SolverSettings,
    hierarchy: Hierarchy,
    qp: QpWorkspace,
    report: SolveReport,
    q0: DVector<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    qp_lo: Vec<f64>,
    qp_hi: Vec<f64>,
    zeros: Vec<f64>,
    /// QP solution buffers: one per IKTC level (size Σ_{k≥i} m_k), then one of size n.
    xs: Vec<DVector<f64>>,
    /// The level the last IKTC correction started from ([`Climb::FromLast`]).
    last_from: Option<usize>,
    /// The infeasibility certificate tried before each correction QP.
    screen: Screen,
    /// The hold on the corrected level ([`SolverSettings::level_hold`]).
    hold: LevelHold,
    /// The re-based demands ([`SolverSettings::rebase_release`]).
    rebase: Rebase,
    /// The active sets of the last optima, tried before each correction QP.
    warm: WarmStart,
    /// The previous solve's q̈ \[rad/s²\] ([`SolverSettings::continuity`]; zero before the first).
    previous: DVector<f64>,
    /// q̈₀ − q̈₋ of the current solve \[rad/s²\].
    step_change: Vec<f64>,
    /// The continuity QP's Hessian `I + μ GᵀG` (top-left block used) and linear term.
    continuity_h: DMatrix<f64>,
    continuity_c: Vec<f64>,
    // Cascade buffers.
    h: DMatrix<f64>,
    c: Vec<f64>,
    a_eq: DMatrix<f64>,
    b_eq: Vec<f64>,
    eye: DMatrix<f64>,
}

impl Solver {
    /// A solver for `nv` velocity coordinates and levels of sizes `dims` (priority order).
    pub fn new(nv: usize, dims: &[usize], settings: SolverSettings) -> Result<Self> {
        settings.validate()?;
        let total: usize = dims.iter().sum();
        Ok(Self {
            settings,
            hierarchy: Hierarchy::new(nv, dims),
            qp: QpWorkspace::new(total.max(nv), total, nv),
            report: SolveReport::new(dims),
            q0: DVector::zeros(nv),
            lo: vec![0.0; nv],
            hi: vec![0.0; nv],
            qp_lo: vec![0.0; nv],
            qp_hi: vec![0.0; nv],
            zeros: vec![0.0; total.max(nv)],
            xs: {
                let mut v: Vec<DVector<f64>> = (0..dims.len())
                    .map(|i| DVector::zeros(dims[i..].iter().sum()))
                    .collect();
                v.push(DVector::zeros(nv));
                v
            },
            last_from: None,
            screen: Screen::new(dims.len(), total),
            hold: LevelHold::default(),
            rebase: Rebase::new(nv, dims),
            warm: WarmStart::new(dims.len(), total, nv),
            previous: DVector::zeros(nv),
            step_change: vec![0.0; nv],
            continuity_h: DMatrix::zeros(total, total),
            continuity_c: vec![0.0; total],
            h: DMatrix::zeros(nv, nv),
            c: vec![0.0; nv],
            a_eq: DMatrix::zeros(total.max(1), nv),
            b_eq: vec![0.0; total.max(1)],
            eye: DMatrix::identity(nv, nv),
        })
    }

    /// The settings.
    pub fn settings(&self) -> &SolverSettings {
        &self.settings
    }

    /// The report of the last solve.
    pub fn report(&self) -> &SolveReport {
        &self.report
    }

    /// Solves `levels` (priority order) under `bounds` with `method`, writing q̈ into `qdd`.
    ///
    /// Bad input (sizes, NaN) is an error; a hard problem (an empty box, an infeasible
    /// correction) is reported in [`Solver::report`] with the fallback taken.
    pub fn solve(
        &mut self,
        method: Method,
        levels: &[TaskEquation],
        bounds: &AccelerationBox,
        qdd: &mut DVector<f64>,
    ) -> Result<&SolveReport> {
        let n = self.hierarchy.n();
        check_dim("q̈", n, qdd.len())?;
        check_dim("acceleration box", n, bounds.nv())?;
        for l in levels {
            l.validate()?;
        }
        self.report.reset(method);
        // Errata 3.3: IKTC solves the levels re-based on what was achieved (`rebase` module).
        let rebase = method == Method::Iktc && self.settings.rebase_release < 1.0;
        let mut rebased = Vec::new();
        if rebase {
            self.rebase.apply(levels);
            rebased = std::mem::take(&mut self.rebase.levels);
        }
        let solved = self.solve_levels(method, if rebase { &rebased } else { levels }, bounds, qdd);
        if rebase {
            self.rebase.levels = rebased;
            if solved.is_ok() {
                self.rebase
                    .update(&self.report.corrections, self.settings.rebase_release);
            }
        }
        solved?;
        self.report.violation = self.violation(qdd);
        // The box is the promise: a q̈ of IKTC or GF outside it by more than rounding (a QP
        // that lost its accuracy) is clamped into it and reported, never returned silently.
        // Outside by more than the box tolerance but within rounding of a large correction
        // (the QP's rows carry ≈ 1e-16 of the prioritized solution's size, which reaches
        // 1e7 rad/s² near a singularity: a few 1e-8 rad/s² left outside), it is clamped too,
        // without a fallback: the limits hold exactly.
        let limit = INACCURATE_FACTOR * self.settings.box_tolerance;
        if matches!(method, Method::Iktc | Method::Cascade)
            && self.report.violation > self.settings.box_tolerance
        {
            self.clamp_into_box(qdd);
            if self.report.violation > limit {
                self.report.fallback = Some(Fallback::ClampedToBox);
            }
            self.report.violation = self.violation(qdd);
        }
        for (i, l) in levels.iter().enumerate() {
            // e = J q̈ − h, by columns of J (contiguous).
            let e = &mut self.report.task_errors[i];
            let m = l.dim();
            let es = e.as_mut_slice();
            for (x, h) in es.iter_mut().zip(l.rhs.iter()) {
                *x = -h;
            }
            let js = l.jacobian.as_slice();
            for c in 0..n {
                let qc = qdd[c];
                if qc != 0.0 {
                    for (x, j) in es.iter_mut().zip(&js[c * m..(c + 1) * m]) {
                        *x += j * qc;
                    }
                }
            }
            self.report.task_error_norms[i] = e.norm();
        }
        self.previous.copy_from(qdd);
        Ok(&self.report)
    }

    /// The prioritized solution of `levels`, the box, and the method's q̈ (the body of
    /// [`Solver::solve`] between the checks and the task errors).
    fn solve_levels(
        &mut self,
        method: Method,
        levels: &[TaskEquation],
        bounds: &AccelerationBox,
        qdd: &mut DVector<f64>,
    ) -> Result<()> {
        let n = self.hierarchy.n();
        self.hierarchy.solve(levels, &self.settings, &mut self.q0)?;
        self.report.ranks.copy_from_slice(self.hierarchy.ranks());
        // The box, with empty dofs relaxed to their midpoint (the least possible violation).
        let mut empty = 0;
        for d in 0..n {
            let (l, u) = (bounds.lower[d], bounds.upper[d]);
            if l.is_nan() || u.is_nan() {
                return Err(crate::Error::NonFinite {
                    what: format!("acceleration box of dof {d}"),
                    value: f64::NAN,
                });
            }
            if l > u {
                empty += 1;
                let mid = 0.5 * (l + u);
                self.lo[d] = mid;
                self.hi[d] = mid;
            } else {
                self.lo[d] = l;
                self.hi[d] = u;
            }
        }
        self.report.empty_box_dofs = empty;
        if empty > 0 {
            self.report.fallback = Some(Fallback::EmptyBox);
        }
        self.report.violation_before = self.violation(&self.q0);
        match method {
            Method::Prioritized => qdd.copy_from(&self.q0),
            Method::Clamp => self.clamp(qdd),
            Method::Iktc => self.iktc(levels, qdd)?,
            Method::Cascade => self.cascade(levels, qdd)?,
        }
        Ok(())
    }

    fn violation(&self, q: &DVector<f64>) -> f64 {
        let mut v: f64 = 0.0;
        for d in 0..q.len() {
            v = v.max(self.lo[d] - q[d]).max(q[d] - self.hi[d]);
        }
        v
    }

    /// Clamps `qdd` itself (not the prioritized solution) into the box.
    fn clamp_into_box(&self, qdd: &mut DVector<f64>) {
        for d in 0..qdd.len() {
            qdd[d] = qdd[d].clamp(self.lo[d], self.hi[d]);
        }
    }

    fn clamp(&self, qdd: &mut DVector<f64>) {
        for d in 0..qdd.len() {
            qdd[d] = self.q0[d].clamp(self.lo[d], self.hi[d]);
        }
    }

    /// IKTC (Algorithms 1–2, eqs. 23–25): if the prioritized q̈ leaves the box, find the least
    /// correction of levels i..n_T, min ½‖Δh^a_i‖² s.t. b_l − q̈ ≤ g^a_i Δh^a_i ≤ b_u − q̈, for
    /// the largest i for which the QP is feasible; q̈* = q̈ + g^a_i Δh^a_i. The search starts at
    /// the bottom or where the last correction started ([`Climb`]); feasibility is monotone in
    /// i, so both find the same level.
    fn iktc(&mut self, levels: &[TaskEquation], qdd: &mut DVector<f64>) -> Result<()> {
        qdd.copy_from(&self.q0);
        if self.report.violation_before <= self.settings.box_tolerance {
            self.hold.idle(self.settings.level_hold);
            return Ok(());
        }
        let n = self.hierarchy.n();
        let nt = levels.len();
        if nt == 0 {
            self.report.fallback = Some(Fallback::ClampedToBox);
            self.clamp(qdd);
            return Ok(());
        }
        for d in 0..n {
            self.qp_lo[d] = self.lo[d] - self.q0[d];
            self.qp_hi[d] = self.hi[d] - self.q0[d];
            self.step_change[d] = self.q0[d] - self.previous[d];
        }
        let start = match self.settings.climb {
            Climb::FromBottom => nt - 1,
            Climb::FromLast => self.last_from.unwrap_or(nt - 1).min(nt - 1),
        };
        // G blocks of levels start..n_T (Algorithm 1 builds them bottom-up; each is independent),
        // in the coordinates of the corrections that move q̈ (`Hierarchy::build_correction_map`).
        let _ = self.hierarchy.build_correction_map(levels, start, nt);
        let mut found = None;
        if self.level_feasible(start)? {
            // Down the priorities while still feasible.
            found = Some(start);
            for i in start + 1..nt {
                if !self.level_feasible(i)? {
                    break;
                }
                found = Some(i);
            }
        } else {
            // Up the priorities until feasible.
            for i in (0..start).rev() {
                let _ = self.hierarchy.build_correction_map(levels, i, i + 1);
                if self.level_feasible(i)? {
                    found = Some(i);
                    break;
                }
            }
        }
        let Some(i) = found else {
            self.hold.idle(self.settings.level_hold);
            self.last_from = Some(0);
            self.report.fallback = Some(Fallback::ClampedToBox);
            self.clamp(qdd);
            return Ok(());
        };
        self.report.feasible_from = Some(i);
        let i = self.held_level(levels, i)?;
        self.last_from = Some(i);
        self.report.corrected_from = Some(i);
        let h = &self.hierarchy;
        let off = h.correction_offset(i);
        let total = h.correction_offset(nt);
        let g = h.correction_map();
        let x = &self.xs[i];
        for c in 0..total - off {
            let dh = x[c];
            if dh != 0.0 {
                for d in 0..n {
                    qdd[d] += g[(d, off + c)] * dh;
                }
            }
        }
        // Δh of each corrected level from its coordinates in the map.
        let (h, x) = (&mut self.hierarchy, &self.xs[i]);
        let mut c = 0;
        for (k, corr) in self.report.corrections.iter_mut().enumerate().skip(i) {
            let w = h.correction_width(k);
            h.correction_demand(k, &x.as_slice()[c..c + w], corr.as_mut_slice());
            c += w;
        }
        Ok(())
    }

    /// The level to correct from, given Algorithm 2's `found` (see the `continuity` module):
    /// the held level when the hold keeps it, its QP solved into `xs` if the climb did not;
    /// `found` if that QP fails (it cannot, feasibility being monotone, but for rounding).
    fn held_level(&mut self, levels: &[TaskEquation], found: usize) -> Result<usize> {
        let chosen = self.hold.choose(found, self.settings.level_hold);
        if chosen == found {
            return Ok(found);
        }
        let solved = match self.settings.climb {
            // The climb started at the last level (= the held one) and went down from it.
            Climb::FromLast if self.last_from == Some(chosen) => true,
            _ => {
                let _ = self.hierarchy.build_correction_map(levels, chosen, found);
                self.level_feasible(chosen)?
            }
        };
        Ok(if solved { chosen } else { found })
    }

    /// Solves the correction QP of levels i..n_T into `xs[i]` (the correction map of those
    /// levels built); true when it is feasible. Counts the QP in the report. The variables are
    /// the map's coordinates (`Hierarchy::build_correction_map`): r_k per level of rank r_k,
    /// none for a level of rank 0; when no level has any, no QP is run and the level is
    /// infeasible (q̈ is outside the box and they cannot move it).
    fn level_feasible(&mut self, i: usize) -> Result<bool> {
        let off = self.hierarchy.correction_offset(i);
        let ma = self
            .hierarchy
            .correction_offset(self.hierarchy.dims().len())
            - off;
        self.xs[i].fill(0.0);
        if ma == 0 {
            // Nothing to correct: feasible only if already inside, which it is not.
            return Ok(false);
        }
        let g = self.hierarchy.correction_map().columns(off, ma);
        let mu = self.settings.continuity;
        if mu == 0.0
            && self.settings.warm_start
            && self.warm.solve(
                i,
                &g,
                &self.qp_lo,
                &self.qp_hi,
                self.settings.qp.feasibility_tolerance,
                &mut self.xs[i].as_mut_slice()[..ma],
            )
        {
            self.report.qp_solves += 1;
            self.report.qp_warm_started += 1;
            return Ok(true);
        }
        if self.settings.screen
            && self.screen.proves_infeasible(
                i,
                &g,
                &self.qp_lo,
                &self.qp_hi,
                self.settings.qp.feasibility_tolerance,
            )
        {
            self.report.screened_infeasible += 1;
            return Ok(false);
        }
        if mu > 0.0 {
            // H = I + μ GᵀG, c = μ Gᵀ(q̈₀ − q̈₋) (the `continuity` module notes).
            for a in 0..ma {
                let ga = g.column(a);
                for b in 0..=a {
                    let v = mu * ga.dot(&g.column(b)) + if a == b { 1.0 } else { 0.0 };
                    self.continuity_h[(a, b)] = v;
                    self.continuity_h[(b, a)] = v;
                }
                let mut s = 0.0;
                for (x, d) in ga.iter().zip(&self.step_change) {
                    s += x * d;
                }
                self.continuity_c[a] = mu * s;
            }
        }
        let problem = QpProblem {
            hessian: if mu > 0.0 {
                Hessian::Dense(self.continuity_h.view((0, 0), (ma, ma)))
            } else {
                Hessian::Identity
            },
            c: if mu > 0.0 {
                &self.continuity_c[..ma]
            } else {
                &self.zeros[..ma]
            },
            a_eq: self.a_eq.rows(0, 0),
            b_eq: &[],
            a_in: g,
            lower: &self.qp_lo,
            upper: &self.qp_hi,
        };
        let rep = self.qp.solve_into(
            &problem,
            &self.settings.qp,
            &mut self.xs[i].as_mut_slice()[..ma],
        )?;
        self.report.qp_solves += 1;
        self.report.qp_iterations += rep.iterations;
        if rep.status == QpStatus::Optimal {
            if mu == 0.0 {
                self.warm.remember(i, self.qp.active_set());
            }
            Ok(true)
        } else {
            self.warm.forget(i);
            self.report.qp_infeasible += 1;
            let failed = match rep.status {
                QpStatus::Infeasible { constraint } => Some(constraint),
                _ => None,
            };
            self.screen.remember(i, self.qp.active_set(), failed);
            Ok(false)
        }
    }

    /// GF (Kanoun et al.): for k = 1..n_T, min ½‖J_k q̈ − h_k‖² + ½ε‖q̈‖² subject to the box
    /// and J_j q̈ = J_j q̈*_j for every j < k (the optimal slack of each higher level frozen).
    fn cascade(&mut self, levels: &[TaskEquation], qdd: &mut DVector<f64>) -> Result<()> {
        let n = self.hierarchy.n();
        let eps = self.settings.cascade_regularization;
        let mut rows = 0;
        let mut have = false;
        for (k, l) in levels.iter().enumerate() {
            let m = l.dim();
            // H = JᵀJ + εI, c = −Jᵀh.
            for a in 0..n {
                for b in 0..=a {
                    let mut s = 0.0;
                    for r in 0..m {
                        s += l.jacobian[(r, a)] * l.jacobian[(r, b)];
                    }
                    if a == b {
                        s += eps;
                    }
                    self.h[(a, b)] = s;
                    self.h[(b, a)] = s;
                }
                let mut s = 0.0;
                for r in 0..m {
                    s -= l.jacobian[(r, a)] * l.rhs[r];
                }
                self.c[a] = s;
            }
            let problem = QpProblem {
                hessian: Hessian::Dense(self.h.view((0, 0), (n, n))),
                c: &self.c,
                a_eq: self.a_eq.rows(0, rows),
                b_eq: &self.b_eq[..rows],
                a_in: self.eye.view((0, 0), (n, n)),
                lower: &self.lo,
                upper: &self.hi,
            };
            let nt = levels.len();
            let rep = self
                .qp
                .solve(&problem, &self.settings.qp, &mut self.xs[nt])?;
            self.report.qp_solves += 1;
            self.report.qp_iterations += rep.iterations;
            if rep.status != QpStatus::Optimal {
                self.report.qp_infeasible += 1;
                self.report.fallback = Some(Fallback::CascadeStoppedAtLevel(k));
                if !have {
                    qdd.copy_from(&self.q0);
                }
                self.clamp_in_place(qdd);
                return Ok(());
            }
            qdd.copy_from(&self.xs[levels.len()]);
            have = true;
            // Freeze this level: J_k q̈ = J_k q̈*_k.
            for r in 0..m {
                let mut s = 0.0;
                for c in 0..n {
                    let v = l.jacobian[(r, c)];
                    self.a_eq[(rows + r, c)] = v;
                    s += v * qdd[c];
                }
                self.b_eq[rows + r] = s;
            }
            rows += m;
        }
        Ok(())
    }

    fn clamp_in_place(&self, qdd: &mut DVector<f64>) {
        for d in 0..qdd.len() {
            qdd[d] = qdd[d].clamp(self.lo[d], self.hi[d]);
        }
    }
}
