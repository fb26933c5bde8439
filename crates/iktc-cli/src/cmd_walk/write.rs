//! The output files of a walking run: walk.csv, walk_summary.json, the figures and
//! walk_viewer.html.

use std::path::Path;

use anyhow::{Context, Result};
use iktc::sim::viewer::walking_viewer;
use iktc::sim::{Experiment, ImitateConfig, WalkRun, WalkStep, WalkSummary};
use iktc::walk::{sole_corners, Pose2};
use iktc_report::{write_csv, write_figure, Figure, Panel, Series};

use super::ratio_text;
use crate::columns::{level_number, phase_number};
use crate::viewer::write_viewer;

/// The damping ratio after the push along x̃ in words, or "(no push)".
fn damping_text(s: &WalkSummary) -> String {
    s.push.map_or("(no push)".into(), |p| ratio_text(&p.x))
}

/// One column of a run: `f` of every tick.
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
    write_csv(&dir.join("walk.csv"), &csv_header(), &csv_rows(with))?;
    write_summary(with, without, dir)?;
    let t = col(with, &|s| s.t);
    let mut figs = Vec::new();
    write_figure(&zmp_figure(with, without, &t), dir, "walk_zmp")?;
    figs.push(("walk_zmp.svg".into(), format!(
        "ZMP: reference, measured with and without the damping controller, and the support polygon; damping ratio after the push (x̃) {} with, {} without",
        damping_text(&with.summary), damping_text(&without.summary)
    )));
    let sole = (imitate.support.sole_length, imitate.support.sole_width);
    write_figure(
        &Figure::new("Footsteps, COM and ZMP from above")
            .panel(footsteps_panel(with, sole))
            .panel_size(800, 420),
        dir,
        "walk_footsteps",
    )?;
    figs.push((
        "walk_footsteps.svg".into(),
        "Footsteps from above with the COM and the ZMP".into(),
    ));
    write_figure(&phases_figure(with, &t), dir, "walk_phases")?;
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

/// The column names of walk.csv (times in s, positions in m, tick times in µs).
fn csv_header() -> Vec<String> {
    [
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
    .to_vec()
}

/// The rows of walk.csv, one per tick, in the order of [`csv_header`].
fn csv_rows(with: &WalkRun) -> Vec<Vec<f64>> {
    with.steps
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
        .collect()
}

/// Writes walk_summary.json: both summaries, the footsteps and the phases.
fn write_summary(with: &WalkRun, without: &WalkRun, dir: &Path) -> Result<()> {
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
    Ok(())
}

/// The ZMP over time [m] with the support polygon's extent, and the ZMP deviation after the
/// push [mm], with and without the damping controller.
fn zmp_figure(with: &WalkRun, without: &WalkRun, t: &[f64]) -> Figure {
    let mut fig = Figure::new("ZMP while walking and imitating, push at the dashed event");
    for (i, axis) in ["x", "y"].iter().enumerate() {
        fig = fig.panel(zmp_axis_panel(with, without, t, i, axis));
    }
    fig.panel(
        Panel::new(
            "ZMP deviation after the push (x̃, local frame)",
            "t [s]",
            "deviation [mm]",
        )
        .with(Series::line(
            "controller on",
            t.to_vec(),
            col(with, &|s| 1e3 * s.zmp_deviation[0]),
        ))
        .with(Series::line(
            "controller off",
            t.to_vec(),
            col(without, &|s| 1e3 * s.zmp_deviation[0]),
        )),
    )
}

/// The ZMP along world axis `i` (named `axis`) [m]: reference, measured with and without the
/// controller, and the support polygon's extent along the axis.
fn zmp_axis_panel(with: &WalkRun, without: &WalkRun, t: &[f64], i: usize, axis: &str) -> Panel {
    // The extent of the support polygon along the axis.
    let extent = |fold: fn(f64, f64) -> f64, start: f64| {
        col(with, &|s| s.support.iter().map(|v| v[i]).fold(start, fold))
    };
    let lo = extent(f64::min, f64::INFINITY);
    let hi = extent(f64::max, f64::NEG_INFINITY);
    Panel::new(
        format!("ZMP {axis} (world)"),
        "t [s]",
        format!("{axis} [m]"),
    )
    .with(Series::line(
        "reference",
        t.to_vec(),
        col(with, &|s| s.zmp_reference[i]),
    ))
    .with(Series::line(
        "measured, controller on",
        t.to_vec(),
        col(with, &|s| s.zmp_measured[i]),
    ))
    .with(Series::line(
        "measured, controller off",
        t.to_vec(),
        col(without, &|s| s.zmp_measured[i]),
    ))
    .with(Series::dashed(
        "support polygon extent (soles)",
        t.to_vec(),
        lo,
    ))
    .with(Series::dashed("", t.to_vec(), hi))
}

/// The footsteps (soles of `sole` = length, width [m]) from above with the COM and the ZMP.
fn footsteps_panel(with: &WalkRun, sole: (f64, f64)) -> Panel {
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
    top.with(Series::line(
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
    ))
}

/// The phase timeline, the ankle heights [m], the damping controller's COM offset [mm] and the
/// level IKTC's correction started from.
fn phases_figure(with: &WalkRun, t: &[f64]) -> Figure {
    Figure::new("Support phases, feet and the damping controller")
        .panel(
            Panel::new(
                "support phase (0 double, 1 left stance, 2 right stance)",
                "t [s]",
                "phase",
            )
            .with(Series::line(
                "phase",
                t.to_vec(),
                col(with, &|s| phase_number(s.phase)),
            )),
        )
        .panel(ankle_panel(with, t))
        .panel(
            Panel::new(
                "damping controller: COM offset Δc (world)",
                "t [s]",
                "Δc [mm]",
            )
            .with(Series::line(
                "Δc x",
                t.to_vec(),
                col(with, &|s| 1e3 * s.com_offset[0]),
            ))
            .with(Series::line(
                "Δc y",
                t.to_vec(),
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
                t.to_vec(),
                col(with, &|s| level_number(s.corrected_from)),
            )),
        )
}

/// The ankle heights [m], achieved and referenced, of both feet.
fn ankle_panel(with: &WalkRun, t: &[f64]) -> Panel {
    Panel::new("ankle heights", "t [s]", "z [m]")
        .with(Series::line(
            "left",
            t.to_vec(),
            col(with, &|s| s.feet[0][2]),
        ))
        .with(Series::line(
            "right",
            t.to_vec(),
            col(with, &|s| s.feet[1][2]),
        ))
        .with(Series::dashed(
            "left reference",
            t.to_vec(),
            col(with, &|s| s.feet_reference[0][2]),
        ))
        .with(Series::dashed(
            "right reference",
            t.to_vec(),
            col(with, &|s| s.feet_reference[1][2]),
        ))
}
