//! `iktc imitate`: the humanoid imitation experiment of Section 5.3 (Table 1, Figs. 18–21).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use iktc::limits::BoundMethod;
use iktc::sim::imitate::LEVEL_NAMES;
use iktc::sim::viewer::imitation_viewer;
use iktc::sim::{Experiment, ImitateConfig, ImitateRun};
use iktc::solver::Method;
use iktc_report::{write_csv, write_figure, Figure, Panel, Section, Series, Table};

use crate::columns::level_number;
use crate::scenario::{health_text, prepare, prepare_config, ScenarioArgs};
use crate::viewer::write_viewer;

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
    let narrowed: Vec<(String, usize)> = s
        .narrowed
        .iter()
        .filter_map(|n| {
            e.robot
                .joint_v_index(&n.joint)
                .ok()
                .map(|v| (n.joint.clone(), v))
        })
        .collect();
    // trajectory.csv
    let mut header: Vec<String> = vec!["t".into()];
    for (name, _) in &narrowed {
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
    let rows: Vec<Vec<f64>> = r
        .steps
        .iter()
        .map(|st| {
            let mut v = vec![st.t];
            for (_, d) in &narrowed {
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
        .collect();
    write_csv(&dir.join("trajectory.csv"), &header, &rows)?;
    // joints.csv: every dof position.
    let mut jh: Vec<String> = vec!["t".into()];
    jh.extend(r.dof_names.iter().cloned());
    let jrows: Vec<Vec<f64>> = r
        .steps
        .iter()
        .map(|st| std::iter::once(st.t).chain(st.q.iter().copied()).collect())
        .collect();
    write_csv(&dir.join("joints.csv"), &jh, &jrows)?;
    std::fs::write(
        dir.join("summary.json"),
        crate::finite::to_json("summary.json", s)?,
    )?;
    let tag = format!("{} / {} bounds", s.solver.to_uppercase(), s.bounds);
    let t: Vec<f64> = r.steps.iter().map(|st| st.t).collect();
    let col =
        |f: &dyn Fn(&iktc::sim::ImitateStep) -> f64| r.steps.iter().map(f).collect::<Vec<f64>>();
    let mut figs = Vec::new();
    // Figs. 18–19: q, qd, qdd of the narrowed joints with their limits.
    for (i, (name, d)) in narrowed.iter().enumerate() {
        let d = *d;
        let lim = r.limits[d];
        let num = 18 + i;
        let fig = Figure::new(format!(
            "Fig. {num} — {name}: q, qd, qdd with limits ({tag})"
        ))
        .panel(
            Panel::new(format!("q {name}"), "t [s]", "q [rad]")
                .with(Series::line(
                    format!("q {name}"),
                    t.clone(),
                    col(&|st| st.q[d]),
                ))
                .hline(lim.lower, "lower limit (narrowed)")
                .hline(lim.upper, "upper limit (narrowed)"),
        )
        .panel(
            Panel::new(format!("qd {name}"), "t [s]", "qd [rad/s]")
                .with(Series::line(
                    format!("qd {name}"),
                    t.clone(),
                    col(&|st| st.qd[d]),
                ))
                .hline(lim.velocity, "+v_max")
                .hline(-lim.velocity, "-v_max"),
        )
        .panel(
            Panel::new(format!("qdd {name}"), "t [s]", "qdd [rad/s²]")
                .with(Series::line(
                    format!("qdd {name}"),
                    t.clone(),
                    col(&|st| st.qdd[d]),
                ))
                .with(Series::dashed(
                    "box lower b_l",
                    t.clone(),
                    col(&|st| st.box_lower[d].max(-2.0 * lim.acceleration)),
                ))
                .with(Series::dashed(
                    "box upper b_u",
                    t.clone(),
                    col(&|st| st.box_upper[d].min(2.0 * lim.acceleration)),
                ))
                .hline(lim.acceleration, "+a_max")
                .hline(-lim.acceleration, "-a_max"),
        );
        let stem = format!("fig{num}_{}", name.to_lowercase());
        write_figure(&fig, dir, &stem)?;
        figs.push((format!("{stem}.svg"), format!("Fig. {num}: {name} (narrowed): q, qd, qdd with its limits and the acceleration box ({tag})")));
    }
    // Fig. 20: desired and corrected pelvis height and attitude.
    let fig = Figure::new(format!(
        "Fig. 20 — pelvis height and attitude: desired and corrected ({tag})"
    ))
    .panel(
        Panel::new("pelvis height", "t [s]", "z [m]")
            .with(Series::dashed(
                "desired",
                t.clone(),
                col(&|st| st.pelvis_height_desired),
            ))
            .with(Series::line(
                "corrected (achieved)",
                t.clone(),
                col(&|st| st.pelvis_height),
            )),
    )
    .panel(
        Panel::new("pelvis roll", "t [s]", "roll [rad]")
            .with(Series::dashed(
                "desired",
                t.clone(),
                col(&|st| st.pelvis_rpy_desired[0]),
            ))
            .with(Series::line(
                "corrected (achieved)",
                t.clone(),
                col(&|st| st.pelvis_rpy[0]),
            )),
    )
    .panel(
        Panel::new("pelvis pitch", "t [s]", "pitch [rad]")
            .with(Series::dashed(
                "desired",
                t.clone(),
                col(&|st| st.pelvis_rpy_desired[1]),
            ))
            .with(Series::line(
                "corrected (achieved)",
                t.clone(),
                col(&|st| st.pelvis_rpy[1]),
            )),
    );
    write_figure(&fig, dir, "fig20_pelvis")?;
    figs.push((
        "fig20_pelvis.svg".into(),
        format!("Fig. 20: desired and corrected pelvis height (top) and attitude ({tag})"),
    ));
    // Task errors per level.
    let mut fig = Figure::new(format!("Tracking error of each level ({tag})")).columns(2);
    let units = ["m, rad", "m", "rad", "m", "rad"];
    for (i, l) in LEVEL_NAMES.iter().enumerate() {
        fig = fig.panel(
            Panel::new(
                format!("{} ({} rows)", l, s.level_dims.get(i).copied().unwrap_or(0)),
                "t [s]",
                format!("|x_d - x| [{}]", units[i]),
            )
            .with(Series::line(*l, t.clone(), col(&|st| st.level_error[i]))),
        );
    }
    write_figure(&fig, dir, "task_errors")?;
    figs.push((
        "task_errors.svg".into(),
        format!("Tracking error |x_d − x| of each level ({tag})"),
    ));
    // Which level was corrected, when.
    let mut corr = Panel::new(
        "highest corrected level (0 = none)",
        "t [s]",
        "level (1 = feet … 5 = upper body)",
    )
    .with(Series::points(
        "corrected from",
        t.clone(),
        col(&|st| level_number(st.corrected_from)),
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
        mags = mags.with(Series::line(*l, t.clone(), col(&|st| st.correction[i])));
    }
    write_figure(
        &Figure::new(format!("Task corrections ({tag})"))
            .panel(corr)
            .panel(mags),
        dir,
        "corrections",
    )?;
    figs.push((
        "corrections.svg".into(),
        format!("Which level was corrected, when, and by how much ({tag})"),
    ));
    let mut viewer = imitation_viewer(r, e)?;
    crate::viewer::attach(&mut viewer, &e.robot, meshes)?;
    write_viewer(&dir.join("viewer.html"), &viewer)?;
    Ok(figs)
}

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

/// Runs the default imitation (JVRC-1, humanoid3d_dance_b) with IKTC, GF, the paper's bound
/// and Algorithm 2 as printed with the viable bounds under `out/imitate`, and returns the report
/// section.
pub fn imitate_section(out: &Path) -> Result<Section> {
    let base = out.join("imitate");
    let (e, _) = Experiment::jvrc1()?;
    let mut sec = Section::new("Imitating a captured motion with JVRC-1 (Section 5.3)").intro(
        "<p>The DeepMimic clip <code>humanoid3d_dance_b</code> is retargeted onto JVRC-1 (built-in map <code>deepmimic_jvrc1</code>: \
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
         than their limits and leave their ranges (they are clamped), so the upper-body level, the lowest, is corrected most of the time.</p>",
    );
    let mut table = Table::new(
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
    );
    let mut runs = Vec::new();
    // The last run is Algorithm 2 as printed with the viable bounds, to show the smoothness
    // figures beside the defaults'.
    let defaults = ImitateConfig::jvrc1();
    for (name, method, bounds, hold, continuity, smoothing) in [
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
    ] {
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
        sec = sec.link(
            format!("imitate/{name}/trajectory.csv"),
            format!("{name}: trajectory.csv"),
        );
        runs.push(r);
    }
    // IKTC against GF: what each sacrifices (errata 3.2: IKTC's single QP is not lexicographic).
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
    write_figure(&cmp, &base, "iktc_vs_gf")?;
    sec = sec.figure("imitate/iktc_vs_gf.svg", "IKTC and GF side by side: errors of the pelvis attitude, pelvis height and upper-body levels");
    Ok(sec.table(table))
}
