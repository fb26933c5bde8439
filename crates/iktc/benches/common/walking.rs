//! The walking-imitation closed loop shared by the benches: JVRC-1 imitating the default clip
//! while it walks, with the simulated compliant robot (one IPCJ plant per plane) giving the
//! measured ZMP.

use iktc::balance::{Plane, PlantParams, SimPlant, SimSettings, SupportPhase};
use iktc::model::{jvrc1, ModelOptions, Robot};
use iktc::motion::{builtin_clip, builtin_map, RobotReferences};
use iktc::sim::{
    imitation_references, ImitateConfig, WalkImitateConfig, WalkTick, WalkingController,
};
use nalgebra::{Rotation2, Vector2};

/// JVRC-1 and the references of the default imitation run.
pub fn imitation_setup() -> (Robot, RobotReferences) {
    let robot = jvrc1(&ModelOptions::default()).expect("JVRC-1");
    let clip = builtin_clip("humanoid3d_dance_b").expect("clip");
    let map = builtin_map("deepmimic_jvrc1").expect("map");
    let refs =
        imitation_references(&robot, &clip, &map, &ImitateConfig::default()).expect("references");
    (robot, refs)
}

/// The default walking controller and its two plants (double-support parameters, 1 ms step).
pub fn walking_setup(robot: &Robot, refs: &RobotReferences) -> (WalkingController, [SimPlant; 2]) {
    let cfg = WalkImitateConfig::jvrc1().expect("config");
    let wc = WalkingController::new(robot, refs, &cfg).expect("walking controller");
    let cases = *wc.cases();
    let plants = [Plane::Xz, Plane::Yz].map(|plane| {
        SimPlant::new(
            PlantParams::from_model(
                *cases.get(plane, SupportPhase::Double),
                robot.total_mass(),
                1e-3,
            ),
            &SimSettings::default(),
        )
        .expect("plant")
    });
    (wc, plants)
}

/// Drives the plants with the COM the tick commanded (its deviation from the nominal COM in
/// the local frame, over the pendulum length), after [`WalkingController::integrate`].
pub fn feed_plants(wc: &WalkingController, wt: &WalkTick, plants: &mut [SimPlant; 2]) {
    let com = wc.imitation().kinematics().com();
    let d = Rotation2::new(wt.local_yaw).inverse() * (Vector2::new(com.x, com.y) - wt.com_nominal);
    let l = wc.pendulum_length();
    for (i, p) in plants.iter_mut().enumerate() {
        let _ = p.advance(d[i] / l);
    }
}
