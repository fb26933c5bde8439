//! Run health: the checks that end a scenario run that has gone wrong, instead of letting it
//! print a summary of nonsense.
//!
//! Three conditions are checked at every tick of the imitation, walking and push runs:
//!
//! * **a task that must hold drifts**: the feet, `‖p_foot − p_ref‖ ≤`
//!   [`HealthSettings::foot_position_tolerance`] and the rotation angle of `R_ref⁻¹ R_foot` `≤`
//!   [`HealthSettings::foot_rotation_tolerance`];
//! * **the state stops being finite**: any entry of q, q̇, q̈ or the COM is NaN or ±∞;
//! * **the ZMP leaves the support polygon** (the robot would fall; in a kinematic run without
//!   dynamics, the COM's ground projection): its signed distance to the polygon, `min_edges ((b − a) × (p − a)) / ‖b − a‖` (positive inside, see
//!   [`SupportPolygon::closest_edge`]), must stay `≥ −`[`HealthSettings::zmp_tolerance`]; the
//!   report names the edge it crossed and the direction of the edge's outward normal.
//!
//! By default the first failed check ends the run with [`Error::RunFailed`], which names the
//! time, the quantity, its value and the tolerance. With [`HealthSettings::keep_going`] the
//! run continues and every failed check is recorded in the [`HealthReport`] of its summary
//! (first occurrence, worst value, ticks); a non-finite state still ends the run — there is
//! nothing sensible to integrate from it — and the report says so
//! ([`HealthReport::completed`] = false), so that no summary, CSV or viewer ever carries a
//! non-finite number from the state.

use serde::Serialize;

pub use crate::error::health::{HealthCheck, HealthIssue};
use crate::error::{Error, Result};
use crate::walk::SupportPolygon;

/// Tolerances of the run checks, and whether a failed check stops the run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HealthSettings {
    /// Largest distance of a foot from its reference \[m\] (default 0.01 m). A held foot that
    /// moves 1 cm has slid on the ground: the default imitation keeps its feet within 2 mm and
    /// the default walk its stance feet within a few mm, so this leaves room for tracking
    /// transients and none for a foot given up by the solver.
    pub foot_position_tolerance: f64,
    /// Largest rotation of a foot from its reference \[rad\] (default 0.05 rad ≈ 2.9°): tilting
    /// a 0.2 m sole by 0.05 rad lifts one edge by 5 mm, a lost contact.
    pub foot_rotation_tolerance: f64,
    /// How far the ZMP may be outside the support polygon \[m\] (default 0: the edge is the
    /// limit of the contact forces; a positive value accepts that much modelling error).
    pub zmp_tolerance: f64,
    /// Continue after a failed check and mark it in the summary instead of stopping with an
    /// error (default false). A non-finite state ends the run either way.
    pub keep_going: bool,
}

impl Default for HealthSettings {
    fn default() -> Self {
        Self {
            foot_position_tolerance: 0.01,
            foot_rotation_tolerance: 0.05,
            zmp_tolerance: 0.0,
            keep_going: false,
        }
    }
}

impl HealthSettings {
    /// Checks that the tolerances are finite and non-negative.
    pub fn validate(&self) -> Result<()> {
        for (name, v, unit) in [
            ("foot_position_tolerance", self.foot_position_tolerance, "m"),
            (
                "foot_rotation_tolerance",
                self.foot_rotation_tolerance,
                "rad",
            ),
            ("zmp_tolerance", self.zmp_tolerance, "m"),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidSetting {
                    name: format!("health.{name}"),
                    value: v.to_string(),
                    expected: format!("a finite tolerance >= 0 [{unit}]"),
                });
            }
        }
        Ok(())
    }
}

/// The health of a run, kept in its summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HealthReport {
    /// The settings used.
    pub settings: HealthSettings,
    /// No check failed.
    pub healthy: bool,
    /// The run reached its last tick (false: a non-finite state ended it early).
    pub completed: bool,
    /// Ticks on which at least one check failed.
    pub failed_ticks: usize,
    /// The failed checks, one entry per check and quantity, in order of first failure.
    pub issues: Vec<HealthIssue>,
}

/// Whether the run may go on after a tick's checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Go on.
    Continue,
    /// Stop here (a non-finite state with [`HealthSettings::keep_going`]).
    Stop,
}

/// Applies the checks tick by tick and collects the [`HealthReport`].
#[derive(Debug, Clone)]
pub struct HealthMonitor {
    settings: HealthSettings,
    issues: Vec<HealthIssue>,
    failed_ticks: usize,
    failed_now: bool,
    completed: bool,
}

