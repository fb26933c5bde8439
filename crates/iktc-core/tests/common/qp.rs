//! Shared helpers of the QP tests: seeded random problems, the clarabel oracle, a KKT check.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use iktc_core::solver::{Hessian, QpProblem, QpReport, QpSettings, QpStatus, QpWorkspace};
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// An owned QP; `h = None` means `H = I`.
#[derive(Debug, Clone)]
pub struct OwnedQp {
    pub h: Option<DMatrix<f64>>,
    pub c: Vec<f64>,
    pub a_eq: DMatrix<f64>,
    pub b_eq: Vec<f64>,
    pub a_in: DMatrix<f64>,
    pub l: Vec<f64>,
    pub u: Vec<f64>,
}

impl OwnedQp {
    pub fn n(&self) -> usize {
        self.c.len()
    }

    pub fn view(&self) -> QpProblem<'_> {
        QpProblem {
            hessian: match &self.h {
                None => Hessian::Identity,
                Some(h) => Hessian::Dense(h.as_view()),
            },
            c: &self.c,
            a_eq: self.a_eq.as_view(),
            b_eq: &self.b_eq,
            a_in: self.a_in.as_view(),
            lower: &self.l,
            upper: &self.u,
        }
    }

    pub fn h_dense(&self) -> DMatrix<f64> {
        self.h
            .clone()
            .unwrap_or_else(|| DMatrix::identity(self.n(), self.n()))
    }

    pub fn objective(&self, x: &DVector<f64>) -> f64 {
        let h = self.h_dense();
        0.5 * x.dot(&(&h * x)) + DVector::from_column_slice(&self.c).dot(x)
    }

    /// Largest violation of any row at `x`, computed independently of the solver.
    pub fn violation(&self, x: &DVector<f64>) -> f64 {
        let mut worst = 0.0_f64;
        if self.a_eq.nrows() > 0 {
            let r = &self.a_eq * x;
            for (ri, bi) in r.iter().zip(&self.b_eq) {
                worst = worst.max((ri - bi).abs());
            }
        }
        if self.a_in.nrows() > 0 {
            let r = &self.a_in * x;
            for ((ri, li), ui) in r.iter().zip(&self.l).zip(&self.u) {
                worst = worst.max(li - ri).max(ri - ui);
            }
        }
        worst
    }

    /// Appends a row to `A_in`.
    pub fn push_in(&mut self, row: &[f64], l: f64, u: f64) {
        let n = self.n();
        let m = self.a_in.nrows();
        let mut a = DMatrix::zeros(m + 1, n);
        a.view_mut((0, 0), (m, n)).copy_from(&self.a_in);
        a.row_mut(m).copy_from_slice(row);
        self.a_in = a;
        self.l.push(l);
        self.u.push(u);
    }

    /// Appends a row to `A_eq`.
    pub fn push_eq(&mut self, row: &[f64], b: f64) {
        let n = self.n();
        let m = self.a_eq.nrows();
        let mut a = DMatrix::zeros(m + 1, n);
        a.view_mut((0, 0), (m, n)).copy_from(&self.a_eq);
        a.row_mut(m).copy_from_slice(row);
        self.a_eq = a;
        self.b_eq.push(b);
    }
}

/// What the oracle concluded.
#[derive(Debug, Clone)]
pub enum Verdict {
    Solved { x: DVector<f64>, objective: f64 },
    Infeasible,
    Unclear(SolverStatus),
}

/// Column-compressed copy of a dense matrix, dropping exact zeros (upper triangle only if asked).
fn csc(m: &DMatrix<f64>, upper_only: bool) -> CscMatrix<f64> {
    let mut colptr = vec![0];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            if upper_only && i > j {
                break;
            }
            let v = m[(i, j)];
            if v != 0.0 {
                rowval.push(i);
                nzval.push(v);
            }
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(m.nrows(), m.ncols(), colptr, rowval, nzval)
}

