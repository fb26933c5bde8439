//! The keypoint retargeting tick (references, kinematics, box, IKTC or its GF fallback,
//! integration) allocates nothing after setup, checked with a counting global allocator (its
//! own test binary).

use iktc::profile::RobotProfile;
use iktc::retarget::{builtin_motion, keypoint_controller, KeypointSettings};

#[path = "../../iktc-core/tests/common/mod.rs"]
mod common;
use common::alloc as counting_alloc;
use counting_alloc::allocations;

#[global_allocator]
static A: counting_alloc::Counting = counting_alloc::Counting;

#[test]
fn the_keypoint_tick_allocates_nothing_on_jvrc1_and_g1() {
    let kp = builtin_motion("humanoid3d_dance_a")
        .unwrap()
        .keypoints(iktc::motion::DEFAULT_MAX_GAP)
        .unwrap();
    for robot in ["jvrc1", "g1"] {
        let profile = RobotProfile::builtin(robot).unwrap();
        let mut ctl =
            keypoint_controller(&profile, &kp, None, &KeypointSettings::default()).unwrap();
        let n = ctl.ticks();
        let mut qps = 0;
        let before = allocations();
        for _ in 0..100 {
            qps += ctl.tick(0, true).unwrap().qp_solves;
            ctl.integrate().unwrap();
        }
        for k in 0..n {
            qps += ctl.tick(k, false).unwrap().qp_solves;
            ctl.integrate().unwrap();
        }
        let after = allocations();
        assert!(qps > 100, "{robot}: {qps} QPs: the box must bind");
        assert_eq!(
            after - before,
            0,
            "{robot}: {} allocations in {n} ticks",
            after - before
        );
    }
}
