//! The QP solver never panics: on arbitrary data (wild magnitudes, zeros, NaN and infinities
//! sprinkled in) it returns a report or an error, and a report's objective is finite.
//!
//! On these seeds about a tenth of the cases end `Optimal`, a tenth `Infeasible`, the rest in
//! input errors (non-finite entries, indefinite H) or the overflow error (finite entries near
//! 1e300).

use iktc_core::solver::{Hessian, QpProblem, QpSettings, QpStatus, QpWorkspace};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

/// A value of any magnitude, sign, or a special one.
fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        60 => (-1.0f64..1.0, -300i32..300).prop_map(|(m, e)| m * 10f64.powi(e)),
        20 => -10.0f64..10.0,
        8 => Just(0.0),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
    ]
}

#[derive(Debug, Clone)]
struct Wild {
    n: usize,
    identity: bool,
    h: Vec<f64>,
    c: Vec<f64>,
    a_eq: Vec<f64>,
    b_eq: Vec<f64>,
    a_in: Vec<f64>,
    l: Vec<f64>,
    u: Vec<f64>,
}

fn wild_problem() -> impl Strategy<Value = Wild> {
    (1usize..6, 0usize..4, 0usize..6, any::<bool>()).prop_flat_map(|(n, m_eq, m_in, identity)| {
        (
            Just((n, m_eq, m_in, identity)),
            prop::collection::vec(wild(), n * n),
            prop::collection::vec(wild(), n),
            prop::collection::vec(wild(), m_eq * n),
            prop::collection::vec(wild(), m_eq),
            prop::collection::vec(wild(), m_in * n),
            prop::collection::vec(wild(), m_in),
            prop::collection::vec(wild(), m_in),
        )
            .prop_map(|((n, _, _, identity), h, c, a_eq, b_eq, a_in, l, u)| Wild {
                n,
                identity,
                h,
                c,
                a_eq,
                b_eq,
                a_in,
                l,
                u,
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, rng_seed: proptest::test_runner::RngSeed::Fixed(17), ..ProptestConfig::default() })]

    #[test]
    fn never_panics(w in wild_problem()) {
        let n = w.n;
        // H = MᵀM-like from wild entries is rarely PD: symmetrise so that both the
        // factorisation error and the solve paths are reached
        let m = DMatrix::from_column_slice(n, n, &w.h);
        let h = if w.h.iter().all(|v| v.is_finite()) { &m * m.transpose() + DMatrix::identity(n, n) } else { m };
        let a_eq = DMatrix::from_row_slice(w.b_eq.len(), n, &w.a_eq);
        let a_in = DMatrix::from_row_slice(w.l.len(), n, &w.a_in);
        // order the ends where both are numbers so that some problems are valid
        let (l, u): (Vec<f64>, Vec<f64>) = w.l.iter().zip(&w.u).map(|(&a, &b)| if a <= b { (a, b) } else if b <= a { (b, a) } else { (a, b) }).unzip();
        let problem = QpProblem {
            hessian: if w.identity { Hessian::Identity } else { Hessian::Dense(h.as_view()) },
            c: &w.c,
            a_eq: a_eq.as_view(),
            b_eq: &w.b_eq,
            a_in: a_in.as_view(),
            lower: &l,
            upper: &u,
        };
        let mut ws = QpWorkspace::new(n, 4, 6);
        let mut x = DVector::zeros(n);
        let result = ws.solve(&problem, &QpSettings::default(), &mut x);
        if let Ok(report) = result {
            prop_assert!(report.objective.is_finite());
            if report.status == QpStatus::Optimal {
                prop_assert!(x.iter().all(|v| v.is_finite()));
            }
        }
    }
}