/// Solves the problem with clarabel (interior point, an independent method and code).
///
/// Rows: equalities of `A_eq` and rows of `A_in` with `l = u` in the zero cone; each finite end
/// of the other rows as one row of the nonnegative cone (`a x ≤ u`, `−a x ≤ −l`).
pub fn clarabel_solve(p: &OwnedQp) -> Verdict {
    let n = p.n();
    let mut eq_rows: Vec<(Vec<f64>, f64)> = Vec::new();
    let mut in_rows: Vec<(Vec<f64>, f64)> = Vec::new();
    for i in 0..p.a_eq.nrows() {
        eq_rows.push((p.a_eq.row(i).iter().copied().collect(), p.b_eq[i]));
    }
    for i in 0..p.a_in.nrows() {
        let a: Vec<f64> = p.a_in.row(i).iter().copied().collect();
        if p.l[i] == p.u[i] {
            eq_rows.push((a, p.l[i]));
            continue;
        }
        if p.u[i].is_finite() {
            in_rows.push((a.clone(), p.u[i]));
        }
        if p.l[i].is_finite() {
            in_rows.push((a.iter().map(|v| -v).collect(), -p.l[i]));
        }
    }
    let m = eq_rows.len() + in_rows.len();
    let mut a = DMatrix::zeros(m, n);
    let mut b = Vec::with_capacity(m);
    for (i, (row, rhs)) in eq_rows.iter().chain(&in_rows).enumerate() {
        a.row_mut(i).copy_from_slice(row);
        b.push(*rhs);
    }
    let mut cones = Vec::new();
    if !eq_rows.is_empty() {
        cones.push(SupportedConeT::ZeroConeT(eq_rows.len()));
    }
    if !in_rows.is_empty() {
        cones.push(SupportedConeT::NonnegativeConeT(in_rows.len()));
    }
    let settings = DefaultSettings {
        verbose: false,
        tol_gap_abs: 1e-11,
        tol_gap_rel: 1e-11,
        tol_feas: 1e-11,
        max_iter: 400,
        ..DefaultSettings::default()
    };
    let mut solver = match DefaultSolver::new(
        &csc(&p.h_dense(), true),
        &p.c,
        &csc(&a, false),
        &b,
        &cones,
        settings,
    ) {
        Ok(s) => s,
        Err(_) => return Verdict::Unclear(SolverStatus::NumericalError),
    };
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            let x = DVector::from_vec(solver.solution.x.clone());
            Verdict::Solved {
                objective: p.objective(&x),
                x,
            }
        }
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
            Verdict::Infeasible
        }
        other => Verdict::Unclear(other),
    }
}

use super::rng;

fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    rng.random_range(lo..hi)
}

/// Random symmetric positive definite matrix `s (Mᵀ M / n + δ I)`.
pub fn random_spd(rng: &mut ChaCha8Rng, n: usize) -> DMatrix<f64> {
    let m = DMatrix::from_fn(n, n, |_, _| uniform(rng, -1.0, 1.0));
    let delta = 10f64.powf(uniform(rng, -2.0, 0.0));
    let scale = 10f64.powf(uniform(rng, -1.0, 1.0));
    let mut h = (m.transpose() * &m) / n as f64 + DMatrix::identity(n, n) * delta;
    h *= scale;
    // exact symmetry
    let ht = h.transpose();
    (h + ht) * 0.5
}

/// A random row: dense in [−1, 1] or (one in four) a unit vector (a box row as in the IK tick).
fn random_row(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    if rng.random_range(0..4) == 0 {
        let mut r = vec![0.0; n];
        r[rng.random_range(0..n)] = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        r
    } else {
        (0..n).map(|_| uniform(rng, -1.0, 1.0)).collect()
    }
}

/// Kinds of random problems.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Dense H, random rows, feasible by construction.
    Generic,
    /// H = I, otherwise as Generic.
    Identity,
    /// Duplicate rows, combinations, many rows through one point, `l = u`, redundant equalities.
    Degenerate,
    /// A feasible set of width 1e-5..1e-3 (nearly infeasible).
    NearlyInfeasible,
    /// Infeasible by construction (Farkas combination or inconsistent equalities).
    Infeasible,
}

/// Size ranges of random problems.
#[derive(Debug, Clone, Copy)]
pub struct Sizes {
    /// Largest number of variables (at least 1).
    pub max_vars: usize,
    /// Largest number of inequality rows before the kind adds its own.
    pub max_ineq: usize,
    /// Largest number of equality rows, as a fraction of n.
    pub eq_fraction: f64,
}

/// The sizes of the task: n in 1..=40, inequality rows 0..=60, equalities 0..=n/2.
pub const SMALL: Sizes = Sizes {
    max_vars: 40,
    max_ineq: 60,
    eq_fraction: 0.5,
};

/// The largest sizes the solver is meant for: n up to 60, 80 inequality rows, m_eq up to n.
pub const LARGE: Sizes = Sizes {
    max_vars: 60,
    max_ineq: 80,
    eq_fraction: 1.0,
};

/// A random problem of the given kind with [`SMALL`] sizes (plus the rows the kind adds:
/// redundant copies, combinations, conflicting rows).
pub fn random_problem(seed: u64, kind: Kind) -> OwnedQp {
    random_problem_sized(seed, kind, SMALL)
}

