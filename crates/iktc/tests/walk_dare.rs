//! The Riccati solver and the preview gains, checked against independent computations:
//! the DARE residual written out here, plain value iteration (backward Riccati recursion
//! with a long horizon) and the time-varying finite-horizon preview LQ.

use iktc::walk::{
    solve_dare, CartTable, DareSettings, DareStatus, PreviewController, PreviewSettings,
};
use nalgebra::DMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `X − (AᵀXA − AᵀXB(R + BᵀXB)⁻¹BᵀXA + Q)`, relative to `‖X‖`.
fn residual(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
    x: &DMatrix<f64>,
) -> f64 {
    let s = r + b.transpose() * x * b;
    let s_inv = s.try_inverse().unwrap();
    let rhs = a.transpose() * x * a - a.transpose() * x * b * s_inv * b.transpose() * x * a + q;
    (x - rhs).norm() / x.norm()
}

/// Value iteration `P ← Q + AᵀPA − AᵀPB(R + BᵀPB)⁻¹BᵀPA` from `P = 0`: the cost-to-go of
/// ever longer finite horizons. Returns `P` and the number of steps.
fn value_iteration(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> (DMatrix<f64>, usize) {
    let mut p = DMatrix::zeros(a.nrows(), a.nrows());
    for k in 0..2_000_000 {
        let s = r + b.transpose() * &p * b;
        let next = q + a.transpose() * &p * a
            - a.transpose() * &p * b * s.try_inverse().unwrap() * b.transpose() * &p * a;
        let change = (&next - &p).norm() / next.norm().max(1.0);
        p = next;
        if change < 1e-15 {
            return (p, k);
        }
    }
    panic!("value iteration did not converge");
}

fn gain(a: &DMatrix<f64>, b: &DMatrix<f64>, r: &DMatrix<f64>, p: &DMatrix<f64>) -> DMatrix<f64> {
    (r + b.transpose() * p * b).try_inverse().unwrap() * b.transpose() * p * a
}

fn augmented(
    settings: &PreviewSettings,
) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    // Built here from the paper's formulas, not taken from the library.
    let (dt, zc, g) = (settings.dt, settings.com_height, settings.gravity);
    let a = DMatrix::from_row_slice(3, 3, &[1.0, dt, dt * dt / 2.0, 0.0, 1.0, dt, 0.0, 0.0, 1.0]);
    let b = DMatrix::from_column_slice(3, 1, &[dt * dt * dt / 6.0, dt * dt / 2.0, dt]);
    let c = DMatrix::from_row_slice(1, 3, &[1.0, 0.0, -zc / g]);
    let ca = &c * &a;
    let cb = (&c * &b)[(0, 0)];
    let mut at = DMatrix::zeros(4, 4);
    at[(0, 0)] = 1.0;
    at.view_mut((0, 1), (1, 3)).copy_from(&ca);
    at.view_mut((1, 1), (3, 3)).copy_from(&a);
    let mut bt = DMatrix::zeros(4, 1);
    bt[(0, 0)] = cb;
    bt.view_mut((1, 0), (3, 1)).copy_from(&b);
    let mut q = DMatrix::zeros(4, 4);
    q[(0, 0)] = settings.q_e;
    for i in 0..3 {
        q[(i + 1, i + 1)] = settings.q_x[i];
    }
    let r = DMatrix::from_element(1, 1, settings.r);
    (at, bt, q, r)
}

#[test]
fn augmented_model_matches_the_paper() {
    let s = PreviewSettings::default();
    let m = CartTable::new(s.dt, s.com_height, s.gravity).unwrap();
    let (a, b, _) = m.augmented();
    let (at, bt, _, _) = augmented(&s);
    assert!((a - at).norm() < 1e-15 && (b - bt).norm() < 1e-15);
}

#[test]
fn preview_riccati_solution_satisfies_the_dare_and_matches_value_iteration() {
    for settings in [
        PreviewSettings::default(),
        PreviewSettings {
            q_x: [1.0, 0.1, 0.01],
            r: 1e-5,
            com_height: 0.6,
            ..PreviewSettings::default()
        },
        PreviewSettings {
            dt: 0.01,
            ..PreviewSettings::default()
        },
    ] {
        let ctrl = PreviewController::new(&settings).unwrap();
        let (a, b, q, r) = augmented(&settings);
        let x = &ctrl.riccati().x;
        let res = residual(&a, &b, &q, &r, x);
        assert!(res < 1e-11, "DARE residual {res}");
        assert!(ctrl.riccati().residual < 1e-11);
        assert_eq!(ctrl.riccati().status, DareStatus::Converged);
        let (pv, steps) = value_iteration(&a, &b, &q, &r);
        let rel = (x - &pv).norm() / pv.norm();
        assert!(
            rel < 1e-8,
            "P differs from value iteration ({steps} steps) by {rel}"
        );
        // Gains [G_I, G_x] of the library against the value-iteration P.
        let k = gain(&a, &b, &r, &pv);
        let kl = [
            ctrl.integral_gain(),
            ctrl.state_gain()[0],
            ctrl.state_gain()[1],
            ctrl.state_gain()[2],
        ];
        for i in 0..4 {
            assert!(
                (kl[i] - k[(0, i)]).abs() <= 1e-7 * k[(0, i)].abs().max(1.0),
                "gain {i}: {} vs {}",
                kl[i],
                k[(0, i)]
            );
        }
        // Doubling needs far fewer steps than value iteration.
        assert!(ctrl.riccati().iterations < 40);
    }
}

