//! Solvers.

pub mod qp;

pub use qp::{
    ActiveConstraint, Hessian, QpConstraint, QpProblem, QpReport, QpSettings, QpStatus, QpWorkspace,
};

mod continuity;
mod gram;
mod hierarchy;
mod kernels;
mod rebase;
mod reflectors;
mod report;
mod screen;
mod selection;
mod settings;
mod solve;
mod warm;

pub use hierarchy::Hierarchy;
pub use report::{Fallback, Method, SolveReport};
pub use settings::{Climb, Damping, SolverSettings};
pub use solve::Solver;