/// A random problem of the given kind and sizes.
pub fn random_problem_sized(seed: u64, kind: Kind, sizes: Sizes) -> OwnedQp {
    let mut rng = rng(seed);
    let n = rng.random_range(1..=sizes.max_vars);
    let m_in = rng.random_range(0..=sizes.max_ineq);
    let m_eq = rng.random_range(0..=(n as f64 * sizes.eq_fraction) as usize);
    let x_feas: Vec<f64> = (0..n).map(|_| uniform(&mut rng, -1.0, 1.0)).collect();
    let xf = DVector::from_column_slice(&x_feas);
    let h = if kind == Kind::Identity || rng.random_range(0..5) == 0 && kind != Kind::Generic {
        None
    } else {
        Some(random_spd(&mut rng, n))
    };
    // unconstrained minimum far away so that many rows are active
    let target: Vec<f64> = (0..n).map(|_| uniform(&mut rng, -5.0, 5.0)).collect();
    let hd = h.clone().unwrap_or_else(|| DMatrix::identity(n, n));
    let c = -(&hd * DVector::from_column_slice(&target));
    let mut p = OwnedQp {
        h,
        c: c.iter().copied().collect(),
        a_eq: DMatrix::zeros(0, n),
        b_eq: vec![],
        a_in: DMatrix::zeros(0, n),
        l: vec![],
        u: vec![],
    };
    let width = if kind == Kind::NearlyInfeasible {
        10f64.powf(uniform(&mut rng, -5.0, -3.0))
    } else {
        1.0
    };
    for _ in 0..m_eq {
        let row = random_row(&mut rng, n);
        let b = DVector::from_column_slice(&row).dot(&xf);
        p.push_eq(&row, b);
    }
    for _ in 0..m_in {
        let row = random_row(&mut rng, n);
        let v = DVector::from_column_slice(&row).dot(&xf);
        let (l, u) = match rng.random_range(0..6) {
            0 => (v - width * uniform(&mut rng, 0.0, 1.0), f64::INFINITY),
            1 => (f64::NEG_INFINITY, v + width * uniform(&mut rng, 0.0, 1.0)),
            2 if kind == Kind::Degenerate => (v, v + width),
            3 if kind == Kind::Degenerate => (v - width, v),
            _ => (
                v - width * uniform(&mut rng, 0.0, 1.0),
                v + width * uniform(&mut rng, 0.0, 1.0),
            ),
        };
        p.push_in(&row, l, u);
    }
    match kind {
        Kind::Degenerate => add_degenerate_rows(&mut rng, &mut p, &xf),
        Kind::Infeasible => make_infeasible(&mut rng, &mut p, &xf),
        Kind::NearlyInfeasible => add_nearly_conflicting_row(&mut rng, &mut p, &xf),
        _ => {}
    }
    p
}

fn dot(a: &[f64], x: &DVector<f64>) -> f64 {
    a.iter().zip(x.iter()).map(|(a, b)| a * b).sum()
}

fn combination(
    rng: &mut ChaCha8Rng,
    m: &DMatrix<f64>,
    k: usize,
) -> (Vec<usize>, Vec<f64>, Vec<f64>) {
    let n = m.ncols();
    let mut idx = Vec::new();
    let mut w = Vec::new();
    let mut row = vec![0.0; n];
    for _ in 0..k {
        let i = rng.random_range(0..m.nrows());
        let wi = uniform(rng, 0.2, 2.0);
        for (r, a) in row.iter_mut().zip(m.row(i).iter()) {
            *r += wi * a;
        }
        idx.push(i);
        w.push(wi);
    }
    (idx, w, row)
}

