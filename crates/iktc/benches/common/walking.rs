//! The walking-imitation closed loop shared by the benches: JVRC-1 imitating the default clip
//! while it walks, with the simulated compliant robot of the walking run ([`WalkPlants`])
//! giving the measured ZMP.

use iktc::model::{jvrc1, ModelOptions, Robot};
use iktc::motion::{builtin_clip, builtin_map, RobotReferences};
use iktc::sim::{
    imitation_references, ImitateConfig, WalkImitateConfig, WalkPlants, WalkingController,
};

/// JVRC-1 and the references of the default imitation run.
pub fn imitation_setup() -> (Robot, RobotReferences) {
    let robot = jvrc1(&ModelOptions::default()).expect("JVRC-1");
    let clip = builtin_clip("humanoid3d_dance_b").expect("clip");
    let map = builtin_map("deepmimic_jvrc1").expect("map");
    let refs =
        imitation_references(&robot, &clip, &map, &ImitateConfig::default()).expect("references");
    (robot, refs)
}

/// The default walking controller and its simulated robot ([`WalkPlants`], the walking run's
/// own: models switched with the phase, the default push).
pub fn walking_setup(robot: &Robot, refs: &RobotReferences) -> (WalkingController, WalkPlants) {
    let cfg = WalkImitateConfig::jvrc1().expect("config");
    let wc = WalkingController::new(robot, refs, &cfg).expect("walking controller");
    let plants = WalkPlants::new(&wc, robot.total_mass(), &cfg).expect("plants");
    (wc, plants)
}
