//! Settings of the prioritized solvers (IKTC, cascade, clamp).

use super::qp::QpSettings;
use crate::error::{Error, Result};

/// Damping of the least-squares inverses (paper Section 2.2, eqs. 8–10).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Damping {
    /// Plain pseudo-inverse (λ = 0); rank loss is handled by the rank threshold alone.
    None,
    /// A constant damping factor λ [task unit / joint unit, i.e. the unit of a singular value
    /// of J]: bounds the gain of each inverse by 1/(2λ) at the price of a bias of order λ²/σ².
    Fixed(f64),
    /// Damping only near a singularity (Nakamura & Hanafusa; Chiaverini): with σ the smallest
    /// kept singular value (estimated by the last pivot of the pivoted QR),
    /// λ² = (1 − (σ/ε)²) λ_max² when σ < ε, else 0.
    Adaptive {
        /// λ_max: the damping reached at the singularity.
        max: f64,
        /// ε: the size of the singular region.
        threshold: f64,
    },
}

/// Where IKTC's climb (Algorithm 2) starts looking for the lowest-priority level whose
/// correction brings q̈ into the box.
///
/// Feasibility is monotone in the level: the correction of levels i..n_T may use every
/// column that the correction of levels i+1..n_T may use, so if level i+1 is feasible so is
/// level i. The answer — the largest feasible i — is therefore the same from any start; only
/// the number of QPs differs. An infeasible QP is the expensive one (the dual active-set method
/// proves infeasibility only after fixing every variable), so starting where the last tick
/// ended saves the infeasible checks below it when the limits bind for many ticks in a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Climb {
    /// Algorithm 2 as printed: from the lowest-priority level upwards.
    FromBottom,
    /// From the level the last correction started from (the bottom on the first tick): down
    /// while feasible, else up until feasible. Same answer, fewer QPs in steady contact.
    FromLast,
}

