//! `iktc walk`: the humanoid walks while it imitates, with the damping controller in the loop
//! (Sections 4 and 5.3): ZMP over time, footsteps from above, the phase timeline, the narrowed
//! joints, a viewer.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use iktc::profile::RobotProfile;
use iktc::sim::{Experiment, ImitateConfig, Push, PushAxisMetrics, WalkImitateConfig, WalkRun};

use crate::scenario::{health_text, prepare, ScenarioArgs};

mod section;
mod write;

pub use section::walk_section;
use write::write_walk;

/// Arguments of `iktc walk`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    #[command(flatten)]
    pub walk: WalkArgs,
    /// Output directory.
    #[arg(long, default_value = "out/walk")]
    pub out: PathBuf,
}

/// The walking options.
#[derive(clap::Args, Debug, Clone)]
pub struct WalkArgs {
    /// Number of footsteps.
    #[arg(long, default_value_t = 4)]
    pub steps: usize,
    /// Step length [m]; 0 steps in place [default: the profile's `walk.step_length`, else 0.1].
    #[arg(long)]
    pub step_length: Option<f64>,
    /// Leave the damping controller out of the loop (the run without it is still made, for
    /// the comparison).
    #[arg(long)]
    pub no_damping: bool,
    /// Push on the COM: TIME,IMPULSE_X,IMPULSE_Y [s, N·s, N·s], or `none` [default: the
    /// profile's `walk.push`, else a forward push at 2.15 s that changes the COM velocity by
    /// 0.080 m/s (5 N·s on JVRC-1's 62.4 kg)].
    #[arg(long)]
    pub push: Option<String>,
    /// Low-pass the captured motion at this cut-off [Hz] before it becomes the upper body's
    /// references [default: 6, the imitation's].
    #[arg(long, value_name = "HZ", conflicts_with = "no_smoothing")]
    pub smoothing: Option<f64>,
    /// The motion as captured, not low-passed.
    #[arg(long)]
    pub no_smoothing: bool,
    /// Passes of the ZMP correction of the walking pattern: where the commanded motion's own
    /// ZMP (its links' masses and inertias) comes within 5 mm of the support polygon's edge,
    /// the COM reference is moved by preview control so that it does not; at most 10, and the
    /// passes stop once one no longer brings the ZMP closer [default: 0, the paper's
    /// cart-table pattern].
    #[arg(long, default_value_t = 0)]
    pub zmp_passes: usize,
}

impl WalkArgs {
    /// `imitate` with `--smoothing` or `--no-smoothing` (unchanged without either).
    pub fn apply_smoothing(&self, imitate: &mut ImitateConfig) {
        if self.no_smoothing {
            imitate.smoothing = None;
        } else if let Some(hz) = self.smoothing {
            imitate.smoothing = Some(hz);
        }
    }
}

fn parse_push(s: &str) -> Result<Option<Push>> {
    if s.trim() == "none" {
        return Ok(None);
    }
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .with_context(|| format!("--push `{s}`: expected TIME,IMPULSE_X,IMPULSE_Y or none"))?;
    if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
        anyhow::bail!(
            "--push `{s}`: expected three finite numbers TIME,IMPULSE_X,IMPULSE_Y or none"
        );
    }
    Ok(Some(Push {
        time: v[0],
        impulse: [v[1], v[2]],
    }))
}

/// The walking settings: the profile's ([`RobotProfile::walk_config`]), then the flags.
fn config(
    e: &Experiment,
    profile: &RobotProfile,
    imitate: &ImitateConfig,
    w: &WalkArgs,
) -> Result<WalkImitateConfig> {
    let mut cfg = profile
        .walk_config(
            &e.robot,
            WalkImitateConfig {
                imitate: imitate.clone(),
                ..WalkImitateConfig::jvrc1()?
            },
        )
        .context("the robot profile's walking settings")?;
    cfg.steps = w.steps;
    cfg.damping = !w.no_damping;
    cfg.zmp_passes = w.zmp_passes;
    if let Some(l) = w.step_length {
        cfg.step_length = l;
    }
    if let Some(p) = &w.push {
        cfg.push = parse_push(p)?;
    }
    Ok(cfg)
}

/// Figures written (path relative to the output directory, caption).
pub type Figures = Vec<(String, String)>;

