//! Scenarios: the paper's experiments as runnable, recorded simulations.

#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub mod experiment;
pub mod health;
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub mod imitate;
pub mod margins;
pub mod planar3r;
pub mod smoothness;
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub mod sweep;
pub mod switches;
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub mod viewer;
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub mod viewer_mesh;
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub mod walk_imitate;
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub mod walk_plants;

#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub use experiment::{load_clip, load_map, Experiment, LoadedClip};
pub use health::{HealthCheck, HealthIssue, HealthMonitor, HealthReport, HealthSettings, Verdict};
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub use imitate::{
    imitation_references, run_imitate, ImitateConfig, ImitateRun, ImitateStep, ImitateSummary,
    ImitationController, ImitationTasks, IMITATE_LEVEL_HOLD, IMITATE_SMOOTHING,
};
pub use margins::{dof_margins, held_limit, median, percentile, DofMargins, JointMargin};
pub use planar3r::{
    run_planar3r, ArmTask, Planar3rConfig, Planar3rRun, Planar3rStep, Planar3rSummary,
};
pub use smoothness::{DofSmoothness, JointSmoothness};
pub use switches::LevelSwitches;
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub use walk_imitate::{
    run_walk_imitate, Push, PushAxisMetrics, WalkImitateConfig, WalkPushSummary, WalkRun, WalkStep,
    WalkSummary, WalkTick, WalkingController,
};
#[cfg(all(feature = "urdf", feature = "json", feature = "toml"))]
pub use walk_plants::WalkPlants;
