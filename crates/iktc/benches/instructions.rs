//! Instruction counts of the control ticks and of a clip's retargeting, by Valgrind's
//! Callgrind through gungraun: figures that stay put on a shared machine, where the wall-clock
//! benches (`peer_problem`, `retarget_tick`, `batch`) move by ±20 % from run to run. Each
//! benchmark runs once under Callgrind, its setup (model, controller, warm-up) not counted, nor
//! the drop of the controller it returns.
//!
//! - `peer_problem`: 100 steps of the peer problem (`peer/problem.rs`, IKTC) after its 50
//!   warm-up steps, as shipped (level 5: 20 joints, 38 rows for n = 38) and with one joint
//!   left out of level 5 (37 rows).
//! - `keypoint_tick`: 100 ticks of the keypoint retargeting of `humanoid3d_dance_b` onto G1
//!   (the `retarget_tick` bench's controller, settled on the first frame), from tick 100.
//! - `retarget_clip`: `BatchRetarget::retarget` of the shared DeepMimic walk onto G1 by the
//!   default route (reading, plan, settling, every tick, quality figures), 1 frame of output
//!   per 200 Hz tick; divide by the clip's frames (printed by the `batch` bench) for the count
//!   per frame.
//!
//! Needs `valgrind` and the runner of the same version as the `gungraun` dev-dependency:
//! `cargo install gungraun-runner --version 0.20.0 --locked`, then
//! `cargo bench -p iktc --bench instructions`.

use std::hint::black_box;
use std::path::PathBuf;

use gungraun::{library_benchmark, library_benchmark_group, main};
use iktc::batch::BatchRetarget;
use iktc::limits::BoundMethod;
use iktc::model::ModelOptions;
use iktc::profile::RobotProfile;
use iktc::retarget::{builtin_motion, keypoint_controller, KeypointController, KeypointSettings};
use iktc::sim::ImitateConfig;
use iktc::solver::{Method, SolverSettings};

#[path = "peer/problem.rs"]
mod peer;
use peer::{PeerProblem, UPPER_BODY, WARMUP};

/// Steps or ticks counted per benchmark.
const COUNTED: usize = 100;

fn peer_warmed(joints: usize) -> PeerProblem {
    let mut p = PeerProblem::with_upper_body(
        Method::Iktc,
        SolverSettings::default(),
        BoundMethod::viable(),
        &ModelOptions::default(),
        &UPPER_BODY[..joints],
    )
    .expect("peer problem");
    for _ in 0..WARMUP {
        p.step().expect("warm-up step");
    }
    p
}

#[library_benchmark]
#[bench::rows_38(setup = peer_warmed, args = (20))]
#[bench::rows_37(setup = peer_warmed, args = (19))]
fn peer_problem(mut p: PeerProblem) -> PeerProblem {
    for _ in 0..COUNTED {
        black_box(p.step().expect("step").qp_solves);
    }
    p
}

/// The keypoint controller of `humanoid3d_dance_b` on G1, settled on the first frame and run
/// to tick 100.
fn keypoint_start() -> KeypointController {
    let profile = RobotProfile::builtin("g1").expect("g1");
    let kp = builtin_motion("humanoid3d_dance_b")
        .and_then(|m| m.keypoints(iktc::motion::DEFAULT_MAX_GAP))
        .expect("keypoints");
    let mut ctl =
        keypoint_controller(&profile, &kp, None, &KeypointSettings::default()).expect("controller");
    for _ in 0..300 {
        ctl.tick(0, true).expect("settle");
        ctl.integrate().expect("integrate");
    }
    for k in 0..100 {
        ctl.tick(k, false).expect("tick");
        ctl.integrate().expect("integrate");
    }
    ctl
}

#[library_benchmark]
#[bench::g1_dance_b(setup = keypoint_start)]
fn keypoint_tick(mut ctl: KeypointController) -> KeypointController {
    for k in 100..100 + COUNTED {
        black_box(ctl.tick(k, false).expect("tick").qp_solves);
        ctl.integrate().expect("integrate");
    }
    ctl
}

/// The batch retargeting of G1 and the shared walk clip's path.
fn clip_setup() -> (BatchRetarget, PathBuf) {
    let profile = RobotProfile::builtin("g1").expect("g1");
    let b = BatchRetarget::from_profile(profile, ImitateConfig::default()).expect("batch");
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data/motions/deepmimic/humanoid3d_walk.txt");
    (b, path)
}

#[library_benchmark]
#[bench::g1_walk(setup = clip_setup)]
fn retarget_clip((b, path): (BatchRetarget, PathBuf)) -> usize {
    black_box(b.retarget(&path).expect("retarget").trajectory.len())
}

library_benchmark_group!(
    name = ticks;
    benchmarks = peer_problem, keypoint_tick, retarget_clip
);

main!(library_benchmark_groups = ticks);
