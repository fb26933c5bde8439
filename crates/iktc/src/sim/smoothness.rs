//! How smooth a commanded joint acceleration is: jerk and sign reversals of its change.
//!
//! A position-controlled robot receives q̈ₖ (held constant over tick k). Its tick-to-tick change
//! is the commanded jerk
//!
//! ```text
//! jₖ = (q̈ₖ − q̈ₖ₋₁) / Δt   [rad/s³],   k = 1 … N−1,
//! ```
//!
//! and a command that alternates tick by tick (a square wave at half the control rate) shows up
//! as a change whose sign reverses at every tick: tick k is a *reversal* when
//! `(q̈ₖ − q̈ₖ₋₁)(q̈ₖ₋₁ − q̈ₖ₋₂) < 0`, both changes larger than
//! 10⁻⁶ in magnitude (changes of rounding size are not a motion). Per
//! joint this module gives the RMS and largest |jₖ|, the share of the N−2 ticks that are
//! reversals, and the standard deviation of q̈ itself (a joint at rest on a limit should have
//! none).

use serde::Serialize;

/// A change of q̈ between two ticks no larger than this in magnitude \[rad/s²\] is treated as no
/// change when counting sign reversals. Rounding of the solvers is of order 1e-12 rad/s² on
/// accelerations of order 10 rad/s²; 1e-6 rad/s² stays far above it and far below any change a
/// drive could feel (it moves a joint by 1e-11 rad in a 5 ms tick). Larger values hide small
/// oscillations; smaller ones count rounding as chatter.
pub(crate) const REVERSAL_CHANGE_TOLERANCE: f64 = 1e-6;

/// Smoothness of one dof's commanded acceleration over a run (or a window of it).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct DofSmoothness {
    /// RMS over the ticks of the commanded jerk `(q̈ₖ − q̈ₖ₋₁)/Δt` \[rad/s³\] (0 with < 2 ticks).
    pub rms_jerk: f64,
    /// Largest |`(q̈ₖ − q̈ₖ₋₁)/Δt`| \[rad/s³\].
    pub max_jerk: f64,
    /// Share of the ticks (out of N − 2) where the change of q̈ reverses its sign \[–\], in
    /// `[0, 1]`; 0 with fewer than 3 ticks.
    pub reversal_share: f64,
    /// Standard deviation of q̈ over the ticks \[rad/s²\].
    pub qdd_std: f64,
}

impl DofSmoothness {
    /// The smoothness of the per-tick commands `qdd` \[rad/s²\] of one dof at the control period
    /// `dt` \[s\] (see the module docs for the formulas). Non-finite samples are not expected
    /// (the solvers never return them); they propagate into the figures.
    pub fn of(qdd: &[f64], dt: f64) -> Self {
        let n = qdd.len();
        if n == 0 {
            return Self::default();
        }
        let mean = qdd.iter().sum::<f64>() / n as f64;
        let qdd_std = (qdd.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        let mut sum_sq = 0.0;
        let mut max_jerk = 0.0_f64;
        let mut reversals = 0usize;
        let mut last_change = 0.0_f64;
        for (k, w) in qdd.windows(2).enumerate() {
            let change = w[1] - w[0];
            let jerk = change / dt;
            sum_sq += jerk * jerk;
            max_jerk = max_jerk.max(jerk.abs());
            if k > 0
                && change.abs() > REVERSAL_CHANGE_TOLERANCE
                && last_change.abs() > REVERSAL_CHANGE_TOLERANCE
                && change * last_change < 0.0
            {
                reversals += 1;
            }
            last_change = change;
        }
        Self {
            rms_jerk: if n >= 2 {
                (sum_sq / (n - 1) as f64).sqrt()
            } else {
                0.0
            },
            max_jerk,
            reversal_share: if n >= 3 {
                reversals as f64 / (n - 2) as f64
            } else {
                0.0
            },
            qdd_std,
        }
    }
}

/// [`DofSmoothness`] of a named joint.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointSmoothness {
    /// Joint (dof) name.
    pub joint: String,
    /// Its figures.
    #[serde(flatten)]
    pub smoothness: DofSmoothness,
}

/// The smoothness of every dof `dofs` of recorded commands: `qdd(k, d)` is q̈ of dof `d` at
/// tick `k` \[rad/s²\], for ticks `ticks`; `names(d)` names dof `d`. Allocates (reports only).
pub fn joints_smoothness(
    dofs: impl IntoIterator<Item = usize>,
    ticks: std::ops::Range<usize>,
    dt: f64,
    qdd: impl Fn(usize, usize) -> f64,
    names: impl Fn(usize) -> String,
) -> Vec<JointSmoothness> {
    dofs.into_iter()
        .map(|d| {
            let column: Vec<f64> = ticks.clone().map(|k| qdd(k, d)).collect();
            JointSmoothness {
                joint: names(d),
                smoothness: DofSmoothness::of(&column, dt),
            }
        })
        .collect()
}

/// The worst figures over several joints: largest RMS jerk, max jerk, reversal share and q̈
/// standard deviation (each maximised separately).
pub fn worst(joints: &[JointSmoothness]) -> DofSmoothness {
    joints.iter().fold(DofSmoothness::default(), |w, j| {
        let s = j.smoothness;
        DofSmoothness {
            rms_jerk: w.rms_jerk.max(s.rms_jerk),
            max_jerk: w.max_jerk.max(s.max_jerk),
            reversal_share: w.reversal_share.max(s.reversal_share),
            qdd_std: w.qdd_std.max(s.qdd_std),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::DofSmoothness;

    #[test]
    fn square_wave_reverses_every_tick() {
        // q̈ = ±1: every change is ±2, jerk 2/Δt, each change reverses the previous one.
        let dt = 0.01;
        let qdd: Vec<f64> = (0..101)
            .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let s = DofSmoothness::of(&qdd, dt);
        assert!((s.rms_jerk - 200.0).abs() < 1e-9);
        assert!((s.max_jerk - 200.0).abs() < 1e-9);
        assert_eq!(s.reversal_share, 1.0);
        // 51 samples at +1 and 50 at −1: mean 1/101, std √(1 − 1/101²).
        let std = (1.0 - 1.0 / 101.0_f64.powi(2)).sqrt();
        assert!((s.qdd_std - std).abs() < 1e-12);
    }

    #[test]
    fn ramp_and_constant_have_no_reversal() {
        let dt = 0.005;
        let ramp: Vec<f64> = (0..50).map(|k| 0.3 * k as f64).collect();
        let s = DofSmoothness::of(&ramp, dt);
        assert_eq!(s.reversal_share, 0.0);
        assert!((s.rms_jerk - 0.3 / dt).abs() < 1e-9);
        let flat = DofSmoothness::of(&[2.0; 10], dt);
        assert_eq!(
            (flat.rms_jerk, flat.max_jerk, flat.qdd_std),
            (0.0, 0.0, 0.0)
        );
        // Rounding-sized alternation is not chatter.
        let noise: Vec<f64> = (0..20)
            .map(|k| if k % 2 == 0 { 1e-13 } else { 0.0 })
            .collect();
        assert_eq!(DofSmoothness::of(&noise, dt).reversal_share, 0.0);
        assert_eq!(DofSmoothness::of(&[], dt), DofSmoothness::default());
    }
}
