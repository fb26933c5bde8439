//! Solvers.

pub mod qp;

pub use qp::{
    ActiveConstraint, Hessian, QpConstraint, QpProblem, QpReport, QpSettings, QpStatus, QpWorkspace,
};
