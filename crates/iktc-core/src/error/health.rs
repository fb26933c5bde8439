//! What a failed run check reports: the one error that is not about bad input
//! ([`crate::Error::RunFailed`]). The checks themselves belong to the scenarios that run them
//! (`iktc::sim::health`); this is their plain data, so that the error type can hold it.

use std::fmt;

use serde::{Serialize, Serializer};

/// Which check failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HealthCheck {
    /// A foot left its reference position.
    FootPosition,
    /// A foot rotated away from its reference orientation.
    FootRotation,
    /// The state (or a quantity computed from it) is NaN or infinite.
    NonFinite,
    /// The ZMP (or, for a kinematic run, the COM's ground projection) is outside the
    /// support polygon.
    ZmpOutside,
}

/// One failed check: where and when it first failed, by how much, and how often.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HealthIssue {
    /// The check.
    pub check: HealthCheck,
    /// The quantity, with its unit (e.g. "position error of foot r_ankle \[m\]").
    pub quantity: String,
    /// Time of the first failure \[s\].
    pub time: f64,
    /// The quantity's value then (non-finite values are written as text in JSON).
    #[serde(serialize_with = "number_or_text")]
    pub value: f64,
    /// The tolerance it exceeded (same unit).
    pub tolerance: f64,
    /// Where: the polygon edge crossed and the direction, or the entry that is not finite.
    pub detail: String,
    /// Worst value over the ticks it failed (ZMP: the largest distance outside).
    #[serde(serialize_with = "number_or_text")]
    pub worst_value: f64,
    /// Time of the worst value \[s\].
    pub worst_time: f64,
    /// Ticks on which it failed.
    pub ticks: usize,
}

fn number_or_text<S: Serializer>(v: &f64, s: S) -> std::result::Result<S::Ok, S::Error> {
    if v.is_finite() {
        s.serialize_f64(*v)
    } else {
        s.serialize_str(&v.to_string())
    }
}

impl fmt::Display for HealthIssue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.check {
            HealthCheck::NonFinite => write!(
                f,
                "at t = {:.4} s the {} is {} ({})",
                self.time, self.quantity, self.value, self.detail
            ),
            _ => write!(
                f,
                "at t = {:.4} s the {} is {:.4e}, beyond its tolerance {:.4e}{}{}",
                self.time,
                self.quantity,
                self.value,
                self.tolerance,
                if self.detail.is_empty() { "" } else { ": " },
                self.detail
            ),
        }
    }
}
