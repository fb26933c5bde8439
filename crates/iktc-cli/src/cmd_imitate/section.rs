//! The imitation section of the report (`iktc reproduce`).

use std::path::Path;

use anyhow::Result;
use iktc::limits::BoundMethod;
use iktc::sim::imitate::LEVEL_NAMES;
use iktc::sim::{Experiment, ImitateConfig, ImitateRun};
use iktc::solver::Method;
use iktc_report::{write_figure, Figure, Panel, Section, Series, Table};

use super::write_imitate;

/// The section's introduction (HTML).
const INTRO: &str = "<p>The DeepMimic clip <code>humanoid3d_dance_b</code> is retargeted onto JVRC-1 (built-in map <code>deepmimic_jvrc1</code>: \
         chest → waist, neck → neck, shoulders and elbows → arms, root → pelvis height and attitude; natural cubic splines to 200 Hz). \
         Tasks of Table 1 in priority order: both feet (12), COM x-y (2), pelvis attitude (3), pelvis height (1), upper-body joints (20); n = 38. \
         L_KNEE is narrowed to [0.55, 0.95] rad and L_HIP_R to [−0.05, 0.05] rad, as the paper narrows LKN and LHR, so that the pelvis tasks get corrected. \
         Feet: soles 0.2 × 0.1 m under the ankles (nominal), the support polygon is their convex hull; the COM reference moves to its centre in 0.5 s. \
         Margins are signed (positive = a limit exceeded, in-step peaks included). Tick times are wall-clock times of this run. The third run uses the paper's bound, eq. (14), which lets joints pass their limits (errata 3.1). \
         IKTC and GF run with the imitation's defaults: the quiet bounds with the soft approach to the range ends at the tasks' rate √k<sub>p</sub> = 10 /s, \
         the clip low-passed at 6 Hz (IKTC also with a hold of 4 ticks on the corrected level); \
         the third and fourth runs take the clip as captured, and the fourth is Algorithm 2 as printed with the viable bounds, \
         for the smoothness figures of old and new side by side (jerk = (q̈<sub>k</sub> − q̈<sub>k−1</sub>)/Δt). \
         The clip's arms pass near the shoulders' pitch–roll–yaw singularity (roll ±90°): the retargeted shoulder pitch and yaw then spin far faster \
         than their limits and leave their ranges (they are clamped), so the upper-body level, the lowest, is corrected most of the time.</p>";

