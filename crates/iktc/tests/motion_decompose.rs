//! Tests of the rotation decomposition (generalised Euler angles and least squares).

use iktc::motion::{
    compose_rotation, decompose_rotation, decompose_rotation_with, rotation_angle,
    DecomposeSettings, DecompositionMethod,
};
use iktc::Error;
use nalgebra::{UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{FRAC_PI_2, PI};

fn random_rotation(rng: &mut ChaCha8Rng) -> UnitQuaternion<f64> {
    // Uniform on SO(3) (Shoemake): three uniforms.
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let a = (1.0 - u1).sqrt();
    let b = u1.sqrt();
    let q = nalgebra::Quaternion::new(
        a * (2.0 * PI * u2).sin(),
        a * (2.0 * PI * u2).cos(),
        b * (2.0 * PI * u3).sin(),
        b * (2.0 * PI * u3).cos(),
    );
    UnitQuaternion::from_quaternion(q)
}

fn random_unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 0.2 && n <= 1.0 {
            return v / n;
        }
    }
}

fn basis(i: usize) -> Vector3<f64> {
    let mut v = Vector3::zeros();
    v[i] = 1.0;
    v
}

/// The residual angle of R(θ) against r, computed independently of the library.
fn misfit(r: &UnitQuaternion<f64>, axes: &[Vector3<f64>], theta: &[f64]) -> f64 {
    let mut q = UnitQuaternion::identity();
    for (a, t) in axes.iter().zip(theta) {
        q *= UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(*a), *t);
    }
    (r * q.inverse()).angle()
}

fn wrapped_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(2.0 * PI);
    d.min(2.0 * PI - d)
}

/// All 12 Euler orders (6 Tait–Bryan, 6 proper), expressed in a random orthonormal frame, with a
/// random handedness; angles drawn away from gimbal lock. With `previous` near the truth the
/// truth comes back; without it the reconstruction is exact and the angles lie in (−π, π].
#[test]
fn closed_form_recovers_random_angles_for_all_orders() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let orders: Vec<[usize; 3]> = vec![
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
        [0, 1, 0],
        [0, 2, 0],
        [1, 0, 1],
        [1, 2, 1],
        [2, 0, 2],
        [2, 1, 2],
    ];
    let mut checked = 0;
    for trial in 0..600 {
        let order = orders[trial % orders.len()];
        let frame = random_rotation(&mut rng);
        let flip = if rng.random::<bool>() { -1.0 } else { 1.0 };
        let axes: Vec<Vector3<f64>> = order
            .iter()
            .enumerate()
            .map(|(j, &i)| frame * basis(i) * if j == 2 { flip } else { 1.0 })
            .collect();
        let truth = [
            rng.random_range(-PI..PI),
            rng.random_range(-PI..PI),
            rng.random_range(-PI..PI),
        ];
        // Distance of θ2 from the singular values λ, λ + π.
        let lambda = axes[0]
            .dot(&axes[1].cross(&axes[2]))
            .atan2(axes[0].dot(&axes[2]));
        if (truth[1] - lambda).sin().abs() < 0.1 {
            continue;
        }
        let r = compose_rotation(&axes, &truth).unwrap();
        let previous: Vec<f64> = truth
            .iter()
            .map(|t| t + rng.random_range(-0.05..0.05))
            .collect();
        let mut out = [0.0; 3];
        let rep = decompose_rotation(&r, &axes, Some(&previous), &mut out).unwrap();
        assert_eq!(
            rep.method,
            DecompositionMethod::ClosedForm { singular: false }
        );
        for (o, t) in out.iter().zip(&truth) {
            assert!(
                (o - t).abs() < 1e-9,
                "trial {trial} order {order:?}: {out:?} vs {truth:?}"
            );
        }
        assert!(rep.residual < 1e-12);
        // The closed form is exact: the Gauss–Newton polish has (almost) nothing to do.
        assert!(
            rep.iterations <= 1,
            "trial {trial}: {} polish iterations",
            rep.iterations
        );

        let rep = decompose_rotation(&r, &axes, None, &mut out).unwrap();
        assert!(misfit(&r, &axes, &out) < 1e-9, "trial {trial}: misfit");
        assert!(rep.residual < 1e-12);
        assert!(out.iter().all(|t| *t > -PI - 1e-12 && *t <= PI + 1e-12));
        checked += 1;
    }
    assert!(checked > 400);
}

