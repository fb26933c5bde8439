//! A cheap subset of the issue-11 sweep (`examples/sweep.rs`): the punch clip with each solver
//! at Δt = 10 ms, viable bounds: no limit exceeded (in-step peaks included), no empty box.

use iktc::model::{jvrc1, ModelOptions};
use iktc::sim::sweep::{sweep_case, SWEEP_METHODS};

/// Rounding allowed on a limit \[rad\], \[rad/s\], \[rad/s²\]: the solvers accept a q̈
/// outside the box by up to `SolverSettings::box_tolerance` (1e-9 rad/s²).
const LIMIT_ROUNDING: f64 = 1e-6;

#[test]
fn punch_at_10_ms_stays_inside_every_limit() {
    let robot = jvrc1(&ModelOptions::default()).unwrap();
    for method in SWEEP_METHODS {
        let r = sweep_case(&robot, "humanoid3d_punch", method, 0.01).unwrap();
        println!("{r:?}");
        assert!(r.steps > 0);
        assert!(r.position_excursion <= LIMIT_ROUNDING, "{r:?}");
        assert!(r.velocity_excursion <= LIMIT_ROUNDING, "{r:?}");
        assert!(r.acceleration_excursion <= LIMIT_ROUNDING, "{r:?}");
        assert_eq!(r.empty_box_steps, 0, "{r:?}");
    }
}
