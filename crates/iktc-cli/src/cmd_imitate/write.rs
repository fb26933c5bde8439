//! The output files of an imitation run: trajectory.csv, joints.csv, summary.json, the figures
//! and viewer.html.

use std::path::Path;

use anyhow::{Context, Result};
use iktc::sim::imitate::LEVEL_NAMES;
use iktc::sim::viewer::imitation_viewer;
use iktc::sim::{Experiment, ImitateRun, ImitateStep};
use iktc_report::{write_csv, write_figure, Figure, Panel, Series};

use crate::columns::level_number;
use crate::viewer::write_viewer;

/// One column of a run: `f` of every tick.
fn col(r: &ImitateRun, f: &dyn Fn(&ImitateStep) -> f64) -> Vec<f64> {
    r.steps.iter().map(f).collect()
}

/// Writes trajectory.csv, summary.json, the figures and viewer.html; returns the figures
/// (path relative to `dir`, caption).
pub fn write_imitate(
    r: &ImitateRun,
    e: &Experiment,
    meshes: Option<&iktc::mesh::MeshSet>,
    dir: &Path,
) -> Result<Vec<(String, String)>> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let s = &r.summary;
    let narrowed = narrowed_dofs(r, e);
    write_csv(
        &dir.join("trajectory.csv"),
        &trajectory_header(&narrowed),
        &trajectory_rows(r, &narrowed),
    )?;
    write_joints(r, dir)?;
    std::fs::write(
        dir.join("summary.json"),
        crate::finite::to_json("summary.json", s)?,
    )?;
    let tag = format!("{} / {} bounds", s.solver.to_uppercase(), s.bounds);
    let t: Vec<f64> = r.steps.iter().map(|st| st.t).collect();
    let mut figs = Vec::new();
    // Figs. 18–19: q, qd, qdd of the narrowed joints with their limits.
    for (i, (name, d)) in narrowed.iter().enumerate() {
        let num = 18 + i;
        let fig = joint_figure(r, &t, name, *d, num, &tag);
        let stem = format!("fig{num}_{}", name.to_lowercase());
        write_figure(&fig, dir, &stem)?;
        figs.push((format!("{stem}.svg"), format!("Fig. {num}: {name} (narrowed): q, qd, qdd with its limits and the acceleration box ({tag})")));
    }
    write_figure(&pelvis_figure(r, &t, &tag), dir, "fig20_pelvis")?;
    figs.push((
        "fig20_pelvis.svg".into(),
        format!("Fig. 20: desired and corrected pelvis height (top) and attitude ({tag})"),
    ));
    write_figure(&errors_figure(r, &t, &tag), dir, "task_errors")?;
    figs.push((
        "task_errors.svg".into(),
        format!("Tracking error |x_d − x| of each level ({tag})"),
    ));
    write_figure(&corrections_figure(r, &t, &tag), dir, "corrections")?;
    figs.push((
        "corrections.svg".into(),
        format!("Which level was corrected, when, and by how much ({tag})"),
    ));
    let mut viewer = imitation_viewer(r, e)?;
    crate::viewer::attach(&mut viewer, &e.robot, meshes)?;
    write_viewer(&dir.join("viewer.html"), &viewer)?;
    Ok(figs)
}

/// The narrowed joints of the run that the robot has: (joint name, velocity index).
fn narrowed_dofs(r: &ImitateRun, e: &Experiment) -> Vec<(String, usize)> {
    r.summary
        .narrowed
        .iter()
        .filter_map(|n| {
            e.robot
                .joint_v_index(&n.joint)
                .ok()
                .map(|v| (n.joint.clone(), v))
        })
        .collect()
}

/// The column names of trajectory.csv: time, the narrowed joints' motion and acceleration box,
/// the pelvis, each level's error and correction, the COM and the tick's cost.
fn trajectory_header(narrowed: &[(String, usize)]) -> Vec<String> {
    let mut header: Vec<String> = vec!["t".into()];
    for (name, _) in narrowed {
        for p in ["q", "qd", "qdd", "box_lower", "box_upper"] {
            header.push(format!("{p}_{name}"));
        }
    }
    header.extend(["pelvis_height_desired", "pelvis_height"].map(String::from));
    for p in ["desired", "actual"] {
        for a in ["roll", "pitch", "yaw"] {
            header.push(format!("pelvis_{a}_{p}"));
        }
    }
    for l in LEVEL_NAMES {
        header.push(format!("error_{l}"));
    }
    for l in LEVEL_NAMES {
        header.push(format!("correction_{l}"));
    }
    header.extend(
        [
            "corrected_from_level",
            "com_x",
            "com_y",
            "com_margin",
            "foot_drift",
            "qp_solves",
            "tick_us",
        ]
        .map(String::from),
    );
    header
}

/// The rows of trajectory.csv, one per tick, in the order of [`trajectory_header`].
fn trajectory_rows(r: &ImitateRun, narrowed: &[(String, usize)]) -> Vec<Vec<f64>> {
    r.steps
        .iter()
        .map(|st| {
            let mut v = vec![st.t];
            for (_, d) in narrowed {
                v.extend([
                    st.q[*d],
                    st.qd[*d],
                    st.qdd[*d],
                    st.box_lower[*d],
                    st.box_upper[*d],
                ]);
            }
            v.extend([st.pelvis_height_desired, st.pelvis_height]);
            v.extend(st.pelvis_rpy_desired);
            v.extend(st.pelvis_rpy);
            v.extend(st.level_error);
            v.extend(st.correction);
            v.extend([
                level_number(st.corrected_from),
                st.com[0],
                st.com[1],
                st.com_margin,
                st.foot_drift,
                st.qp_solves as f64,
                st.tick_us,
            ]);
            v
        })
        .collect()
}

