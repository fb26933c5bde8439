//! `iktc walk`: the humanoid walks while it imitates, with the damping controller in the loop
//! (Sections 4 and 5.3): ZMP over time, footsteps from above, the phase timeline, the narrowed
//! joints, a viewer.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use iktc::profile::RobotProfile;
use iktc::sim::viewer::walking_viewer;
use iktc::sim::{
    Experiment, ImitateConfig, Push, PushAxisMetrics, WalkImitateConfig, WalkRun, WalkStep,
    WalkSummary,
};
use iktc::walk::{sole_corners, Pose2};
use iktc_report::{write_csv, write_figure, Figure, Panel, Section, Series, Table};

use crate::columns::{level_number, phase_number};
use crate::scenario::{health_text, prepare, ScenarioArgs};
use crate::viewer::write_viewer;

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

fn settling_text(m: &PushAxisMetrics) -> String {
    m.settling_time
        .map_or("not settled".into(), |t| format!("{t:.2}"))
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

fn damping_text(s: &WalkSummary) -> String {
    s.push.map_or("(no push)".into(), |p| ratio_text(&p.x))
}

fn col(r: &WalkRun, f: &dyn Fn(&WalkStep) -> f64) -> Vec<f64> {
    r.steps.iter().map(f).collect()
}

/// Writes trajectory.csv, summary.json, the figures and viewer.html of a walking run.
pub fn write_walk(
    with: &WalkRun,
    without: &WalkRun,
    e: &Experiment,
    imitate: &ImitateConfig,
    meshes: Option<&iktc::mesh::MeshSet>,
    dir: &Path,
) -> Result<Vec<(String, String)>> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let header: Vec<String> = [
        "t",
        "phase",
        "zmp_ref_x",
        "zmp_ref_y",
        "zmp_model_x",
        "zmp_model_y",
        "zmp_x",
        "zmp_y",
        "zmp_margin",
        "zmp_dev_x_local",
        "zmp_dev_y_local",
        "com_pattern_x",
        "com_pattern_y",
        "com_ref_x",
        "com_ref_y",
        "com_x",
        "com_y",
        "com_z",
        "dc_x",
        "dc_y",
        "left_ref_x",
        "left_ref_y",
        "left_ref_z",
        "right_ref_x",
        "right_ref_y",
        "right_ref_z",
        "left_x",
        "left_y",
        "left_z",
        "right_x",
        "right_y",
        "right_z",
        "corrected_from_level",
        "qp_solves",
        "tick_us",
    ]
    .map(String::from)
    .to_vec();
    let rows: Vec<Vec<f64>> = with
        .steps
        .iter()
        .map(|s| {
            let mut v = vec![s.t, phase_number(s.phase)];
            v.extend(s.zmp_reference);
            v.extend(s.zmp_model);
            v.extend(s.zmp_measured);
            v.push(s.zmp_margin);
            v.extend(s.zmp_deviation);
            v.extend(s.com_pattern);
            v.extend(s.com_reference);
            v.extend(s.com);
            v.extend(s.com_offset);
            v.extend(s.feet_reference[0]);
            v.extend(s.feet_reference[1]);
            v.extend(s.feet[0]);
            v.extend(s.feet[1]);
            v.extend([
                level_number(s.corrected_from),
                s.qp_solves as f64,
                s.tick_us,
            ]);
            v
        })
        .collect();
    write_csv(&dir.join("walk.csv"), &header, &rows)?;
    let summary = serde_json::json!({
        "with_damping": with.summary,
        "without_damping": without.summary,
        "footsteps": with.footsteps,
        "phases": with.phases,
    });
    std::fs::write(
        dir.join("walk_summary.json"),
        crate::finite::to_json("walk_summary.json", &summary)?,
    )?;
    let t = col(with, &|s| s.t);
    let mut figs = Vec::new();
    // ZMP over time with the support polygon's extent.
    let sole = (imitate.support.sole_length, imitate.support.sole_width);
    let mut fig = Figure::new("ZMP while walking and imitating, push at the dashed event");
    for (i, axis) in ["x", "y"].iter().enumerate() {
        // The extent of the support polygon along the axis.
        let extent = |fold: fn(f64, f64) -> f64, start: f64| {
            col(with, &|s| s.support.iter().map(|v| v[i]).fold(start, fold))
        };
        let lo = extent(f64::min, f64::INFINITY);
        let hi = extent(f64::max, f64::NEG_INFINITY);
        fig = fig.panel(
            Panel::new(
                format!("ZMP {axis} (world)"),
                "t [s]",
                format!("{axis} [m]"),
            )
            .with(Series::line(
                "reference",
                t.clone(),
                col(with, &|s| s.zmp_reference[i]),
            ))
            .with(Series::line(
                "measured, controller on",
                t.clone(),
                col(with, &|s| s.zmp_measured[i]),
            ))
            .with(Series::line(
                "measured, controller off",
                t.clone(),
                col(without, &|s| s.zmp_measured[i]),
            ))
            .with(Series::dashed(
                "support polygon extent (soles)",
                t.clone(),
                lo,
            ))
            .with(Series::dashed("", t.clone(), hi)),
        );
    }
    fig = fig.panel(
        Panel::new(
            "ZMP deviation after the push (x̃, local frame)",
            "t [s]",
            "deviation [mm]",
        )
        .with(Series::line(
            "controller on",
            t.clone(),
            col(with, &|s| 1e3 * s.zmp_deviation[0]),
        ))
        .with(Series::line(
            "controller off",
            t.clone(),
            col(without, &|s| 1e3 * s.zmp_deviation[0]),
        )),
    );
    write_figure(&fig, dir, "walk_zmp")?;
    figs.push(("walk_zmp.svg".into(), format!(
        "ZMP: reference, measured with and without the damping controller, and the support polygon; damping ratio after the push (x̃) {} with, {} without",
        damping_text(&with.summary), damping_text(&without.summary)
    )));
    // Footsteps from above.
    let mut top = Panel::new("Footsteps from above", "x [m]", "y [m]").equal_aspect();
    for (k, (side, p)) in with.footsteps.iter().enumerate() {
        let mut corners = sole_corners(&Pose2::new(p[0], p[1], p[2]), sole.0, sole.1).to_vec();
        corners.push(corners[0]);
        let xs = corners.iter().map(|c| c.0).collect();
        let ys = corners.iter().map(|c| c.1).collect();
        let label = match (k, side) {
            (0, _) => "footsteps (soles)",
            _ => "",
        };
        top = top.with(Series::line(label, xs, ys));
    }
    top = top
        .with(Series::line(
            "COM",
            col(with, &|s| s.com[0]),
            col(with, &|s| s.com[1]),
        ))
        .with(Series::dashed(
            "ZMP reference",
            col(with, &|s| s.zmp_reference[0]),
            col(with, &|s| s.zmp_reference[1]),
        ))
        .with(Series::points(
            "ZMP measured",
            col(with, &|s| s.zmp_measured[0]),
            col(with, &|s| s.zmp_measured[1]),
        ));
    write_figure(
        &Figure::new("Footsteps, COM and ZMP from above")
            .panel(top)
            .panel_size(800, 420),
        dir,
        "walk_footsteps",
    )?;
    figs.push((
        "walk_footsteps.svg".into(),
        "Footsteps from above with the COM and the ZMP".into(),
    ));
    // Phase timeline, feet heights, damping controller output.
    let fig = Figure::new("Support phases, feet and the damping controller")
        .panel(
            Panel::new(
                "support phase (0 double, 1 left stance, 2 right stance)",
                "t [s]",
                "phase",
            )
            .with(Series::line(
                "phase",
                t.clone(),
                col(with, &|s| phase_number(s.phase)),
            )),
        )
        .panel(
            Panel::new("ankle heights", "t [s]", "z [m]")
                .with(Series::line(
                    "left",
                    t.clone(),
                    col(with, &|s| s.feet[0][2]),
                ))
                .with(Series::line(
                    "right",
                    t.clone(),
                    col(with, &|s| s.feet[1][2]),
                ))
                .with(Series::dashed(
                    "left reference",
                    t.clone(),
                    col(with, &|s| s.feet_reference[0][2]),
                ))
                .with(Series::dashed(
                    "right reference",
                    t.clone(),
                    col(with, &|s| s.feet_reference[1][2]),
                )),
        )
        .panel(
            Panel::new(
                "damping controller: COM offset Δc (world)",
                "t [s]",
                "Δc [mm]",
            )
            .with(Series::line(
                "Δc x",
                t.clone(),
                col(with, &|s| 1e3 * s.com_offset[0]),
            ))
            .with(Series::line(
                "Δc y",
                t.clone(),
                col(with, &|s| 1e3 * s.com_offset[1]),
            )),
        )
        .panel(
            Panel::new(
                "IKTC: level the correction started from (0 = none)",
                "t [s]",
                "level",
            )
            .with(Series::points(
                "corrected from",
                t.clone(),
                col(with, &|s| level_number(s.corrected_from)),
            )),
        );
    write_figure(&fig, dir, "walk_phases")?;
    figs.push((
        "walk_phases.svg".into(),
        "Phase timeline, ankle heights, the damping controller's COM offset and IKTC's corrections"
            .into(),
    ));
    let mut viewer = walking_viewer(
        with,
        e,
        imitate.dt,
        [imitate.support.sole_length, imitate.support.sole_width],
    )?;
    crate::viewer::attach(&mut viewer, &e.robot, meshes)?;
    write_viewer(&dir.join("walk_viewer.html"), &viewer)?;
    Ok(figs)
}

