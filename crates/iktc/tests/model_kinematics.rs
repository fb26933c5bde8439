//! Kinematics against finite differences and closed forms.

#[path = "../../iktc-core/tests/common/mod.rs"]
mod common;
use common::model as common_model;
use common::rng;
use common_model::*;
use iktc::model::RobotFiles;

use iktc::model::*;
use nalgebra::{DMatrix, DVector, Matrix4, Vector3};

/// Central differences with step 1e-6 have truncation error O(ε²) ≈ 1e-12 · (third
/// derivative) and round-off ≈ 1e-16 / 1e-6 = 1e-10 per unit of position: 1e-6 leaves a
/// margin of 100× on metre-sized robots.
const FD_JACOBIAN_TOL: f64 = 1e-6;
const FD_EPS: f64 = 1e-6;
/// The drift is checked by a central difference of J q̇ along q̇ (step 1e-5: round-off
/// ≈ 1e-15 / 1e-5 = 1e-10 · |v|, truncation ≈ 1e-10 · |jerk|); velocities here are O(1–10).
const FD_DRIFT_EPS: f64 = 1e-5;
const FD_DRIFT_TOL: f64 = 1e-5;

fn check_frame(robot: &Robot, s: &State, f: FrameId) {
    let kin = Kinematics::new(robot, s).unwrap();
    let mut j = DMatrix::zeros(6, robot.nv());
    kin.frame_jacobian(robot, f, &mut j).unwrap();
    let jfd = fd_frame_jacobian(robot, s, f, FD_EPS);
    let err = (&j - &jfd).abs().max();
    assert!(
        err < FD_JACOBIAN_TOL,
        "frame {f:?}: |J − J_fd| = {err}\nJ = {j}\nJfd = {jfd}"
    );
    // Velocity is J q̇.
    let v = kin.frame_velocity(robot, f).unwrap();
    let jv = &j * &s.qd;
    assert!((v - &jv).abs().max() < 1e-9 * (1.0 + jv.abs().max()));
    // Drift: d/dt (J q̇) along q(t) = q ⊕ t q̇ with q̈ = 0.
    let vel = |t: f64| {
        let st = displaced(robot, s, &s.qd, t);
        Kinematics::new(robot, &st)
            .unwrap()
            .frame_velocity(robot, f)
            .unwrap()
    };
    let fd = (vel(FD_DRIFT_EPS) - vel(-FD_DRIFT_EPS)) / (2.0 * FD_DRIFT_EPS);
    let d = kin.frame_drift(robot, f).unwrap();
    assert!(
        (d - fd).abs().max() < FD_DRIFT_TOL * (1.0 + fd.abs().max()),
        "frame {f:?}: drift {d} vs fd {fd}"
    );
    // Position's second difference, independent of the Jacobian code.
    let pos = |t: f64| {
        let st = displaced(robot, s, &s.qd, t);
        Kinematics::new(robot, &st)
            .unwrap()
            .frame_pose(robot, f)
            .unwrap()
            .translation
            .vector
    };
    let h = 1e-4;
    let acc = (pos(h) - 2.0 * pos(0.0) + pos(-h)) / (h * h);
    // Second differences: round-off 1e-16/1e-8 = 1e-8 · |p|, truncation h² · |p''''|.
    assert!(
        (d.fixed_rows::<3>(0) - acc).abs().max() < 1e-4 * (1.0 + acc.abs().max()),
        "frame {f:?}: linear drift {} vs second difference {acc}",
        d.fixed_rows::<3>(0)
    );
}

fn check_com(robot: &Robot, s: &State) {
    let kin = Kinematics::new(robot, s).unwrap();
    let mut j = DMatrix::zeros(3, robot.nv());
    kin.com_jacobian(robot, &mut j).unwrap();
    let jfd = fd_com_jacobian(robot, s, FD_EPS);
    let err = (&j - &jfd).abs().max();
    assert!(err < FD_JACOBIAN_TOL, "|Jcom − fd| = {err}");
    assert!(
        (kin.com_velocity() - &j * &s.qd).abs().max() < 1e-9 * (1.0 + kin.com_velocity().norm())
    );
    let vel = |t: f64| {
        let st = displaced(robot, s, &s.qd, t);
        Kinematics::new(robot, &st).unwrap().com_velocity()
    };
    let fd = (vel(FD_DRIFT_EPS) - vel(-FD_DRIFT_EPS)) / (2.0 * FD_DRIFT_EPS);
    let d = kin.com_drift();
    assert!(
        (d - fd).abs().max() < FD_DRIFT_TOL * (1.0 + fd.abs().max()),
        "COM drift {d} vs {fd}"
    );
}