/// The first optimal increment `Δu₀` from `X₀ = 0` of the finite-horizon problem over `m`
/// samples (terminal cost `Q`, no Riccati solution used) when the reference steps by 1 m at
/// sample `j` (`Δp^ref_j = 1`), by the time-varying backward recursion
/// `P_k = Q + AᵀP_{k+1}A − AᵀP_{k+1}B s_k⁻¹ BᵀP_{k+1}A`,
/// `g_k = (A − B K_k)ᵀ (P_{k+1} E d_{k+1} + g_{k+1})`, `Δu_k = −s_k⁻¹ Bᵀ(P_{k+1}(A X + E d_{k+1}) + g_{k+1})`,
/// with `E = −(1, 0, 0, 0)ᵀ` (the error drops when the reference rises).
fn first_increment(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
    m: usize,
    j: usize,
) -> f64 {
    let mut e = DMatrix::zeros(4, 1);
    e[(0, 0)] = -1.0;
    let mut p = q.clone();
    let mut g = DMatrix::zeros(4, 1);
    let mut du0 = 0.0;
    for k in (0..m).rev() {
        let d = if k + 1 == j { 1.0 } else { 0.0 };
        let s = (r + b.transpose() * &p * b)[(0, 0)];
        let kk = b.transpose() * &p * a / s;
        let w = &p * &e * d + &g;
        if k == 0 {
            du0 = -(b.transpose() * &w)[(0, 0)] / s;
        }
        let g_next = (a - b * &kk).transpose() * w;
        let p_next = q + a.transpose() * &p * a - a.transpose() * &p * b * &kk;
        p = p_next;
        g = g_next;
    }
    du0
}

#[test]
fn preview_gains_match_the_finite_horizon_lq() {
    let settings = PreviewSettings::default();
    let ctrl = PreviewController::new(&settings).unwrap();
    let (a, b, q, r) = augmented(&settings);
    let gp = ctrl.preview_gains();
    assert_eq!(gp.len(), 320);
    let m = 4000; // 20 s ≫ the closed loop's settling time and the preview
    for j in [1, 2, 5, 20, 100, 200, 320] {
        let du = first_increment(&a, &b, &q, &r, m, j);
        let lib = -gp[j - 1];
        assert!(
            (du - lib).abs() <= 1e-7 * du.abs().max(1e-3),
            "j = {j}: {du} vs {lib}"
        );
    }
    // Preview gains decay: the far future matters less.
    assert!(gp[319].abs() < 0.05 * gp[0].abs());
}

#[test]
fn random_systems_satisfy_the_dare() {
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    for _ in 0..20 {
        let n = rng.random_range(2..6);
        let m = rng.random_range(1..3);
        let a = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
        let b = DMatrix::from_fn(n, m, |_, _| rng.random_range(-1.0..1.0));
        let c = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
        let q = c.transpose() * &c + DMatrix::identity(n, n) * 0.01;
        let l = DMatrix::from_fn(m, m, |_, _| rng.random_range(-1.0..1.0));
        let r = &l * l.transpose() + DMatrix::identity(m, m) * 0.1;
        let sol = solve_dare(&a, &b, &q, &r, &DareSettings::default()).unwrap();
        assert_eq!(sol.status, DareStatus::Converged);
        let res = residual(&a, &b, &q, &r, &sol.x);
        assert!(res < 1e-11, "residual {res}");
        let (pv, _) = value_iteration(&a, &b, &q, &r);
        assert!((&sol.x - &pv).norm() <= 1e-8 * pv.norm());
        // Stabilizing: the closed loop's spectral radius is below 1.
        let k = gain(&a, &b, &r, &sol.x);
        let ac = &a - &b * k;
        let rho = ac
            .complex_eigenvalues()
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max);
        assert!(rho < 1.0, "spectral radius {rho}");
    }
}

#[test]
fn non_stabilizable_is_a_status_and_bad_input_an_error() {
    // Unstable mode 2 not reachable from u.
    let a = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, 0.5]);
    let b = DMatrix::from_column_slice(2, 1, &[0.0, 1.0]);
    let q = DMatrix::identity(2, 2);
    let r = DMatrix::identity(1, 1);
    let sol = solve_dare(&a, &b, &q, &r, &DareSettings::default()).unwrap();
    assert_ne!(sol.status, DareStatus::Converged, "{sol:?}");

    let s = DareSettings::default();
    let a_ok = DMatrix::from_row_slice(2, 2, &[1.0, 0.1, 0.0, 1.0]);
    assert!(solve_dare(&a_ok, &b, &q, &DMatrix::identity(2, 2), &s).is_err());
    assert!(solve_dare(&a_ok, &DMatrix::zeros(3, 1), &q, &r, &s).is_err());
    assert!(solve_dare(&DMatrix::zeros(2, 3), &b, &q, &r, &s).is_err());
    let mut nan = q.clone();
    nan[(1, 1)] = f64::NAN;
    assert!(solve_dare(&a_ok, &b, &nan, &r, &s).is_err());
    assert!(solve_dare(&a_ok, &b, &q, &DMatrix::from_element(1, 1, -1.0), &s).is_err());
    let asym = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]);
    assert!(solve_dare(&a_ok, &b, &asym, &r, &s).is_err());
    for bad in [
        DareSettings {
            tolerance: 0.0,
            ..s
        },
        DareSettings {
            tolerance: f64::NAN,
            ..s
        },
        DareSettings {
            max_iterations: 0,
            ..s
        },
    ] {
        assert!(solve_dare(&a_ok, &b, &q, &r, &bad).is_err());
    }
}
