//! Bad input to the QP solver is an `iktc_core::Error` naming what is wrong; one test each.

use iktc_core::solver::{Hessian, QpProblem, QpSettings, QpWorkspace};
use iktc_core::Error;
use nalgebra::{DMatrix, DVector};

/// A valid problem with n = 2, one equality and two inequality rows, as owned data.
struct Data {
    h: DMatrix<f64>,
    c: Vec<f64>,
    a_eq: DMatrix<f64>,
    b_eq: Vec<f64>,
    a_in: DMatrix<f64>,
    l: Vec<f64>,
    u: Vec<f64>,
}

impl Data {
    fn new() -> Self {
        Self {
            h: DMatrix::from_row_slice(2, 2, &[2.0, 0.5, 0.5, 1.0]),
            c: vec![1.0, -1.0],
            a_eq: DMatrix::from_row_slice(1, 2, &[1.0, 1.0]),
            b_eq: vec![0.5],
            a_in: DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]),
            l: vec![-1.0, f64::NEG_INFINITY],
            u: vec![1.0, 2.0],
        }
    }

    fn problem(&self) -> QpProblem<'_> {
        QpProblem {
            hessian: Hessian::Dense(self.h.as_view()),
            c: &self.c,
            a_eq: self.a_eq.as_view(),
            b_eq: &self.b_eq,
            a_in: self.a_in.as_view(),
            lower: &self.l,
            upper: &self.u,
        }
    }
}

fn solve_with(problem: &QpProblem<'_>, settings: &QpSettings) -> iktc_core::Result<()> {
    let mut ws = QpWorkspace::new(2, 1, 2);
    let mut x = DVector::zeros(problem.c.len());
    ws.solve(problem, settings, &mut x).map(|_| ())
}

fn solve(problem: &QpProblem<'_>) -> iktc_core::Result<()> {
    solve_with(problem, &QpSettings::default())
}

#[test]
fn valid_problem_is_accepted() {
    assert!(solve(&Data::new().problem()).is_ok());
}

#[test]
fn columns_of_a_in_must_match_c() {
    let mut d = Data::new();
    d.a_in = DMatrix::zeros(2, 3);
    let err = solve(&d.problem()).unwrap_err();
    assert!(
        matches!(&err, Error::DimensionMismatch { what, expected: 2, got: 3 } if what.contains("A_in"))
    );
}

#[test]
fn columns_of_a_eq_must_match_c() {
    let mut d = Data::new();
    d.a_eq = DMatrix::zeros(1, 1);
    let err = solve(&d.problem()).unwrap_err();
    assert!(matches!(&err, Error::DimensionMismatch { what, .. } if what.contains("A_eq")));
}

#[test]
fn length_of_b_eq_must_match_rows() {
    let mut d = Data::new();
    d.b_eq = vec![0.5, 1.0];
    let err = solve(&d.problem()).unwrap_err();
    assert!(
        matches!(&err, Error::DimensionMismatch { what, expected: 1, got: 2 } if what.contains("b_eq"))
    );
}

#[test]
fn length_of_limits_must_match_rows() {
    let mut d = Data::new();
    d.u = vec![1.0];
    let err = solve(&d.problem()).unwrap_err();
    assert!(
        matches!(&err, Error::DimensionMismatch { what, expected: 2, got: 1 } if what.contains("u"))
    );
}

#[test]
fn length_of_x_must_be_n() {
    let d = Data::new();
    let mut ws = QpWorkspace::new(2, 1, 2);
    let mut x = DVector::zeros(3);
    let err = ws
        .solve(&d.problem(), &QpSettings::default(), &mut x)
        .unwrap_err();
    assert!(
        matches!(&err, Error::DimensionMismatch { what, expected: 2, got: 3 } if what.contains("x"))
    );
}

#[test]
fn hessian_size_must_be_n_by_n() {
    let mut d = Data::new();
    d.h = DMatrix::identity(3, 3);
    let err = solve(&d.problem()).unwrap_err();
    assert!(matches!(&err, Error::DimensionMismatch { what, .. } if what.contains("H")));
}

#[test]
fn more_variables_than_the_workspace_is_an_error() {
    let d = Data::new();
    let mut ws = QpWorkspace::new(1, 1, 2);
    let mut x = DVector::zeros(2);
    let err = ws
        .solve(&d.problem(), &QpSettings::default(), &mut x)
        .unwrap_err();
    assert!(
        matches!(&err, Error::DimensionMismatch { what, expected: 1, got: 2 } if what.contains("variables"))
    );
}

#[test]
fn more_rows_than_the_workspace_is_an_error() {
    let d = Data::new();
    let mut ws = QpWorkspace::new(2, 1, 1);
    let mut x = DVector::zeros(2);
    let err = ws
        .solve(&d.problem(), &QpSettings::default(), &mut x)
        .unwrap_err();
    assert!(
        matches!(&err, Error::DimensionMismatch { what, expected: 1, got: 2 } if what.contains("inequality"))
    );
}