#[test]
fn jvrc1_jacobians_and_drifts_match_finite_differences() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    assert_eq!(robot.nv(), 38);
    assert_eq!(robot.nq(), 39);
    let mut r = rng(7);
    let frames = ["r_ankle", "l_ankle", "PELVIS_S", "R_WRIST_Y_S", "NECK_P_S"];
    for _ in 0..5 {
        let s = random_state(&mut r, &robot);
        for name in frames {
            check_frame(&robot, &s, robot.frame_id(name).unwrap());
        }
        check_com(&robot, &s);
    }
}

#[test]
fn random_trees_match_finite_differences() {
    let mut r = rng(11);
    for case in 0..40 {
        let base = if case % 2 == 0 {
            BaseKind::Floating
        } else {
            BaseKind::Fixed
        };
        let robot = random_tree(&mut r, 2 + case % 9, base);
        let s = random_state(&mut r, &robot);
        check_frame(&robot, &s, robot.frame_id("tool").unwrap());
        check_frame(&robot, &s, FrameId(r_index(&robot)));
        check_com(&robot, &s);
    }
}

fn r_index(robot: &Robot) -> usize {
    robot.links().len() / 2
}

#[test]
fn planar3r_matches_closed_form() {
    let robot = planar3r();
    let deg = std::f64::consts::PI / 180.0;
    let tip = robot.frame_id("tip").unwrap();
    // Errata 2.1: q(t0) = (90°, −90°, 90°) gives P = (1, 2), θ3 = 90°.
    let mut s = State::neutral(&robot);
    s.q = DVector::from_vec(vec![90.0 * deg, -90.0 * deg, 90.0 * deg]);
    let kin = Kinematics::new(&robot, &s).unwrap();
    let t = kin.frame_pose(&robot, tip).unwrap();
    assert!((t.translation.vector - Vector3::new(1.0, 2.0, 0.0)).norm() < 1e-12);
    assert!((t.rotation.angle() - 90.0 * deg).abs() < 1e-12);
    // General closed form on random configurations.
    let mut r = rng(3);
    for _ in 0..100 {
        let s = random_state(&mut r, &robot);
        let (a, b, c) = (s.q[0], s.q[0] + s.q[1], s.q[0] + s.q[1] + s.q[2]);
        let p = Vector3::new(
            a.cos() + b.cos() + c.cos(),
            a.sin() + b.sin() + c.sin(),
            0.0,
        );
        let kin = Kinematics::new(&robot, &s).unwrap();
        let t = kin.frame_pose(&robot, tip).unwrap();
        assert!((t.translation.vector - p).norm() < 1e-12);
        let (roll, pitch, yaw) = t.rotation.euler_angles();
        assert!(roll.abs() < 1e-12 && pitch.abs() < 1e-12);
        assert!(
            ((yaw - c + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                - std::f64::consts::PI)
                .abs()
                < 1e-9
        );
    }
}

/// exp of the 4×4 twist matrix, computed by nalgebra's general matrix exponential: an
/// independent reference for the closed-form SE(3) exponential.
fn matrix_exp_twist(v: &Vector3<f64>, w: &Vector3<f64>) -> Matrix4<f64> {
    let mut m = Matrix4::zeros();
    m.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&iktc::model::spatial::skew(w));
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(v);
    m.exp()
}

