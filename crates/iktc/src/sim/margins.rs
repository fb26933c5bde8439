//! How close a recorded trajectory came to each joint limit, as signed margins.

use crate::limits::{peak_in_step, DofLimits};
use crate::model::JointLimit;

/// The margins of one joint in a run's summary: the largest excursion beyond each limit
/// (positive = exceeded, negative = the closest approach stayed that far inside).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct JointMargin {
    /// Joint name.
    pub joint: String,
    /// \[rad\].
    pub position: f64,
    /// \[rad/s\].
    pub velocity: f64,
    /// \[rad/s²\].
    pub acceleration: f64,
}

impl JointMargin {
    /// The summary entry of the dof margins `m` of joint `joint`.
    pub fn new(joint: String, m: &DofMargins) -> Self {
        Self {
            joint,
            position: m.position,
            velocity: m.velocity,
            acceleration: m.acceleration,
        }
    }
}

/// The limits a run was held to (the controller's [`DofLimits`], narrowed ranges included) as
/// the [`JointLimit`] the margins are measured against, with the given `effort` \[N·m or N\].
pub fn held_limit(d: &DofLimits, effort: f64) -> JointLimit {
    JointLimit {
        lower: d.position_min,
        upper: d.position_max,
        velocity: d.velocity_max,
        acceleration: d.acceleration_max,
        jerk: d.jerk_max,
        effort,
    }
}

/// Largest excursion beyond each limit of one dof over a run: positive = the limit was
/// exceeded by that much, negative = the closest approach stayed that far inside.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DofMargins {
    /// Dof name.
    #[serde(skip)]
    pub index: usize,
    /// max over the run of max(q − q_max, q_min − q), in-step peaks included \[rad\].
    pub position: f64,
    /// max of |q̇| − v_max \[rad/s\].
    pub velocity: f64,
    /// max of |q̈| − a_max \[rad/s²\].
    pub acceleration: f64,
}

/// Computes the margins of one dof from per-step samples: q_k, q̇_k at the start of step k and
/// the constant q̈_k applied over it (duration `dt` \[s\]). Infinite limits give −∞ margins.
pub fn dof_margins(
    index: usize,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    dt: f64,
    limit: &JointLimit,
) -> DofMargins {
    let mut m = DofMargins {
        index,
        position: f64::NEG_INFINITY,
        velocity: f64::NEG_INFINITY,
        acceleration: f64::NEG_INFINITY,
    };
    for k in 0..q.len().min(qd.len()).min(qdd.len()) {
        let ex = peak_in_step(q[k], qd[k], qdd[k], dt);
        m.position = m
            .position
            .max(ex.max - limit.upper)
            .max(limit.lower - ex.min);
        let v_end = qd[k] + dt * qdd[k];
        m.velocity = m
            .velocity
            .max(qd[k].abs() - limit.velocity)
            .max(v_end.abs() - limit.velocity);
        m.acceleration = m.acceleration.max(qdd[k].abs() - limit.acceleration);
    }
    m
}

/// Median of a sample (0 for an empty one).
pub fn median(v: &[f64]) -> f64 {
    percentile(v, 0.5)
}

/// The p-quantile (0 ≤ p ≤ 1) of a sample by nearest rank (0 for an empty one).
pub fn percentile(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mut s: Vec<f64> = v.iter().copied().filter(|x| !x.is_nan()).collect();
    s.sort_by(|a, b| a.total_cmp(b));
    if s.is_empty() {
        return 0.0;
    }
    let i = ((p.clamp(0.0, 1.0) * (s.len() - 1) as f64).round() as usize).min(s.len() - 1);
    s[i]
}
