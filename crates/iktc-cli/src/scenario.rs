//! The arguments `iktc imitate` and `iktc walk` share (robot, motion, map, solver, bounds,
//! period, checks) and their translation into the library's [`Experiment`] and
//! [`ImitateConfig`].

use anyhow::{Context, Result};
use iktc::limits::{BoundMethod, OutsideLimits};
use iktc::motion::{MotionFormat, RetargetMap};
use iktc::profile::RobotProfile;
use iktc::resources::RunLimits;
use iktc::sim::{load_clip, load_map, Experiment, ImitateConfig};

use crate::cmd_run::{BoundsArg, SolverArg};
use crate::robot_arg::{resolve_robot, ProfileFlags, ResolvedRobot, RobotOptions};

/// Robot, motion and solver options of `iktc imitate` and `iktc walk`.
#[derive(clap::Args, Debug)]
pub struct ScenarioArgs {
    /// Robot: a built-in profile (jvrc1, g1), a robot profile (.toml) or a URDF (.urdf) or
    /// MuJoCo MJCF (.xml) file (floating base; its feet, pelvis and posture from --feet, --sole, --ankle-height,
    /// --pelvis, --posture).
    #[arg(long, default_value = "jvrc1")]
    pub robot: String,
    #[command(flatten)]
    pub robot_options: RobotOptions,
    #[command(flatten)]
    pub profile: ProfileFlags,
    /// Motion: a built-in DeepMimic clip (humanoid3d_dance_a, humanoid3d_dance_b,
    /// humanoid3d_punch, humanoid3d_walk) or a skeleton motion file (.bvh, .amc, DeepMimic,
    /// AMASS .npz with --body-model), its format detected from its content and extension.
    #[arg(long, default_value = iktc::sim::experiment::DEFAULT_CLIP)]
    pub motion: String,
    #[command(flatten)]
    pub motion_options: crate::cmd_map::MotionArgs,
    /// Retargeting map: a built-in name (deepmimic_jvrc1, bvh_jvrc1, deepmimic_g1) or a TOML
    /// file; default: the robot profile's map for the motion's format (profile key
    /// `imitate.maps.deepmimic` or `imitate.maps.bvh`).
    #[arg(long)]
    pub map: Option<String>,
    /// Solver.
    #[arg(long, value_enum, default_value = "iktc")]
    pub solver: SolverArg,
    /// Joint bounds (default: quiet).
    #[arg(long, value_enum)]
    pub bounds: Option<BoundsArg>,
    /// Start even if a joint is outside its (narrowed) range, and bring it back at the
    /// acceleration limit (viable or quiet bounds); without it such a start is an error.
    #[arg(long)]
    pub recover: bool,
    /// Soft approach to the range ends at this rate [1/s] (viable or quiet bounds): a joint
    /// nearing a limit is braked like a critically damped spring, so its command changes
    /// smoothly. Default: the tasks' rate √k_p (10 /s) on the joint route and in walking, none
    /// in keypoint retargeting; 0 turns it off.
    #[arg(long, value_name = "RATE")]
    pub approach_rate: Option<f64>,
    /// Control period [s]: 1e-5 to 0.1 s; keypoint retargeting needs less than 0.041 s (the
    /// held feet's gains are unstable beyond).
    #[arg(long, default_value_t = 0.005)]
    pub dt: f64,
    /// Keep running when a run check fails (a foot drifts past its tolerance, the ZMP leaves
    /// the support polygon) and mark it in the summary, instead of stopping with an error.
    #[arg(long)]
    pub keep_going: bool,
    /// Most control ticks of one run.
    #[arg(long, default_value_t = RunLimits::default().max_ticks)]
    pub max_ticks: usize,
}

/// The retargeting map: `--map` if given, else the robot profile's map for the motion's format;
/// checked against the robot (an unknown joint names the map entry and its source).
fn choose_map(spec: Option<&str>, format: MotionFormat, r: &ResolvedRobot) -> Result<RetargetMap> {
    let Some(spec) = spec else {
        let format = if format == MotionFormat::DeepMimic {
            "deepmimic"
        } else {
            "bvh"
        };
        let profile = r
            .profile
            .as_ref()
            .context("`planar3r` has no profile and cannot imitate a motion")?;
        return profile
            .retarget_map(format, &r.robot)
            .map_err(|e| r.explain(e));
    };
    load_map(spec, &r.robot).with_context(|| format!("--map `{spec}`"))
}

