//! The control tick allocates nothing: kinematics and task linearisation on a built model,
//! checked with a counting global allocator (its own test binary).

use iktc::model::*;
use iktc::task::*;
use nalgebra::DMatrix;

#[path = "../../iktc-core/tests/common/mod.rs"]
mod common;
use common::alloc as counting_alloc;
use counting_alloc::allocations as count;

#[global_allocator]
static A: counting_alloc::Counting = counting_alloc::Counting;

#[test]
fn kinematics_and_tasks_allocate_nothing() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let mut s = State::neutral(&robot);
    s.qd.fill(0.3);
    let mut kin = Kinematics::new(&robot, &s).unwrap();
    let g = Gains::default();
    let mut stack = TaskStack::default();
    stack.push(
        "feet",
        vec![
            Task::Frame(FrameTask::new(&robot, "r_ankle", Axes::ALL, g).unwrap()),
            Task::Frame(FrameTask::new(&robot, "l_ankle", Axes::ALL, g).unwrap()),
        ],
    );
    stack.push(
        "com",
        vec![Task::Com(
            ComTask::new(&robot, [true, true, false], g).unwrap(),
        )],
    );
    stack.push(
        "pelvis",
        vec![Task::Frame(
            FrameTask::new(&robot, "PELVIS_S", Axes::ORIENTATION, g).unwrap(),
        )],
    );
    stack.push(
        "upper",
        vec![Task::Joint(
            JointTask::new(&robot, &["WAIST_Y", "NECK_Y"], g).unwrap(),
        )],
    );
    let mut eqs = stack.equations(&robot);
    let mut j6 = DMatrix::zeros(6, robot.nv());
    let mut j3 = DMatrix::zeros(3, robot.nv());
    let foot = robot.frame_id("r_ankle").unwrap();
    let before = count();
    for k in 0..10 {
        s.q[7 + k] += 0.01;
        kin.update(&robot, &s).unwrap();
        kin.frame_jacobian(&robot, foot, &mut j6).unwrap();
        let _ = kin.frame_drift(&robot, foot).unwrap();
        kin.com_jacobian(&robot, &mut j3).unwrap();
        stack.linearize(&robot, &kin, &s, &mut eqs).unwrap();
    }
    let after = count();
    assert_eq!(
        after - before,
        0,
        "the tick allocated {} times",
        after - before
    );
}