/// Independent reference: nalgebra's `euler_angles` (R = Rz(yaw)·Ry(pitch)·Rx(roll), pitch in
/// [−π/2, π/2]) must equal the decomposition on axes (z, y, x) without `previous`.
#[test]
fn zyx_matches_nalgebra_euler_angles() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let axes = [Vector3::z(), Vector3::y(), Vector3::x()];
    for _ in 0..200 {
        let r = random_rotation(&mut rng);
        let (roll, pitch, yaw) = r.euler_angles();
        if pitch.abs() > FRAC_PI_2 - 0.05 {
            continue;
        }
        let mut out = [0.0; 3];
        decompose_rotation(&r, &axes, None, &mut out).unwrap();
        assert!(wrapped_diff(out[0], yaw) < 1e-9, "{out:?} vs {yaw}");
        assert!((out[1] - pitch).abs() < 1e-9);
        assert!(wrapped_diff(out[2], roll) < 1e-9);
    }
}

/// A smooth trajectory through gimbal lock (θ2 = π/2 exactly at the middle sample for X-Y-Z):
/// decomposing frame after frame with the previous result stays continuous and exact.
#[test]
fn continuity_through_gimbal_lock() {
    let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
    let n = 201;
    let truth = |i: usize| {
        let t = i as f64 / (n - 1) as f64; // t = 0.5 exactly at i = 100
        [0.3 + 0.5 * t, FRAC_PI_2 + 0.2 * (t - 0.5), -0.2 + 0.4 * t]
    };
    let max_true_step = (0.5f64.powi(2) + 0.2f64.powi(2) + 0.4f64.powi(2)).sqrt() / (n - 1) as f64;
    let mut prev: Option<[f64; 3]> = None;
    let mut saw_singular = false;
    for i in 0..n {
        let th = truth(i);
        let r = compose_rotation(&axes, &th).unwrap();
        let mut out = [0.0; 3];
        let rep = decompose_rotation(&r, &axes, prev.as_ref().map(|p| &p[..]), &mut out).unwrap();
        if rep.method == (DecompositionMethod::ClosedForm { singular: true }) {
            saw_singular = true;
            // θ1 + θ3 is the true sum and the split is nearest to the previous angles: the
            // Lagrange condition of min ‖θ − p‖² s.t. θ1 + θ3 = φ is θ1 − p1 = θ3 − p3.
            let p = prev.unwrap();
            assert!(((out[0] - p[0]) - (out[2] - p[2])).abs() < 1e-9);
            assert!((out[0] + out[2] - (th[0] + th[2])).abs() < 1e-9);
        }
        assert!(misfit(&r, &axes, &out) < 1e-9, "frame {i}");
        if let Some(p) = prev {
            let step =
                ((out[0] - p[0]).powi(2) + (out[1] - p[1]).powi(2) + (out[2] - p[2]).powi(2))
                    .sqrt();
            assert!(
                step < 2.0 * max_true_step,
                "frame {i}: jump {step} {out:?} {p:?}"
            );
        } else {
            for (o, t) in out.iter().zip(&th) {
                assert!((o - t).abs() < 1e-9);
            }
        }
        prev = Some(out);
    }
    assert!(
        saw_singular,
        "the middle frame must be detected as gimbal-locked"
    );
    let last = prev.unwrap();
    for (o, t) in last.iter().zip(&truth(n - 1)) {
        assert!((o - t).abs() < 1e-6, "{last:?}");
    }
}

/// Exactly singular rotation without previous: θ3 = 0 and the whole of θ1 + θ3 goes to θ1.
#[test]
fn gimbal_lock_without_previous_puts_everything_on_the_first_axis() {
    let axes = [Vector3::z(), Vector3::y(), Vector3::x()];
    let r = compose_rotation(&axes, &[0.4, FRAC_PI_2, 0.3]).unwrap();
    let mut out = [0.0; 3];
    let rep = decompose_rotation(&r, &axes, None, &mut out).unwrap();
    assert_eq!(
        rep.method,
        DecompositionMethod::ClosedForm { singular: true }
    );
    // Rz(a)·Ry(π/2)·Rx(c) = Rz(a − c)·Ry(π/2): θ1 = 0.4 − 0.3, θ3 = 0.
    assert!(
        (out[0] - 0.1).abs() < 1e-9 && (out[1] - FRAC_PI_2).abs() < 1e-9 && out[2].abs() < 1e-9,
        "{out:?}"
    );
}