/// One row of the summary table (margins in rad, rad/s, rad/s²; drift in m / rad; jerk in
/// rad/s³; tick times in µs).
fn summary_row(name: &str, r: &ImitateRun) -> Vec<String> {
    let s = &r.summary;
    vec![
        name.into(),
        format!(
            "{:+.1e} / {:+.1e} / {:+.1e}",
            s.worst_position_margin, s.worst_velocity_margin, s.worst_acceleration_margin
        ),
        format!(
            "{} / {} / {}",
            s.position_binding_steps, s.velocity_binding_steps, s.acceleration_binding_steps
        ),
        format!("{:.1e} / {:.1e}", s.foot_drift, s.foot_rotation_drift),
        format!("{} ({:.3})", s.com_inside_support, s.com_min_margin),
        s.levels
            .iter()
            .map(|l| format!("{:.2e}", l.rms_error))
            .collect::<Vec<_>>()
            .join(" / "),
        format!(
            "{} ({})",
            s.pelvis_corrected_steps, s.pelvis_corrected_while_narrowed_at_limit
        ),
        format!("{} ({})", s.level_switches.switches, s.level_switches.flips),
        s.narrowed_smoothness
            .iter()
            .map(|j| {
                format!(
                    "{} {:.0} / {:.0} ({:.0} %)",
                    j.joint,
                    j.smoothness.rms_jerk,
                    j.smoothness.max_jerk,
                    100.0 * j.smoothness.reversal_share
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
        format!("{:.2} / {}", s.qp_per_step_mean, s.qp_per_step_max),
        format!("{:.0} / {:.0}", s.tick_median_us, s.tick_p99_us),
    ]
}

/// One of the report's runs: name, method, bounds, level hold [ticks], continuity, smoothing
/// cut-off [Hz].
type ReportRun = (&'static str, Method, BoundMethod, usize, f64, Option<f64>);

/// The report's runs. The last run is Algorithm 2 as printed with the viable bounds, to show
/// the smoothness figures beside the defaults'.
fn section_runs() -> [ReportRun; 4] {
    let defaults = ImitateConfig::jvrc1();
    [
        (
            "iktc",
            Method::Iktc,
            defaults.bounds,
            defaults.solver.level_hold,
            defaults.solver.continuity,
            defaults.smoothing,
        ),
        (
            "gf",
            Method::Cascade,
            defaults.bounds,
            1,
            0.0,
            defaults.smoothing,
        ),
        (
            "iktc_paper_bounds",
            Method::Iktc,
            BoundMethod::Paper,
            1,
            0.0,
            None,
        ),
        (
            "iktc_viable_alg2",
            Method::Iktc,
            BoundMethod::viable(),
            1,
            0.0,
            None,
        ),
    ]
}

/// The empty summary table with its header.
fn summary_table() -> Table {
    Table::new(
        "Summaries",
        [
            "run",
            "worst margin pos / vel / acc",
            "ticks on a pos / vel / acc limit",
            "foot drift [m / rad]",
            "COM over support (min margin m)",
            "RMS error per level (feet / COM / att. / height / upper)",
            "pelvis corrected ticks (with narrowed joint on limit)",
            "corrected-level changes (undone at the next tick)",
            "narrowed joints: RMS / max jerk [rad/s³] (ticks where q̈'s change reverses)",
            "QPs per tick mean / max",
            "tick median / p99 [µs]",
        ]
        .map(String::from)
        .to_vec(),
    )
}

/// Runs the default imitation (JVRC-1, humanoid3d_dance_b) with IKTC, GF, the paper's bound
/// and Algorithm 2 as printed with the viable bounds under `out/imitate`, and returns the report
/// section.
pub fn imitate_section(out: &Path) -> Result<Section> {
    let base = out.join("imitate");
    let (e, _) = Experiment::jvrc1()?;
    let mut sec =
        Section::new("Imitating a captured motion with JVRC-1 (Section 5.3)").intro(INTRO);
    let mut table = summary_table();
    let mut runs = Vec::new();
    for (name, method, bounds, hold, continuity, smoothing) in section_runs() {
        let mut cfg = ImitateConfig {
            method,
            bounds,
            smoothing,
            ..ImitateConfig::jvrc1()
        };
        cfg.solver.level_hold = hold;
        cfg.solver.continuity = continuity;
        // A report compares the methods: a run whose feet drift past their tolerance (the
        // paper's bound, 58 ticks of the default clip) is shown with its health report.
        cfg.health.keep_going = true;
        let r = e.imitate(&cfg)?;
        // JVRC-1: no meshes, the stick figure.
        let figs = write_imitate(&r, &e, None, &base.join(name))?;
        table = table.row(summary_row(name, &r));
        sec = add_run(sec, name, figs);
        runs.push(r);
    }
    write_figure(&comparison_figure(&runs), &base, "iktc_vs_gf")?;
    sec = sec.figure("imitate/iktc_vs_gf.svg", "IKTC and GF side by side: errors of the pelvis attitude, pelvis height and upper-body levels");
    Ok(sec.table(table))
}

/// `sec` with the figures of run `name` (IKTC's only) and the links to its files.
fn add_run(mut sec: Section, name: &str, figs: Vec<(String, String)>) -> Section {
    if name == "iktc" {
        for (f, c) in figs {
            sec = sec.figure(format!("imitate/{name}/{f}"), c);
        }
    }
    sec = sec.link(
        format!("imitate/{name}/viewer.html"),
        format!("{name}: 3D viewer (Fig. 21)"),
    );
    sec = sec.link(
        format!("imitate/{name}/summary.json"),
        format!("{name}: summary.json"),
    );
    sec.link(
        format!("imitate/{name}/trajectory.csv"),
        format!("{name}: trajectory.csv"),
    )
}

/// IKTC against GF (`runs[0]`, `runs[1]`): the tracking errors of the lower levels (m or rad),
/// what each sacrifices (errata 3.2: IKTC's single QP is not lexicographic).
fn comparison_figure(runs: &[ImitateRun]) -> Figure {
    let t: Vec<f64> = runs[0].steps.iter().map(|st| st.t).collect();
    let get = |i: usize, l: usize| {
        runs[i]
            .steps
            .iter()
            .map(|st| st.level_error[l])
            .collect::<Vec<f64>>()
    };
    let mut cmp = Figure::new("IKTC and GF: tracking errors of the lower levels");
    for (l, unit) in [(2, "rad"), (3, "m"), (4, "rad")] {
        cmp = cmp.panel(
            Panel::new(LEVEL_NAMES[l], "t [s]", format!("|x_d - x| [{unit}]"))
                .with(Series::line("IKTC", t.clone(), get(0, l)))
                .with(Series::dashed("GF", t.clone(), get(1, l))),
        );
    }
    cmp
}