#[test]
fn constant_twist_integrates_to_the_se3_exponential() {
    let robot = random_tree(&mut rng(1), 1, BaseKind::Floating);
    let mut r = rng(5);
    for _ in 0..10 {
        let mut s = random_state(&mut r, &robot);
        let t0 = s.base_pose(&robot);
        let (v, w) = (rand_vec3(&mut r, 1.0), rand_vec3(&mut r, 2.0));
        for k in 0..3 {
            s.qd[k] = v[k];
            s.qd[3 + k] = w[k];
        }
        let (n, dt) = (1000, 1e-3);
        for _ in 0..n {
            s.integrate(&robot, &DVector::zeros(robot.nv()), dt)
                .unwrap();
        }
        let t = n as f64 * dt;
        let expected = t0.to_homogeneous() * matrix_exp_twist(&(v * t), &(w * t));
        let got = s.base_pose(&robot).to_homogeneous();
        assert!((got - expected).abs().max() < 1e-9, "{got} vs {expected}");
        // Closed form equals the matrix exponential too.
        let closed = iktc::model::spatial::se3_exp(&(v * t), &(w * t)).to_homogeneous();
        assert!((closed - matrix_exp_twist(&(v * t), &(w * t))).abs().max() < 1e-12);
    }
    // Small angles use the Taylor branch.
    let (v, w) = (
        Vector3::new(0.3, -0.2, 0.1),
        Vector3::new(1e-6, -2e-6, 3e-7),
    );
    let closed = iktc::model::spatial::se3_exp(&v, &w).to_homogeneous();
    assert!((closed - matrix_exp_twist(&v, &w)).abs().max() < 1e-14);
}

#[test]
fn joint_integration_is_constant_acceleration() {
    let robot = planar3r();
    let mut s = State::neutral(&robot);
    s.q = DVector::from_vec(vec![1.5, 0.1, -0.2]);
    s.qd = DVector::from_vec(vec![0.3, -0.1, 0.2]);
    let a = DVector::from_vec(vec![2.0, -1.0, 0.5]);
    let dt = 0.01;
    let (q0, v0) = (s.q.clone(), s.qd.clone());
    s.integrate(&robot, &a, dt).unwrap();
    assert!((&s.q - (&q0 + &v0 * dt + &a * (0.5 * dt * dt))).norm() < 1e-15);
    assert!((&s.qd - (&v0 + &a * dt)).norm() < 1e-15);
}

#[test]
fn jvrc1_summary_values() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    // Total mass: the sum of every <mass value="..."/> in the file, parsed independently.
    let text = iktc::model::JVRC1_URDF;
    let m: f64 = text
        .split("<mass value=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap().parse::<f64>().unwrap())
        .sum();
    assert!((robot.total_mass() - m).abs() < 1e-9);
    assert!(
        (m - 62.4).abs() < 0.5,
        "NOTICE says 62.4 kg, file sums to {m}"
    );
    assert_eq!(robot.n_active(), 32);
    // Neutral pose: COM above the pelvis origin region, below the head.
    let s = State::neutral(&robot);
    let kin = Kinematics::new(&robot, &s).unwrap();
    let com = kin.com();
    let foot = kin
        .frame_pose(&robot, robot.frame_id("r_ankle").unwrap())
        .unwrap();
    assert!(
        com.z > foot.translation.z + 0.5,
        "COM {com} vs ankle {}",
        foot.translation.vector
    );
    // Legs: the right ankle is at negative y, the left at positive y.
    let lf = kin
        .frame_pose(&robot, robot.frame_id("l_ankle").unwrap())
        .unwrap();
    assert!(foot.translation.y < 0.0 && lf.translation.y > 0.0);
}

#[test]
fn mimic_joints_follow_their_master() {
    // Unlock the fingers' master R_UTHUMB: its mimics follow it.
    let mut o = ModelOptions {
        base: BaseKind::Fixed,
        ..Default::default()
    };
    for f in JVRC1_FINGERS.iter().filter(|f| f.starts_with("L_")) {
        o.locked.push((f.to_string(), 0.0));
    }
    let robot = Robot::from_urdf_str(JVRC1_URDF, &o).unwrap();
    let n_mimic = robot
        .joints()
        .iter()
        .filter(|j| matches!(j.role, JointRole::Mimic { .. }))
        .count();
    assert_eq!(n_mimic, 5, "R_UTHUMB drives 5 mimics");
    let mut r = rng(2);
    let s = random_state(&mut r, &robot);
    for name in ["R_LLITTLE_S", "R_LTHUMB_S"] {
        if let Ok(f) = robot.frame_id(name) {
            check_frame(&robot, &s, f);
        }
    }
}