impl HealthMonitor {
    /// A monitor with no failure yet. Errors: invalid settings.
    pub fn new(settings: HealthSettings) -> Result<Self> {
        settings.validate()?;
        Ok(Self {
            settings,
            issues: Vec::new(),
            failed_ticks: 0,
            failed_now: false,
            completed: true,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &HealthSettings {
        &self.settings
    }

    fn fail(&mut self, issue: HealthIssue) -> Result<()> {
        if !self.settings.keep_going {
            return Err(Error::RunFailed(Box::new(issue)));
        }
        self.failed_now = true;
        let worse = |a: f64, b: f64| a > b || a.is_nan();
        match self
            .issues
            .iter_mut()
            .find(|i| i.check == issue.check && i.quantity == issue.quantity)
        {
            Some(i) => {
                i.ticks += 1;
                if worse(issue.value, i.worst_value) {
                    i.worst_value = issue.value;
                    i.worst_time = issue.time;
                }
            }
            None => self.issues.push(issue),
        }
        Ok(())
    }

    fn issue(
        check: HealthCheck,
        quantity: String,
        time: f64,
        value: f64,
        tolerance: f64,
        detail: String,
    ) -> HealthIssue {
        HealthIssue {
            check,
            quantity,
            time,
            value,
            tolerance,
            detail,
            worst_value: value,
            worst_time: time,
            ticks: 1,
        }
    }

    /// Checks one foot at time `t` \[s\]: its position error \[m\] and rotation error \[rad\]
    /// against the tolerances. A non-finite error counts as a non-finite state.
    pub fn check_foot(
        &mut self,
        t: f64,
        foot: &str,
        position_error: f64,
        rotation_error: f64,
    ) -> Result<Verdict> {
        for (value, what) in [
            (position_error, "position error"),
            (rotation_error, "rotation error"),
        ] {
            if !value.is_finite() {
                return self.non_finite(t, &format!("{what} of foot {foot}"), value, "");
            }
        }
        let s = self.settings;
        if position_error > s.foot_position_tolerance {
            self.fail(Self::issue(
                HealthCheck::FootPosition,
                format!("position error of foot {foot} [m]"),
                t,
                position_error,
                s.foot_position_tolerance,
                "the feet task is not held".into(),
            ))?;
        }
        if rotation_error > s.foot_rotation_tolerance {
            self.fail(Self::issue(
                HealthCheck::FootRotation,
                format!("rotation error of foot {foot} [rad]"),
                t,
                rotation_error,
                s.foot_rotation_tolerance,
                "the feet task is not held".into(),
            ))?;
        }
        Ok(Verdict::Continue)
    }

    /// Checks that every entry of `values` is finite; `what` names the vector and `names`
    /// (if as long as `values`) its entries.
    pub fn check_finite(
        &mut self,
        t: f64,
        what: &str,
        names: &[String],
        values: &[f64],
    ) -> Result<Verdict> {
        match values.iter().position(|v| !v.is_finite()) {
            None => Ok(Verdict::Continue),
            Some(i) => {
                let entry = names
                    .get(i)
                    .map_or_else(|| format!("entry {i}"), |n| format!("entry {i}, {n}"));
                self.non_finite(t, what, values[i], &entry)
            }
        }
    }

    fn non_finite(&mut self, t: f64, what: &str, value: f64, entry: &str) -> Result<Verdict> {
        let detail = if entry.is_empty() {
            "the run is stopped: nothing sensible follows from a non-finite state".to_string()
        } else {
            format!("{entry}; the run is stopped: nothing sensible follows from a non-finite state")
        };
        self.fail(Self::issue(
            HealthCheck::NonFinite,
            what.to_string(),
            t,
            value,
            0.0,
            detail,
        ))?;
        self.completed = false;
        Ok(Verdict::Stop)
    }

    /// Checks that the point `p` \[m\] (in the polygon's frame) is inside `polygon`, up to
    /// [`HealthSettings::zmp_tolerance`]; `point` names it ("ZMP", or "COM" for a kinematic
    /// run's static criterion) and `frame` the frame for the report (e.g. "world axes").
    pub fn check_support(
        &mut self,
        t: f64,
        polygon: &SupportPolygon,
        p: (f64, f64),
        point: &str,
        frame: &str,
    ) -> Result<Verdict> {
        if !(p.0.is_finite() && p.1.is_finite()) {
            let v = if p.0.is_finite() { p.1 } else { p.0 };
            return self.non_finite(t, &format!("{point} [m]"), v, "");
        }
        let Some(edge) = polygon.closest_edge(p) else {
            return Ok(Verdict::Continue);
        };
        let outside = -edge.margin;
        if outside > self.settings.zmp_tolerance {
            self.fail(Self::issue(
                HealthCheck::ZmpOutside,
                format!("distance of the {point} outside the support polygon [m]"),
                t,
                outside,
                self.settings.zmp_tolerance,
                format!(
                    "{point} ({:.4}, {:.4}) m beyond the edge ({:.4}, {:.4})–({:.4}, {:.4}), towards {} ({}): the robot would fall",
                    p.0,
                    p.1,
                    edge.start.0,
                    edge.start.1,
                    edge.end.0,
                    edge.end.1,
                    direction_name(edge.outward_normal),
                    frame
                ),
            ))?;
        }
        Ok(Verdict::Continue)
    }

    /// Closes the checks of one tick (counts it if a check failed).
    pub fn end_tick(&mut self) {
        if self.failed_now {
            self.failed_ticks += 1;
            self.failed_now = false;
        }
    }

    /// The report.
    pub fn report(&self) -> HealthReport {
        HealthReport {
            settings: self.settings,
            healthy: self.issues.is_empty(),
            completed: self.completed,
            failed_ticks: self.failed_ticks,
            issues: self.issues.clone(),
        }
    }
}

/// A direction in the ground plane in words: the nearest of the four axis directions
/// (`+x` front, `−x` back, `+y` left, `−y` right) and the unit vector itself.
pub fn direction_name(n: (f64, f64)) -> String {
    let axis = if n.0.abs() >= n.1.abs() {
        if n.0 >= 0.0 {
            "+x (front)"
        } else {
            "−x (back)"
        }
    } else if n.1 >= 0.0 {
        "+y (left)"
    } else {
        "−y (right)"
    };
    format!("{axis}, outward normal ({:+.3}, {:+.3})", n.0, n.1)
}