/// Settings of [`Solver`](super::Solver). Every threshold is documented with what it trades.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Damping of each level's inverse J̄_i^{λ+}. Default: none (the paper's 3R experiment).
    pub damping: Damping,
    /// A pivot |R_jj| of the pivoted QR of a task-consistent Jacobian below this counts as a lost
    /// rank \[unit of a singular value of J, ≈ 1 for metres and radians\]. Larger values drop
    /// nearly dependent rows sooner (robust, less tracking); smaller ones keep them and amplify
    /// noise near singularities. Default 1e-9.
    pub rank_threshold: f64,
    /// A q̈ violating the box by at most this is inside it \[rad/s²\]. Default 1e-9: far below
    /// any physical acceleration, above the QP's rounding.
    pub box_tolerance: f64,
    /// Regularisation ε of each cascade (GF) QP, min ½‖J_k q̈ − h_k‖² + ½ε‖q̈‖², which makes its
    /// Hessian positive definite and picks the least-norm solution, as the pseudo-inverse does
    /// \[–\]. Larger values bias the cascade towards small q̈; smaller ones make its Hessian
    /// ill-conditioned. Default 1e-8.
    pub cascade_regularization: f64,
    /// Before each IKTC correction QP, try to prove the level infeasible with the rows the
    /// last infeasible QP of that level ended with active (a relaxation: it never rejects a
    /// feasible level, and it allows the QP's feasibility tolerance; see the `screen` module
    /// notes in the solver). Saves the m_c iterations an infeasible QP needs when a level stays
    /// infeasible tick after tick. Default true.
    pub screen: bool,
    /// Where IKTC's climb starts. Default [`Climb::FromLast`].
    pub climb: Climb,
    /// Hold on IKTC's corrected level \[ticks\]: a level that had to be corrected stays the
    /// level corrected from until a lower-priority level has sufficed for this many ticks in a
    /// row (the `continuity` module notes in the solver: the equations). Removes the tick-by-tick
    /// alternation of Algorithm 2's choice between two levels near the boundary of feasibility;
    /// the box and the levels above the corrected one stay exact. Longer holds correct the held
    /// levels longer than needed; 0 or 1 is Algorithm 2 exactly. Default 1.
    pub level_hold: usize,
    /// Release rate `r` of the re-based demands of IKTC's corrected levels \[–\], in (0, 1]
    /// (errata 3.3; the `rebase` module notes in the solver: `w ← (1 − r)(w + Δh)`). Below 1 a
    /// sacrificed level's demand converges on what the limits let it achieve, so it stops pushing
    /// into them tick after tick, and recovers its CLIK demand with a time constant of about
    /// `Δt/r` once they let it. Smaller values push more gently and recover more slowly; 1 is
    /// IKTC as printed. GF and clamp are not affected. Default 1.
    pub rebase_release: f64,
    /// Before each IKTC correction QP, try the rows active at that level's last optimum: the
    /// least-norm correction on them is the QP's optimum when its multipliers have the right
    /// signs and it satisfies every row (see the `warm` module notes in the solver); otherwise
    /// the QP runs as before. Same answer up to rounding and the QP's feasibility tolerance,
    /// fewer QP iterations when the same level is corrected tick after tick. Default true.
    pub warm_start: bool,
    /// Weight `μ` of the continuity term of IKTC's correction QP \[–\] (the `continuity`
    /// module notes in the solver): `min ½‖Δh‖² + ½μ‖q̈ − q̈₋‖²` over the corrections of the
    /// levels Algorithm 2 chose, `q̈₋` the previous solve's q̈. The level chosen is unchanged
    /// (feasibility does not depend on the objective), the box and the levels above it stay
    /// exact; among the corrections that make q̈ fit the box, the one nearer the last command
    /// is preferred, so q̈ does not jump when the corrected level changes. The two norms mix
    /// task units (m/s², rad/s²) with joint units (rad/s²); `μ` weighs one against the other.
    /// 0 is IKTC as printed. The warm start is not used when `μ > 0` (it assumes `min ½‖Δh‖²`).
    /// Default 0.
    pub continuity: f64,
    /// Settings of the QPs.
    pub qp: QpSettings,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            damping: Damping::None,
            rank_threshold: 1e-9,
            box_tolerance: 1e-9,
            cascade_regularization: 1e-8,
            screen: true,
            climb: Climb::FromLast,
            level_hold: 1,
            rebase_release: 1.0,
            warm_start: true,
            continuity: 0.0,
            qp: QpSettings::default(),
        }
    }
}

fn positive(name: &str, v: f64, allow_zero: bool) -> Result<()> {
    if v.is_finite() && (v > 0.0 || (allow_zero && v == 0.0)) {
        Ok(())
    } else {
        Err(Error::InvalidSetting {
            name: name.into(),
            value: v.to_string(),
            expected: if allow_zero {
                "a finite number ≥ 0".into()
            } else {
                "a finite number > 0".into()
            },
        })
    }
}

impl SolverSettings {
    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        match self.damping {
            Damping::None => {}
            Damping::Fixed(l) => positive("damping λ", l, true)?,
            Damping::Adaptive { max, threshold } => {
                positive("adaptive damping λ_max", max, true)?;
                positive("adaptive damping threshold ε", threshold, false)?;
            }
        }
        positive("rank_threshold", self.rank_threshold, false)?;
        positive("box_tolerance", self.box_tolerance, true)?;
        positive("cascade_regularization", self.cascade_regularization, false)?;
        positive("continuity", self.continuity, true)?;
        if !(self.rebase_release > 0.0 && self.rebase_release <= 1.0) {
            return Err(Error::InvalidSetting {
                name: "rebase_release".into(),
                value: self.rebase_release.to_string(),
                expected: "a release rate in (0, 1] [–] (1: no re-base)".into(),
            });
        }
        self.qp.validate()
    }
}
