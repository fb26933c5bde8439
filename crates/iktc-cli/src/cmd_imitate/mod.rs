//! `iktc imitate`: the humanoid imitation experiment of Section 5.3 (Table 1, Figs. 18–21).

use std::path::PathBuf;

use anyhow::{Context, Result};
use iktc::sim::ImitateRun;

use crate::scenario::{health_text, prepare, prepare_config, ScenarioArgs};

mod section;
mod write;

pub use section::imitate_section;
use write::write_imitate;

/// Arguments of `iktc imitate`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Retargeting: body keypoints tracked by a task stack (with the joint route's figures
    /// beside them), or the paper's joint-angle route (figures, summary and 3D viewer).
    #[arg(long, value_enum, default_value = "keypoints")]
    pub retarget: crate::cmd_keypoints::RetargetArg,
    #[command(flatten)]
    pub keypoints: crate::cmd_keypoints::KeypointArgs,
    /// Output directory.
    #[arg(long, default_value = "out/imitate")]
    pub out: PathBuf,
    /// Walking moved to its own command, `iktc walk` (kept only to say so).
    #[arg(long, hide = true)]
    pub walk: bool,
}

/// Runs `iktc imitate`.
pub fn run(a: &Args) -> Result<()> {
    if a.walk {
        anyhow::bail!(
            "`iktc imitate --walk` is now `iktc walk` (same options, plus --steps, --step-length, --push, --no-damping)"
        );
    }
    if a.retarget == crate::cmd_keypoints::RetargetArg::Keypoints {
        let (resolved, mut cfg) = prepare_config(&a.scenario)?;
        a.keypoints.apply(a.retarget, &mut cfg)?;
        let profile = resolved
            .profile
            .as_ref()
            .context("`planar3r` has no profile and cannot imitate a motion")?;
        let sc = &a.scenario;
        let bounds = crate::scenario::keypoint_bounds(sc)?;
        let map = match &sc.map {
            Some(spec) => Some(
                iktc::sim::load_map(spec, &resolved.robot)
                    .with_context(|| format!("--map `{spec}`"))?,
            ),
            None => None,
        };
        return crate::cmd_keypoints::run(
            profile,
            &sc.motion,
            &sc.motion_options,
            &cfg,
            (bounds, map.as_ref()),
            &a.keypoints,
            &a.out,
        );
    }
    let (e, mut cfg, profile) = prepare(&a.scenario)?;
    a.keypoints.apply(a.retarget, &mut cfg)?;
    let r = e.imitate(&cfg)?;
    let meshes = crate::viewer::robot_meshes(&profile);
    let files = write_imitate(&r, &e, meshes.as_ref(), &a.out)?;
    print_summary(&r)?;
    crate::outln!(
        "wrote {} figures, trajectory.csv, summary.json and viewer.html to {}",
        files.len(),
        a.out.display()
    )?;
    Ok(())
}

fn print_summary(r: &ImitateRun) -> std::io::Result<()> {
    let s = &r.summary;
    crate::outln!(
        "imitation, {} with {} bounds (soft approach {}), clip {}, {} ticks of {} s: worst margins position {:+.2e} rad, velocity {:+.2e} rad/s, acceleration {:+.2e} rad/s²",
        s.solver,
        s.bounds,
        crate::cmd_walk::approach_text(s.approach_rate),
        crate::cmd_walk::smoothing_text(s.smoothing_hz),
        s.steps, s.dt, s.worst_position_margin, s.worst_velocity_margin, s.worst_acceleration_margin
    )?;
    crate::outln!(
        "limits binding: position {} ticks, velocity {}, acceleration {}; pelvis corrected {} ticks ({} with a narrowed joint on its limit)",
        s.position_binding_steps, s.velocity_binding_steps, s.acceleration_binding_steps, s.pelvis_corrected_steps, s.pelvis_corrected_while_narrowed_at_limit
    )?;
    crate::outln!(
        "empty boxes {} ticks, fallbacks {} ticks, joints recovering into their range {} ticks",
        s.empty_box_steps,
        s.fallback_steps,
        s.recovering_steps
    )?;
    crate::outln!(
        "the corrected level changed {} times between consecutive ticks, {} of them undone at the next tick",
        s.level_switches.switches, s.level_switches.flips
    )?;
    crate::outln!(
        "foot drift {:.2e} m / {:.2e} rad; COM over the support polygon: {} (min margin {:.3} m); ZMP min margin {:.3} m; tick median {:.1} µs, p99 {:.1} µs",
        s.foot_drift, s.foot_rotation_drift, s.com_inside_support, s.com_min_margin, s.zmp_min_margin, s.tick_median_us, s.tick_p99_us
    )?;
    crate::outln!("{}", health_text(&s.health))?;
    Ok(())
}
