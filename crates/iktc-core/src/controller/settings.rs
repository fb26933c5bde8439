//! Settings of a [`Controller`](super::Controller): the solver and the bounds it uses.

use crate::error::Result;
use crate::limits::BoundMethod;
use crate::solver::{Method, SolverSettings};

/// What a controller solves with, chosen once when it is built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerSettings {
    /// The solver: IKTC (default), the GF cascade, clamping or the plain prioritized solution.
    pub method: Method,
    /// How joint limits become the acceleration box (default: [`BoundMethod::Quiet`], the
    /// discrete-time-safe bounds of [`BoundMethod::Viable`] with a discrete braking curve, on
    /// which a joint driven into a limit comes to rest instead of chattering;
    /// [`BoundMethod::Paper`] is eq. 14 as printed).
    pub bounds: BoundMethod,
    /// Damping, rank threshold, box tolerance and QP settings of the solver.
    pub solver: SolverSettings,
}

impl Default for ControllerSettings {
    fn default() -> Self {
        Self {
            method: Method::Iktc,
            bounds: BoundMethod::quiet(),
            solver: SolverSettings::default(),
        }
    }
}

impl ControllerSettings {
    /// Checks the bound method and the solver settings.
    pub fn validate(&self) -> Result<()> {
        self.bounds.validate()?;
        self.solver.validate()
    }
}