/// Random non-orthogonal axes (1, 2 or 3 of them): representable rotations come back exactly,
/// with the true angles when `previous` is near them; two axes are unique without `previous`.
#[test]
fn least_squares_recovers_random_axes() {
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    for trial in 0..300 {
        let k = 1 + trial % 3;
        let axes: Vec<Vector3<f64>> = (0..k).map(|_| random_unit(&mut rng)).collect();
        // Keep consecutive axes well apart (parallel axes are redundant).
        if axes.windows(2).any(|w| w[0].dot(&w[1]).abs() > 0.9) {
            continue;
        }
        let truth: Vec<f64> = (0..k).map(|_| rng.random_range(-2.5..2.5)).collect();
        let r = compose_rotation(&axes, &truth).unwrap();
        let prev: Vec<f64> = truth
            .iter()
            .map(|t| t + rng.random_range(-0.1..0.1))
            .collect();
        let mut out = vec![0.0; k];
        let rep = decompose_rotation(&r, &axes, Some(&prev), &mut out).unwrap();
        assert!(
            rep.residual < 1e-10,
            "trial {trial}: residual {}",
            rep.residual
        );
        assert!(misfit(&r, &axes, &out) < 1e-9);
        for (o, t) in out.iter().zip(&truth) {
            assert!(
                (o - t).abs() < 1e-7,
                "trial {trial} k {k}: {out:?} vs {truth:?}"
            );
        }
        if k <= 2 {
            decompose_rotation(&r, &axes, None, &mut out).unwrap();
            for (o, t) in out.iter().zip(&truth) {
                assert!(
                    wrapped_diff(*o, *t) < 1e-7,
                    "trial {trial} k {k}: {out:?} vs {truth:?}"
                );
            }
        }
    }
}

/// Rotations that the axes cannot represent: one axis gives the exact minimiser (checked against a
/// fine scan), two axes a local minimum (no ±1e-4 perturbation improves it).
#[test]
fn least_squares_minimises_the_residual() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for _ in 0..40 {
        let r = random_rotation(&mut rng);
        let a = random_unit(&mut rng);
        let mut out = [0.0];
        let rep = decompose_rotation(&r, &[a], None, &mut out).unwrap();
        let best_scan = (0..20000)
            .map(|i| misfit(&r, &[a], &[-PI + 2.0 * PI * i as f64 / 20000.0]))
            .fold(f64::INFINITY, f64::min);
        assert!(rep.residual <= best_scan + 1e-12);
        assert!((rep.residual - misfit(&r, &[a], &out)).abs() < 1e-9);

        let axes = [random_unit(&mut rng), random_unit(&mut rng)];
        let mut out = [0.0; 2];
        let rep = decompose_rotation(&r, &axes, None, &mut out).unwrap();
        for i in 0..2 {
            for h in [-1e-4, 1e-4] {
                let mut t = out;
                t[i] += h;
                assert!(misfit(&r, &axes, &t) >= rep.residual - 1e-12);
            }
        }
    }
}

/// The twist is undefined for a half turn about an axis normal to the joint axis: the previous
/// angle is kept.
#[test]
fn undefined_twist_keeps_previous() {
    let r = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI);
    let mut out = [0.0];
    let rep = decompose_rotation(&r, &[Vector3::z()], Some(&[0.7]), &mut out).unwrap();
    assert_eq!(rep.method, DecompositionMethod::Twist { singular: true });
    assert_eq!(out[0], 0.7);
}

#[test]
fn bad_input_is_an_error() {
    let r = UnitQuaternion::identity();
    let mut out3 = [0.0; 3];
    assert!(matches!(
        decompose_rotation(&r, &[], None, &mut []),
        Err(Error::InvalidSetting { .. })
    ));
    let four = [Vector3::x(); 4];
    assert!(decompose_rotation(&r, &four, None, &mut [0.0; 4]).is_err());
    let axes = [Vector3::x(), Vector3::y(), Vector3::z()];
    assert!(matches!(
        decompose_rotation(&r, &axes, None, &mut [0.0; 2]),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        decompose_rotation(&r, &axes, Some(&[0.0]), &mut out3),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        decompose_rotation(&r, &axes, Some(&[0.0, f64::NAN, 0.0]), &mut out3),
        Err(Error::NonFinite { .. })
    ));
    let zero = [Vector3::x(), Vector3::zeros(), Vector3::z()];
    assert!(matches!(
        decompose_rotation(&r, &zero, None, &mut out3),
        Err(Error::InvalidSetting { .. })
    ));
    let nan_q = UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(f64::NAN, 0.0, 0.0, 0.0));
    assert!(matches!(
        decompose_rotation(&nan_q, &axes, None, &mut out3),
        Err(Error::NonFinite { .. })
    ));
    let bad = DecomposeSettings {
        damping: 0.0,
        ..DecomposeSettings::default()
    };
    assert!(decompose_rotation_with(&r, &axes, None, &bad, &mut out3).is_err());
    assert!(DecomposeSettings::default().validate().is_ok());
    assert!(compose_rotation(&axes, &[0.0]).is_err());
}

#[test]
fn rotation_angle_is_precise_near_identity() {
    let q = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 1e-10);
    assert!((rotation_angle(&q) - 1e-10).abs() < 1e-22);
}