fn add_degenerate_rows(rng: &mut ChaCha8Rng, p: &mut OwnedQp, xf: &DVector<f64>) {
    let n = p.n();
    // duplicates of inequality rows, same or shifted bounds
    for _ in 0..rng.random_range(0..=5) {
        if p.a_in.nrows() == 0 {
            break;
        }
        let i = rng.random_range(0..p.a_in.nrows());
        let row: Vec<f64> = p.a_in.row(i).iter().copied().collect();
        let (l, u) = if rng.random_bool(0.5) {
            (p.l[i], p.u[i])
        } else {
            let v = dot(&row, xf);
            (v - uniform(rng, 0.0, 0.5), v + uniform(rng, 0.0, 0.5))
        };
        p.push_in(&row, l, u);
    }
    // linear combinations of inequality rows, tight at x_feas
    for _ in 0..rng.random_range(0..=5) {
        if p.a_in.nrows() == 0 {
            break;
        }
        let k = rng.random_range(1..=3);
        let (_, _, row) = combination(rng, &p.a_in.clone(), k);
        let v = dot(&row, xf);
        if rng.random_bool(0.5) {
            p.push_in(&row, v, f64::INFINITY);
        } else {
            p.push_in(&row, f64::NEG_INFINITY, v);
        }
    }
    // many rows through x_feas: more than n tight rows
    if rng.random_bool(0.5) {
        for _ in 0..rng.random_range(n..=n + 5) {
            let row = random_row(rng, n);
            let v = dot(&row, xf);
            p.push_in(&row, v, f64::INFINITY);
        }
    }
    // fixed rows l = u
    for _ in 0..rng.random_range(0..=2) {
        let row = random_row(rng, n);
        let v = dot(&row, xf);
        p.push_in(&row, v, v);
    }
    // redundant equalities: duplicates and combinations with consistent right-hand sides
    for _ in 0..rng.random_range(0..=3) {
        if p.a_eq.nrows() == 0 {
            break;
        }
        let k = rng.random_range(1..=3);
        let (idx, w, row) = combination(rng, &p.a_eq.clone(), k);
        let b: f64 = idx.iter().zip(&w).map(|(&i, wi)| wi * p.b_eq[i]).sum();
        p.push_eq(&row, b);
    }
}

/// Adds a row `a = Σ w_i a_i` (w > 0) of rows with finite lower ends with an upper end below
/// `Σ w_i l_i` by a margin (Farkas: infeasible), or an inconsistent equality.
fn make_infeasible(rng: &mut ChaCha8Rng, p: &mut OwnedQp, xf: &DVector<f64>) {
    let n = p.n();
    // margins from 1e-6 (far above the 1e-9 feasibility tolerance, but a thin gap) to 1
    let margin = 10f64.powf(uniform(rng, -6.0, 0.0));
    let choice = rng.random_range(0..4);
    if choice == 0 && p.a_eq.nrows() > 0 {
        let k = rng.random_range(1..=2);
        let (idx, w, row) = combination(rng, &p.a_eq.clone(), k);
        let b: f64 = idx.iter().zip(&w).map(|(&i, wi)| wi * p.b_eq[i]).sum();
        if rng.random_bool(0.5) {
            p.push_eq(&row, b + margin);
        } else {
            p.push_in(&row, b + margin, b + margin);
        }
        return;
    }
    // rows with lower ends (new ones), plus (choice 1) any multiple of existing equalities
    let k = rng.random_range(1..=3);
    let mut row = vec![0.0; n];
    let mut bound = 0.0;
    if choice == 1 && p.a_eq.nrows() > 0 {
        for _ in 0..rng.random_range(1..=2) {
            let i = rng.random_range(0..p.a_eq.nrows());
            let v = uniform(rng, -2.0, 2.0);
            for (r, a) in row.iter_mut().zip(p.a_eq.row(i).iter()) {
                *r += v * a;
            }
            bound += v * p.b_eq[i];
        }
    }
    for _ in 0..k {
        let a = random_row(rng, n);
        let l = dot(&a, xf) - uniform(rng, 0.0, 1.0);
        let w = uniform(rng, 0.2, 2.0);
        p.push_in(
            &a,
            l,
            if rng.random_bool(0.5) {
                f64::INFINITY
            } else {
                l + 2.0
            },
        );
        for (r, ai) in row.iter_mut().zip(&a) {
            *r += w * ai;
        }
        bound += w * l;
    }
    let norm = row.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-3);
    let upper = bound - margin * norm;
    p.push_in(&row, upper - 1.0, upper);
    // shuffle the new rows into the others is not needed: the order of rows is arbitrary
}

/// Adds a Farkas-type row that leaves a small positive margin (feasible, barely).
fn add_nearly_conflicting_row(rng: &mut ChaCha8Rng, p: &mut OwnedQp, xf: &DVector<f64>) {
    let n = p.n();
    let k = rng.random_range(1..=3);
    let mut row = vec![0.0; n];
    let mut bound = 0.0;
    for _ in 0..k {
        let a = random_row(rng, n);
        let l = dot(&a, xf) - uniform(rng, 0.0, 1e-3);
        let w = uniform(rng, 0.2, 2.0);
        p.push_in(&a, l, f64::INFINITY);
        for (r, ai) in row.iter_mut().zip(&a) {
            *r += w * ai;
        }
        bound += w * l;
    }
    let v = dot(&row, xf);
    // feasible: x_feas satisfies it; the set {a_i x ≥ l_i, a x ≤ upper} is thin
    let upper = v.max(bound) + 1e-5;
    p.push_in(&row, f64::NEG_INFINITY, upper);
}

