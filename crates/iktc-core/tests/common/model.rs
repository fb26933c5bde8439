//! Shared helpers for model tests: random trees and finite differences.

use iktc_core::model::*;
use nalgebra::{DMatrix, DVector, Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub fn rand_vec3(r: &mut ChaCha8Rng, s: f64) -> Vector3<f64> {
    Vector3::new(
        r.random_range(-s..s),
        r.random_range(-s..s),
        r.random_range(-s..s),
    )
}

pub fn rand_rot(r: &mut ChaCha8Rng) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(rand_vec3(r, 3.0))
}

/// A random tree of `n` joints (revolute, prismatic, fixed; rotated axes), each child
/// attached to a random earlier link.
pub fn random_tree(r: &mut ChaCha8Rng, n: usize, base: BaseKind) -> Robot {
    let mut b = RobotBuilder::new("random").link(Link {
        name: "l0".into(),
        mass: 2.0,
        com: rand_vec3(r, 0.1),
        inertia: nalgebra::Matrix3::identity() * 0.01,
    });
    for i in 1..=n {
        let parent = r.random_range(0..i);
        let kind = match r.random_range(0..10) {
            0..=5 => JointKind::Revolute {
                axis: Unit::new_normalize(rand_vec3(r, 1.0) + Vector3::new(0.0, 0.0, 1e-3)),
            },
            6..=8 => JointKind::Prismatic {
                axis: Unit::new_normalize(rand_vec3(r, 1.0) + Vector3::new(1e-3, 0.0, 0.0)),
            },
            _ => JointKind::Fixed,
        };
        b = b
            .link(Link {
                name: format!("l{i}"),
                mass: r.random_range(0.1..3.0),
                com: rand_vec3(r, 0.2),
                inertia: nalgebra::Matrix3::identity() * 0.01,
            })
            .joint(JointSpec {
                name: format!("j{i}"),
                parent: format!("l{parent}"),
                child: format!("l{i}"),
                origin: Isometry3::from_parts(Translation3::from(rand_vec3(r, 0.5)), rand_rot(r)),
                kind,
                limit: JointLimit {
                    lower: -2.0,
                    upper: 2.0,
                    velocity: 5.0,
                    acceleration: 50.0,
                    jerk: f64::INFINITY,
                    effort: 10.0,
                },
                mimic: None,
            });
    }
    b = b.frame(
        "tool",
        format!("l{n}"),
        Isometry3::from_parts(Translation3::from(rand_vec3(r, 0.3)), rand_rot(r)),
    );
    b.build(&ModelOptions {
        base,
        ..Default::default()
    })
    .expect("random tree is valid")
}

/// A random state: base pose and joints in range, random velocities.
pub fn random_state(r: &mut ChaCha8Rng, robot: &Robot) -> State {
    let mut s = State::neutral(robot);
    if robot.base() == BaseKind::Floating {
        let pose = Isometry3::from_parts(Translation3::from(rand_vec3(r, 1.0)), rand_rot(r));
        s.set_base_pose(robot, &pose).unwrap();
    }
    for (i, j) in robot.active_joints().enumerate() {
        let lo = j.limit.lower.max(-3.0);
        let hi = j.limit.upper.min(3.0);
        s.q[robot.base_nq() + i] = if hi > lo { r.random_range(lo..hi) } else { lo };
    }
    for k in 0..robot.nv() {
        s.qd[k] = r.random_range(-2.0..2.0);
    }
    s
}

/// q ⊕ t·dir with the model's own integrator under zero acceleration (exact for joints,
/// the SE(3) exponential for the base).
pub fn displaced(robot: &Robot, s: &State, dir: &DVector<f64>, t: f64) -> State {
    let mut x = s.clone();
    if t == 0.0 {
        return x;
    }
    x.qd = dir * t.signum();
    x.integrate(robot, &DVector::zeros(robot.nv()), t.abs())
        .unwrap();
    x.qd = s.qd.clone();
    x
}

pub fn rotation_difference(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> Vector3<f64> {
    (a * b.inverse()).scaled_axis()
}

/// Central-difference Jacobian of a frame (rows v then ω, world axes).
pub fn fd_frame_jacobian(robot: &Robot, s: &State, f: FrameId, eps: f64) -> DMatrix<f64> {
    let nv = robot.nv();
    let mut j = DMatrix::zeros(6, nv);
    for k in 0..nv {
        let mut e = DVector::zeros(nv);
        e[k] = 1.0;
        let kp = Kinematics::new(robot, &displaced(robot, s, &e, eps)).unwrap();
        let km = Kinematics::new(robot, &displaced(robot, s, &e, -eps)).unwrap();
        let (tp, tm) = (
            kp.frame_pose(robot, f).unwrap(),
            km.frame_pose(robot, f).unwrap(),
        );
        let dv = (tp.translation.vector - tm.translation.vector) / (2.0 * eps);
        let dw = rotation_difference(&tp.rotation, &tm.rotation) / (2.0 * eps);
        for r in 0..3 {
            j[(r, k)] = dv[r];
            j[(r + 3, k)] = dw[r];
        }
    }
    j
}

pub fn fd_com_jacobian(robot: &Robot, s: &State, eps: f64) -> DMatrix<f64> {
    let nv = robot.nv();
    let mut j = DMatrix::zeros(3, nv);
    for k in 0..nv {
        let mut e = DVector::zeros(nv);
        e[k] = 1.0;
        let cp = Kinematics::new(robot, &displaced(robot, s, &e, eps))
            .unwrap()
            .com();
        let cm = Kinematics::new(robot, &displaced(robot, s, &e, -eps))
            .unwrap()
            .com();
        j.set_column(k, &((cp - cm) / (2.0 * eps)));
    }
    j
}