/// Runs the walking imitation with and without the damping controller (for the comparison),
/// writes everything to `dir` and returns the figures (path relative to `dir`, caption) and the
/// two runs (with, without).
fn run_walk(
    e: &Experiment,
    profile: &RobotProfile,
    imitate: &ImitateConfig,
    w: &WalkArgs,
    dir: &Path,
) -> Result<(Figures, WalkRun, WalkRun)> {
    let (with, without) = e.walk_with_and_without_damping(&config(e, profile, imitate, w)?)?;
    let meshes = crate::viewer::robot_meshes(profile);
    let figs = write_walk(&with, &without, e, imitate, meshes.as_ref(), dir)?;
    Ok((figs, with, without))
}

/// Runs `iktc walk`.
pub fn run(a: &Args) -> Result<()> {
    let (e, mut cfg, profile) = prepare(&a.scenario)?;
    a.walk.apply_smoothing(&mut cfg);
    let (figs, with, without) = run_walk(&e, &profile, &cfg, &a.walk, &a.out)?;
    print_walk(&with, &without)?;
    crate::outln!(
        "wrote {} figures, walk.csv, walk_summary.json and walk_viewer.html to {}",
        figs.len(),
        a.out.display()
    )?;
    Ok(())
}

/// "10 /s", or "off" for a rate of 0.
pub fn approach_text(rate: f64) -> String {
    if rate > 0.0 {
        format!("{rate} /s")
    } else {
        "off".into()
    }
}

/// "low-passed at 6 Hz", or "as captured".
pub fn smoothing_text(hz: Option<f64>) -> String {
    hz.map_or_else(
        || "as captured".into(),
        |hz| format!("low-passed at {hz} Hz"),
    )
}

/// Prints the two summaries.
pub fn print_walk(with: &WalkRun, without: &WalkRun) -> std::io::Result<()> {
    for r in [with, without] {
        let s = &r.summary;
        crate::outln!(
            "walking imitation (soft approach {}, clip {}), damping controller {}: ZMP min margin {:+.4} m (inside: {}), stance feet error {:.2e} m / slip {:.2e} m, worst margins {:+.1e} rad {:+.1e} rad/s {:+.1e} rad/s²",
            approach_text(s.approach_rate), smoothing_text(s.smoothing_hz),
            if s.damping { "on " } else { "off" }, s.min_zmp_margin, s.zmp_inside, s.max_stance_foot_error, s.max_stance_foot_slip, s.worst_margins[0], s.worst_margins[1], s.worst_margins[2]
        )?;
        match &s.push {
            Some(p) => crate::outln!(
                "  after the push: x̃ {}; ỹ {}; ZMP outside the support polygon by at most {:.4} m",
                axis_text(&p.x),
                axis_text(&p.y),
                p.zmp_excursion
            )?,
            None => crate::outln!("  no push")?,
        }
        crate::outln!(
            "  the commanded motion's own ZMP (links' masses and inertias) outside the pattern's polygon on {} single- and {} double-support ticks (smallest margin {:+.4} m): no robot follows the plan there without tipping",
            s.plan_zmp_outside_single, s.plan_zmp_outside_double, s.plan_zmp_min_margin
        )?;
        if !s.zmp_corrections.is_empty() {
            crate::outln!(
                "  ZMP correction: {} passes run, largest |Δp| per pass [m]: {:?}",
                s.zmp_corrections.len(),
                s.zmp_corrections
            )?;
        }
        crate::outln!(
            "  tick median {:.1} µs, p99 {:.1} µs; {}",
            s.tick_median_us,
            s.tick_p99_us,
            health_text(&s.health)
        )?;
        crate::outln!(
            "  corrected {} ticks; the corrected level changed {} times between consecutive ticks, {} of them undone at the next tick",
            s.corrected_ticks, s.level_switches.switches, s.level_switches.flips
        )?;
    }
    Ok(())
}

fn ratio_text(m: &PushAxisMetrics) -> String {
    m.damping_ratio
        .map_or("not fitted (within the noise)".into(), |z| {
            format!("{z:.3}")
        })
}

/// One axis of a push response in words.
fn axis_text(m: &PushAxisMetrics) -> String {
    format!(
        "peak {:.4} m, damping ratio {}, settling {}",
        m.peak,
        ratio_text(m),
        m.settling_time
            .map_or("never (not settled)".into(), |t| format!("{t:.2} s"))
    )
}