/// Runs the default walking imitation into `out/walk` and returns its report section.
pub fn walk_section(out: &Path) -> Result<Section> {
    let (e, imitate) = Experiment::jvrc1()?;
    let profile = RobotProfile::builtin("jvrc1")?;
    let w = WalkArgs {
        steps: 4,
        step_length: None,
        no_damping: false,
        push: None,
        smoothing: None,
        no_smoothing: false,
        zmp_passes: 0,
    };
    let dir = out.join("walk");
    let (figs, with, without) = run_walk(&e, &profile, &imitate, &w, &dir)?;
    let mut sec = Section::new("Walking while imitating, with the damping controller (Sections 4 and 5.3)").intro(
        "<p>The legs follow a walking pattern (4 steps of 0.1 m; ZMP preview control on the cart-table model, \
         quintic swing feet) while the upper body imitates <code>humanoid3d_dance_b</code> under the Table 1 stack \
         with the narrowed joints. The damping controller reads the ZMP of a simulated compliant robot (an IPCJ per \
         plane with the robot's COM height, lag, a true delay, sensor noise) and offsets the COM reference; a forward \
         push of 5 N·s hits the robot in single support at 2.15 s. The same run without the controller is shown for comparison.</p>",
    );
    for (f, c) in figs {
        sec = sec.figure(format!("walk/{f}"), c);
    }
    let mut table = Table::new(
        "Walking summaries (margins: position rad / velocity rad/s / acceleration rad/s²)",
        [
            "damping controller",
            "ZMP min margin [m]",
            "ZMP inside",
            "stance foot error / slip [m]",
            "worst margins",
            "push peak x̃ / ỹ [m]",
            "damping ratio x̃ / ỹ",
            "settling x̃ / ỹ [s]",
            "ZMP outside after the push [m]",
            "health",
            "corrected ticks; level changes (undone next tick)",
            "worst joint: RMS jerk [rad/s³] (share of ticks where q̈'s change reverses)",
            "median / p99 tick [µs]",
        ]
        .map(String::from)
        .to_vec(),
    );
    for r in [&with, &without] {
        let s = &r.summary;
        table = table.row(vec![
            if s.damping { "on".into() } else { "off".into() },
            format!("{:+.4}", s.min_zmp_margin),
            s.zmp_inside.to_string(),
            format!(
                "{:.1e} / {:.1e}",
                s.max_stance_foot_error, s.max_stance_foot_slip
            ),
            format!(
                "{:+.0e} / {:+.0e} / {:+.0e}",
                s.worst_margins[0], s.worst_margins[1], s.worst_margins[2]
            ),
            s.push.map_or("no push".into(), |p| {
                format!("{:.4} / {:.4}", p.x.peak, p.y.peak)
            }),
            s.push.map_or("–".into(), |p| {
                format!("{} / {}", ratio_text(&p.x), ratio_text(&p.y))
            }),
            s.push.map_or("–".into(), |p| {
                format!("{} / {}", settling_text(&p.x), settling_text(&p.y))
            }),
            s.push
                .map_or("–".into(), |p| format!("{:.4}", p.zmp_excursion)),
            health_text(&s.health),
            format!(
                "{}; {} ({})",
                s.corrected_ticks, s.level_switches.switches, s.level_switches.flips
            ),
            format!(
                "{:.0} ({:.0} %)",
                s.smoothness_worst.rms_jerk,
                100.0 * s.smoothness_worst.reversal_share
            ),
            format!("{:.0} / {:.0}", s.tick_median_us, s.tick_p99_us),
        ]);
    }
    sec = sec.table(table);
    sec = sec.link(
        "walk/walk_viewer.html",
        "3D viewer of the walk (footsteps and phases)",
    );
    sec = sec.link("walk/walk_summary.json", "walk_summary.json");
    sec = sec.link("walk/walk.csv", "walk.csv");
    Ok(sec)
}