/// The robot and the run configuration the arguments describe (robot flags, profile, solver,
/// bounds, control period, recovery, run checks).
/// The joint bounds of keypoint retargeting: `--bounds`, else its own default
/// (`KeypointSettings::default().bounds`); `--recover` applies to them too.
pub fn keypoint_bounds(a: &ScenarioArgs) -> Result<BoundMethod> {
    let mut bounds = a.bounds.map_or_else(
        || iktc::retarget::KeypointSettings::default().bounds,
        BoundsArg::method,
    );
    if let (true, BoundMethod::Viable(s) | BoundMethod::Quiet(s)) = (a.recover, &mut bounds) {
        s.outside = OutsideLimits::Recover;
    }
    match a.approach_rate {
        Some(rate) => with_approach_rate(bounds, rate),
        None => Ok(bounds),
    }
}

/// `bounds` with `--approach-rate RATE`; an error names the flag.
fn with_approach_rate(bounds: BoundMethod, rate: f64) -> Result<BoundMethod> {
    bounds
        .with_approach_rate(rate)
        .with_context(|| format!("--approach-rate {rate}"))
}

pub fn prepare_config(a: &ScenarioArgs) -> Result<(ResolvedRobot, ImitateConfig)> {
    let mut ro = a.robot_options.clone();
    let path = std::path::Path::new(&a.robot);
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("urdf") || e.eq_ignore_ascii_case("xml"))
    {
        // The imitation moves a free-floating humanoid.
        ro.floating = true;
    }
    let resolved = resolve_robot(&a.robot, &ro, Some(&a.profile))?;
    let profile = resolved
        .profile
        .as_ref()
        .context("`planar3r` has no profile and cannot imitate a motion")?;
    let mut cfg = profile
        .imitate_config(ImitateConfig {
            method: a.solver.method(),
            bounds: a
                .bounds
                .map_or_else(|| ImitateConfig::default().bounds, BoundsArg::method),
            dt: a.dt,
            run_limits: RunLimits {
                max_ticks: a.max_ticks,
                ..RunLimits::default()
            },
            ..ImitateConfig::default()
        })
        .map_err(|e| resolved.explain(e))?;
    cfg.run_limits.check_dt("--dt", a.dt)?;
    match &mut cfg.bounds {
        BoundMethod::Viable(settings) | BoundMethod::Quiet(settings) if a.recover => {
            settings.outside = OutsideLimits::Recover;
        }
        BoundMethod::Paper if a.recover => {
            anyhow::bail!("--recover needs --bounds viable or quiet");
        }
        _ => {}
    }
    // The imitation's default rate with the viable or quiet bounds; the paper's bound has none.
    match (a.approach_rate, cfg.bounds) {
        (None, BoundMethod::Paper) => {}
        (rate, bounds) => {
            let rate = rate.unwrap_or_else(|| ImitateConfig::default().bounds.approach_rate());
            cfg.bounds = with_approach_rate(bounds, rate)?;
        }
    }
    cfg.health.keep_going = a.keep_going;
    Ok((resolved, cfg))
}

/// The experiment, its configuration and the robot's profile the arguments describe.
pub fn prepare(a: &ScenarioArgs) -> Result<(Experiment, ImitateConfig, RobotProfile)> {
    let (resolved, cfg) = prepare_config(a)?;
    let loaded = load_clip(&a.motion, &a.motion_options.options()?)
        .with_context(|| format!("--motion `{}`", a.motion))?;
    if let Some(decided) = &loaded.decided {
        crate::outln!("{decided}")?;
    }
    let map = choose_map(a.map.as_deref(), loaded.format, &resolved)?;
    let profile = resolved
        .profile
        .context("`planar3r` has no profile and cannot imitate a motion")?;
    Ok((
        Experiment {
            robot: resolved.robot,
            clip: loaded.clip,
            map,
        },
        cfg,
        profile,
    ))
}

/// The health of a run in words: "healthy", or every failed check with its first and worst
/// value (runs continued with `--keep-going`).
pub fn health_text(h: &iktc::sim::HealthReport) -> String {
    if h.healthy {
        return "run checks: healthy".into();
    }
    let mut s = format!(
        "run checks: FAILED on {} ticks{} (continued with --keep-going)",
        h.failed_ticks,
        if h.completed {
            ""
        } else {
            ", stopped early on a non-finite state"
        }
    );
    for i in &h.issues {
        s.push_str(&format!(
            "; {i} (worst {:.4e} at t = {:.4} s, {} ticks)",
            i.worst_value, i.worst_time, i.ticks
        ));
    }
    s
}
