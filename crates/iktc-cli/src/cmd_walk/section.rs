//! The walking section of the report (`iktc reproduce`).

use std::path::Path;

use anyhow::Result;
use iktc::profile::RobotProfile;
use iktc::sim::{Experiment, PushAxisMetrics, WalkRun, WalkSummary};
use iktc_report::{Section, Table};

use super::{ratio_text, run_walk, WalkArgs};
use crate::scenario::health_text;

/// The settling time of one axis of a push response [s], or "not settled".
fn settling_text(m: &PushAxisMetrics) -> String {
    m.settling_time
        .map_or("not settled".into(), |t| format!("{t:.2}"))
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
    sec = sec.table(summary_table(&with, &without));
    sec = sec.link(
        "walk/walk_viewer.html",
        "3D viewer of the walk (footsteps and phases)",
    );
    sec = sec.link("walk/walk_summary.json", "walk_summary.json");
    sec = sec.link("walk/walk.csv", "walk.csv");
    Ok(sec)
}

/// The table of the two walking summaries, with and without the damping controller.
fn summary_table(with: &WalkRun, without: &WalkRun) -> Table {
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
    for r in [with, without] {
        table = table.row(summary_row(&r.summary));
    }
    table
}

/// One row of the summary table (margins in rad, rad/s, rad/s²; lengths in m; jerk in rad/s³;
/// tick times in µs).
fn summary_row(s: &WalkSummary) -> Vec<String> {
    vec![
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
    ]
}