#[test]
fn nan_in_c_is_an_error() {
    let mut d = Data::new();
    d.c[1] = f64::NAN;
    let err = solve(&d.problem()).unwrap_err();
    assert!(matches!(&err, Error::NonFinite { what, .. } if what == "c[1]"));
}

#[test]
fn nan_in_b_eq_is_an_error() {
    let mut d = Data::new();
    d.b_eq[0] = f64::NAN;
    let err = solve(&d.problem()).unwrap_err();
    assert!(matches!(&err, Error::NonFinite { what, .. } if what == "b_eq[0]"));
}

#[test]
fn infinity_in_a_in_is_an_error() {
    let mut d = Data::new();
    d.a_in[(1, 0)] = f64::INFINITY;
    let err = solve(&d.problem()).unwrap_err();
    assert!(matches!(&err, Error::NonFinite { what, .. } if what == "A_in[(1, 0)]"));
}

#[test]
fn nan_in_hessian_is_an_error() {
    let mut d = Data::new();
    d.h[(0, 0)] = f64::NAN;
    let err = solve(&d.problem()).unwrap_err();
    assert!(matches!(&err, Error::NonFinite { what, .. } if what.starts_with("H")));
}

#[test]
fn nan_limit_is_an_error() {
    let mut d = Data::new();
    d.l[1] = f64::NAN;
    let err = solve(&d.problem()).unwrap_err();
    assert!(matches!(&err, Error::NonFinite { what, .. } if what.contains("row 1")));
}

#[test]
fn lower_above_upper_is_an_error() {
    let mut d = Data::new();
    d.l[0] = 1.5;
    let err = solve(&d.problem()).unwrap_err();
    assert!(
        matches!(&err, Error::InvalidLimit { what, lower, upper } if what.contains("row 0") && *lower == 1.5 && *upper == 1.0)
    );
}

#[test]
fn lower_end_at_plus_infinity_is_an_error() {
    let mut d = Data::new();
    d.l[0] = f64::INFINITY;
    d.u[0] = f64::INFINITY;
    let err = solve(&d.problem()).unwrap_err();
    assert!(matches!(&err, Error::InvalidLimit { what, .. } if what.contains("row 0")));
}

#[test]
fn indefinite_hessian_is_an_error() {
    let mut d = Data::new();
    d.h = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
    let err = solve(&d.problem()).unwrap_err();
    assert!(
        matches!(&err, Error::InvalidSetting { name, expected, .. } if name.contains("H") && expected.contains("positive definite"))
    );
}

#[test]
fn singular_hessian_is_an_error() {
    let mut d = Data::new();
    d.h = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
    let err = solve(&d.problem()).unwrap_err();
    assert!(
        matches!(&err, Error::InvalidSetting { expected, .. } if expected.contains("positive definite"))
    );
}

#[test]
fn asymmetric_hessian_is_an_error() {
    let mut d = Data::new();
    d.h[(0, 1)] = 0.6;
    let err = solve(&d.problem()).unwrap_err();
    assert!(
        matches!(&err, Error::InvalidSetting { expected, .. } if expected.contains("symmetric"))
    );
}

#[test]
fn zero_iterations_setting_is_an_error() {
    let settings = QpSettings {
        max_iterations: 0,
        ..QpSettings::default()
    };
    let err = solve_with(&Data::new().problem(), &settings).unwrap_err();
    assert!(matches!(&err, Error::InvalidSetting { name, .. } if name == "max_iterations"));
}

#[test]
fn negative_feasibility_tolerance_is_an_error() {
    let settings = QpSettings {
        feasibility_tolerance: -1e-9,
        ..QpSettings::default()
    };
    let err = solve_with(&Data::new().problem(), &settings).unwrap_err();
    assert!(matches!(&err, Error::InvalidSetting { name, .. } if name == "feasibility_tolerance"));
}

#[test]
fn nan_dependence_tolerance_is_an_error() {
    let settings = QpSettings {
        linear_dependence_tolerance: f64::NAN,
        ..QpSettings::default()
    };
    assert!(settings.validate().is_err());
    let err = solve_with(&Data::new().problem(), &settings).unwrap_err();
    assert!(
        matches!(&err, Error::InvalidSetting { name, .. } if name == "linear_dependence_tolerance")
    );
}

#[test]
fn default_settings_are_valid() {
    assert!(QpSettings::default().validate().is_ok());
}

#[test]
fn overflowing_data_is_an_error_not_a_panic() {
    let mut d = Data::new();
    d.h = DMatrix::identity(2, 2);
    d.c = vec![1e308, 1e308];
    d.b_eq = vec![1e308];
    d.l = vec![-1e308, f64::NEG_INFINITY];
    d.u = vec![1e308, 1e308];
    let err = solve(&d.problem()).unwrap_err();
    assert!(
        matches!(&err, Error::NonFinite { what, .. } if what.contains("overflow")),
        "{err:?}"
    );
}