/// Multiplies each row of `A_eq`, `A_in` and its bounds by `10^U(−2, 2)`: the solution is
/// unchanged, the multipliers scale inversely.
pub fn scale_rows(p: &mut OwnedQp, seed: u64) {
    let mut rng = rng(seed);
    for i in 0..p.a_eq.nrows() {
        let f = 10f64.powf(uniform(&mut rng, -2.0, 2.0));
        p.a_eq.row_mut(i).scale_mut(f);
        p.b_eq[i] *= f;
    }
    for i in 0..p.a_in.nrows() {
        let f = 10f64.powf(uniform(&mut rng, -2.0, 2.0));
        p.a_in.row_mut(i).scale_mut(f);
        p.l[i] *= f;
        p.u[i] *= f;
    }
}

/// Number of rows of `A_in` within `tol` of an end at `x`, plus the rows of `A_eq`.
pub fn tight_rows(p: &OwnedQp, x: &DVector<f64>, tol: f64) -> usize {
    let mut count = p.a_eq.nrows();
    if p.a_in.nrows() > 0 {
        let ax = &p.a_in * x;
        for ((v, l), u) in ax.iter().zip(&p.l).zip(&p.u) {
            if (v - l).abs() <= tol || (v - u).abs() <= tol {
                count += 1;
            }
        }
    }
    count
}

/// Solves with a fresh workspace.
pub fn solve(p: &OwnedQp, settings: &QpSettings) -> (QpReport, DVector<f64>, Vec<f64>, Vec<f64>) {
    let mut ws = QpWorkspace::new(p.n(), p.a_eq.nrows(), p.a_in.nrows());
    let mut x = DVector::zeros(p.n());
    let report = ws
        .solve(&p.view(), settings, &mut x)
        .expect("valid problem");
    (
        report,
        x,
        ws.multipliers_eq().to_vec(),
        ws.multipliers_in().to_vec(),
    )
}

/// Residuals of the KKT conditions at `(x, y_eq, y_in)`, each relative to its natural scale.
#[derive(Debug, Clone, Copy)]
pub struct Kkt {
    /// `‖H x + c − A_eqᵀ y_eq − A_inᵀ y_in‖∞ / (1 + ‖c‖∞ + ‖H x‖∞ + Σ|y| ‖a‖∞)`.
    pub stationarity: f64,
    /// Largest constraint violation [row units].
    pub primal: f64,
    /// Largest wrong-signed multiplier: `max(−y_i)` over rows only at their lower end, etc.
    pub dual_sign: f64,
    /// `max |y_i| · (distance of row i to the end its sign refers to)`.
    pub complementarity: f64,
}

pub fn kkt(p: &OwnedQp, x: &DVector<f64>, y_eq: &[f64], y_in: &[f64]) -> Kkt {
    let h = p.h_dense();
    let hx = &h * x;
    let mut g = &hx + DVector::from_column_slice(&p.c);
    let mut scale = 1.0 + p.c.iter().fold(0.0_f64, |a, v| a.max(v.abs())) + hx.amax();
    let mut ymax = 0.0_f64;
    for (i, y) in y_eq.iter().enumerate() {
        g -= p.a_eq.row(i).transpose() * *y;
        ymax = ymax.max(y.abs() * p.a_eq.row(i).amax());
    }
    let mut dual_sign = 0.0_f64;
    let mut compl = 0.0_f64;
    let ax = if p.a_in.nrows() > 0 {
        &p.a_in * x
    } else {
        DVector::zeros(0)
    };
    for (i, &y) in y_in.iter().enumerate() {
        g -= p.a_in.row(i).transpose() * y;
        ymax = ymax.max(y.abs() * p.a_in.row(i).amax());
        if y > 0.0 {
            if p.l[i] == f64::NEG_INFINITY {
                dual_sign = dual_sign.max(y);
            } else {
                compl = compl.max(y * (ax[i] - p.l[i]).abs());
            }
        } else if y < 0.0 {
            if p.u[i] == f64::INFINITY {
                dual_sign = dual_sign.max(-y);
            } else {
                compl = compl.max(-y * (ax[i] - p.u[i]).abs());
            }
        }
    }
    scale += ymax;
    Kkt {
        stationarity: g.amax() / scale,
        primal: p.violation(x),
        dual_sign,
        complementarity: compl,
    }
}

/// True if the status is `Optimal`.
pub fn optimal(r: &QpReport) -> bool {
    r.status == QpStatus::Optimal
}
