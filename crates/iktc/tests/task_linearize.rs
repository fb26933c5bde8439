//! Tasks: the sign conventions of h, checked by closing the loop on the error dynamics
//! ë + k_v ė + k_p e = 0 (eq. 12), whose critically damped solution is known in closed form.

#[path = "../../iktc-core/tests/common/mod.rs"]
mod common;
use common::model as common_model;
use common::rng;
use common_model::*;

use iktc::model::*;
use iktc::task::*;
use nalgebra::{DMatrix, DVector, Isometry3, Translation3, UnitQuaternion, Vector3};

/// Solves J q̈ = h in the least-squares, minimum-norm sense (SVD; tests only).
fn solve(eq: &TaskEquation) -> DVector<f64> {
    eq.jacobian
        .clone()
        .svd(true, true)
        .solve(&eq.rhs, 1e-12)
        .unwrap()
}

/// Critically damped error e(t) = (e0 + (ė0 + ω e0) t) e^{−ωt}, ω = √k_p.
fn closed_form(e0: f64, ed0: f64, kp: f64, t: f64) -> f64 {
    let w = kp.sqrt();
    (e0 + (ed0 + w * e0) * t) * (-w * t).exp()
}

/// The constant-acceleration integrator is second order: with Δt = 1 ms the simulated error
/// follows the continuous closed form to about k_p Δt · e0 ≈ 1e-3 relative.
const TRACKING_TOL: f64 = 5e-3;

#[test]
fn frame_position_error_follows_eq_12() {
    let robot = planar3r();
    let mut s = State::neutral(&robot);
    s.q = DVector::from_vec(vec![1.5, -1.2, 1.0]);
    let mut t = FrameTask::new(
        &robot,
        "tip",
        Axes([true, true, false, false, false, false]),
        Gains::critical(100.0),
    )
    .unwrap();
    let kin = Kinematics::new(&robot, &s).unwrap();
    let p0 = kin.frame_pose(&robot, t.frame()).unwrap();
    let target = Isometry3::from_parts(
        Translation3::from(p0.translation.vector + Vector3::new(0.05, -0.03, 0.0)),
        p0.rotation,
    );
    t.set_reference(FrameReference::hold(target)).unwrap();
    let mut eq = TaskEquation::zeros("tip", 2, robot.nv());
    let mut task = Task::Frame(t);
    let (e0x, e0y) = (0.05, -0.03);
    let dt = 1e-3;
    let mut kin = kin;
    for step in 0..400 {
        kin.update(&robot, &s).unwrap();
        task.linearize(&robot, &kin, &s, &mut eq, 0).unwrap();
        let time = step as f64 * dt;
        let (ex, ey) = (
            closed_form(e0x, 0.0, 100.0, time),
            closed_form(e0y, 0.0, 100.0, time),
        );
        assert!(
            (eq.error[0] - ex).abs() < TRACKING_TOL * e0x.abs(),
            "t={time}: {} vs {ex}",
            eq.error[0]
        );
        assert!((eq.error[1] - ey).abs() < TRACKING_TOL * e0y.abs());
        let qdd = solve(&eq);
        s.integrate(&robot, &qdd, dt).unwrap();
    }
}

#[test]
fn orientation_and_com_errors_follow_eq_12_on_jvrc1() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let mut s = State::neutral(&robot);
    let kin0 = Kinematics::new(&robot, &s).unwrap();
    let pelvis = robot.frame_id("PELVIS_S").unwrap();
    let p0 = kin0.frame_pose(&robot, pelvis).unwrap();
    let rot_err = Vector3::new(0.04, -0.02, 0.03);
    let target = Isometry3::from_parts(
        p0.translation,
        UnitQuaternion::from_scaled_axis(rot_err) * p0.rotation,
    );
    let mut ft = FrameTask::new(
        &robot,
        "PELVIS_S",
        Axes::ORIENTATION,
        Gains::critical(100.0),
    )
    .unwrap();
    ft.set_reference(FrameReference::hold(target)).unwrap();
    let mut ct = ComTask::new(&robot, [true, true, false], Gains::critical(100.0)).unwrap();
    let c0 = kin0.com();
    ct.set_reference(ComReference {
        position: c0 + Vector3::new(0.02, 0.01, 0.0),
        velocity: Vector3::zeros(),
        acceleration: Vector3::zeros(),
    })
    .unwrap();
    let mut stack = TaskStack::default();
    stack.push("pelvis+com", vec![Task::Frame(ft), Task::Com(ct)]);
    let mut eqs = stack.equations(&robot);
    assert_eq!(eqs[0].dim(), 5);
    let mut kin = kin0;
    let dt = 1e-3;
    let e0 = [rot_err.x, rot_err.y, rot_err.z, 0.02, 0.01];
    for step in 0..300 {
        kin.update(&robot, &s).unwrap();
        stack.linearize(&robot, &kin, &s, &mut eqs).unwrap();
        let time = step as f64 * dt;
        for (k, &e0k) in e0.iter().enumerate() {
            let want = closed_form(e0k, 0.0, 100.0, time);
            // Rotation-vector errors compose non-linearly: allow a little more.
            assert!(
                (eqs[0].error[k] - want).abs() < 2e-2 * e0[k].abs(),
                "row {k} t={time}: {} vs {want}",
                eqs[0].error[k]
            );
        }
        let qdd = solve(&eqs[0]);
        s.integrate(&robot, &qdd, dt).unwrap();
    }
}

