//! A controller's tick (prepare, solve, integrate; references set through handles) allocates
//! nothing, checked with the shared counting allocator (its own test binary).

use iktc::prelude::*;

#[path = "../../iktc-core/tests/common/mod.rs"]
mod common;
use common::alloc as counting_alloc;
use counting_alloc::allocations;

#[global_allocator]
static A: counting_alloc::Counting = counting_alloc::Counting;

#[test]
fn the_controller_tick_allocates_nothing() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    let mut state = State::neutral(&robot);
    for (joint, q) in [("HIP_P", -0.4), ("KNEE", 0.8), ("ANKLE_P", -0.4)] {
        for side in ["R", "L"] {
            state
                .set_joint(&robot, &format!("{side}_{joint}"), q)
                .unwrap();
        }
    }
    state.set_joint(&robot, "R_ELBOW_P", -0.5).unwrap();
    for method in [Method::Iktc, Method::Cascade] {
        let mut b = Controller::builder(robot.clone(), &state).unwrap();
        b.settings(ControllerSettings {
            method,
            ..ControllerSettings::default()
        });
        let feet = [
            b.level("feet").frame("r_ankle", Axes::ALL).unwrap(),
            b.frame("l_ankle", Axes::ALL).unwrap(),
        ];
        let com = b.level("com").com([true, true, false]).unwrap();
        let arm = b.level("arm").joints(&["R_ELBOW_P", "WAIST_Y"]).unwrap();
        let com0 = b.kinematics().com();
        let mut ctl = b.build().unwrap();
        let foot = ctl.frame(feet[0]).unwrap().reference;
        let mut s = state.clone();
        let mut qps = 0;
        let before = allocations();
        for tick in 0..400 {
            let x = (tick as f64 * 0.02).sin();
            // The elbow is sent past its upper limit (0 rad): the box binds, the solver corrects.
            ctl.set_joints_reference(arm, &[0.3, 0.4 * x], &[0.0; 2], &[0.0; 2])
                .unwrap();
            ctl.set_com_reference(
                com,
                ComReference::hold(com0 + Vector3::new(0.02 * x, 0.0, 0.0)),
            )
            .unwrap();
            ctl.set_frame_reference(feet[0], foot).unwrap();
            if tick % 2 == 0 {
                qps += ctl.step(&mut s, 0.005).unwrap().qp_solves;
            } else {
                ctl.prepare(&s, 0.005).unwrap();
                let _ = (ctl.equations().len(), ctl.bounds().nv());
                qps += ctl.solve().unwrap().qp_solves;
                ctl.integrate(&mut s).unwrap();
            }
        }
        let after = allocations();
        assert!(qps > 50, "{method:?}: the box must bind ({qps} QPs)");
        assert_eq!(
            after - before,
            0,
            "{method:?}: {} allocations",
            after - before
        );
    }
}
