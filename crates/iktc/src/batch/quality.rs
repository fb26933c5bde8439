//! The quality figures of one retargeted clip, a flat record for the dataset report: what the
//! imitation run already measures ([`ImitateSummary`]), one number per quality.

use serde::Serialize;

use crate::sim::ImitateSummary;

/// One clip's quality figures (the `figures` of its `quality.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClipQuality {
    /// Duration of the run \[s\].
    pub duration: f64,
    /// Control ticks run.
    pub ticks: usize,
    /// All run checks passed (feet held, state finite, COM over the support polygon).
    pub healthy: bool,
    /// Ticks on which a run check failed.
    pub failed_ticks: usize,
    /// RMS tracking error of the feet level ‖x_d − x‖ \[m, rad mixed\].
    pub rms_error_feet: f64,
    /// RMS tracking error of the COM x-y level \[m\].
    pub rms_error_com: f64,
    /// RMS tracking error of the pelvis attitude \[rad\].
    pub rms_error_pelvis_attitude: f64,
    /// RMS tracking error of the pelvis height \[m\].
    pub rms_error_pelvis_height: f64,
    /// RMS tracking error of the upper-body joints \[rad\].
    pub rms_error_upper_body: f64,
    /// Largest tracking error of the upper-body joints \[rad\].
    pub max_error_upper_body: f64,
    /// Foot slip: largest foot position drift from its held pose \[m\].
    pub foot_slip: f64,
    /// Largest foot rotation drift \[rad\].
    pub foot_rotation_slip: f64,
    /// Worst signed position margin over the joints \[rad\] (positive: a limit exceeded).
    pub worst_position_margin: f64,
    /// Worst signed velocity margin \[rad/s\].
    pub worst_velocity_margin: f64,
    /// Worst signed acceleration margin \[rad/s²\].
    pub worst_acceleration_margin: f64,
    /// Share of the ticks with a joint on its position limit \[–\].
    pub position_binding_share: f64,
    /// Smallest distance of the COM's ground projection inside the support polygon \[m\].
    pub com_min_margin: f64,
    /// Largest RMS commanded jerk over the joints \[rad/s³\].
    pub max_rms_jerk: f64,
    /// Joint with that largest RMS jerk.
    pub jerkiest_joint: String,
    /// Share of the ticks with a fallback (empty box, nothing to correct) \[–\].
    pub fallback_share: f64,
    /// Median tick time \[µs\] (wall clock, noisy).
    pub tick_median_us: f64,
}

impl ClipQuality {
    /// The figures of a run's summary.
    pub fn from_summary(s: &ImitateSummary) -> Self {
        let rms = |i: usize| s.levels.get(i).map_or(0.0, |l| l.rms_error);
        let ticks = s.steps.max(1) as f64;
        let jerkiest = s
            .smoothness
            .iter()
            .max_by(|a, b| a.smoothness.rms_jerk.total_cmp(&b.smoothness.rms_jerk));
        Self {
            duration: s.duration,
            ticks: s.steps,
            healthy: s.health.healthy,
            failed_ticks: s.health.failed_ticks,
            rms_error_feet: rms(0),
            rms_error_com: rms(1),
            rms_error_pelvis_attitude: rms(2),
            rms_error_pelvis_height: rms(3),
            rms_error_upper_body: rms(4),
            max_error_upper_body: s.levels.get(4).map_or(0.0, |l| l.max_error),
            foot_slip: s.foot_drift,
            foot_rotation_slip: s.foot_rotation_drift,
            worst_position_margin: s.worst_position_margin,
            worst_velocity_margin: s.worst_velocity_margin,
            worst_acceleration_margin: s.worst_acceleration_margin,
            position_binding_share: s.position_binding_steps as f64 / ticks,
            com_min_margin: s.com_min_margin,
            max_rms_jerk: jerkiest.map_or(0.0, |j| j.smoothness.rms_jerk),
            jerkiest_joint: jerkiest.map_or_else(String::new, |j| j.joint.clone()),
            fallback_share: s.fallback_steps as f64 / ticks,
            tick_median_us: s.tick_median_us,
        }
    }
}