/// JVRC-1 at a random state drawn from `seed`, and its kinematics.
fn jvrc1_at_random_state(seed: u64) -> (Robot, State, Kinematics) {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let s = random_state(&mut rng(seed), &robot);
    let kin = Kinematics::new(&robot, &s).unwrap();
    (robot, s, kin)
}

#[test]
fn joint_task_rows_select_joints() {
    let (robot, s, kin) = jvrc1_at_random_state(4);
    let mut jt = JointTask::new(
        &robot,
        &["WAIST_Y", "L_ELBOW_P"],
        Gains { kp: 4.0, kv: 3.0 },
    )
    .unwrap();
    jt.set_reference(&[0.1, -0.5], &[0.2, 0.0], &[1.0, -1.0])
        .unwrap();
    let mut eq = TaskEquation::zeros("j", 2, robot.nv());
    jt.linearize(&robot, &kin, &s, &mut eq, 0).unwrap();
    let iw = robot.joint_v_index("WAIST_Y").unwrap();
    let qw = s.q[robot.joint_q_index("WAIST_Y").unwrap()];
    let mut expected_row = DMatrix::zeros(1, robot.nv());
    expected_row[(0, iw)] = 1.0;
    assert_eq!(eq.jacobian.row(0).into_owned(), expected_row);
    let h = 1.0 + 3.0 * (0.2 - s.qd[iw]) + 4.0 * (0.1 - qw);
    assert!((eq.rhs[0] - h).abs() < 1e-12);
}

/// A weight w scales the joint task's rows, J and h alike (w J q̈ = w h), and leaves its
/// errors as they are; a weight that is not finite and > 0 is refused.
#[test]
fn joint_task_weight_scales_its_rows() {
    let (robot, s, kin) = jvrc1_at_random_state(5);
    let names = ["WAIST_Y", "L_ELBOW_P", "R_KNEE"];
    let mut one = JointTask::new(&robot, &names, Gains { kp: 9.0, kv: 6.0 }).unwrap();
    one.set_reference(&[0.1, -0.5, 0.7], &[0.2, 0.0, -0.1], &[1.0, -1.0, 0.5])
        .unwrap();
    let mut heavy = one.clone();
    heavy.set_weight(0.3).unwrap();
    assert_eq!((one.weight(), heavy.weight()), (1.0, 0.3));
    let mut e1 = TaskEquation::zeros("one", 3, robot.nv());
    let mut ew = TaskEquation::zeros("weighted", 3, robot.nv());
    one.linearize(&robot, &kin, &s, &mut e1, 0).unwrap();
    heavy.linearize(&robot, &kin, &s, &mut ew, 0).unwrap();
    // One multiplication by w per entry: equal to rounding of the product.
    assert!((&ew.jacobian - &e1.jacobian * 0.3).abs().max() < 1e-15);
    assert!((&ew.rhs - &e1.rhs * 0.3).abs().max() < 1e-12);
    assert_eq!(ew.error, e1.error);
    for w in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = heavy.set_weight(w).unwrap_err().to_string();
        assert!(e.contains("weight"), "{e}");
    }
    assert_eq!(
        heavy.weight(),
        0.3,
        "a refused weight leaves the task as it was"
    );
}

#[test]
fn tasks_reject_bad_input() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let e = FrameTask::new(&robot, "no_such_frame", Axes::ALL, Gains::default()).unwrap_err();
    let msg = e.to_string();
    // The valid names are listed, the ten nearest and how many more.
    assert!(
        msg.contains("no_such_frame") && msg.contains("valid names") && msg.contains("more"),
        "{msg}"
    );
    let e = JointTask::new(&robot, &["R_UTHUMB"], Gains::default()).unwrap_err();
    assert!(e.to_string().contains("locked"), "{e}");
    let mut jt = JointTask::new(&robot, &["WAIST_Y"], Gains::default()).unwrap();
    assert!(matches!(
        jt.set_reference(&[f64::NAN], &[0.0], &[0.0]),
        Err(iktc::Error::NonFinite { .. })
    ));
    assert!(matches!(
        jt.set_reference(&[0.0, 1.0], &[0.0], &[0.0]),
        Err(iktc::Error::DimensionMismatch { .. })
    ));
    assert!(FrameTask::new(&robot, "PELVIS_S", Axes([false; 6]), Gains::default()).is_err());
    assert!(ComTask::new(&robot, [true, false, false], Gains { kp: -1.0, kv: 0.0 }).is_err());
    let s = State::neutral(&robot);
    let kin = Kinematics::new(&robot, &s).unwrap();
    let mut eq = TaskEquation::zeros("too small", 1, robot.nv());
    let mut ft = FrameTask::new(&robot, "PELVIS_S", Axes::ALL, Gains::default()).unwrap();
    assert!(matches!(
        ft.linearize(&robot, &kin, &s, &mut eq, 0),
        Err(iktc::Error::DimensionMismatch { .. })
    ));
}