/// Writes joints.csv: every dof position [rad or m] over time [s].
fn write_joints(r: &ImitateRun, dir: &Path) -> Result<()> {
    let mut jh: Vec<String> = vec!["t".into()];
    jh.extend(r.dof_names.iter().cloned());
    let jrows: Vec<Vec<f64>> = r
        .steps
        .iter()
        .map(|st| std::iter::once(st.t).chain(st.q.iter().copied()).collect())
        .collect();
    write_csv(&dir.join("joints.csv"), &jh, &jrows)?;
    Ok(())
}

/// Fig. `num` (18 or 19): q [rad], qd [rad/s], qdd [rad/s²] of the narrowed joint `name` (dof
/// `d`) with its limits and the acceleration box.
fn joint_figure(r: &ImitateRun, t: &[f64], name: &str, d: usize, num: usize, tag: &str) -> Figure {
    let lim = r.limits[d];
    Figure::new(format!(
        "Fig. {num} — {name}: q, qd, qdd with limits ({tag})"
    ))
    .panel(
        Panel::new(format!("q {name}"), "t [s]", "q [rad]")
            .with(Series::line(
                format!("q {name}"),
                t.to_vec(),
                col(r, &|st| st.q[d]),
            ))
            .hline(lim.lower, "lower limit (narrowed)")
            .hline(lim.upper, "upper limit (narrowed)"),
    )
    .panel(
        Panel::new(format!("qd {name}"), "t [s]", "qd [rad/s]")
            .with(Series::line(
                format!("qd {name}"),
                t.to_vec(),
                col(r, &|st| st.qd[d]),
            ))
            .hline(lim.velocity, "+v_max")
            .hline(-lim.velocity, "-v_max"),
    )
    .panel(
        Panel::new(format!("qdd {name}"), "t [s]", "qdd [rad/s²]")
            .with(Series::line(
                format!("qdd {name}"),
                t.to_vec(),
                col(r, &|st| st.qdd[d]),
            ))
            .with(Series::dashed(
                "box lower b_l",
                t.to_vec(),
                col(r, &|st| st.box_lower[d].max(-2.0 * lim.acceleration)),
            ))
            .with(Series::dashed(
                "box upper b_u",
                t.to_vec(),
                col(r, &|st| st.box_upper[d].min(2.0 * lim.acceleration)),
            ))
            .hline(lim.acceleration, "+a_max")
            .hline(-lim.acceleration, "-a_max"),
    )
}

/// Fig. 20: desired and corrected pelvis height [m] and attitude (roll, pitch) [rad].
fn pelvis_figure(r: &ImitateRun, t: &[f64], tag: &str) -> Figure {
    Figure::new(format!(
        "Fig. 20 — pelvis height and attitude: desired and corrected ({tag})"
    ))
    .panel(
        Panel::new("pelvis height", "t [s]", "z [m]")
            .with(Series::dashed(
                "desired",
                t.to_vec(),
                col(r, &|st| st.pelvis_height_desired),
            ))
            .with(Series::line(
                "corrected (achieved)",
                t.to_vec(),
                col(r, &|st| st.pelvis_height),
            )),
    )
    .panel(
        Panel::new("pelvis roll", "t [s]", "roll [rad]")
            .with(Series::dashed(
                "desired",
                t.to_vec(),
                col(r, &|st| st.pelvis_rpy_desired[0]),
            ))
            .with(Series::line(
                "corrected (achieved)",
                t.to_vec(),
                col(r, &|st| st.pelvis_rpy[0]),
            )),
    )
    .panel(
        Panel::new("pelvis pitch", "t [s]", "pitch [rad]")
            .with(Series::dashed(
                "desired",
                t.to_vec(),
                col(r, &|st| st.pelvis_rpy_desired[1]),
            ))
            .with(Series::line(
                "corrected (achieved)",
                t.to_vec(),
                col(r, &|st| st.pelvis_rpy[1]),
            )),
    )
}

/// The tracking error |x_d − x| of each level (m or rad).
fn errors_figure(r: &ImitateRun, t: &[f64], tag: &str) -> Figure {
    let mut fig = Figure::new(format!("Tracking error of each level ({tag})")).columns(2);
    let units = ["m, rad", "m", "rad", "m", "rad"];
    for (i, l) in LEVEL_NAMES.iter().enumerate() {
        fig = fig.panel(
            Panel::new(
                format!(
                    "{} ({} rows)",
                    l,
                    r.summary.level_dims.get(i).copied().unwrap_or(0)
                ),
                "t [s]",
                format!("|x_d - x| [{}]", units[i]),
            )
            .with(Series::line(
                *l,
                t.to_vec(),
                col(r, &|st| st.level_error[i]),
            )),
        );
    }
    fig
}

/// Which level was corrected, when, and the size of the corrections |Δh_i| [task unit/s²].
fn corrections_figure(r: &ImitateRun, t: &[f64], tag: &str) -> Figure {
    let mut corr = Panel::new(
        "highest corrected level (0 = none)",
        "t [s]",
        "level (1 = feet … 5 = upper body)",
    )
    .with(Series::points(
        "corrected from",
        t.to_vec(),
        col(r, &|st| level_number(st.corrected_from)),
    ));
    corr = corr
        .hline(3.0, "pelvis attitude")
        .hline(4.0, "pelvis height");
    let mut mags = Panel::new(
        "size of the corrections |Δh_i|",
        "t [s]",
        "|Δh| [task unit/s²]",
    );
    for (i, l) in LEVEL_NAMES.iter().enumerate().skip(2) {
        mags = mags.with(Series::line(*l, t.to_vec(), col(r, &|st| st.correction[i])));
    }
    Figure::new(format!("Task corrections ({tag})"))
        .panel(corr)
        .panel(mags)
}
